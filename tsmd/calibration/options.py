"""Tuning of the identification of one sweep (:mod:`tsmd.calibration.identify`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

from tsmd.calibration.unit_part import UnitPart
from tsmd.profile.device import DeviceKnob, DeviceModel
from tsmd.profile.reading_offset import ReadingOffset


@dataclass(frozen=True)
class BacklashReference:
    """The data sheet's backlash on its unit (other knob at 0) and its current's swing there:
    what a unit whose current does not show its backlash is given instead
    (:func:`tsmd.calibration.recovery.unseen_backlash_deg`)."""

    pos_deg: float
    neg_deg: float
    swing_A: float
    bend_gain: float = 1.0
    """The backlash with the other knob at +-90 deg over what the swing alone predicts
    (``DeviceKnob.backlash_bend_gain``)."""

    @staticmethod
    def of(knob: DeviceKnob) -> BacklashReference | None:
        """The sheet knob's reference, None where it lacks a backlash or the swing."""
        pos, neg, swing = (knob.reference_backlash_pos_deg, knob.reference_backlash_neg_deg,
                           knob.reference_release_swing_A)
        if pos is None or neg is None or swing is None or not swing > 0.0:
            return None
        gain = knob.backlash_bend_gain
        return BacklashReference(pos, neg, swing, 1.0 if gain is None else gain)


