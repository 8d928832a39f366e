"""Tension-play parameters of one catheter from its calibration sweeps (motor current only).

Per sweep (one knob swept +-A, the other held at a grid angle) and side:

* the dead-zone edge ``D``: what the current analysis (:mod:`tsmd.calibration.identify`) found
  (no data-sheet offset: that was one unit's); the backlash at the amplitude ``B_A``: the
  profile's B, by the rule the product's data sheet chose (session 12: the settle rule's B,
  used before whatever the product's rule, read 1.5-2.3x the tip's backlash on a coilpipe unit
  whose sheet chose the local rule, and ours lost to the paper's there);
* the zero-tension point ``x0``: the loaded current ramp (from 10 deg past ``D`` to 5 deg before
  the turn) fitted by a line and extrapolated to the current that moves the knob the same way
  through the dead zone, where no tendon is loaded (friction and any sensor offset cancel);
* ``beta = B_A / (A - x0)``: the backlash grows with the load, and the load with ``x - x0``;
* the loaded slope ``omega``: per unit, from the backlash gains the current shows against the
  data-sheet unit's (:mod:`tsmd.calibration.unit_slope`);
* the release line's slope: the locus of backlash ends has slope ``omega / (1 - beta)``, but
  where a product's release path after the backlash is shallower or steeper than that locus (a
  lumped catheter's is 7 % shallower; the current cannot see it: a released tendon's current is
  friction only), the data sheet's tracked ``release_omega`` gives the product's ratio
  ``release_omega (1 - beta_sheet) / omega_sheet``
  (:func:`tsmd.compensation.release_ratio.release_slope_ratio`); the unit's
  release line then has that ratio times its own locus slope and still passes through its own
  backlash end at the calibration amplitude (:func:`~tsmd.calibration.release_path.
  release_through_amplitude`);
* the plateau heights ``H``: product constants, from the data sheet's reference points through
  the edges the current showed on the data-sheet unit (``reference_dead_zone_*_deg``), so that
  each unit's loaded line moves with its own edges (more slack: the tip reaches less at +-90).
  Without those data-sheet keys, the paper's assumption: the line through the reference point
  and this unit's own edge at 0 deg. Where the sheet opts in to the dead-zone loop
  (``plateau_gap_deg``, ``plateau_gap_factor``), each unit's own plateau moves them apart by
  ``factor (gap - sheet's gap) / 2``, the gap read from its loop's current
  (:mod:`tsmd.calibration.dead_zone_loop`, session 25). Where the sheet keeps its unit's
  tracked flats (``flat_height_*_deg``, session 28) they are the heights, no line drawn back.

``beta`` and ``x0`` scatter from sweep to sweep (``B_A`` by about 1 deg); over the grid they are
smoothed by a least-squares polynomial in the other knob's angle (degree 2; on three grid points
that passes through each), which keeps a trend the coupling gives and removes the scatter. The
edges ``D``, which coupling can move steeply, get a running median of three instead (a value
confidently off that median is kept). ``lag_s`` is the delay that maps
commanded onto actual position. The tip is never used.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.dead_zone_loop import plateau_shift_deg
from tsmd.calibration.edge_level import edge_level_grid
from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.fresh_hold import with_fresh_hold
from tsmd.calibration.identify import settle_rule_backlash
from tsmd.calibration.lag import estimate_lag_s
from tsmd.calibration.load_ramp import SideFit, fit_sweep_sides
from tsmd.calibration.loaded_knee import sweep_knees
from tsmd.calibration.read_gain import BACKLASH_NAMES, read_gains, read_side_ratio
from tsmd.calibration.reading_offset import calibrated_edges, offset_at, reference_edge_deg
from tsmd.calibration.release_end import plateau_moved, side_ratios
from tsmd.calibration.release_path import release_through_amplitude
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.unit_slope import GainReading, gain_scatter, weighed_omega
from tsmd.compensation.level_grid import LevelGrid
from tsmd.compensation.loaded_shape import curved, shaped_height
from tsmd.compensation.paper import at_other_knob_zero, plateau_heights
from tsmd.compensation.release_ratio import RELEASE_RATIO_RANGE, release_slope_ratio
from tsmd.compensation.tension_play_params import BETA_RANGE, TensionPlayParams

FloatArray = NDArray[np.float64]
@dataclass(frozen=True)
class SweepCurrent:
    """One sweep's arrays (uncompensated) and the current analysis' D and B (deg)."""

    other_knob_deg: float
    t_s: FloatArray
    cmd_deg: FloatArray
    pos_deg: FloatArray
    current_A: FloatArray
    dead_zone_pos_deg: float
    dead_zone_neg_deg: float
    backlash_pos_deg: float
    backlash_neg_deg: float
    lag_s: float | None = None
    """The drive's lag when already estimated; None: estimated here from t, cmd and pos."""
    dead_zone_u95_deg: tuple[float, float] = (math.inf, math.inf)
    """The calibration's 95 % uncertainty of (D_pos, D_neg); inf: unknown (always smoothed)."""
    settle_backlash_deg: tuple[float, float] | None = None
    """The settle rule's (B_pos, B_neg) where the B above is another rule's: a sheet whose gain
    was read with the settle rule scales omega by a unit gain read the same way. None: the B
    above is the settle rule's."""
    backlash_unseen: tuple[bool, bool] = (False, False)
    """(+, -): the current did not show that backlash (the B is the sheet's, no reading offset
    was subtracted from it)."""
    own_offset_deg: tuple[float | None, float | None] = (None, None)
    """(+, -): the unit's own reading offset where its current showed the play's end
    (:mod:`tsmd.calibration.play_engage`); None: the sheet's was subtracted."""


