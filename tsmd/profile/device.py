"""The data sheet's types: what a manufacturer measured once per product (slope omega, reference
points, limits, the stages' opt-in choices), per knob and for the device (``tsmd datasheet``)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from tsmd.compensation.level_grid import LevelGrid
from tsmd.compensation.loaded_shape import LoadedShape, ShapeGrid
from tsmd.compensation.reversal_release import ReleaseEndShape
from tsmd.compensation.safety import KnobLimits
from tsmd.profile.reading_offset import ReadingOffset

DEVICE_SCHEMA_VERSION = 1
RELEASE_RULES = ("line", "swing", "local", "recovery")
"""The backlash rules a data sheet can name (``DeviceKnob.backlash_release_rule``)."""
RATIO_GAINS = ("settle", "rule")
"""The gains a data sheet can take its release-path ratio against
(``DeviceKnob.release_ratio_gain``)."""
BEND_RELEASE_PER_EDGE_RANGE: tuple[float, float] = (0.2, 5.0)
"""Plausible release-line moves per degree of dead-zone edge move in a sheath bend (measured:
0.55-1.26 on the simulated products, docs/online.md session 11)."""
BEND_GAIN_PER_RELEASE_RANGE: tuple[float, float] = (-0.5, 0.5)
"""Plausible relative backlash-gain growth per degree of release-line move (measured ~0.06)."""
BEND_GAIN_PER_SLOPE_RANGE: tuple[float, float] = (0.0, 10.0)
"""Plausible relative beta growths per unit of loaded-slope rise in a bend that moves no edge
(session 22)."""
BEND_OMEGA_PER_GAIN_RANGE: tuple[float, float] = (-2.0, 2.0)
"""Plausible relative omega changes per relative beta change in a bend (session 22)."""


@dataclass(frozen=True)
class ReferencePoint:
    """A knob angle and the tip angle it gives (design assumption 1: other knob at 0 deg)."""

    knob_deg: float
    tip_deg: float


DEFAULT_HANDLE_SLIP_DEG = 3.0
"""Handle slip of a data sheet written before it was a constant of the sheet."""


@dataclass(frozen=True)
class DeviceKnob:
    """Data-sheet constants of one knob."""

    omega: float
    reference_pos: ReferencePoint
    reference_neg: ReferencePoint
    limits: KnobLimits
    release_omega: float | None = None
    """Optional, measured on the data-sheet unit only (`tsmd datasheet`): tip/knob slope of the
    release branches. Method ours uses only its ratio to the locus of backlash ends that
    ``reference_backlash_gain`` gives on the same unit (a product's shape constant), never the
    slope itself."""
    reference_backlash_pos_deg: float | None = None
    """Optional: the data-sheet unit's tip backlash after the reversal at reference_pos
    (calibration compares its own backlash with it as a plausibility check)."""
    reference_backlash_neg_deg: float | None = None
    """Optional: the same after the reversal at reference_neg."""
    dead_zone_offset_deg: float | None = None
    """Optional: on the data-sheet unit, how far beyond the current's edge the tip leaves the
    plateau. Informational: no compensator uses it."""
    reference_dead_zone_pos_deg: float | None = None
    """Optional (with ``_neg``): the dead-zone edges tsmd's calibration found in the current of
    the unit the reference points were measured on (other knob at 0): the plateau heights are
    then product constants and each unit's loaded line moves with its own edges (method ours)."""
    reference_dead_zone_neg_deg: float | None = None
    handle_slip_deg: float = DEFAULT_HANDLE_SLIP_DEG
    """Knob travel over which the handle's static friction fades to kinetic after a restart
    (the online estimator models it; a sheet without it gets the default)."""
    reference_backlash_gain: float | None = None
    """Optional: the data-sheet unit's backlash gain beta (mean of both sides) from its own
    sweep current (other knob at 0): method ours scales omega per unit by ``1 - beta``."""
    backlash_settle_fraction: float | None = None
    """Optional: on the data-sheet unit, the share of its swing after a reversal that the motor
    current has made up when the tip starts back (the end of the backlash). Per product: where
    it is below :data:`tsmd.calibration.options.SETTLED_FRACTION`, calibration ends the backlash
    at this share instead of where the current has settled (old sheets: the settle rule)."""
    backlash_release_slope_ratio: float | None = None
    """Optional: on the data-sheet unit, the current's slope just after the tip's release over
    its loaded ramp's (:func:`tsmd.calibration.release.release_slope_ratio`): with it the share
    above moves per unit with that unit's own ratio (old sheets: one share for every unit)."""
    reference_release_swing_A: float | None = None
    """Optional, on the data-sheet unit: the motor current's swing after a reversal from the
    loaded current to the release level (:func:`tsmd.calibration.release.release_swing`): with
    it the reference backlashes scale to another unit's own swing for the check that B can be
    seen in the current (old sheets: the reference backlashes as they are)."""
    backlash_settle_lag_deg: float | None = None
    """Optional, on the data-sheet unit: knob travel from where the paper's settle rule ends
    the backlash to where the tip has moved back 1 deg (median over the reversals). Where the
    settle rule is kept (``backlash_settle_fraction`` >= 0.99) calibration ends every unit's
    backlash that much later (old sheets: at the settle)."""
    loaded_shape_pos: LoadedShape | None = None
    """Optional, on the data-sheet unit: the loaded branch's shape (tip travel past the plateau
    in knob degrees at ``omega`` against knob travel past the current's edge,
    :mod:`tsmd.compensation.loaded_shape`); method ours bends each unit's loaded and release
    lines by it (old sheets: straight lines)."""
    loaded_shape_neg: LoadedShape | None = None
    backlash_release_line_share: float | None = None
    """Optional, on the data-sheet unit: the share of its gap to the release branch (a line
    fitted over :data:`tsmd.calibration.release.RELEASE_LINE_WINDOW_DEG` of travel after the
    reversal, taken at the same knob angle) that the current has closed when the tip has moved
    back 1 deg (median over the reversals). Where given it replaces
    ``backlash_settle_fraction``, whose level is read after the end and so moves with it on a
    sloped release branch (session 10); old sheets keep that one."""
    backlash_release_local_share: float | None = None
    """Optional, on the data-sheet unit: the share of its gap to the release branch just beyond
    the tip's release (a line over 5-20 deg past it, read back there:
    :func:`tsmd.calibration.release.local_share_at`) closed at the tip's release, median over
    the reversals; used where ``backlash_release_rule`` is "local"."""
    backlash_release_rule: str | None = None
    """Optional, the product's choice among the fraction rules (one of
    :data:`RELEASE_RULES`): "line" ends the backlash at ``backlash_release_line_share`` of the
    gap to the release line, "swing" at ``backlash_settle_fraction`` of the swing to the
    release level (or the settle rule where that share is settled), "local" at
    ``backlash_release_local_share`` of the gap to the branch just beyond. ``tsmd datasheet`` picks
    the one whose calibration of the sheet's own unit best reproduces its tracked tip (session
    11); without it a sheet keeps the rule its fields imply (line where the line share is
    given)."""
    backlash_settled_share: bool | None = None
    """Optional, the product's choice (``tsmd datasheet``, session 22): ``true`` where the
    knob's rule ("swing") reads its share even though the share is settled (at or above
    :data:`tsmd.calibration.options.SETTLED_FRACTION`), with the knee where chosen, instead of
    the paper's settle rule (jawcrimp phi1: the current still moves when the tip lets go, and
    the settle point comes late on some half-cycles). Absent: the settle rule, as before."""
    backlash_recovery_lag_deg: float | None = None
    """Optional, on the data-sheet unit: knob travel from the end of the current's recovery
    from its overshoot after a reversal (:func:`tsmd.calibration.recovery.recovery_end`) to
    where the tip has moved back 1 deg (median over the reversals); needed by the rule
    "recovery" (a self-locking handle, session 16)."""
    backlash_bend_gain: float | None = None
    """Optional, on the data-sheet unit: its tip's backlash with the other knob at +-90 deg over
    what its reference backlash scaled by the current's swing there predicts, relative to the
    same at the other knob's 0 (:func:`tsmd.calibration.recovery.bend_gain`); the rule
    "recovery" scales a backlash the current does not show by it (1 without it)."""
    edge_curve: bool | None = None
    """Optional, the product's choice of the curved-hinge check on the dead-zone edge
    (:mod:`tsmd.calibration.curved_ramp`): a knee in the loaded current must also beat a
    smoothly bending ramp (``true``; jawcrimp) or is taken as before (absent)."""
    edge_rise: bool | None = None
    """Optional, the product's dead-zone edge reader (``tsmd datasheet --edge-rise``): ``true``
    reads each edge where the current starts to rise (``IdentifyOptions.edge = "rise"``) instead
    of fitting a hinge or knee to it. For a handle whose current steps up where the tendon
    takes up and then climbs a rippled ramp (warmgear's spur gear): there the fit flips between
    hinge and knee from one unit to the next while the step's start keeps the same lag to the
    tip, which the product's reading offset takes out (docs/calibration.md, session 25)."""
    backlash_knee: bool | None = None
    """Optional, the product's choice of the knee (:mod:`tsmd.calibration.knee`): a fraction
    rule's backlash end beyond the point where the current's rise falls below its own scatter
    moves back to that point. It places the end where the current creeps slowly after the
    release (stickslip, coilpipe) and too early where the current slows gradually (lumped), so
    ``tsmd datasheet`` turns it on only where it calibrates the sheet's own unit closer to its
    tracked tip (session 12). None or False: off."""
    settle_gain_read: bool | None = None
    """Optional: ``false`` where the sheet's unit, calibrated as every unit is, does not read
    its own ``reference_backlash_gain`` (the slope ratio that reading gives is off 1 by more
    than its 95 % half-width, :mod:`tsmd.datasheet_settle_gain`): each unit's omega then takes
    no settle-rule reading (session 25). None or True: read."""
    backlash_stick_end: bool | None = None
    """Optional, the product's choice of the stick phase's end (:mod:`tsmd.calibration.stick_end`):
    every half-cycle's backlash ends where the current's steep fall after the reversal levels
    off, not where the rule ends it (session 25: notchclutch, whose current creeps on for 10-20
    deg after the tip is let go). ``tsmd datasheet --stick-end`` turns it on where it reads the
    sheet unit's backlash with less scatter about its tip; None or False: off."""
    reference_rule_backlash_gain: float | None = None
    """Optional: the data-sheet unit's backlash gain as ``reference_backlash_gain`` but with B
    by the product's chosen rule and knee (fast calibrations of that unit, ``tsmd
    datasheet``): method ours reads each unit's gain by that rule too and weighs both readings
    by their scatter (:mod:`tsmd.calibration.unit_slope`, session 13)."""
    reference_tip_backlash_gain: float | None = None
    """Optional, tracked on the data-sheet unit (``tsmd datasheet --tip-backlash-gain``, opt-in,
    session 16): how much the tip's backlash grows per degree of reversal amplitude (reversals
    at 60 and 90 deg, :mod:`tsmd.datasheet_amplitude`). Method ours takes its release-path
    ratio against the gain reading that brings the sheet unit's moved gain nearer it
    (:func:`tsmd.compensation.release_ratio.ratio_gain`); None: the settle rule's."""
    release_ratio_gain: str | None = None
    """Optional, the product's choice of the gain its release-path ratio is taken against:
    "settle" (``reference_backlash_gain``) or "rule" (``reference_rule_backlash_gain``, the
    reading every unit's beta is fitted with); it overrides the choice by the tip gains
    (:func:`tsmd.compensation.release_ratio.ratio_gain`). Set by hand on the sheet's unit's
    tracking (session 21, cyclopebax phi2); None: chosen as before."""
    reference_tip_line_backlash_gain: float | None = None
    """Optional, tracked on the data-sheet unit (``tsmd datasheet --tip-line-backlash-gain``,
    opt-in, session 17): the same growth with the tip's backlash read at the corners of the
    paper's lines (where the release line meets the reversal's level) instead of at the 1 deg
    threshold, which a tip that starts back gradually after a reversal (rounded corners) reaches
    early. Where given, :func:`~tsmd.compensation.release_ratio.ratio_gain` chooses against it
    instead of ``reference_tip_backlash_gain``."""
    reference_release_end_offset_deg: float | None = None
    """Optional, tracked on the data-sheet unit (``tsmd datasheet --release-end-offset``,
    opt-in, session 18): how much farther from the dead zone the tip's release ends (reaches
    its plateau) than the knob current's release ramp turns flat, both read on the same sweeps
    (:mod:`tsmd.datasheet_release_end`). Where given, method ours reads each unit's release end
    from its calibration current (:mod:`tsmd.calibration.release_end`), adds this and draws the
    release line from the unit's backlash end to there, instead of the product's ratio times
    the unit's locus slope; None: the ratio."""
    reference_release_plateau_deg: float | None = None
    """Optional, tracked with ``reference_release_end_offset_deg`` on the same sweeps: the
    sheet unit's tip plateau after a release (magnitude, mean of both sides). Where both are
    given, method ours's plateaus are this (each edge moved along its loaded line) and the
    release line is drawn to the end at it."""
    other_tip_gain: float | None = None
    """Optional, tracked on the data-sheet unit: how many degrees this knob's tip plane shows per
    degree the other plane's tip is bent (a shaft that winds up in torsion turns the planes into
    each other; the current cannot see it). Method ours aims each knob at its desired angle less
    this times the other knob's (session 14); None: 0."""
    reading_offset: ReadingOffset | None = None
    """Optional, measured on the data-sheet unit (``tsmd datasheet``, its fast calibrations
    against its tracked tip, session 14): what the current reads minus what the tip shows, per
    parameter and other-knob angle (:mod:`tsmd.profile.reading_offset`); calibration subtracts
    it where it is sure and large enough (:mod:`tsmd.calibration.reading_offset`). None: none."""
    loaded_shape_grid: tuple[ShapeGrid, ShapeGrid] | None = None
    """Optional, tracked on the data-sheet unit (``tsmd datasheet --loaded-shape``): the
    loaded-branch templates (positive, negative side) over the other knob's angle, where the
    other plane's bend changes the knob's branch (a spine both planes share, session 15);
    method ours bends each unit's lines by the template at the other knob's angle. None: the
    one template ``loaded_shape_pos/neg`` (or straight lines) at every angle."""
    loaded_knee_pos_deg: float | None = None
    """Optional, on the data-sheet unit (``tsmd datasheet --loaded-shape``): the knee of its
    loaded current ramp, knob travel past the current's edge with the other knob at 0
    (:mod:`tsmd.calibration.loaded_knee`). Where the sheet and a unit's profile both carry one,
    method ours moves the templates' knee to the unit's (:mod:`tsmd.compensation.knee_map`,
    session 15). None: the templates as measured."""
    loaded_knee_neg_deg: float | None = None
    dead_zone_unit_u95_deg: float | None = None
    """Optional, measured on the manufacturer's sample of the product (``tsmd datasheet
    --unit-sample``: the sheet's unit and declared sample units, each calibrated with the fast
    protocol and compared with its tracked tip, session 19): the 95 % half-width of what a
    calibration's dead-zone edge misses of the tip beyond its own half-cycles' scatter (the
    product's bias and unit-to-unit part, which no sweep narrows,
    :mod:`tsmd.calibration.unit_part`). Calibration reports it in quadrature with the gate's
    half-width; None: nothing added."""
    backlash_unit_u95_deg: float | None = None
    """Optional, as ``dead_zone_unit_u95_deg`` for the backlash; where given it replaces the
    share-based part of a "line" rule (:data:`tsmd.calibration.options.LINE_SHARE_UNIT_U95`,
    measured on segments only)."""
    sample_offset_dead_zone_pos_deg: float | None = None
    """Optional, measured on the product's sample with the unit parts (session 28): where every
    sample unit's values of this parameter miss their tips on one side, the units' mean miss
    (value minus tip, deg), which calibration subtracts from the reported value only
    (:mod:`tsmd.calibration.sample_offset`); the unit part is then the scatter about it. None: 0."""
    sample_offset_dead_zone_neg_deg: float | None = None
    """As ``sample_offset_dead_zone_pos_deg`` for the negative dead-zone edge."""
    sample_offset_backlash_pos_deg: float | None = None
    """As ``sample_offset_dead_zone_pos_deg`` for the positive backlash."""
    sample_offset_backlash_neg_deg: float | None = None
    """As ``sample_offset_dead_zone_pos_deg`` for the negative backlash."""
    release_round: float | None = None
    """Optional, tracked on the data-sheet unit (session 20): the half-width of the tip's
    rounded start after a reversal, in backlashes at a 90 deg reversal as the current reads them
    (:mod:`tsmd.compensation.release_round`); calibration copies it into each unit's profile and
    method ours scales it by the unit's own backlash. None: a sharp corner."""
    release_shift: float | None = None
    """Optional, with ``release_round``: how much later the tip's release line lies than the
    current's backlash end, in the same backlashes. None: 0."""
    torque_ripple_period_deg: float | None = None
    """Optional, the handle's: the knob angle over which its torque ripples (a detent's notch
    spacing, a cogging period); the dead-zone edge fit averages the current over it
    (:func:`tsmd.calibration.pieces.period_mean`). None: no ripple."""
    loaded_level_grid: LevelGrid | None = None
    """Optional, tracked on the data-sheet unit (``tsmd datasheet --level-grid``, session 21):
    each side's shift of its plateau height over the other knob's angle, where the other
    plane's bend moves the tip's flats and loaded branches inward (a spine both planes share;
    :mod:`tsmd.compensation.level_grid`); calibration copies it into each unit's profile.
    None: the heights at every angle."""
    edge_level_share: float | None = None
    """Optional, tracked on the data-sheet unit (``tsmd datasheet --edge-level-share``, session
    23): the share of the current's edge movement over the other knob's angle that the tip's
    loaded level does not follow (:mod:`tsmd.calibration.edge_level`); calibration turns it and
    the unit's own edges into the unit's level grid. None: the tip follows the edge."""
    release_end_shape: ReleaseEndShape | None = None
    """Optional, read from the data-sheet unit's tip (session 23, ``tsmd datasheet
    --release-end-shape``): where the tip's release ends after a reversal at a fraction of
    90 deg, as a ratio of where it ends after 90 (:mod:`tsmd.compensation.reversal_release`);
    calibration copies it into each unit's profile and method ours draws a release line per
    reversal to that end. None: the static release lines."""
    plateau_gap_deg: float | None = None
    """Optional, read on the data-sheet unit (``tsmd datasheet --plateau-gap``, session 25):
    the dead-zone loop's plateau gap from its motor current, knob deg
    (:mod:`tsmd.calibration.dead_zone_loop`). Where given with ``plateau_gap_factor``, the
    calibration plays the loop on each unit and moves its plateau heights apart by ``factor
    (gap - this) / 2`` (the opt-in; None: no loop, the heights as before)."""
    plateau_gap_factor: float | None = None
    """Optional, with ``plateau_gap_deg``: the sheet unit's tracked flats (both sides' plateau
    heights, summed) over that gap."""
    calibrated_dead_zone_pos_deg: float | None = None
    """Optional (with ``_neg``), read on the data-sheet unit (``tsmd datasheet --unit-edges``,
    session 26): the dead-zone edges its own calibration gives method ours (the profile's
    edges at the other knob's 0, after the reading offset), read as every unit's are: same
    protocol, same time since the catheter was switched on. Where given, the plateau heights
    are drawn through these instead of ``reference_dead_zone_*_deg`` (whose tracked sweep is
    read in the unit's first minutes; warmgear's shaft has by then not yet warmed, its slack
    not yet shrunk). With ``--unit-edges-move`` (session 28) less the move of the sheet
    unit's tip lines between its fresh and calibrated state (every unit's own edges carry that
    move, and a unit is used calibrated). None: the reference edges."""
    calibrated_dead_zone_neg_deg: float | None = None
    flat_height_pos_deg: float | None = None
    """Optional (with ``_neg``), tracked on the data-sheet unit (``tsmd datasheet
    --flat-heights``, session 28): the tip's flat where the knob crosses 0 coming up (the
    height the positive loaded branch leaves) and coming down, kept where the sheet's unit shows
    them nearer its tip than the heights drawn back from the reference points
    (:mod:`tsmd.datasheet_flat_heights`). Where given, method ours takes them as every unit's
    plateau heights. None: the drawn heights."""
    flat_height_neg_deg: float | None = None
    slope_gain_weight: float | None = None
    """Optional, chosen on the product's sample (``tsmd datasheet --update --slope-sample``,
    session 27): the share of the loaded-slope change a unit's backlash-gain reading says that
    the sample's tracked tips showed (0..1). A unit's omega ratio against the sheet's moves by
    this share of what the readings give (:func:`tsmd.calibration.unit_slope.weighed_omega`):
    1 where all backlash is rope stretch the loaded line also loses, less where friction
    holds part of it (wormeyelet's eyelet band and disks). None: 1, every unit's omega as before."""
    hold_at_home: bool | None = None
    """Optional, the product's choice, tracked on the data-sheet unit (``tsmd datasheet --update
    --home-hold``, session 27, :mod:`tsmd.datasheet_home_hold`): method ours keeps this knob's
    command while it rests inside its plateau band and the other knob moves its branches
    (:func:`tsmd.compensation.ours._keep_at_home`), where the sheet unit's tip holds still
    there; None or False: the knob follows its moved branch."""



@dataclass(frozen=True)
class DeviceModel:
    """Data-sheet constants of a catheter type (omega, reference points, limits)."""

    device_model: str
    knobs: tuple[DeviceKnob, DeviceKnob]
    description: str = ""
    schema_version: int = DEVICE_SCHEMA_VERSION
    bend_release_per_edge: float | None = None
    """Optional, measured on the data-sheet unit (`tsmd datasheet --bend-relation`, calibrated
    straight and bent): how far a tendon's release line moves per degree its dead-zone edge
    moves in a sheath bend. With ``bend_gain_per_release_deg`` it is the product's bend
    relation, which online re-estimation applies (a sheet without it: none)."""
    bend_gain_per_release_deg: float | None = None
    """Optional, with the field above: the backlash gain's relative growth per degree of
    release-line move in a bend."""
    bend_gain_per_slope: float | None = None
    """Optional, with the bend relation: beta's relative growth per unit of the loaded ramps'
    slope rise in a bend that moves no edge, x0 kept (measured on the data-sheet unit with the
    online estimator's slope reading, `--bend-slopes`, session 22). None: 0."""
    bend_omega_per_gain: float | None = None
    """Optional, with the bend relation: omega's relative change per relative change of the
    knob's mean beta in a bend. None: omega follows the release-slope relation."""

    @property
    def limits(self) -> tuple[KnobLimits, KnobLimits]:
        return (self.knobs[0].limits, self.knobs[1].limits)

    def with_knob_flag(self, name: str, on: tuple[bool, bool]) -> DeviceModel:
        """The sheet with a per-knob opt-in field ``name`` true where ``on`` says and absent
        (None) elsewhere: how a data-sheet stage writes its per-knob choice."""
        flags: list[dict[str, Any]] = [{name: True if o else None} for o in on]
        knobs = tuple(dataclasses.replace(k, **f)
                      for k, f in zip(self.knobs, flags, strict=True))
        return dataclasses.replace(self, knobs=(knobs[0], knobs[1]))
