"""From identified sweeps to a catheter profile: quality checks, H from the data sheet, grids.

The quality checks refuse to build a profile that would be wrong and say why: a parameter no
half-cycle could give, cycles that disagree, values outside the plausible range, a weak signal, a
grid without the sweep at 0 deg that design assumption 1 needs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime

import numpy as np

from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.estimate import Estimate, EstimateOptions, point_estimates
from tsmd.calibration.recovery import BACKLASH_SWING_SCATTER, expected_backlash_deg
from tsmd.calibration.sweep_result import PARAMETERS, SweepResult
from tsmd.calibration.tension_play_fit import SweepPrefit
from tsmd.compensation.paper import height_from_reference
from tsmd.profile import KNOB_NAMES, CatheterProfile, DeviceModel, KnobProfile
from tsmd.recording import Recording

KNOB_LABELS = ("phi1", "phi2")


@dataclass(frozen=True)
class GridPoint:
    """One identified sweep: which knob, where the other knob was, what was found."""

    knob: int
    other_deg: float
    result: SweepResult
    recording: Recording | None = None
    label: str = ""
    prefit: SweepPrefit | None = None
    """What the tension-play fit takes from this sweep's own signals, when already analysed (in
    the identification worker, overlapped with the next sweep); None: the fit analyses it."""
    model_result: SweepResult | None = None
    """The same sweep in our compensator's frame (only the reading offsets of
    :data:`tsmd.calibration.reading_offset.MODEL_MIN_OFFSET_DEG` and more applied), where that
    differs from ``result`` (the reported values, every sure offset applied); None: the same."""

    def in_model_frame(self) -> GridPoint:
        """This point as our compensator's fit reads it."""
        if self.model_result is None:
            return self
        return replace(self, result=self.model_result, model_result=None)

    @property
    def name(self) -> str:
        return self.label or (f"{KNOB_LABELS[self.knob]} sweep, {KNOB_LABELS[1 - self.knob]} at "
                              f"{self.other_deg:+.0f} deg")


@dataclass(frozen=True)
class QualityLimits:
    """What a trustworthy calibration must show."""

    estimate: EstimateOptions = field(default_factory=EstimateOptions)
    """Pooling of the half-cycles and the tip-error gate that triggers re-sweeps."""
    refuse_tip_error_deg: float = 5.0
    """After the re-sweep budget: a parameter whose 95 % uncertainty still costs more than this
    on the tip is refused (between the gate and this it is accepted with a warning)."""
    max_backlash_deg: float = 60.0
    max_dead_zone_fraction: float = 0.8
    """A dead-zone edge beyond this fraction of the sweep amplitude is implausible."""
    min_snr: float = 4.0


@dataclass
class QualityReport:
    """Figures the profile keeps and the problems that stop a calibration."""

    figures: dict[str, float] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    """Findings that do not stop the calibration but that its user must read."""

    def raise_if_bad(self) -> None:
        """Refuse with every problem; warnings found so far follow them (they often say why)."""
        if self.problems:
            head = f"calibration refused ({len(self.problems)} problem"
            head += "s): " if len(self.problems) > 1 else "): "
            tail = "".join(f"; warning: {w}" for w in self.warnings)
            raise CalibrationError(head + "; ".join(self.problems) + tail)


def check_quality(points: Sequence[GridPoint], limits: QualityLimits | None = None,
                  amplitude_deg: float = 90.0,
                  omegas: Sequence[float] = (1.0, 1.0)) -> QualityReport:
    """Check every grid point; collect all problems (not just the first).

    ``omegas``: the data sheet's tip/knob slope per knob, which turns a parameter's uncertainty
    into what it costs on the tip.
    """
    lim = limits or QualityLimits()
    report = QualityReport()
    estimates = point_estimates([p.result for p in points], lim.estimate)
    by_point = {id(p): e for p, e in zip(points, estimates, strict=True)}
    for knob in (0, 1):
        mine = [p for p in points if p.knob == knob]
        label = KNOB_LABELS[knob]
        if not mine:
            report.problems.append(f"{label}: no sweep")
            continue
        grid = sorted(p.other_deg for p in mine)
        if len(set(grid)) != len(grid):
            report.problems.append(f"{label}: two sweeps at the same other-knob angle")
        if len(grid) < 2:
            report.problems.append(f"{label}: needs sweeps at >= 2 other-knob angles, got {grid}")
        if not any(abs(g) < 1e-6 for g in grid):
            report.problems.append(
                f"{label}: no sweep with the other knob at 0 deg (design assumption 1 needs it)")
        spreads: list[float] = []
        snrs: list[float] = []
        costs: list[float] = []
        for p in mine:
            _check_point(p, lim, amplitude_deg, report.problems, spreads)
            costs += _check_uncertainty(p, by_point[id(p)], omegas[knob], lim, report)
            if math.isfinite(p.result.snr):
                snrs.append(p.result.snr)
        report.figures[f"{label}_max_cycle_spread_deg"] = max(spreads) if spreads else 0.0
        report.figures[f"{label}_max_tip_uncertainty_deg"] = max(costs) if costs else 0.0
        report.figures[f"{label}_resweeps"] = float(sum(p.result.resweeps for p in mine))
        report.figures[f"{label}_min_snr"] = min(snrs) if snrs else 0.0
        report.figures[f"{label}_sweeps"] = float(len(mine))
    return report