def smooth_over_grid(grid_deg: Sequence[float], values: Sequence[float]) -> list[float]:
    """Least-squares polynomial over the grid: degree 2 (a coupling that differs at both ends
    of the other knob's range from its middle is at least quadratic; on three grid points a
    line moved the middle's value by the ends', and with it ``omega``), fewer on fewer points
    (n - 1: through every point)."""
    g = np.asarray(grid_deg, float)
    y = np.asarray(values, float)
    degree = max(0, min(2, g.size - 1))
    coef = np.polyfit(g, y, degree)
    return [float(v) for v in np.polyval(coef, g)]


def median_of_three(values: Sequence[float], u95_deg: Sequence[float] | None = None
                    ) -> list[float]:
    """Each inner grid value replaced by the median of it and its neighbours: removes one
    sweep's outlier (an edge scatters by ~0.5 deg per sweep) and keeps any monotone trend the
    coupling of the knobs gives exactly. With the calibration's 95 % uncertainties
    (``u95_deg``), a value farther from that median than both uncertainties together is kept:
    it is the catheter's, not scatter (a dead zone wider at both ends of the other knob's range
    than at 0, a V, has its vertex at a grid point that the median would move onto a wing)."""
    v = [float(x) for x in values]
    if len(v) < 3:
        return v
    u = [math.inf] * len(v) if u95_deg is None else [float(x) for x in u95_deg]
    out = list(v)
    for i in range(1, len(v) - 1):
        j = i - 1 + int(np.argsort(v[i - 1:i + 2], kind="stable")[1])
        if not abs(v[i] - v[j]) > u[i] + u[j]:
            out[i] = v[j]
    return out


