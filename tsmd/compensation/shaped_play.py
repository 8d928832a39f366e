"""The tension play's branches with loaded lines bent by a per-product template.

:func:`tsmd.compensation.tension_play.branches` with each side's loaded line bent by its
:class:`tsmd.compensation.loaded_shape.LoadedShape` (the release lines stay straight); without a
(curved) template the straight model's own function is used, so its commands stay bit for bit.
"""

from __future__ import annotations

from tsmd.compensation.loaded_shape import LoadedShape, curved
from tsmd.compensation.tension_play import _FAR_DEG, Branches, branches, envelopes
from tsmd.compensation.tension_play_params import BETA_RANGE

_STRAIGHT = LoadedShape((0.0, 1.0), (0.0, 1.0))


def model_branches(omega: float, height_pos_deg: float, height_neg_deg: float, d_pos: float,
                   d_neg: float, beta_pos: float, beta_neg: float, x0_pos: float,
                   x0_neg: float, shape_pos: LoadedShape | None = None,
                   shape_neg: LoadedShape | None = None) -> Branches:
    """The branches of one knob: straight (``branches``) unless a side has a curved template."""
    sp, sn = curved(shape_pos), curved(shape_neg)
    if sp is None and sn is None:
        return branches(omega, height_pos_deg, height_neg_deg, d_pos, d_neg, beta_pos,
                        beta_neg, x0_pos, x0_neg)
    return shaped_branches(omega, height_pos_deg, height_neg_deg, d_pos, d_neg, beta_pos,
                           beta_neg, x0_pos, x0_neg, sp, sn)


def shaped_branches(omega: float, height_pos_deg: float, height_neg_deg: float, d_pos: float,
                    d_neg: float, beta_pos: float, beta_neg: float, x0_pos: float,
                    x0_neg: float, shape_pos: LoadedShape | None,
                    shape_neg: LoadedShape | None) -> Branches:
    """``tension_play.branches`` with each side's loaded line bent by its template.

    rising  = H_pos + omega T_pos(max(x - D_pos, 0)) + min(R_neg(x) - H_pos, 0)
    falling = H_neg - omega T_neg(max(D_neg - x, 0)) + max(R_pos(x) - H_neg, 0)
    The release lines R stay straight, as the data sheet's release slope ratio was measured
    (``tension_play.release_line``), and pass where the bent loaded line ends at the
    template's far end: R_pos(x) = H_pos + omega (a_pos(x) + T_pos(u_end) - u_end) with
    a_pos(x) = (x - beta x0) / (1 - beta) - D_pos, R_neg mirrored. Bending them too moved
    the tip's release on the blind plant by up to 9 deg (docs/model.md, session 10).
    Sampled at every knot the templates map to, so the piecewise-linear result is exact.
    """
    w, h_pos, h_neg = omega, height_pos_deg, height_neg_deg
    sp = shape_pos if shape_pos is not None else _STRAIGHT
    sn = shape_neg if shape_neg is not None else _STRAIGHT
    bp = min(max(beta_pos, BETA_RANGE[0]), BETA_RANGE[1])
    bn = min(max(beta_neg, BETA_RANGE[0]), BETA_RANGE[1])

    def a_pos(x: float) -> float:  # the release line's argument, knob deg past the edge
        return (x - bp * x0_pos) / (1.0 - bp) - d_pos

    def a_neg(x: float) -> float:
        return (x - bn * x0_neg) / (1.0 - bn) - d_neg

    def x_pos(a: float) -> float:  # inverse of a_pos
        return (a + d_pos) * (1.0 - bp) + bp * x0_pos

    def x_neg(a: float) -> float:
        return (a + d_neg) * (1.0 - bn) + bn * x0_neg

    off_pos, off_neg = sp.far_offset_deg, sn.far_offset_deg

    def rising(x: float) -> float:
        return (h_pos + w * sp.at(max(x - d_pos, 0.0))
                + min(h_neg + w * (a_neg(x) - off_neg) - h_pos, 0.0))

    def falling(x: float) -> float:
        return (h_neg - w * sn.at(max(d_neg - x, 0.0))
                + max(h_pos + w * (a_pos(x) + off_pos) - h_neg, 0.0))

    kinks = {-_FAR_DEG, _FAR_DEG, d_pos, d_neg,
             x_neg((h_pos - h_neg) / w + off_neg),  # R_neg meets the rising plateau
             x_pos((h_neg - h_pos) / w - off_pos)}  # R_pos meets the falling plateau
    kinks.update(d_pos + u for u in sp.travel_deg)
    kinks.update(d_neg - u for u in sn.travel_deg)
    return envelopes(kinks, rising, falling, w)