@dataclass(frozen=True)
class IdentifyOptions:
    """Tuning of the identification; the defaults follow the paper where it says something."""

    cutoff_hz: float = 20.0
    filter_order: int = 3
    max_gap_s: float = 0.5
    min_reversal_deg: float = 10.0
    """Direction changes smaller than this are jitter, not reversals."""
    grid_step_deg: float = 0.25
    """The current is resampled on this knob-angle grid for change-point detection."""
    min_snr: float = 4.0
    """The current must rise by this many noise sigmas past the dead-zone edge."""
    edge_margin_deg: float = 3.0
    """An edge closer than this to the end of a half-cycle was not reached."""
    peak_noise_k: float = 3.0
    """A peak after a reversal must stand out of the noise by this many sigmas."""
    flat_slope_fraction: float = 0.3
    """"Constant" current: rising slower than this fraction of the loaded ramp's slope."""
    penalty_k: float = 20.0
    """Change-point penalty in units of noise variance x log(n) (PELT)."""
    edge: str = "fit"
    """"fit" (the default): the least-squares line intersection of the dead-zone level with the
    loaded ramp, or with the end of a steep first rise where the current shows one
    (:mod:`tsmd.calibration.branch_fit`); "knee": the same from the change points' pieces;
    "rise": the paper's edge, where the current starts to rise (the tendon engages; the tip
    follows a few degrees later, and the exact start of a gentle rise scatters by 3 deg from
    cycle to cycle; docs/calibration.md)."""
    knee_slope_ratio: float = 1.5
    edge_curve: bool = False
    """``edge="fit"``: a knee must also beat a smoothly bending ramp (a curved hinge) by the
    penalty, else the edge is the curve's start (:mod:`tsmd.calibration.curved_ramp`). The
    product's choice (data-sheet ``edge_curve``): off, warmgear's real corner read 2-3 deg
    early; on, jawcrimp's wall-loaded ramp stops flipping between its start and a knee."""
    fit_before_deg: float = 12.0
    """``edge="fit"``: the window fitted starts this far before the rise the pieces show ..."""
    fit_after_deg: float = 15.0
    """... and ends this far after it (the loaded ramp)."""
    max_knee_deg: float = 15.0
    torque_ripple_period_deg: float | None = None
    """``edge="fit"``: the knob angle over which the handle's torque ripples (a detent's notch
    spacing, cogging), or None. The ripple of that period is taken out of the half-cycle's
    current first (its departure from the one-period mean, folded on the period:
    :func:`tsmd.calibration.pieces.ripple_removed`), which removes a periodic ripple of any
    shape and leaves the engagement's corner as it is: a notch's steep-then-shallow stretch on
    the loaded ramp otherwise reads as a knee one period late
    (:func:`tsmd.calibration.pieces.fitted_edge`)."""
    settle_hold_deg: float = 1.0
    """The current must stay on the constant level this long to count as settled."""
    backlash_tangent_deg: float = 3.0
    """Stretch of current before it settles that is extended to meet the constant level."""
    backlash: str = "settle"
    """"settle" (the paper's point a2): where the current joins the release level within the
    noise; "fraction": where it has made up ``backlash_fraction`` of its jump to that level;
    "recovery" (a self-locking handle, session 16): where the current's recovery from its
    overshoot past the release level ends (:mod:`tsmd.calibration.recovery`), plus
    ``backlash_recovery_lag_deg``."""
    backlash_recovery_lag_deg: float = 0.0
    """"recovery": knob travel from the recovery's end to the tip's release on the data
    sheet's unit (``DeviceKnob.backlash_recovery_lag_deg``)."""
    min_backlash_visibility: float = 20.0
    """"recovery": a half-cycle whose recovery explains the current better than a line by less
    than this (noise variance x log n) does not show its backlash (screwrod development units
    1-8: below 20 the ends scatter by 3.5-5.6 deg sd, above by 0.9-1.9)."""
    unseen_backlash: BacklashReference | None = None
    """"recovery": where no half-cycle of a sweep shows the backlash, the sheet's reference
    scaled by the unit's swing is used and flagged (None: no value)."""
    backlash_fraction: float = 0.975
    release_level: str = "median"
    """"fraction": what the share is of. "median" (sheets before session 10): the swing to the
    current's median over 5-20 deg after the end tested, iterated; "line": the gap to the
    release branch fitted as a line once per half-cycle, at the same knob angle
    (:func:`tsmd.calibration.release.line_share_end`), which a sloped branch cannot drag along;
    "local": the gap to a line fitted over the 5-20 deg just beyond each candidate end, the
    first candidate that has closed the share (:func:`tsmd.calibration.release.local_share_end`,
    session 11: a shelf that ramps on later)."""
    backlash_reference_slope_ratio: float | None = None
    """"fraction" with a data sheet that measured it: the release-to-loaded slope ratio
    (:func:`tsmd.calibration.release.release_slope_ratio`) on the sheet's unit, where the share
    was ``backlash_fraction``; each sweep's own ratio then moves its share by
    ``backlash_share_per_slope_ratio`` per unit of ratio (None: one share for every unit)."""
    backlash_share_per_slope_ratio: float = 0.0
    backlash_settle_lag_deg: float = 0.0
    """"settle" with a data sheet that measured it: how much further the knob turns, on the
    sheet's unit, from where the current has settled to where the tip has moved back 1 deg
    (``DeviceKnob.backlash_settle_lag_deg``); the backlash ends that far beyond the settle."""
    backlash_knee: bool = False
    """"fraction": an end beyond the current's knee (where its approach has slowed to the
    release branch's creep, below its scatter per deg) is moved back to the knee
    (:func:`tsmd.calibration.knee.resolvable_end`, session 12). Off by default: it placed every
    value of held-out stickslip and coilpipe but moved lumped's ends before the tip's release
    (0/8 accepted, 291/448; docs/calibration.md, session 12), so it is not a rule for every
    product; False: the rule's end as is."""
    backlash_stick_end: bool = False
    """The backlash ends where the current's steep fall after the reversal (the stick phase)
    ends, whatever the rule (:mod:`tsmd.calibration.stick_end`, session 25; the data sheet's
    ``backlash_stick_end``): the rule's end is kept only where the current shows no such fall.
    False: the rule's end."""
    release_fit_half_deg: float = 4.0
    """"fraction": the share's crossing is read off a quadratic fitted to the current over this
    much knob travel either side of it (noise averaged; narrow enough for a quadratic to follow
    the curve: 2.5-6 deg gave the same accuracy on lumped development units 1-8)."""
    min_level_deg: float = 3.0
    """A run of flat pieces shorter than this after a reversal is a pause in the transient (a
    turn of the filtered reversal, a speed change), not the release level, which lasts until
    the dead-zone edge."""
    reading_offset: ReadingOffset | None = None
    """The product's reading offset from the data sheet, subtracted from this knob's values
    where sure (:mod:`tsmd.calibration.reading_offset`); None: the values as read."""
    release_slope: float | None = None
    """The product's release slope (data sheet ``release_omega``, else ``omega``): a B read at
    the play's end (:mod:`tsmd.calibration.play_engage`) is moved by the knob travel the tip
    needs to move the sheet's 1 deg; None: not moved."""
    unit_part: UnitPart | None = None
    """The product's part of the error that no sweep narrows, from the data sheet's sample
    (:mod:`tsmd.calibration.unit_part`), reported with each value; None: the share's part."""
    max_tracking_error_deg: float = 10.0
    min_follow_ratio: float = 0.5
    """The knob must travel at least this fraction of the commanded travel (else: stalled)."""