def fit_tension_play(sweeps: Sequence[SweepCurrent], device_knob: Any,
                     plateau_gap_deg: float | None = None) -> TensionPlayParams:
    """One knob's parameters from all its sweeps (ValueError naming the sweep that fails).

    ``device_knob``: the data sheet's knob (``omega``, ``reference_pos``/``_neg`` and optionally
    ``reference_dead_zone_*_deg``), measured once per product on another unit.
    ``plateau_gap_deg``: this unit's dead-zone loop gap (:mod:`tsmd.calibration.dead_zone_loop`);
    with the sheet's ``plateau_gap_deg`` and ``plateau_gap_factor`` it moves the plateau heights
    apart by ``factor (gap - sheet's) / 2`` each (None, or a sheet without them: unchanged).
    """
    if len(sweeps) < 2:
        raise ValueError("needs sweeps at >= 2 other-knob angles")
    order = sorted(sweeps, key=lambda s: s.other_knob_deg)
    grid = [float(s.other_knob_deg) for s in order]
    if any(b <= a for a, b in itertools.pairwise(grid)):
        raise ValueError(f"two sweeps at the same other-knob angle: {grid}")
    pos_fits: list[SideFit] = []
    neg_fits: list[SideFit] = []
    for s in order:
        where = f"sweep with the other knob at {s.other_knob_deg:+.0f} deg"
        values = (s.dead_zone_pos_deg, s.dead_zone_neg_deg, s.backlash_pos_deg,
                  s.backlash_neg_deg)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"{where}: no finite D/B from the current: {values}")
        try:
            fit_pos, fit_neg = fit_sweep_sides(s.pos_deg, s.current_A, *values)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None
        pos_fits.append(fit_pos)
        neg_fits.append(fit_neg)
    d_pos = median_of_three([f.dead_zone_deg for f in pos_fits],
                            [s.dead_zone_u95_deg[0] for s in order])
    d_neg = median_of_three([f.dead_zone_deg for f in neg_fits],
                            [s.dead_zone_u95_deg[1] for s in order])
    k = device_knob
    # H: with the data-sheet unit's own edges a product constant (the unit's loaded line moves
    # with its edges); without them the paper's assumption (the line through the reference point)
    ref_pos = getattr(k, "reference_dead_zone_pos_deg", None)
    ref_neg = getattr(k, "reference_dead_zone_neg_deg", None)
    # the sheet's edges were read from current; the unit's are corrected by the product's
    # reading offset (other knob at 0, where the sheet read them): read both the same way
    offset = getattr(k, "reading_offset", None)
    ref_pos = reference_edge_deg(offset, "dead_zone_pos_deg", ref_pos)
    ref_neg = reference_edge_deg(offset, "dead_zone_neg_deg", ref_neg)
    edge_pos = at_other_knob_zero(grid, d_pos) if ref_pos is None else float(ref_pos)
    edge_neg = at_other_knob_zero(grid, d_neg) if ref_neg is None else float(ref_neg)
    edge_pos, edge_neg = calibrated_edges(k, edge_pos, edge_neg)  # read as a unit's (s26)
    h_pos, h_neg = plateau_heights(k, edge_pos, edge_neg)
    # the product's loaded-branch template (data sheet) bends the line through the reference
    shape_pos = curved(getattr(k, "loaded_shape_pos", None))
    shape_neg = curved(getattr(k, "loaded_shape_neg", None))
    shape_grid = getattr(k, "loaded_shape_grid", None)
    if shape_grid is not None:  # templates over the other knob: H where the sheet read it, at 0
        shape_pos, shape_neg = (curved(g.at(0.0)) for g in shape_grid)
    if shape_pos is not None:
        h_pos = shaped_height(k.reference_pos.knob_deg, k.reference_pos.tip_deg, edge_pos,
                              float(k.omega), shape_pos)
    if shape_neg is not None:
        h_neg = shaped_height(k.reference_neg.knob_deg, k.reference_neg.tip_deg, edge_neg,
                              float(k.omega), shape_neg)
    # the sheet unit's tracked flats where its sheet keeps them (session 28): no line drawn back
    flat_pos, flat_neg = (getattr(k, f"flat_height_{s}_deg", None) for s in ("pos", "neg"))
    if flat_pos is not None and flat_neg is not None:
        h_pos, h_neg = float(flat_pos), float(flat_neg)
    # the unit's own plateau, from its dead-zone loop against the sheet unit's (session 25)
    shift = plateau_shift_deg(plateau_gap_deg, getattr(k, "plateau_gap_deg", None),
                              getattr(k, "plateau_gap_factor", None))
    if shift != 0.0:
        h_pos, h_neg = h_pos - shift, h_neg + shift
    # the knee past the edge as the current read it (the sheet's is read so): the product's
    # reading offset the calibration subtracted from the edges added back
    near_zero = min(order, key=lambda w: abs(w.other_knob_deg))  # where the sheet reads its own
    read_pos, read_neg = ((0.0 if offset is None
                           else offset_at(offset, name, near_zero.other_knob_deg)[0])
                          for name in ("dead_zone_pos_deg", "dead_zone_neg_deg"))
    knee, knee_u95 = sweep_knees(near_zero.pos_deg, near_zero.current_A,
                                 near_zero.dead_zone_pos_deg + read_pos,
                                 near_zero.dead_zone_neg_deg + read_neg)
    ks_pos, ks_neg = (getattr(k, f"loaded_knee_{s}_deg", None) for s in ("pos", "neg"))
    lag = float(np.median([estimate_lag_s(np.asarray(s.t_s, float), np.asarray(s.cmd_deg, float),
                                          np.asarray(s.pos_deg, float))
                           if s.lag_s is None else s.lag_s for s in order]))
    beta_pos = smoothed_gains(grid, [f.backlash_gain for f in pos_fits])
    beta_neg = smoothed_gains(grid, [f.backlash_gain for f in neg_fits])
    # the unit's gains with B as the current read it, as the sheet's were (session 23)
    read = read_gains(k, [s.backlash_unseen for s in order], pos_fits, neg_fits,
                      [s.own_offset_deg for s in order])
    omega = loaded_slope(k, grid, order, pos_fits, neg_fits, read)  # scatter: per sweep
    raw_pos, raw_neg = (smoothed_gains(grid, g) for g in read)
    ratio = release_slope_ratio(k)
    x0_pos, x0_neg = (smooth_over_grid(grid, [f.zero_load_deg for f in fits])
                      for fits in (pos_fits, neg_fits))
    ratios = (ratio, ratio)
    if getattr(k, "reference_release_end_offset_deg", None) is not None:
        # the release drawn to its end in this unit's current (session 18)
        h_pos, h_neg, d_pos, d_neg = plateau_moved(k, omega, h_pos, h_neg, d_pos, d_neg)
        ratios = side_ratios(order, k, omega, (h_pos, h_neg), (d_pos, d_neg),
                             (beta_pos, beta_neg), (x0_pos, x0_neg), ratio, RELEASE_RATIO_RANGE)
    sides = []
    for betas, reads, x0s, fits, side_ratio in (
            (beta_pos, raw_pos, x0_pos, pos_fits, ratios[0]),
            (beta_neg, raw_neg, x0_neg, neg_fits, ratios[1])):
        moved = [release_through_amplitude(b, x0, f.amplitude_deg,
                                           read_side_ratio(side_ratio, b, r))
                 for b, r, x0, f in zip(betas, reads, x0s, fits, strict=True)]
        sides.append((tuple(m[0] for m in moved), tuple(m[1] for m in moved)))
    return TensionPlayParams(
        omega=omega, height_pos_deg=float(h_pos), height_neg_deg=float(h_neg),
        other_knob_deg=tuple(grid), dead_zone_pos_deg=tuple(d_pos),
        dead_zone_neg_deg=tuple(d_neg), backlash_gain_pos=sides[0][0],
        backlash_gain_neg=sides[1][0], zero_load_pos_deg=sides[0][1],
        zero_load_neg_deg=sides[1][1], lag_s=min(max(lag, 0.0), 1.0), shape_pos=shape_pos,
        shape_neg=shape_neg, other_tip_gain=float(getattr(k, "other_tip_gain", None) or 0.0),
        shape_grid=shape_grid, loaded_knee_deg=knee, loaded_knee_u95_deg=knee_u95,
        sheet_loaded_knee_deg=(None if ks_pos is None or ks_neg is None
                               else (float(ks_pos), float(ks_neg))),
        release_round=float(getattr(k, "release_round", None) or 0.0),
        release_shift=float(getattr(k, "release_shift", None) or 0.0),
        level_grid=unit_level_grid(k, omega, grid, d_pos, d_neg),
        release_end=getattr(k, "release_end_shape", None),
        hold_at_home=bool(getattr(k, "hold_at_home", None)))


