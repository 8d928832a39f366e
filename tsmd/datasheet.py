"""A device's data sheet, measured as a manufacturer would: once per product, tracker on the tip.

The paper's design assumptions 1-3 give each catheter type constants that calibration does not
identify from current: the loaded tip/knob slope omega and two reference points. Our compensator
adds the release slope, the backlash on the tip after the reversals at the reference points and
how far beyond the current's dead-zone edge the tip leaves the plateau. All come from a +-90 deg,
0.04 Hz sweep of each knob (other knob at 0 deg) with the tip tracked: on the simulator
(:func:`measure_device_constants`) or on a tracked real unit's recordings (:func:`knob_constants`
on each). The constants read once per reversal (release share, slope ratio, backlash) are read
over ``RELEASE_READ_CYCLES``, the others over the first ``ANALYSED_CYCLES``. The tip is used here
only: this is the manufacturer's bench, not the robot.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.analysis import measure_dead_zone_backlash, split_passes
from simrig.plant import Plant
from tsmd.calibration.identify import identify_sweep
from tsmd.calibration.load_ramp import fit_sweep_sides
from tsmd.calibration.loaded_knee import read_loaded_knee
from tsmd.calibration.options import IdentifyOptions
from tsmd.compensation.loaded_shape import LoadedShape
from tsmd.compensation.release_ratio import release_ratio_problem
from tsmd.compensation.safety import KnobLimits
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.datasheet_release import median_ratio, median_share, release_reads
from tsmd.datasheet_shape import measure_loaded_shape
from tsmd.errors import TsmdError
from tsmd.profile import (
    DEFAULT_HANDLE_SLIP_DEG,
    KNOB_NAMES,
    DeviceKnob,
    DeviceModel,
    ProfileError,
    ReferencePoint,
    device_model_from_mapping,
    device_model_to_mapping,
)
from tsmd.profile.schema import plain_values
from tsmd.profile.sheet_schema import OPTIONAL_KNOB_RANGES
from tsmd.recording import Recording
from tsmd.replay import run_trajectory
from tsmd.stack import knob_limits
from tsmd.tip_truth import TIP_THRESHOLD_DEG, tip_reading

SWEEP_HZ = 0.04
SWEEP_AMPLITUDE_DEG = 90.0
ANALYSED_CYCLES = 2.25
"""Cycles whose whole passes give the slopes, reference points and dead-zone edges."""
RELEASE_READ_CYCLES = 24.25
"""Cycles read at their reversals (two per cycle at +-90 deg: 48) for the release share, the
release-to-loaded slope ratio and the reference backlash. One reversal's share + 0.24 x ratio
(the per-unit share's anchor) scatters by 0.009 (sd, lumped unit 0), more than the units'
shares differ (0.008): over 4 reversals the anchor spread 0.966-0.980 over sheet seeds (about
1 deg on every unit's B); over 48 its sd is 0.0015, a fifth of the units' (docs/calibration.md,
session 8, s8-acc2). A product's sheet is measured once on a bench: its sweep may be long."""
CONDITIONING_CYCLES = 1.0
"""Sweep cycles run before a tip measurement is analysed. The plant starts tension-free
(virgin): its first release rests higher and its first engagement of the antagonist comes
later (phi1: plateau 16 instead of 5 deg, D_neg -15 instead of -22 deg on the tip), which a
product's data sheet must not average in; the calibration protocol conditions likewise."""
LOADED_FIT_DEG = (40.0, 85.0)
"""Knob range where the loaded branch is fitted for omega (mirrored for falling passes)."""
RELEASED_FIT_DEG = (35.0, 65.0)
"""Knob range where the releasing branch is fitted for release_omega."""
REFERENCE_BAND_DEG = 0.5
"""Samples within this of the knob's turning point give the reference tip angle."""


class DatasheetError(TsmdError):
    """The data sheet cannot be measured from this input (no tip, no sweep, too short)."""


@dataclass(frozen=True)
class KnobConstants:
    """One knob's data-sheet constants as measured (before limits are attached)."""

    omega: float
    release_omega: float
    reference_pos: ReferencePoint
    reference_neg: ReferencePoint
    reference_backlash_pos_deg: float
    reference_backlash_neg_deg: float
    dead_zone_offset_deg: float
    handle_slip_deg: float = DEFAULT_HANDLE_SLIP_DEG
    """The handle's design value (bearing and brake), not measured here: the sweep never stops
    the knob, so it cannot show the static friction fading after a restart."""
    dead_zone_pos_deg: float | None = None
    """The dead-zone edges the calibration's current analysis finds on this sweep: with them
    the plateau heights are product constants and each unit's loaded line moves with its own
    edges (method ours); None: the paper's line through the reference point."""
    dead_zone_neg_deg: float | None = None
    backlash_gain: float | None = None
    """beta of this unit from the sweep's current (calibration's estimator, mean of both
    sides): method ours scales omega per unit by ``1 - beta`` against it."""
    backlash_settle_fraction: float | None = None
    """Share of the current's swing after a reversal made up when the tip starts back
    (:func:`backlash_settle_fraction`; None: no reversal could be measured)."""
    backlash_release_slope_ratio: float | None = None
    """The current's release-to-loaded slope ratio there (:func:`backlash_release_slope_ratio`)."""
    release_swing_A: float | None = None
    """The current's swing from the loaded current to the release level after a reversal
    (:func:`tsmd.calibration.release.release_swing`, median over the reversals): another unit's
    swing scales the backlash it should show (the "B cannot be seen" warning)."""
    settle_lag_deg: float | None = None
    """Knob travel from where the paper's settle rule ends the backlash to the tip's release
    (1 deg moved back), median over the reversals: a product whose current settles before
    the tip lets go ends every unit's backlash that much later."""
    release_line_share: float | None = None
    """The share of its gap to the release line at the same knob angle that the current has
    closed at the tip's release (:func:`tsmd.calibration.release.line_share_at`), median over
    the reversals."""
    release_local_share: float | None = None
    """The same against the branch just beyond
    (:func:`~tsmd.calibration.release.local_share_at`)."""
    release_reversals: int = 0
    """How many reversals gave the five above (:func:`release_reads`)."""
    loaded_shape_pos: LoadedShape | None = None
    """The loaded branch's template per side (:mod:`tsmd.datasheet_shape`; None: not seen)."""
    loaded_shape_neg: LoadedShape | None = None
    loaded_knee_pos_deg: float | None = None
    """The loaded current ramp's knee per side (:mod:`tsmd.calibration.loaded_knee`)."""
    loaded_knee_neg_deg: float | None = None

    def device_knob(self, limits: KnobLimits, decimals: int = 2) -> DeviceKnob:
        """The data sheet's knob entry, rounded as a data sheet is printed."""
        def r(x: float) -> float:
            return round(float(x), decimals)

        return DeviceKnob(
            r(self.omega), ReferencePoint(r(self.reference_pos.knob_deg),
                                          r(self.reference_pos.tip_deg)),
            ReferencePoint(r(self.reference_neg.knob_deg), r(self.reference_neg.tip_deg)),
            limits, release_omega=r(self.release_omega),
            reference_backlash_pos_deg=r(self.reference_backlash_pos_deg),
            reference_backlash_neg_deg=r(self.reference_backlash_neg_deg),
            dead_zone_offset_deg=r(self.dead_zone_offset_deg),
            handle_slip_deg=r(self.handle_slip_deg),
            reference_dead_zone_pos_deg=(None if self.dead_zone_pos_deg is None
                                         else r(self.dead_zone_pos_deg)),
            reference_dead_zone_neg_deg=(None if self.dead_zone_neg_deg is None
                                         else r(self.dead_zone_neg_deg)),
            reference_backlash_gain=(None if self.backlash_gain is None
                                     else round(float(self.backlash_gain), 3)),
            backlash_settle_fraction=(None if self.backlash_settle_fraction is None
                                      else round(float(self.backlash_settle_fraction), 3)),
            backlash_release_slope_ratio=(None if self.backlash_release_slope_ratio is None
                                          else round(float(self.backlash_release_slope_ratio),
                                                     4)),
            reference_release_swing_A=(None if self.release_swing_A is None
                                       else round(float(self.release_swing_A), 4)),
            backlash_settle_lag_deg=(None if self.settle_lag_deg is None
                                     else r(self.settle_lag_deg)),
            loaded_shape_pos=self.loaded_shape_pos, loaded_shape_neg=self.loaded_shape_neg,
            loaded_knee_pos_deg=(None if self.loaded_knee_pos_deg is None
                                 else r(self.loaded_knee_pos_deg)),
            loaded_knee_neg_deg=(None if self.loaded_knee_neg_deg is None
                                 else r(self.loaded_knee_neg_deg)),
            backlash_release_line_share=(None if self.release_line_share is None
                                         else round(float(self.release_line_share), 4)),
            backlash_release_local_share=(None if self.release_local_share is None
                                          else round(float(self.release_local_share), 4)))


def settle(t_s: NDArray[np.float64], q_deg: NDArray[np.float64], period_s: float,
           move_s: float = 2.0) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    """Prepend a smooth move from 0 to the first sample and a rest, like an operator would.

    Returns the times, the angles and the index of the trajectory's first own sample.
    """
    n_move = round(move_s / period_s)
    s = 0.5 - 0.5 * np.cos(np.linspace(0.0, math.pi, n_move))
    pre = s[:, None] * q_deg[0][None, :]
    rest = np.repeat(q_deg[:1], round(0.5 / period_s), axis=0)
    head = np.vstack([pre, rest])
    tt = np.arange(len(head) + len(t_s)) * period_s
    full: NDArray[np.float64] = np.vstack([head, q_deg]).astype(float)
    return tt.astype(float), full, len(head)


def tip_sweep(knob: int, other_deg: float, period_s: float, cycles: float = ANALYSED_CYCLES
              ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A +-90 deg, 0.04 Hz sweep of ``knob`` (``cycles`` after the conditioning cycles)."""
    t = np.arange(0.0, (CONDITIONING_CYCLES + cycles) / SWEEP_HZ, period_s)
    q = np.zeros((t.size, 2))
    q[:, knob] = SWEEP_AMPLITUDE_DEG * np.sin(2 * math.pi * SWEEP_HZ * t)
    q[:, 1 - knob] = other_deg
    return t, q


def analysed_from(skip: int, period_s: float) -> int:
    """First sample of a :func:`tip_sweep` run (after :func:`settle`) that is analysed."""
    return skip + round(CONDITIONING_CYCLES / SWEEP_HZ / period_s)


def swept_knob(rec: Recording) -> int:
    """Which knob a sweep recording moves (0: phi1, 1: phi2): the one with the wider travel."""
    spans = [float(np.ptp(rec[f"pos{k + 1}"])) if len(rec) else 0.0 for k in (0, 1)]
    return int(np.argmax(spans))


def knob_constants(rec: Recording, knob: int, start: int = 0, stop: int | None = None,
                   ripple_period_deg: float | None = None,
                   edge_rise: bool = False) -> KnobConstants:
    """The data-sheet constants of ``knob`` from a tracked sweep, analysed from row ``start``:
    the whole-pass constants up to row ``stop`` (None: the end), the reversal reads (release
    share and slope ratio, reference backlash) over every reversal to the end.
    ``ripple_period_deg``: the handle's torque ripple period (a design constant), which every
    unit's edge fit averages over, so the sheet unit's current edges are read the same way;
    ``edge_rise``: the product reads its edges where the current starts to rise
    (``DeviceKnob.edge_rise``), the sheet unit's too."""
    if stop is not None:
        whole = knob_constants(Recording({k: v[:stop] for k, v in rec.columns.items()},
                                         rec.metadata), knob, start,
                               ripple_period_deg=ripple_period_deg, edge_rise=edge_rise)
        ends = knob_constants(rec, knob, start, ripple_period_deg=ripple_period_deg,
                              edge_rise=edge_rise)
        return dataclasses.replace(
            whole, reference_backlash_pos_deg=ends.reference_backlash_pos_deg,
            reference_backlash_neg_deg=ends.reference_backlash_neg_deg,
            backlash_settle_fraction=ends.backlash_settle_fraction,
            backlash_release_slope_ratio=ends.backlash_release_slope_ratio,
            release_swing_A=ends.release_swing_A, settle_lag_deg=ends.settle_lag_deg,
            release_line_share=ends.release_line_share,
            release_local_share=ends.release_local_share,
            release_reversals=ends.release_reversals)
    if not rec.has_tip:
        raise DatasheetError("the recording has no tip angles (tip1, tip2): a data sheet "
                             "needs a tracker on the tip")
    t = rec["t"][start:]
    pos = rec[f"pos{knob + 1}"][start:]
    tip = rec[f"tip{knob + 1}"][start:]
    if not np.all(np.isfinite(tip)):
        raise DatasheetError(f"tip{knob + 1} has missing values in the analysed rows")
    if pos.size < 100 or pos.max() < SWEEP_AMPLITUDE_DEG - REFERENCE_BAND_DEG \
            or pos.min() > -SWEEP_AMPLITUDE_DEG + REFERENCE_BAND_DEG:
        raise DatasheetError(f"knob {knob + 1} does not sweep +-{SWEEP_AMPLITUDE_DEG:g} deg in "
                             f"the analysed rows (range {pos.min():.1f}..{pos.max():.1f} deg)")
    dz = measure_dead_zone_backlash(pos, tip, threshold_deg=TIP_THRESHOLD_DEG)
    # B as the scoring truth reads it (the raw tip's 1 deg fires 1.5-2.5 deg early); D stays
    # on the raw tip: the dead-zone offset is what the compensators were built against
    tip_b = tip_reading(t, rec[f"cmd{knob + 1}"][start:], pos, tip)
    # where the calibration's current analysis puts the edges on the same sweep
    cur = identify_sweep(t, rec[f"cmd{knob + 1}"][start:], pos, rec[f"cur{knob + 1}"][start:],
                         IdentifyOptions(torque_ripple_period_deg=ripple_period_deg,
                                         edge="rise" if edge_rise else "fit"))
    dz_offset = 0.5 * ((dz.dead_zone_pos_deg - cur.estimate("dead_zone_pos_deg"))
                       + (cur.estimate("dead_zone_neg_deg") - dz.dead_zone_neg_deg))
    # The backlash gain exactly as the tension-play fit measures every unit's: by the settle
    # rule's backlash (`settle_rule_backlash`), which is what this sweep's own identification
    # (default options: the settle rule) already found
    try:
        sides = fit_sweep_sides(cur.data.pos_deg, cur.data.current_filtered_A,
                                *(cur.estimate(k) for k in ("dead_zone_pos_deg",
                                                            "dead_zone_neg_deg",
                                                            "backlash_pos_deg",
                                                            "backlash_neg_deg")))
        gain: float | None = 0.5 * (sides[0].backlash_gain + sides[1].backlash_gain)
    except ValueError:  # a current without a loaded ramp: the sheet keeps a per-product omega
        gain = None
    loaded, released = [], []
    for a, b, direction in split_passes(pos):
        x, y = direction * pos[a:b], direction * tip[a:b]  # mirror falling passes
        # loaded: moving out of the dead zone; released: moving back towards it
        sel_l = (x >= LOADED_FIT_DEG[0]) & (x <= LOADED_FIT_DEG[1])
        if np.count_nonzero(sel_l) > 10:
            loaded.append(float(np.polyfit(x[sel_l], y[sel_l], 1)[0]))
        xr, yr = -x, -y  # the same pass seen as releasing the other side's tendon
        sel_r = (xr >= RELEASED_FIT_DEG[0]) & (xr <= RELEASED_FIT_DEG[1])
        if np.count_nonzero(sel_r) > 10:
            released.append(float(np.polyfit(xr[sel_r], yr[sel_r], 1)[0]))
    if not loaded or not released:
        raise DatasheetError(f"knob {knob + 1}: no complete pass to fit the tip/knob slopes")
    top = SWEEP_AMPLITUDE_DEG - REFERENCE_BAND_DEG
    reads = release_reads(cur.data, t, tip, settle_deg={
        h.start: h.backlash_deg for h in cur.half_cycles if h.after_reversal})
    lags = [r.settle_lag_deg for r in reads if math.isfinite(r.settle_lag_deg)]
    omega = float(np.median(loaded))
    # the template at the omega the sheet prints, from the current's edges as printed
    shapes = [measure_loaded_shape(pos, tip, round(cur.estimate(f"dead_zone_{s}_deg"), 2),
                                   round(omega, 2), side) for s, side in (("pos", 1), ("neg", -1))]
    knees = [read_loaded_knee(cur.data.pos_deg, cur.data.current_filtered_A,
                              cur.estimate(f"dead_zone_{s}_deg"), side)
             for s, side in (("pos", 1), ("neg", -1))]
    line_shares = [r.line_share for r in reads if math.isfinite(r.line_share)]
    local_shares = [r.local_share for r in reads if math.isfinite(r.local_share)]
    return KnobConstants(
        omega=omega, release_omega=float(np.median(released)),
        reference_pos=ReferencePoint(SWEEP_AMPLITUDE_DEG, float(np.median(tip[pos > top]))),
        reference_neg=ReferencePoint(-SWEEP_AMPLITUDE_DEG, float(np.median(tip[pos < -top]))),
        reference_backlash_pos_deg=float(tip_b.backlash_pos_deg),
        reference_backlash_neg_deg=float(tip_b.backlash_neg_deg),
        dead_zone_offset_deg=float(dz_offset),
        dead_zone_pos_deg=_finite_or_none(cur.estimate("dead_zone_pos_deg")),
        dead_zone_neg_deg=_finite_or_none(cur.estimate("dead_zone_neg_deg")), backlash_gain=gain,
        backlash_settle_fraction=median_share(reads),
        backlash_release_slope_ratio=median_ratio(reads),
        release_swing_A=float(np.median([r.swing_A for r in reads])) if reads else None,
        settle_lag_deg=float(np.median(lags)) if lags else None,
        release_line_share=float(np.median(line_shares)) if line_shares else None,
        release_local_share=float(np.median(local_shares)) if local_shares else None,
        release_reversals=len(reads), loaded_shape_pos=shapes[0], loaded_shape_neg=shapes[1],
        loaded_knee_pos_deg=None if knees[0] is None else knees[0].travel_deg,
        loaded_knee_neg_deg=None if knees[1] is None else knees[1].travel_deg)


def _finite_or_none(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def measure_device_constants(plant_factory: Callable[[], Plant], seed: int = 2000,
                             config: TsmdConfig | None = None,
                             ripple_period_deg: float | None = None,
                             edge_rise: bool = False) -> list[KnobConstants]:
    """Both knobs' constants on the simulated rig: each knob swept through the full stack
    (uncompensated, other knob at 0) for ``RELEASE_READ_CYCLES``, analysed after
    ``CONDITIONING_CYCLES`` (:func:`knob_constants`: the whole-pass constants on the first
    ``ANALYSED_CYCLES``)."""
    cfg = config if config is not None else default_sim_config()
    period_s = cfg.loop.period_s
    out = []
    for knob in (0, 1):
        t, q, skip = settle(*tip_sweep(knob, 0.0, period_s, RELEASE_READ_CYCLES), period_s)
        rec = run_trajectory(t, q, config=cfg, profile=None, method="none", seed=seed,
                             plant=plant_factory())
        # the run is causal: up to the short sweep's last sample it is the short sweep's
        stop = skip + tip_sweep(knob, 0.0, period_s)[0].size
        out.append(knob_constants(rec, knob, analysed_from(skip, period_s), stop,
                                  ripple_period_deg, edge_rise))
    return out


def device_model(name: str, constants: Sequence[KnobConstants], config: TsmdConfig,
                 description: str = "", loaded_shape: bool = False) -> DeviceModel:
    """The data sheet: measured constants with the knobs' limits of ``config``.

    ``loaded_shape``: keep the loaded-branch templates. Off by default: on the family's
    held-out units the template did not improve ours' worst row (docs/model.md, Session 10).
    """
    if len(constants) != 2:
        raise DatasheetError(f"need the constants of 2 knobs, got {len(constants)}")
    if not loaded_shape:
        constants = [dataclasses.replace(c, loaded_shape_pos=None, loaded_shape_neg=None,
                                         loaded_knee_pos_deg=None, loaded_knee_neg_deg=None)
                     for c in constants]
    limits = knob_limits(config)
    knobs = tuple(c.device_knob(lim) for c, lim in zip(constants, limits, strict=True))
    return DeviceModel(name, (knobs[0], knobs[1]), description)


def readable(device: DeviceModel) -> tuple[DeviceModel, list[str]]:
    """The sheet as the schema will read it back: a measured optional value outside the
    schema's range for it (:data:`tsmd.profile.sheet_schema.OPTIONAL_KNOB_RANGES`) is left out and
    named, so the rules that need it are no candidates, instead of the whole measurement being
    lost when the file is written. So is a tracked ``release_omega`` whose release-path ratio
    (:func:`tsmd.compensation.release_ratio.release_slope_ratio`) the loader would refuse
    (session 21, cyclopebax: 0.69 refused every unit's calibration). A refusal of anything else
    is an error."""
    dropped: list[str] = []
    knobs = list(device.knobs)
    for i, knob in enumerate(device.knobs):
        for name, (lo, hi, unit) in OPTIONAL_KNOB_RANGES.items():
            value = getattr(knob, name)
            if value is None or (math.isfinite(value) and lo <= value <= hi):
                continue
            left_out: dict[str, Any] = {name: None}
            knobs[i] = dataclasses.replace(knobs[i], **left_out)
            dropped.append(f"knobs.{KNOB_NAMES[i]}.{name}: {value} {unit} is outside the "
                           f"plausible range [{lo}, {hi}]: left out of the sheet"
                           .replace("  ", " "))
        problem = release_ratio_problem(knobs[i])
        if problem is not None:  # the calibration could not use it on any unit
            knobs[i] = dataclasses.replace(knobs[i], release_omega=None)
            dropped.append(f"knobs.{KNOB_NAMES[i]}.release_omega: {problem}: left out of the "
                           "sheet (the release line keeps the backlash-end locus slope)")
    device = dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
    try:
        device_model_from_mapping(plain_values(device_model_to_mapping(device)), "sheet")
    except ProfileError as exc:
        raise DatasheetError("the measured sheet is not valid: "
                             f"{str(exc).removeprefix('sheet: ')}") from None
    return device, dropped