SETTLED_FRACTION = 0.99
"""A data sheet's settle fraction at or above this is "settled": within about 1 % of the swing
the current's noise hides the rest (a few mA against a swing of 0.2-0.5 A), so the paper's rule
(where the current joins its release level) already marks the tip's release there."""


SHARE_PER_SLOPE_RATIO = -0.34
"""How the share of the swing made up at the tip's release moves with the unit's release-to-
loaded slope ratio (a larger ratio: less friction-wrap in the sheath, the tip lets go earlier
in the current's approach). Fitted on lumped development units 1-8 (fast sweeps, noise seeds 0
and 1; half-cycles' share at the tip's release against their sweep's mean ratio, the ratio's
slope read over :data:`tsmd.calibration.release.RELEASE_SLOPE_WINDOW_DEG`: -0.24 with the
shorter window of session 8, whose noisier ratio attenuated the fit; docs/calibration.md,
sessions 8 and 9); the sheet's own unit gives the anchor."""


LINE_SHARE_PER_SLOPE_RATIO = -0.5
"""As :data:`SHARE_PER_SLOPE_RATIO` for the share of the gap to the release line: fitted on
the half-cycles of the development units (lumped 1-8 seeds 0 and 1: -0.54; segments 1-8 seed 0:
-0.58, with the 40-95 deg line), the share at the tip's release
against the sweep's mean ratio (session 10)."""


LINE_SHARE_UNIT_U95 = 0.026
"""The 95 % half-width of what the slope ratio leaves unknown of a unit's share of the gap to
the release line at the tip's release: t(0.975, 13) x 0.0120, the standard deviation of the
share's unit part once the product's pattern over the other knob and the ratio's move are taken
out, over the 14 knobs of segments development units 1, 3-8 (noise seed 0, fast protocol). The
plant's constants behind it (docs/calibration.md, session 18): the contacts' presliding
displacement moves the tip's B by -+0.6 deg over its scatter with under 3 mA of change in the
motor current, and the ratio follows the sheath's friction-wrap product only to r -0.95. No
sweep narrows it: it widens the reported half-width of B
(:attr:`tsmd.calibration.estimate.Estimate.reported_u95_deg`), not the gate's, where the data
sheet did not measure the product's own part on its sample (``backlash_unit_u95_deg``,
:mod:`tsmd.calibration.unit_part`; session 19: 1.5-4x too wide on lumped and helixbelt)."""