def unit_level_grid(knob: Any, omega: float, grid: Sequence[float],
                    d_pos: Sequence[float], d_neg: Sequence[float]) -> LevelGrid | None:
    """The unit's level grid: the sheet's ``loaded_level_grid`` as it is, or with the sheet's
    ``edge_level_share`` the shift this unit's own edges call for added to it (session 23)."""
    product = getattr(knob, "loaded_level_grid", None)
    share = getattr(knob, "edge_level_share", None)
    if share is None:
        return product
    return edge_level_grid(float(share), omega, grid, d_pos, d_neg, product)


def clamped_gain(beta: float) -> float:
    """A backlash gain held inside :data:`BETA_RANGE`."""
    lo, hi = BETA_RANGE
    return min(max(beta, lo), hi)


def smoothed_gains(grid: Sequence[float], gains: Sequence[float]) -> list[float]:
    """Backlash gains smoothed over the other knob's grid, held inside :data:`BETA_RANGE`."""
    return [clamped_gain(b) for b in smooth_over_grid(grid, gains)]


def gain_reading(sheet_gain: float, grid: Sequence[float], pos: Sequence[float],
                 neg: Sequence[float]) -> GainReading:
    """This unit's gains by one rule, smoothed over the grid and read at the other knob's 0
    (where the sheet measured its gain; mean of both sides), with their raw scatter."""
    at_zero = 0.5 * (at_other_knob_zero(grid, smoothed_gains(grid, pos))
                     + at_other_knob_zero(grid, smoothed_gains(grid, neg)))
    return GainReading(sheet_gain, at_zero, gain_scatter(pos, neg))


