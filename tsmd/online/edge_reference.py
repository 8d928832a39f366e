"""The reference an edge tracker reads against, and the ramps it is learned from.

A mixin of :class:`tsmd.online.estimator.EdgeTracker`: the reference (current level, slope,
residuals, the ramps' knob speed) taken from the settling reference
(:mod:`tsmd.online.reference`), re-learned on crossings within the gate while it settles, the
speed rule that keeps a ramp run much faster or slower than the reference's from measuring
(the sheath's friction is speed-dependent), and the crossings read with more than the slope in
use (flatter ramps, odd slopes, a re-read after the slope in use moved).
"""

from __future__ import annotations

import itertools
import math
from statistics import median

from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.online.other_knob import OtherKnobBins
from tsmd.online.partner import holds_outward_suspect
from tsmd.online.reference import SettlingReference
from tsmd.online.slope_share import SlopeShare
from tsmd.online.slopes import nearest_between

ORDER = itertools.count()
"""One order over every tracker's measurements, so two edges can tell whose came first."""


class ReferenceReadings:
    """The reference of one edge tracker (see the module)."""

    options: EstimatorOptions
    reference: SettlingReference
    bins: OtherKnobBins
    level_A: float | None
    slope_ref_A_per_deg: float | None
    residual_ref_deg: float
    knee_residual_ref_deg: float
    speed_ref_deg_s: float
    estimate_deg: float
    suspects: list[float]
    last_measurement_deg: float
    last_reading_deg: float
    accepted_order: int
    suspect_order: int
    n_between: int
    n_widened: int
    n_steeper: int
    n_own_between: int
    n_own_held: int
    n_followed_own: int
    level_deg: float
    n_flatter_own: int
    knob_change: float
    n_leaning_steeper: int
    n_reread: int
    odd_speed: bool
    ramp_change: float
    held: tuple[LoadedRamp, float, float] | None
    partner: ReferenceReadings | None
    share: SlopeShare
    n_share_read: int

    def _speed_matches(self, ramp: LoadedRamp) -> bool:
        """The ramp ran at a knob speed within ``speed_ratio_max`` of the reference's (True
        when either is unknown or the rule is off)."""
        f, ref = self.options.speed_ratio_max, self.speed_ref_deg_s
        if not (f > 0 and math.isfinite(ref) and ref > 0 and math.isfinite(ramp.speed_deg_s)):
            return True
        return ref / f <= ramp.speed_deg_s <= ref * f

    def _take_reference(self) -> None:
        """The reference in use is the settling reference's latest; the bins start again
        from its ramps (their readings were against the reference before)."""
        ref = self.reference.current
        assert ref is not None
        self.level_A, self.slope_ref_A_per_deg = ref.level_A, ref.slope_A_per_deg
        self.residual_ref_deg, self.knee_residual_ref_deg = ref.residual_deg, ref.knee_residual_deg
        speeds = [r.speed_deg_s for r, _ in self.reference.window if math.isfinite(r.speed_deg_s)]
        self.speed_ref_deg_s = median(speeds) if speeds else math.nan
        self.bins = OtherKnobBins(self.options.other_bin_deg, self.options.bin_min,
                                  self.options.bin_window)
        for r, d in self.reference.window:
            self.bins.teach(self.bins.key(r.other_deg), ref.reading_deg(r, d))

    def _crossing(self, ramp: LoadedRamp, edge_deg: float, slope: float) -> float:
        """How far outward of the profile's edge the line through the ramp's window centre with
        ``slope`` crosses the reference level (the reference's own residual taken out)."""
        assert self.level_A is not None
        return ramp.side * (ramp.crossing_deg(self.level_A, slope) - edge_deg
                            - self.residual_ref_deg)

    def _crossing_read(self, ramp: LoadedRamp, edge_deg: float, slope: float) -> float:
        """The crossing with the slope in use; on a ramp flatter than the reference (with
        ``flatter_reads_between``) the point between it and the reference slope's crossing
        nearest the estimate: the slope turned about a point the current does not show (a
        softer catheter: twistshaft warming in the patient, its tip's edge in place). Within
        the gate (with ``within_gate_reads_own``) then the point between that and the ramp's
        own slope's crossing nearest the estimate: which slope is right nothing says there.
        Outward beyond the gate (with ``suspect_needs_own_slope``) the same when the ramp's own
        slope does not put the crossing beyond the gate too, unless the knob's other edge holds
        an outward suspect: a widening must show with both slopes."""
        raw = self._crossing(ramp, edge_deg, slope)
        assert self.slope_ref_A_per_deg is not None
        target = self.estimate_deg + self.bins.bias_deg(ramp.other_deg)
        if self.options.flatter_reads_between and slope < self.slope_ref_A_per_deg:
            self.n_between += 1
            raw = nearest_between(raw, self._crossing(ramp, edge_deg, self.slope_ref_A_per_deg),
                                  target)
        o = self.options
        if ramp.slope_A_per_deg == slope:
            return raw
        own = self._crossing(ramp, edge_deg, ramp.slope_A_per_deg)
        if abs(raw - target) <= o.gate_deg and self.level_deg == 0.0 and not self.odd_speed:
            self.share.teach(raw, own, target)  # the edge is where the profile says
        if o.within_gate_reads_own and abs(raw - target) <= o.gate_deg:
            self.n_own_between += 1
            if (o.followed_reads_own and self.level_deg != 0.0
                    and abs(own - target) <= o.gate_deg):
                self.n_followed_own += 1  # after a change the reference slope is the old
                return own  # tendon's (``followed_reads_own``)
            return nearest_between(raw, own, target)
        if (o.suspect_needs_own_slope and raw - target > o.gate_deg
                and own - target <= o.gate_deg
                and not holds_outward_suspect(self.partner, o.gate_deg)):
            # outward beyond the gate with the slope in use, not with the ramp's own: nothing
            # says which slope is right, and a widening shows with both (planetwist 101
            # without a change: slow ramps 0.91-0.93 x read +1.82/+2.13 with the slope in
            # use, +0.40/+1.11 with their own, and were followed). Inward, a steeper ramp's
            # crossing is refused when the friction rose (``refuse_inward_on_steeper``).
            self.n_own_held += 1
            return nearest_between(raw, own, target)
        if (o.flatter_suspect_reads_own and raw - target > o.gate_deg
                and own - target > o.gate_deg and ramp.slope_A_per_deg < slope
                and self.knob_change < -o.slope_in_use_tolerance):
            # outward beyond the gate with both slopes on a ramp flatter than the slope in
            # use: the widening is real, its size is the nearer crossing. A friction that
            # falls flattens the ramp about its foot (notchclutch's liner soaking after
            # insertion: ramps 0.76-0.92 x, a +0.5 mm slack read +4.8..+5.3 deg with the
            # slope in use, +3.5..+4.4 with their own, true +3.58).
            self.n_flatter_own += 1
            return own
        if o.suspect_reads_learned_share and abs(raw - target) > o.gate_deg:
            # beyond the gate with the share of the two slopes' crossings that landed on
            # this edge while it was known (:mod:`tsmd.online.slope_share`)
            self.n_share_read += self.share.share is not None
            return self.share.read(raw, own)
        return raw

    def _widening_read(self, ramp: LoadedRamp, edge_deg: float, slope: float,
                       partner: ReferenceReadings | None = None) -> float | None:
        """A ramp whose slope disagrees with the slope in use (``slope``), read with the
        reference's slope and with its own: the nearer crossing when both lie outward beyond
        the gate (with ``odd_slopes_read_widening``), its own slope's when the knob's friction
        rose (:meth:`_knob_steeper`), else None (it measures nothing). After a change the
        slope in use lags by two ramps per edge and the slopes scatter (coilpipe 1, +0.5 mm
        slack: 0.78-1.20 x, the fresh edges +3.4..+4.3 deg; the ramps the slope in use passed
        over read +2.6..+3.7 with the reference's slope and +5.2..+5.3 with their own); without
        a change one of the two stays within the gate (coilpipe 2 phi1, 600 s: 19 odd-slope
        ramps, 0.70-1.86 x, read -3.8..+0.6 with the reference's slope, -9.2..+6.1 with their
        own)."""
        assert self.slope_ref_A_per_deg is not None
        own = self._crossing(ramp, edge_deg, ramp.slope_A_per_deg)
        steeper = self._knob_steeper(ramp, slope, partner)
        if steeper:
            reading = own
        elif self.options.odd_slopes_read_widening:
            reading = min(self._crossing(ramp, edge_deg, self.slope_ref_A_per_deg), own)
        else:
            return None
        beyond = reading - self.bins.bias_deg(ramp.other_deg) - self.estimate_deg
        if beyond <= self.options.gate_deg:
            return None
        self.n_widened += 1
        self.n_steeper += steeper
        return reading

    def _leaning_steeper_read(self, ramp: LoadedRamp, edge_deg: float, slope: float,
                              partner: ReferenceReadings | None) -> float | None:
        """The ramp's own slope's crossing when the knob's friction shows a rise the slope in
        use has not followed yet and the crossing leans outward with either slope (with
        ``leaning_steeper_reads_own``; :attr:`EstimatorOptions.leaning_steeper_reads_own`),
        else None. A bend steepens both tendons' first ramps after it by 5-15 % and widens
        the dead zone; the slope in use, shrunk towards the reference and two ramps per edge
        late, reads a third of the widening inside the gate (lumped 1 phi2: +0.96..+1.33 deg,
        fresh +2.9/+3.1). The lean keeps a steeper ramp whose crossing stays in place (its
        slope's scatter, read outward by its own slope) from becoming a suspect."""
        o = self.options
        tol = o.slope_in_use_tolerance
        if not (o.leaning_steeper_reads_own and not self.odd_speed and partner is not None
                and partner.ramp_change > tol and ramp.slope_A_per_deg / slope - 1.0 > tol):
            return None
        bias = self.bins.bias_deg(ramp.other_deg) + self.estimate_deg
        if self._crossing(ramp, edge_deg, slope) - bias < o.partner_lean * o.gate_deg:
            return None
        own = self._crossing(ramp, edge_deg, ramp.slope_A_per_deg)
        if own - bias <= o.gate_deg:
            return None
        self.n_leaning_steeper += 1
        return own

    def _knob_steeper(self, ramp: LoadedRamp, slope: float,
                      partner: ReferenceReadings | None) -> bool:
        """The ramp, at the reference's speed, is steeper than the slope in use beyond
        ``same_slope_tolerance`` and the knob's other tendon's last ramp (any speed) was
        steeper than its reference by as much (with ``steeper_knob_reads_own``): the sheath's
        friction rose on both tendons (a bend), which the slope in use follows only two ramps
        per edge late, and a flatter slope through the window's centre reads the crossing
        inward (coilpipe 1, 60 deg bend: ramps 1.16-1.34 x read -0.5..+0.6 deg with the
        reference's slope, +1.9..+3.4 with their own; the fresh edges +2.1..+2.5)."""
        tol = self.options.same_slope_tolerance
        return (self.options.steeper_knob_reads_own and not self.odd_speed
                and partner is not None and partner.ramp_change > tol
                and ramp.slope_A_per_deg / slope - 1.0 > tol)

    def _settling(self, ramp: LoadedRamp, profile_edge_deg: float, raw_deg: float) -> bool:
        """While the reference settles, a crossing within the gate re-learns it instead of
        measuring (the catheter's behaviour moving under a reference learned too early is not
        a change; :mod:`tsmd.online.reference`); True when the ramp was taken so. Not a ramp
        steeper than the slope in use, and no ramp once the knob's slopes rose: more friction
        is a bend, whose first crossings read inside the gate (lumped 103 phi2, 60 deg: ramps
        1.11-1.16 x, the bend re-learned into the reference and never followed)."""
        m = raw_deg - self.bins.bias_deg(ramp.other_deg)
        if abs(m - self.estimate_deg) > self.options.gate_deg:
            return False
        self.suspects.clear()
        self.last_measurement_deg = self.last_reading_deg = m
        self.accepted_order = next(ORDER)
        if self.reference.add(ramp, profile_edge_deg):
            self._take_reference()
        return True

    def _reread(self, slope: float) -> None:
        """The last crossing ramp read again with the slope in use now, when that moved beyond
        the tolerance since: a suspect under it joins the suspects (the slope in use follows a
        friction change two ramps late, and the first ramps after a bend read short or
        measured nothing; lumped 103 phi2, 60 deg bend: ramps 1.11-1.16 x, crossings 0.76/1.22
        deg with the old slope, 2.18/2.68 with the new, followed 54 s after the bend)."""
        if self.held is None or self.level_A is None:
            return
        ramp, edge_deg, used = self.held
        self.held = None
        o = self.options
        if (abs(slope / used - 1.0) <= o.slope_in_use_tolerance
                or abs(ramp.slope_A_per_deg / slope - 1.0) > o.same_slope_tolerance):
            return
        m = self._crossing(ramp, edge_deg, slope) - self.bins.bias_deg(ramp.other_deg)
        if m - self.estimate_deg > o.gate_deg:  # outward only: the friction rose
            self.suspects = [*self.suspects, m][-o.confirm:]
            self.suspect_order = next(ORDER)
            self.n_reread += 1