def for_product(options: IdentifyOptions, settle_fraction: float | None,
                slope_ratio: float | None = None,
                settle_lag_deg: float | None = None,
                line_share: float | None = None,
                rule: str | None = None,
                local_share: float | None = None,
                recovery_lag_deg: float | None = None,
                reference: BacklashReference | None = None,
                settled_share: bool = False) -> IdentifyOptions:
    """The identification for one knob of a product whose data sheet measured how far the
    current has come back when the tip starts to move: below :data:`SETTLED_FRACTION` the
    backlash ends at that share of the current's swing ("fraction"), moved per sweep by the
    unit's own slope ratio where the sheet gives its unit's (``slope_ratio``); else the
    settle rule, ended ``settle_lag_deg`` beyond the settle where the sheet measured that lag;
    else as ``options`` say. A sheet's ``line_share`` (the share of the gap to the release
    line) replaces ``settle_fraction`` and its coefficient, unless the sheet's ``rule`` is
    "swing" (``DeviceKnob.backlash_release_rule``: the product keeps the share of the swing)
    or "local" (the share ``local_share`` of the gap to the branch just beyond the end), or
    "recovery" (the end of the current's recovery from its overshoot plus
    ``recovery_lag_deg``, the sheet's ``reference`` where no half-cycle shows it).
    ``settled_share`` (the sheet's ``backlash_settled_share``, session 22): "swing" reads its
    share even at or above :data:`SETTLED_FRACTION`."""
    if options.backlash != "settle":
        return options
    if rule == "recovery" and recovery_lag_deg is not None:
        return replace(options, backlash="recovery", backlash_recovery_lag_deg=recovery_lag_deg,
                       unseen_backlash=reference)
    if rule == "local" and local_share is not None:
        return replace(options, backlash="fraction", backlash_fraction=local_share,
                       release_level="local")
    if line_share is not None and rule != "swing":
        if line_share >= SETTLED_FRACTION:
            return for_product(options, line_share, None, settle_lag_deg)
        line = replace(options, backlash="fraction", backlash_fraction=line_share,
                       release_level="line")
        if slope_ratio is None:
            return line
        return replace(line, backlash_reference_slope_ratio=slope_ratio,
                       backlash_share_per_slope_ratio=LINE_SHARE_PER_SLOPE_RATIO)
    settles = not (settled_share and rule == "swing")
    if settle_fraction is None or (settles and settle_fraction >= SETTLED_FRACTION):
        if settle_lag_deg is None or settle_fraction is None:
            return options
        return replace(options, backlash_settle_lag_deg=settle_lag_deg)
    if slope_ratio is None:
        return replace(options, backlash="fraction", backlash_fraction=settle_fraction)
    return replace(options, backlash="fraction", backlash_fraction=settle_fraction,
                   backlash_reference_slope_ratio=slope_ratio,
                   backlash_share_per_slope_ratio=SHARE_PER_SLOPE_RATIO)


def device_options(options: IdentifyOptions | None, device: DeviceModel
                   ) -> tuple[IdentifyOptions, IdentifyOptions]:
    """Each knob's identification with its product's backlash rule from the data sheet."""
    base = options or IdentifyOptions()
    chosen = []
    for k in device.knobs:
        one = for_product(base, k.backlash_settle_fraction, k.backlash_release_slope_ratio,
                          k.backlash_settle_lag_deg, k.backlash_release_line_share,
                          k.backlash_release_rule, k.backlash_release_local_share,
                          k.backlash_recovery_lag_deg, BacklashReference.of(k),
                          bool(k.backlash_settled_share))
        # the product's knee (tsmd datasheet) where the sheet turns it on
        one = replace(one, backlash_knee=True) if k.backlash_knee else one
        one = replace(one, backlash_stick_end=True) if k.backlash_stick_end else one
        one = replace(one, edge_curve=True) if k.edge_curve else one
        # the product's edge reader: where the current starts to rise (session 25, warmgear)
        one = replace(one, edge="rise") if k.edge_rise else one
        one = replace(one, torque_ripple_period_deg=k.torque_ripple_period_deg)
        # the release slope only serves a B read at a play's end, which needs an offset
        slope = (k.release_omega or k.omega) if k.reading_offset else None
        chosen.append(replace(one, reading_offset=k.reading_offset, unit_part=UnitPart.of(k),
                              release_slope=None if slope is None else float(slope)))
    return chosen[0], chosen[1]