def settle_rule_gains(sweeps: Sequence[SweepCurrent], pos_fits: Sequence[SideFit],
                      neg_fits: Sequence[SideFit]) -> tuple[list[float], list[float]]:
    """Per side and sweep, the gain with the settle rule's B over the same load ramps (the
    play's own gains where a sweep carries no other, or a non-finite, B)."""
    settle = [s.settle_backlash_deg for s in sweeps if s.settle_backlash_deg is not None]
    if len(settle) == len(sweeps) and np.isfinite(settle).all():
        pos, neg = ([clamped_gain(b[i] / abs(f.amplitude_deg - f.zero_load_deg))
                     for b, f in zip(settle, fits, strict=True)]
                    for i, fits in enumerate((pos_fits, neg_fits)))
        return pos, neg
    return [f.backlash_gain for f in pos_fits], [f.backlash_gain for f in neg_fits]


def loaded_slope(device_knob: Any, grid: Sequence[float], sweeps: Sequence[SweepCurrent],
                 pos_fits: Sequence[SideFit], neg_fits: Sequence[SideFit],
                 read: tuple[Sequence[float], Sequence[float]] | None = None) -> float:
    """The unit's omega (:mod:`tsmd.calibration.unit_slope`): each backlash gain the sheet
    holds (the settle rule's, the product rule's) read on this unit with the same rule, the
    readings weighed by their scatter against the sheet's omega; a sheet without a gain keeps
    its omega. ``read``: the play's (+, -) gains with B as the current read it, before the
    reading offset, as the sheet's product-rule gain was read (the play's own without)."""
    readings = []
    settle_gain = getattr(device_knob, "reference_backlash_gain", None)
    # a sheet whose own unit does not read its settle gain so (session 25) takes no reading
    if settle_gain is not None and getattr(device_knob, "settle_gain_read", None) is not False:
        readings.append(gain_reading(float(settle_gain), grid,
                                     *settle_rule_gains(sweeps, pos_fits, neg_fits)))
    rule_gain = getattr(device_knob, "reference_rule_backlash_gain", None)
    if rule_gain is not None:
        pos, neg = (([f.backlash_gain for f in pos_fits], [f.backlash_gain for f in neg_fits])
                    if read is None else read)
        readings.append(gain_reading(float(rule_gain), grid, pos, neg))
    return weighed_omega(float(device_knob.omega), readings,
                         getattr(device_knob, "slope_gain_weight", None))


