"""Dead-zone edge offsets from loaded ramps: bounded, with hysteresis, confidence and freezes.

One :class:`EdgeTracker` per knob and side. The first ``baseline_ramps`` ramps after start
learn the reference (the profile is taken as right at the start of use, right after its
calibration): the current level the ramp has at the calibrated edge, the ramp's slope and the
residual between the edge at that level and the profile's edge; while it settles it is
re-learned on the latest ramps within the gate (:mod:`tsmd.online.reference`). Afterwards
each ramp measures the offset of the edge from the profile's (at the other knob's angle of
that ramp, so the coupling the profile knows is not mistaken for a change). What the slopes
alone say (knee mode, gain, bend share) is :mod:`tsmd.online.edge_slopes`.

- **Noise**: the estimate is the median of the last ``window`` accepted measurements.
- **Spikes / outliers**: a measurement further than ``gate_deg`` from the estimate is held as
  suspect; it is followed only when ``confirm`` suspects in a row agree within
  ``confirm_spread_deg``, or when the other edge of the same knob has a suspect that agrees
  (:meth:`EdgeTracker.agrees_with`, checked by the worker): a shape change, reported as a
  warning.
- **Bounds**: an offset beyond ``max_offset_deg`` is never followed (warning, estimate kept).
- **Hysteresis**: the applied offset moves only when the estimate leaves a band of
  ``deadband_deg`` around it.
- **Freeze**: a stalled motor or a fault freezes the tracker for ``freeze_ramps`` ramps; a
  ramp much steeper or flatter than the reference (a stuck knob, a blocked tip) is refused.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from statistics import median
from typing import Any

from tsmd.online.edge_reference import ORDER, ReferenceReadings
from tsmd.online.edge_slopes import SlopeReadings
from tsmd.online.edge_status import edge_status
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.online.other_knob import OtherKnobBins
from tsmd.online.partner import partner_left_band, partner_shows_change
from tsmd.online.reference import SettlingReference
from tsmd.online.slope_share import SlopeShare
from tsmd.online.slopes import common_change, shrunk_ratio


@dataclass
class EdgeTracker(SlopeReadings, ReferenceReadings):
    """The offset of one dead-zone edge (knob, side) from the profile's; see the module."""

    knob: int
    side: int
    options: EstimatorOptions = field(default_factory=EstimatorOptions)
    level_A: float | None = None
    slope_ref_A_per_deg: float | None = None
    residual_ref_deg: float = 0.0
    knee_residual_ref_deg: float = math.nan
    """The knee's offset from the profile's edge over the baseline (NaN: no knees seen)."""
    estimate_deg: float = 0.0
    level_deg: float = 0.0
    """The last level the tracker was sure of: the profile's (0) until a change is followed.
    Until the window is full, the missing measurements count as this level (a prior), so two
    ramps of a noisy edge cannot move the estimate on their own (lumped 102, no change: phi1
    pos at 0.11 and 1.16 deg gave 0.64)."""
    applied_deg: float = 0.0
    zero_load_deg: float = 0.0
    """How far the tendon's zero-load point x0 moved outward: with the edge (a slack change
    moves the whole characteristic), except for a knee-placed change when
    :attr:`EstimatorOptions.keep_zero_load_in_bend` (a bend on the capstan plant)."""
    accepted: list[float] = field(default_factory=list)
    suspects: list[float] = field(default_factory=list)
    frozen_for: int = 0
    frozen_reason: str = ""
    n_ramps: int = 0
    last_measurement_deg: float = math.nan
    last_reading_deg: float = math.nan
    """The latest measurement any ramp gave (NaN: none yet), kept across ramps that measure
    nothing; the other knob's confirmation reads it (:mod:`tsmd.online.cross_knob`)."""
    recent_slopes: list[float] = field(default_factory=list)
    last_feature: str = ""
    """What placed the last measurement: "knee" or "crossing"."""
    bend_suspect: bool = False
    """The edge's first knee is a suspect beyond the gate the way the slopes changed, with both
    tendons' last ramps > 30 % changed alike: a bend, followed at once on both edges when
    :attr:`EstimatorOptions.follow_bend_at_once` (later lone knees scatter +-1.5 deg)."""
    shared_change: float = 0.0
    """This tendon's slope change as far as the knob's other tendon confirms it (last ramp)."""
    partner_change: float = 0.0
    """The knob's other tendon's slope change at this tendon's last ramp."""
    knob_change: float = 0.0
    """The knob's slope change over both tendons' last ramps (:func:`slopes.pooled_change`)."""
    partner_last_change: float = 0.0
    """The knob's other tendon's last ramp's own slope change (:attr:`last_change`)."""
    knee_slopes: list[float] = field(default_factory=list)
    """The last slopes of ramps fitted past their own knee (after a bend: the loaded ramp
    itself, not a window that starts on the engagement's step)."""
    partner_knee_change: float = 0.0
    n_odd_slope: int = 0
    """Ramps whose slope disagreed with the slope in use: no measurement taken."""
    n_widened: int = 0
    """Odd-slope ramps read as a widening (``odd_slopes_read_widening``, or a steeper knob's)."""
    ramp_change: float = 0.0
    """The last ramp's own slope against the reference, minus 1, whatever its speed."""
    n_steeper: int = 0
    """Of those, steeper ramps read with their own slope (``steeper_knob_reads_own``)."""
    n_own_between: int = 0
    """Crossings within the gate read towards the ramp's own slope (``within_gate_reads_own``)."""
    n_own_held: int = 0
    """Crossings beyond the gate with the slope in use read within it towards the ramp's own
    slope (``suspect_needs_own_slope``)."""
    refining_for: int = 0
    """Measurements after a followed change still to be applied without the dead band
    (``refine_after_follow``)."""
    n_followed_own: int = 0
    """Crossings within the gate after a followed change read with the ramp's own slope
    (``followed_reads_own``)."""
    n_flatter_own: int = 0
    """Crossings outward beyond the gate with both slopes on a flatter ramp, read at its own
    slope (``flatter_suspect_reads_own``)."""
    n_leaning_steeper: int = 0
    """Crossings of steeper ramps read as suspects with their own slope
    (``leaning_steeper_reads_own``)."""
    share: SlopeShare = field(default_factory=SlopeShare)
    """Where this edge's crossings lie between the two slopes' (:mod:`tsmd.online.slope_share`)."""
    n_share_read: int = 0
    """Readings beyond the gate read at the learned share (``suspect_reads_learned_share``)."""
    n_cut: int = 0
    """Readings beyond the gate of windows the change cut in two: no suspect
    (``cut_window_drop``)."""
    cut: bool = False
    """The ramp being read is a window whose current fell (:attr:`LoadedRamp.load_drop`)."""
    n_bin_lean: int = 0
    """Readings beyond the gate held within it by their bin's lean so far
    (``learning_bin_lean_holds``)."""
    n_odd_knee: int = 0
    """Knee-mode ramps whose knee moved against the slope change: no measurement taken."""
    n_odd_crossing: int = 0
    """Crossings inward beyond the gate while the friction rose: no measurement taken."""
    n_odd_speed: int = 0
    """Ramps at a knob speed beyond ``speed_ratio_max`` of the reference's that measured
    nothing (all but those reading outward beyond the gate)."""
    odd_speed: bool = False
    """The last ramp ran at a speed beyond ``speed_ratio_max`` of the reference's."""
    speed_ref_change: float = 0.0
    """The slope change of the edge's last ramp at the reference's speed."""
    speed_ref_deg_s: float = math.nan
    """The reference ramps' median knob speed (NaN: not learned, or no speeds)."""
    n_refused: int = 0
    """Ramps refused for a slope beyond ``slope_ratio_max`` of the reference."""
    suspect_order: int = -1
    """When (:data:`~tsmd.online.edge_reference.ORDER`) the last suspect was taken; -1: none."""
    accepted_order: int = -1
    """When the last measurement within the gate was taken (the edge read where it was)."""
    bins: OtherKnobBins = field(init=False)
    """Where the edge reads against the other knob's angle (:mod:`tsmd.online.other_knob`)."""
    held: tuple[LoadedRamp, float, float] | None = None
    """The last crossing ramp, its profile edge and the slope it was read with (re-read when
    the slope in use moves: :meth:`_reread`)."""
    n_reread: int = 0
    """Ramps that became suspects when re-read with a slope in use that had moved."""
    reference: SettlingReference = field(init=False)
    """The reference being learned, re-learned while it settles (:mod:`tsmd.online.reference`)."""
    other_knob_shows: Callable[[int], bool] | None = field(default=None, repr=False)
    """Whether the other knob's edges show a change this way (+1 outward, -1 inward;
    :func:`tsmd.online.cross_knob.knob_shows`, set by the worker); None: not asked."""
    partner: EdgeTracker | None = field(default=None, repr=False, compare=False)
    """The knob's other edge (set by the worker, or by :meth:`update`'s ``partner``)."""
    n_between: int = 0
    """Crossings of ramps flatter than the reference read between the two slopes' readings
    (:attr:`EstimatorOptions.flatter_reads_between`)."""
    n_partner_held: int = 0
    """Changes (or estimates beyond the dead band) held because the other edge of the knob
    showed none (:attr:`EstimatorOptions.partner_confirms`)."""

    def __post_init__(self) -> None:
        o = self.options
        self.bins = OtherKnobBins(o.other_bin_deg, o.bin_min, o.bin_window)
        self.reference = SettlingReference(o.baseline_ramps, o.settle_ramps, o.deadband_deg,
                                           o.slope_in_use_tolerance)

    @property
    def confidence(self) -> float:
        """0..1: how many measurements back the estimate, and how well they agree."""
        if self.learning or not self.accepted:
            return 0.0
        o = self.options
        spread = max(self.accepted) - min(self.accepted) if len(self.accepted) > 1 else 0.0
        return min(len(self.accepted) / o.window, 1.0) * max(0.0, 1.0 - spread / (2 * o.gate_deg))

    def freeze(self, reason: str, ramps: int | None = None) -> None:
        self.frozen_for = max(self.frozen_for, self.options.freeze_ramps if ramps is None
                              else ramps)
        self.frozen_reason = reason
        self.suspects.clear()

    def update(self, ramp: LoadedRamp, profile_edge_deg: float,
               partner: EdgeTracker | None = None) -> list[tuple[str, str, dict[str, Any]]]:
        """Take one ramp; returns events (level, name, fields) to report. ``partner``: the
        other edge of the same knob (its slopes confirm a friction change)."""
        o = self.options
        self.n_ramps += 1
        self.bend_suspect = False
        self.cut = 0.0 < o.cut_window_drop < ramp.load_drop
        self.partner = partner or self.partner
        events: list[tuple[str, str, dict[str, Any]]] = []
        tag = {"knob": self.knob, "side": "pos" if self.side > 0 else "neg"}
        if self.learning:
            if self.reference.add(ramp, profile_edge_deg):
                self._take_reference()
                self.recent_slopes = [r.slope_A_per_deg for r, _ in self.reference.window]
                events.append(("info", "online reference learned",
                               {**tag, "level_A": round(self.level_A or 0.0, 4)}))
            return events
        assert self.level_A is not None and self.slope_ref_A_per_deg is not None
        ratio = ramp.slope_A_per_deg / self.slope_ref_A_per_deg
        self.ramp_change = ratio - 1.0
        self.odd_speed = not self._speed_matches(ramp)
        if not self.odd_speed:
            self.speed_ref_change = ratio - 1.0
        confirming = (self.speed_ref_change, partner.speed_ref_change if partner else 0.0)
        slope_counts = not (self.odd_speed and o.slopes_at_reference_speed) or (
            all if o.odd_speed_slopes_need_both else any)(
            c * (ratio - 1.0) > 0.0 and abs(c) > o.same_slope_tolerance for c in confirming)
        if slope_counts:
            self.recent_slopes = [*self.recent_slopes, ramp.slope_A_per_deg][-o.slope_window:]
        shared = 0.0 if partner is None else common_change(
            self.slope_change, partner.slope_change, o.same_slope_tolerance)
        self.shared_change = shared
        self.partner_change = 0.0 if partner is None else partner.slope_change
        self.knob_change = self._knob_change_with(partner)
        self.partner_last_change = 0.0 if partner is None else partner.last_change
        if ramp.past_knee and slope_counts:
            self.knee_slopes = [*self.knee_slopes, ramp.slope_A_per_deg][-o.slope_window:]
        self.partner_knee_change = 0.0 if partner is None else partner.knee_slope_change
        shared_ok = (abs(shared) >= 2.0 * o.same_slope_tolerance
                     and 1.0 / o.shared_slope_ratio_max <= ratio <= o.shared_slope_ratio_max)
        in_bounds = 1.0 / o.slope_ratio_max <= ratio <= o.slope_ratio_max or shared_ok
        if not in_bounds and self.odd_speed and o.odd_speed_not_refused:
            # the knob far off the reference's speed: its slope is not the reference's
            # friction (planetwist 1: 0.3 x at 113 deg/s); a stuck knob lags its command
            self.n_odd_speed += 1
            self.last_measurement_deg = math.nan
            return events
        if not in_bounds:
            # A stuck knob or a blocked tip (one tendon's ramp), or a stroke across a shape
            # change: this ramp is refused and the suspects before it are void, but the ramps
            # after it measure (freezing them delayed a slack change by two ramps per side). A
            # steeper ramp on both tendons of the knob is the sheath's friction (a bend): it
            # measures.
            self.suspects.clear()
            self.n_refused += 1
            events.append(("warning", "online ramp refused", {
                **tag, "reason": f"current ramp {ratio:.1f} x the reference slope (stuck knob "
                                 "or blocked tip?)"}))
            return events
        if self.frozen_for > 0:
            self.frozen_for -= 1
            return events
        knee_m = ramp.side * (ramp.knee_deg - profile_edge_deg) - self.knee_residual_ref_deg
        direction = self.knee_direction
        first_knee = self.last_feature != "knee"
        if math.isfinite(knee_m) and direction != 0:
            # The sheath's friction changed the engagement: no level crossing places the
            # edge; the knee, seen in the stroke itself, does. Otherwise the crossing (the
            # knee scatters three times as much: it is resolved to the samples' spacing at
            # full speed, ~0.5 deg, and on the lumped plant's gradual toe by +-3 deg).
            self.last_feature = "knee"
            if not o.knee_places_edge or direction * (knee_m - self.estimate_deg) < -o.gate_deg:
                # More friction (steeper ramps) widens the dead zone, less narrows it; a
                # knee that says the opposite beyond the gate is the toe's shape, not the
                # edge (lumped 104, 60 deg bend: ramps 1.15-1.22 x, knees 2.5-6.25 deg
                # inward, followed: phi1 tracked worse than with online off).
                self.n_odd_knee += 1
                self.last_measurement_deg = math.nan
                return events
            self._measured(knee_m, ramp.other_deg, events)
            own, other = self.last_change, self.partner_last_change
            self.bend_suspect = (first_knee and bool(self.suspects) and own * other > 0.0
                                 and min(abs(own), abs(other)) > 2.0 * o.same_slope_tolerance
                                 and direction * (self.suspects[-1] - self.estimate_deg)
                                 > o.gate_deg)
            return events
        # The crossing on a line through the window's centre (~15 deg back: 10 % of slope is
        # 1.5 deg of edge) with the slope both edges' last ramps agree on; one ramp's slope
        # scatters by 25 % and more, so a ramp that disagrees with it measures nothing.
        tol = o.slope_in_use_tolerance
        change = self.slope_change if partner is None else self._common_change(tol)
        slope = self.slope_ref_A_per_deg * shrunk_ratio(1.0 + change, tol)
        if o.reread_on_slope_change:
            self._reread(slope)
            self.held = (ramp, profile_edge_deg, slope)
        if abs(ramp.slope_A_per_deg / slope - 1.0) > o.same_slope_tolerance:
            widened = self._widening_read(ramp, profile_edge_deg, slope, self.partner)
            if widened is None:
                self.n_odd_slope += 1
                self.last_measurement_deg = math.nan
                return events
            self.last_feature = "crossing"
            self._measured(widened, ramp.other_deg, events)
            return events
        self.last_feature = "crossing"
        leaning = self._leaning_steeper_read(ramp, profile_edge_deg, slope, partner)
        raw = self._crossing_read(ramp, profile_edge_deg, slope) if leaning is None else leaning
        rose = change > tol or ramp.slope_A_per_deg / slope - 1.0 > tol
        if o.refuse_inward_on_steeper and rose and raw - self.estimate_deg < -o.gate_deg:
            # More friction along the tendon (the knob's ramps, or this one, steeper beyond
            # the tolerance) widens the dead zone, never narrows it; an inward crossing then
            # is the ramp's shape or a slope in use that lags (stickslip 101 phi2 after a
            # bend: ramps 13-19 % steeper, crossings -1.0..-2.8 deg, followed inward; the
            # fresh calibration's edges moved -0.4..0).
            self.n_odd_crossing += 1
            self.last_measurement_deg = math.nan
            return events
        if not self.reference.settled:
            if change > tol:  # the knob's friction rose: a change, against the reference
                self.reference.fix()
            elif not rose and self._settling(ramp, profile_edge_deg, raw):
                return events
        self._measured(raw, ramp.other_deg, events)
        return events

    def _measured(self, raw_deg: float, other_deg: float,
                  events: list[tuple[str, str, dict[str, Any]]]) -> None:
        """One measurement of the offset (referred to its bin of the other knob's angle):
        accepted, or a suspect (followed when confirmed)."""
        o = self.options
        m = raw_deg - self.bins.bias_deg(other_deg)
        if o.learning_bin_lean_holds and abs(m - self.estimate_deg) > o.gate_deg:
            lean = self.bins.learning_lean_deg(other_deg, 1 if m > self.estimate_deg else -1)
            if lean != 0.0 and abs(m - lean - self.estimate_deg) <= o.gate_deg:
                # within the gate against what its bin read so far: it teaches the bin
                self.n_bin_lean += 1
                m -= lean
        if self.odd_speed and m - self.estimate_deg <= o.gate_deg:
            # the friction's speed dependence: no reading, but a widening beyond the gate is
            # what a slack or a bend does and stays a suspect (lumped 1, 60 deg bend: read
            # first on ramps at 4.6-7 deg/s against the reference's 15.5)
            self.n_odd_speed += 1
            self.last_measurement_deg = math.nan
            return
        if self.cut and abs(m - self.estimate_deg) > o.gate_deg:
            # a line through a load that collapsed mid-window is no edge: no suspect
            self.n_cut += 1
            self.last_measurement_deg = math.nan
            return
        self.last_measurement_deg = self.last_reading_deg = m
        if abs(m - self.estimate_deg) <= o.gate_deg:
            self.suspects.clear()
            self.accepted_order = next(ORDER)
            key = self.bins.key(other_deg)
            learned = self.bins.learned(key)
            self.bins.teach(key, raw_deg - self.estimate_deg)
            refining = self.refining_for > 0
            if not (learned or o.learning_bins_count or refining):
                # a bin still learning where the current's edge sits: it teaches the bin, not
                # the estimate (a change beyond the gate is a suspect as anywhere); right
                # after a followed change it refines the follow too (``refine_after_follow``)
                return
            self.accepted = [*self.accepted, m][-o.window:]
            self.estimate_deg = median(
                [*self.accepted, *[self.level_deg] * (o.window - len(self.accepted))])
            self.refining_for = max(self.refining_for - 1, 0)
            if refining:
                self.applied_deg = max(-o.max_offset_deg, min(o.max_offset_deg,
                                                               self.estimate_deg))
        else:
            self.suspects = [*self.suspects, m][-o.confirm:]
            self.suspect_order = next(ORDER)
            if (len(self.suspects) >= o.confirm and max(self.suspects) - min(self.suspects)
                    <= o.confirm_spread_deg and self.confirmed_elsewhere(median(self.suspects))):
                events += self.follow(median(self.suspects), "consecutive ramps agree")
        self._apply()

    def confirmed_elsewhere(self, new_deg: float) -> bool:
        """The other knob shows a change the way ``new_deg`` is from the estimate (always
        when not asked: :attr:`other_knob_shows`, and once this edge followed a change: the
        other knob confirms that the catheter changed, the edge's own ramps then place it;
        screwrod 1 after +0.5 mm of slack: phi2's first follow 1.5 deg too far out, its
        correction refused, on / fresh 0.91 -> 1.41); and, the first change, the knob's
        other edge shows one too (:attr:`EstimatorOptions.partner_confirms`)."""
        direction = 1 if new_deg > self.estimate_deg else -1
        if self.level_deg != 0.0:
            return True
        way = direction if self.options.partner_confirms_same_way else 0
        if self.options.partner_confirms and not partner_shows_change(
                self.partner, self.options.partner_lean * self.options.gate_deg, way):
            self.n_partner_held += 1
            return False
        return self.other_knob_shows is None or self.other_knob_shows(direction)

    def agrees_with(self, other: EdgeTracker) -> bool:
        """Both edges of a knob have a suspect and they agree: the knob's shape changed (a
        slack or curvature change moves both tendons' edges outward together; a spike does not
        hit both tendons' ramps alike); with ``fresh_agreement`` only suspects each newer
        than the other edge's last reading within the gate (that edge read where it was)."""
        fresh = not self.options.fresh_agreement or (
            self.suspect_order > other.accepted_order
            and other.suspect_order > self.accepted_order)
        return (bool(self.suspects) and bool(other.suspects) and self.frozen_for == 0
                and other.frozen_for == 0 and fresh
                and abs(self.suspects[-1] - other.suspects[-1]) <= self.options.confirm_spread_deg)

    def follow(self, new_deg: float, why: str, feature: str = ""
               ) -> list[tuple[str, str, dict[str, Any]]]:
        """Take a confirmed change (within the bound) as the estimate; events to report.
        ``feature``: what placed it when not this edge's own last ramp (the other edge's
        knee: a bend)."""
        o = self.options
        self.last_feature = feature or self.last_feature
        tag = {"knob": self.knob, "side": "pos" if self.side > 0 else "neg"}
        kept = list(self.suspects)
        self.suspects.clear()
        if abs(new_deg) > o.max_offset_deg:
            return [("warning", "online change beyond bounds, not followed",
                     {**tag, "offset_deg": round(new_deg, 2), "bound_deg": o.max_offset_deg})]
        events = [("warning", "online shape change followed",
                   {**tag, "from_deg": round(self.estimate_deg, 2), "to_deg": round(new_deg, 2),
                    "why": why})]
        self.accepted = kept or [new_deg]
        self.estimate_deg = self.level_deg = new_deg
        self.refining_for = o.window if o.refine_after_follow else 0
        self.reference.fix()
        self._apply()
        return events

    def _apply(self) -> None:
        o = self.options
        if abs(self.estimate_deg - self.applied_deg) > o.deadband_deg:
            leaves = abs(self.estimate_deg) > abs(self.applied_deg)
            if (o.partner_confirms and leaves and self.level_deg == 0.0
                    and not partner_left_band(self.partner, o.deadband_deg)):
                self.n_partner_held += 1  # one edge's estimate off the profile on its own
            else:
                self.applied_deg = max(-o.max_offset_deg,
                                       min(o.max_offset_deg, self.estimate_deg))
        if self.last_feature != "knee" or not o.keep_zero_load_in_bend:
            self.zero_load_deg = self.applied_deg

    def status(self) -> dict[str, Any]:
        return edge_status(self)
