"""What an edge's loaded ramps' slopes say: the knob's friction change, knee mode, gain, bend share.

Apart from :class:`tsmd.online.estimator.EdgeTracker` (which inherits them) because they read
the slopes only and never place an edge: the tracker's state below is theirs to read.
"""

from __future__ import annotations

from statistics import median

from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.online.slopes import common_change, pooled_change, shrunk_ratio


class SlopeReadings:
    """Slope-derived readings of one edge tracker (see the module)."""

    options: EstimatorOptions
    slope_ref_A_per_deg: float | None
    recent_slopes: list[float]
    knee_slopes: list[float]
    partner_change: float
    partner_last_change: float
    partner_knee_change: float
    knob_change: float
    level_deg: float
    partner: SlopeReadings | None

    def plausible(self, ramp: LoadedRamp | object) -> bool:
        """A ramp whose slope is within ``slope_ratio_max`` of the reference (True while
        learning); anything else (a rejected stroke) is not."""
        if not isinstance(ramp, LoadedRamp):
            return False
        if self.slope_ref_A_per_deg is None:
            return True
        ratio = ramp.slope_A_per_deg / self.slope_ref_A_per_deg
        return 1.0 / self.options.slope_ratio_max <= ratio <= self.options.slope_ratio_max

    @property
    def knob_followed(self) -> bool:
        """An edge of the knob followed a change (its level left the profile's)."""
        return self.level_deg != 0.0 or (self.partner is not None
                                         and self.partner.level_deg != 0.0)

    @property
    def learning(self) -> bool:
        """No reference yet (the first ramps after start)."""
        return self.slope_ref_A_per_deg is None

    @property
    def knee_mode(self) -> bool:
        """Both tendons' ramps of the knob changed slope the same way (:attr:`knee_direction`):
        the sheath's friction changed the engagement, and the knee, not a level crossing,
        places the edge (capstan unit 2, 60 deg bend: ramps 1.17-1.37 x, the crossing 11 deg
        inward, the knee 4-6 deg outward; a slack change leaves the slopes, lumped 101: 0.85-1.07
        x). Not otherwise: on the lumped toe the knee scatters by +-3 deg (session 7)."""
        return self.knee_direction != 0

    @property
    def knee_direction(self) -> int:
        """+1 when both tendons' ramps got steeper (more friction: :attr:`knee_mode`), -1
        flatter, 0 not in knee mode.

        Besides the medians of three ramps, **the last ramp of each tendon alone** counts
        when both changed the same way beyond twice the tolerance (30 %): a bend shows in
        the first ramp of each tendon after it, and waiting for the medians cost two ramps
        per edge (capstan unit 1 phi2: followed 134 s, not 112 s, after a bend at 80 s;
        the RMSE window begins at 113 s). One ramp's slope scatters by 20-50 % now and then,
        so one tendon alone, or a change within 30 %, does not count."""
        tol = self.options.same_slope_tolerance
        own, other = self.slope_change, self.partner_change
        if own * other > 0.0 and min(abs(own), abs(other)) > tol:
            return 1 if own > 0.0 else -1
        own, other = self.last_change, self.partner_last_change
        if own * other > 0.0 and min(abs(own), abs(other)) > 2.0 * tol:
            return 1 if own > 0.0 else -1
        return 0

    @property
    def last_change(self) -> float:
        """The last ramp's slope against the reference, minus 1 (0 while learning)."""
        if self.slope_ref_A_per_deg is None or not self.recent_slopes:
            return 0.0
        return self.recent_slopes[-1] / self.slope_ref_A_per_deg - 1.0

    @property
    def gain_ratio(self) -> float:
        """How much this tendon's backlash gain beta changed: as its loaded current's slope,
        as far as the other tendon confirms it, none within the slopes' scatter
        (:func:`shrunk_ratio`).

        The tension play's backlash after a reversal is the tendon's stretch given back,
        ``B = c T_r``, with the tension ``T_r = k (x_r - x0)`` the current shows; so
        ``beta = B / (x_r - x0) = c k``: with the compliance ``c`` unchanged by a bend, beta
        follows the current's slope ``k`` (capstan units 1, 2, 101 after 60 deg: slope
        1.2-1.4 x past the knee, the fresh calibrations' beta 1.17-1.28 x). In knee mode
        only from ramps fitted past their knee (a window that starts on the engagement's
        grown step reads 2.5-3 x); without such ramps (the lumped plant has no knee) from the
        slope in use when :attr:`EstimatorOptions.gain_from_slope_in_use`. The release
        itself is crossed too fast under compensation to measure it (docs/online.md). Only
        once an edge of the knob followed a change (:attr:`EstimatorOptions.gain_after_follow`):
        a bend, what moves beta, widens the edges too."""
        o = self.options
        if self.learning or (o.gain_after_follow and not self.knob_followed):
            return 1.0  # without a followed change the slopes follow the knob's speed
        if self.knee_mode and self.knee_slopes:
            mine, theirs = self.knee_slope_change, self.partner_knee_change
            tol = o.same_slope_tolerance
        elif o.gain_from_slope_in_use:
            tol = o.slope_in_use_tolerance
            ratio = shrunk_ratio(1.0 + self._common_change(tol), tol)
            return min(max(ratio, 1.0 / o.slope_ratio_max), o.slope_ratio_max)
        else:
            return 1.0
        ratio = shrunk_ratio(1.0 + common_change(mine, theirs, tol), tol)
        return min(max(ratio, 1.0 / o.slope_ratio_max), o.slope_ratio_max)

    def _pooled_ratios(self, partner: SlopeReadings | None) -> list[float]:
        """Both tendons' last slopes, each against its own reference."""
        ratios = [x / self.slope_ref_A_per_deg for x in self.recent_slopes
                  ] if self.slope_ref_A_per_deg else []
        if partner is not None and partner.slope_ref_A_per_deg:
            ratios += [x / partner.slope_ref_A_per_deg for x in partner.recent_slopes]
        return ratios

    def _common_change(self, tol: float) -> float:
        """The slope change the knob's two tendons share (the slope in use's, the gain's)."""
        if self.options.pooled_slope_change:
            return self.knob_change
        return common_change(self.slope_change, self.partner_change, tol)

    @property
    def bend_weight(self) -> float:
        """0..1: how far this tendon's change is a bend (the sheath's friction rose with the
        edge's move) rather than slack (:class:`tsmd.online.bend.BendRelation` applies in that
        share): 1 in knee mode with steeper ramps; otherwise the knob's common slope change,
        none within ``slope_in_use_tolerance`` (a slack change leaves the slopes: lumped 101
        0.85-1.07 x), in full beyond twice it (a 60 deg bend: 1.04-1.21 x on lumped)."""
        if self.learning:
            return 0.0
        if self.knee_direction > 0 and self.knee_slopes:
            return 1.0
        tol = self.options.slope_in_use_tolerance
        change = self._common_change(tol)
        return min(max((change - tol) / tol, 0.0), 1.0) if tol > 0 else float(change > 0)

    @property
    def knee_slope_change(self) -> float:
        """The median slope of the last ramps fitted past their knee against the reference,
        minus 1 (0 without such ramps)."""
        if self.slope_ref_A_per_deg is None or not self.knee_slopes:
            return 0.0
        return median(self.knee_slopes) / self.slope_ref_A_per_deg - 1.0

    @property
    def slope_change(self) -> float:
        """The median of the last ramps' slopes against the reference, minus 1 (0 while
        learning)."""
        if self.slope_ref_A_per_deg is None or not self.recent_slopes:
            return 0.0
        return median(self.recent_slopes) / self.slope_ref_A_per_deg - 1.0

    def _knob_change_with(self, partner: SlopeReadings | None) -> float:
        """The knob's slope change over both tendons' last ramps (:func:`pooled_change`)."""
        return pooled_change(self.slope_change, self.partner_change,
                             self._pooled_ratios(partner))


__all__ = ["SlopeReadings"]