@dataclass(frozen=True)
class SweepPrefit:
    """What the fit takes from one sweep's own signals alone, analysed once per sweep: the
    settle-rule backlash and the drive's lag (together ~0.4 s of a paper sweep, which the
    calibration spends in the identification worker while the next sweep plays)."""

    backlash_pos_deg: float
    backlash_neg_deg: float
    lag_s: float


def prefit_sweep(data: Conditioned) -> SweepPrefit:
    """:class:`SweepPrefit` of one conditioned sweep.

    The backlash is not the identification's own half-cycles': this pass splits the whole
    recording at its reversals again (a first sweep's way down to -A counts, the first
    half-cycle of a recording that starts at -A does not), so it is a second pass over every
    half-cycle."""
    b_pos, b_neg = settle_rule_backlash(data)
    lag = estimate_lag_s(np.asarray(data.t_s, float), np.asarray(data.cmd_deg, float),
                         np.asarray(data.pos_deg, float))
    return SweepPrefit(b_pos, b_neg, lag)


def with_prefit(point: Any) -> Any:
    """``point`` (a grid point) with its :class:`SweepPrefit` (kept if it has one): a re-sweep
    pooled into it later keeps the first sweep's signals, hence this analysis."""
    if point.prefit is not None:
        return point
    return replace(point, prefit=prefit_sweep(point.result.data))


def sweeps_from_points(points: Sequence[Any], knob: int) -> list[SweepCurrent]:
    """:class:`SweepCurrent` of one knob from the calibration's grid points (the edges'
    uncertainties pooled over all of them, as the calibration's own gate does)."""
    out = []
    uncertain = point_estimates([p.result for p in points])
    for p, u in zip(points, uncertain, strict=True):
        if p.knob != knob:
            continue
        d = p.result.data
        est = p.result.estimate
        # the play on the profile's B (the product's rule); the settle rule's for omega's gain
        pre = with_prefit(p).prefit
        out.append(SweepCurrent(float(p.other_deg), d.t_s, d.cmd_deg, d.pos_deg,
                                d.current_filtered_A, est("dead_zone_pos_deg"),
                                est("dead_zone_neg_deg"), est("backlash_pos_deg"),
                                est("backlash_neg_deg"), pre.lag_s,
                                (u["dead_zone_pos_deg"].u95_deg,
                                 u["dead_zone_neg_deg"].u95_deg),
                                (pre.backlash_pos_deg, pre.backlash_neg_deg),
                                (BACKLASH_NAMES[0] in p.result.unseen,
                                 BACKLASH_NAMES[1] in p.result.unseen),
                                (p.result.own_offset_deg.get(BACKLASH_NAMES[0]),
                                 p.result.own_offset_deg.get(BACKLASH_NAMES[1]))))
    return out


PlateauGaps = tuple[float | None, float | None] | None
"""Each knob's dead-zone loop gap (deg; None: not read), or None: no loop played."""


def fit_from_points(points: Sequence[Any], device: Any,
                    plateau_gaps: PlateauGaps = None) -> tuple[TensionPlayParams, ...]:
    """Both knobs' parameters from the calibration's grid points and the data sheet (the
    first sweep's knob also with its fresh hold, :mod:`tsmd.calibration.fresh_hold`), each
    knob's heights moved by its dead-zone loop's gap where one was read."""
    gaps = plateau_gaps or (None, None)
    params = [fit_tension_play(sweeps_from_points(points, k), device.knobs[k], gaps[k])
              for k in (0, 1)]
    return with_fresh_hold(params, points)


def with_tension_play(profile: Any, points: Sequence[Any], device: Any,
                      plateau_gaps: PlateauGaps = None) -> Any:
    """``profile`` with each knob's ``tension_play`` parameters fitted from ``points`` (and
    the dead-zone loop's ``plateau_gaps`` where played)."""
    params = fit_from_points(points, device, plateau_gaps)
    knobs = tuple(replace(k, tension_play=p) for k, p in zip(profile.knobs, params, strict=True))
    return replace(profile, knobs=knobs)
