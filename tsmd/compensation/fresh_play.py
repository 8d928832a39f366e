"""A fresh catheter's branches: never loaded, straight until its first release has ended.

The conditioned model is :func:`tsmd.compensation.tension_play.branches`; a fresh catheter
(the bench's fresh plant, a new catheter on a product profile) differs from it until its first
release hands over to the other tendon (:func:`fresh_state_ends`), by the profile's
``fresh_hold_deg`` and ``fresh_edge_delay_deg`` (:mod:`tsmd.calibration.fresh_hold`).
"""

from __future__ import annotations

from tsmd.compensation.tension_play import (
    _FAR_DEG,
    _FLAT_SLOPE,
    Branches,
    PlayState,
    interp_linear,
    widest_flat,
)


def fresh_branches(b: Branches, omega: float, d_pos: float, d_neg: float, h_pos: float,
                   h_neg: float, hold_deg: float, edge_delay_deg: float | None = None,
                   side: int = 0) -> Branches:
    """The branches of a fresh catheter (straight, never loaded) until its first release ends.

    On the capstan plant a fresh catheter's first loading starts from straight (tip 0) at its
    current edge, ``edge_delay_deg`` beyond the conditioned edge (None: not known), which puts
    its loaded line outward of the conditioned one; and its first release stops early: the
    tip holds where the other side's loaded line is ``hold_deg`` knob degrees inside its edge
    (``H_neg + omega hold`` after a positive loading, mirrored after a negative one), then
    follows that (conditioned) loaded line; from then on the catheter is conditioned
    (:func:`branches`). ``side``: the side loaded first (0: none yet, both lines shifted and no
    hold; +1: the rising line shifted and the positive hold; -1 mirrored).
    """
    if hold_deg <= 0.0 and edge_delay_deg is None:
        return b
    y_pos = h_neg + omega * hold_deg  # the hold after a positive loading
    y_neg = h_pos - omega * hold_deg
    # how far outward (knob deg) the first loaded line lies: from straight at the delayed edge
    s_pos = s_neg = 0.0
    if edge_delay_deg is not None:
        s_pos = max(-h_pos / omega - edge_delay_deg, 0.0) if side >= 0 else 0.0
        s_neg = max(h_neg / omega - edge_delay_deg, 0.0) if side <= 0 else 0.0

    def untilted(x: float, ys: tuple[float, ...]) -> float:
        return interp_linear(x, b.knots, ys) - _FLAT_SLOPE * omega * x

    def falling(x: float) -> float:
        f = untilted(x, b.falling_deg)
        if side > 0:
            f = max(f, min(y_pos, h_neg + omega * (x - d_neg)))
        return min(f, h_neg + omega * (x - s_neg - d_neg)) if x - s_neg < d_neg else f

    def rising(x: float) -> float:
        r = untilted(x, b.rising_deg)
        if side < 0:
            r = min(r, max(y_neg, h_pos + omega * (x - d_pos)))
        return max(r, h_pos + omega * (x + s_pos - d_pos)) if x + s_pos > d_pos else r

    extra = [d_neg + hold_deg, d_pos - hold_deg, d_pos - s_pos, d_neg + s_neg]
    extra += [b.falling_inverse(y_pos), b.rising_inverse(y_neg)] if hold_deg > 0.0 else []
    xs = sorted({*b.knots, *(x for x in extra if -_FAR_DEG < x < _FAR_DEG)})
    xs = [x for i, x in enumerate(xs) if i == 0 or x - xs[i - 1] > 1e-9]
    r = [rising(x) for x in xs]
    f = [falling(x) for x in xs]
    # the outward-shifted lines may cross: where they do, the envelopes have a kink too
    for i in range(len(xs) - 1):
        da, db = r[i] - f[i], r[i + 1] - f[i + 1]
        if da * db < 0.0:
            xs.append(xs[i] + (xs[i + 1] - xs[i]) * da / (da - db))
    xs = sorted(xs)
    lo = [min(rising(x), falling(x)) + _FLAT_SLOPE * omega * x for x in xs]
    hi = [max(rising(x), falling(x)) + _FLAT_SLOPE * omega * x for x in xs]
    return Branches(tuple(xs), tuple(lo), tuple(hi), widest_flat(xs, lo, omega),
                    widest_flat(xs, hi, omega))


def fresh_state_ends(state: PlayState, first_side: int, h_pos: float, h_neg: float,
                     margin_deg: float = 0.5) -> bool:
    """True once a fresh knob's first release has handed over to the other tendon for good:
    after a first positive loading the output went below the falling plateau ``h_neg`` (on the
    negative loaded line, where the fresh and the conditioned branches agree), mirrored after a
    negative one. Above it the conditioned model's falling branch is the release line, which
    the tip on the loaded line is not on."""
    if first_side > 0 and state.direction < 0:
        return state.y_deg < h_neg - margin_deg
    if first_side < 0 and state.direction > 0:
        return state.y_deg > h_pos + margin_deg
    return False