def _check_point(p: GridPoint, lim: QualityLimits, amplitude_deg: float, problems: list[str],
                 spreads: list[float]) -> None:
    r = p.result
    for name in PARAMETERS:
        values = r.values.get(name, ())
        if not values:
            why = "; ".join(r.problems) or "no half-cycle gave it"
            problems.append(f"{p.name}: no {name} ({why})")
            continue
        if len(values) > 1:
            spreads.append(r.spread(name))
    d_pos, d_neg = r.estimate("dead_zone_pos_deg"), r.estimate("dead_zone_neg_deg")
    b_pos, b_neg = r.estimate("backlash_pos_deg"), r.estimate("backlash_neg_deg")
    edge_max = lim.max_dead_zone_fraction * amplitude_deg
    if math.isfinite(d_pos) and not 0.0 < d_pos < edge_max:
        problems.append(f"{p.name}: dead_zone_pos_deg {d_pos:.1f} outside (0, {edge_max:g})")
    if math.isfinite(d_neg) and not -edge_max < d_neg < 0.0:
        problems.append(f"{p.name}: dead_zone_neg_deg {d_neg:.1f} outside ({-edge_max:g}, 0)")
    for name, b in (("backlash_pos_deg", b_pos), ("backlash_neg_deg", b_neg)):
        if math.isfinite(b) and not 0.0 <= b <= lim.max_backlash_deg:
            problems.append(f"{p.name}: {name} {b:.1f} outside [0, {lim.max_backlash_deg:g}]")
    snr = r.median_snr
    if math.isfinite(snr) and snr < lim.min_snr:
        problems.append(f"{p.name}: current signal too weak (SNR {snr:.1f} < {lim.min_snr:g})")


def _check_uncertainty(p: GridPoint, estimates: dict[str, Estimate], omega: float,
                       lim: QualityLimits, report: QualityReport) -> list[float]:
    """The gate after the re-sweeps: warn above the tip-error target, refuse far above it."""
    costs = []
    for name, e in estimates.items():
        if e.n == 0:
            continue  # named by _check_point with the half-cycles' reasons
        cost = e.tip_cost_deg(omega)
        values = ", ".join(f"{v:.1f}" for v in p.result.values.get(name, ()))
        what = (f"{p.name}: {name} {e.value:.1f} +- {e.u95_deg:.1f} deg (95 %, {e.n} "
                f"half-cycles: {values}; {p.result.resweeps} re-sweeps) costs up to "
                f"{cost:.1f} deg on the tip")
        if not math.isfinite(cost):
            continue
        costs.append(cost)
        if name in p.result.unseen:
            # the per-value flag the profile keeps: this value is the sheet's, not a reading
            report.figures[f"{KNOB_LABELS[p.knob]}_{name.removesuffix('_deg')}_unseen_at_"
                           f"{p.other_deg:+.0f}_u95_deg"] = e.u95_deg
            report.warnings.append(
                f"{p.name}: {name} cannot be seen in the current (no half-cycle's recovery "
                f"after the reversal stands out of the noise): {e.value:.1f} +- "
                f"{e.u95_deg:.1f} deg (95 %) is the data sheet's backlash scaled by this "
                f"unit's swing, up to {cost:.1f} deg on the tip; no re-sweep narrows it")
        elif cost > lim.refuse_tip_error_deg:
            report.problems.append(f"{what} (> {lim.refuse_tip_error_deg:g} allowed)")
        elif cost > lim.estimate.max_tip_error_deg:
            report.warnings.append(f"{what} (target {lim.estimate.max_tip_error_deg:g})")
    return costs


BACKLASH_DATASHEET_MIN_RATIO = 0.8
"""Without the sheet unit's release swing (older sheets): backlash from the current below this
share of the data sheet's reference backlash is flagged. It flagged healthy units whose
backlash is small (capstan development units 1, 2, 4-7 and lumped 103 phi2: 0.59-0.78 with B
within 2 deg of the tip), the units' backlashes spreading +-40 % around the sheet unit's."""

def cross_check_device(points: Sequence[GridPoint], device: DeviceModel,
                       report: QualityReport, tip_target_deg: float = 3.0) -> None:
    """Warn where the backlash cannot be seen in the current.

    The paper reads the end of the backlash where the current settles after a reversal; on a
    catheter whose current settles long before the tip moves (a routed handle: the guide
    pins' friction takes most of the swing within a few degrees), B comes out too small and
    nothing in the current's own shape shows it. The data sheet can: its unit's reference
    backlash, scaled to this unit's own swing (a unit with a smaller swing has a smaller
    backlash; a routed handle swings more, not less), is the backlash the current should
    show. Judged on the tip: a warning where the shortfall costs more than ``tip_target_deg``
    beyond the 95 % scatter of healthy units about that law (omega x shortfall). Without the
    sheet unit's swing, the fixed share of before (:data:`BACKLASH_DATASHEET_MIN_RATIO`).
    """
    for knob in (0, 1):
        sheet = device.knobs[knob]
        zero = [p for p in points if p.knob == knob and abs(p.other_deg) < 1e-6]
        if not zero:
            continue
        label = KNOB_LABELS[knob]
        for side, reference in (("pos", sheet.reference_backlash_pos_deg),
                                ("neg", sheet.reference_backlash_neg_deg)):
            name = f"backlash_{side}_deg"
            found = zero[0].result.estimate(name)
            if reference is None or not reference > 0 or not math.isfinite(found):
                continue
            report.figures[f"{label}_backlash_{side}_vs_datasheet"] = found / reference
            swings = [h.release_swing_A for h in zero[0].result.half_cycles
                      if h.backlash_name == name and math.isfinite(h.release_swing_A)]
            ref_swing = sheet.reference_release_swing_A
            if ref_swing is None or not ref_swing > 0 or not swings \
                    or not float(np.median(swings)) > 0:
                if found / reference < BACKLASH_DATASHEET_MIN_RATIO:
                    report.warnings.append(
                        f"{label}: {name} from the current is {found:.1f} deg, "
                        f"{found / reference:.0%} of the data sheet's reference backlash "
                        f"{reference:.1f} deg: the current settles before the tip moves on "
                        "this catheter, so the compensators will under-compensate reversals")
                continue
            swing = float(np.median(swings))
            expected = expected_backlash_deg(reference, swing, ref_swing)
            report.figures[f"{label}_backlash_{side}_vs_expected"] = found / expected
            cost = sheet.omega * (expected - found)
            allowed = tip_target_deg + sheet.omega * 1.96 * BACKLASH_SWING_SCATTER * expected
            if cost > allowed:
                report.warnings.append(
                    f"{label}: {name} from the current is {found:.1f} deg where its swing of "
                    f"{swing * 1e3:.0f} mA (data sheet: {reference:.1f} deg at "
                    f"{ref_swing * 1e3:.0f} mA) implies {expected:.1f} deg, {cost:.1f} deg "
                    f"short on the tip (> {allowed:.1f} allowed): the current settles before "
                    "the tip moves on this catheter, so the compensators will "
                    "under-compensate reversals")


def knob_grid(points: Sequence[GridPoint], knob: int) -> tuple[tuple[float, ...],
                                                                  dict[str, tuple[float, ...]]]:
    """The other-knob grid (sorted) and each parameter's estimate on it."""
    mine = sorted((p for p in points if p.knob == knob), key=lambda p: p.other_deg)
    grid = tuple(float(p.other_deg) for p in mine)
    values = {name: tuple(float(p.result.estimate(name)) for p in mine) for name in PARAMETERS}
    return grid, values


def build_profile(catheter_id: str, device: DeviceModel, points: Sequence[GridPoint], *,
                  quality: QualityReport, software_version: str,
                  interpolation: str = "pchip",
                  source: str = "calibration from motor current") -> CatheterProfile:
    """The profile: grids per knob, H from the reference points at D(0) (assumptions 1-3)."""
    quality.raise_if_bad()
    knobs: list[KnobProfile] = []
    for knob in (0, 1):
        grid, values = knob_grid(points, knob)
        dev = device.knobs[knob]
        zero = int(np.argmin(np.abs(np.asarray(grid))))
        h_pos = height_from_reference(dev.reference_pos.knob_deg, dev.reference_pos.tip_deg,
                                      values["dead_zone_pos_deg"][zero], dev.omega)
        h_neg = height_from_reference(dev.reference_neg.knob_deg, dev.reference_neg.tip_deg,
                                      values["dead_zone_neg_deg"][zero], dev.omega)
        knobs.append(KnobProfile(
            omega=dev.omega, reference_pos=dev.reference_pos, reference_neg=dev.reference_neg,
            height_pos_deg=float(h_pos), height_neg_deg=float(h_neg), other_knob_deg=grid,
            dead_zone_pos_deg=values["dead_zone_pos_deg"],
            dead_zone_neg_deg=values["dead_zone_neg_deg"],
            backlash_pos_deg=values["backlash_pos_deg"],
            backlash_neg_deg=values["backlash_neg_deg"]))
    assert len(KNOB_NAMES) == 2
    return CatheterProfile(
        catheter_id=catheter_id, device_model=device.device_model,
        calibrated_at=datetime.now(UTC).replace(microsecond=0).isoformat(),
        software_version=software_version, interpolation=interpolation,
        knobs=(knobs[0], knobs[1]), source=source, quality=dict(quality.figures))
