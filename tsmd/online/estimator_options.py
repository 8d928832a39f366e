"""The numbers of the edge estimator (:class:`tsmd.online.estimator.EdgeTracker`).

Apart from the tracker so that the configuration and the worker can name them without the
estimator's logic; docs/online.md ("Bounds, hysteresis, confidence, freezes") says what each
one guards against.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class EstimatorOptions:
    baseline_ramps: int = 3
    settle_ramps: int = 0
    """With n > 0 the reference keeps being re-learned on the last ``baseline_ramps`` ramps
    that read within the gate (they do not measure) until the reference of n re-learnings ago
    reads the latest ones within ``deadband_deg`` with a slope within
    ``slope_in_use_tolerance``, a change is followed or the knob's slopes rose
    (:mod:`tsmd.online.reference`). 0 (default): the first ``baseline_ramps`` ramps fix it.
    Session 14 measured 6 (docs/online.md): twistshaft 101-104 and lumped 101 without a change
    drift less (up to 1.75 and 2.17 deg -> 0.58 and 0), but coilpipe 101, screwrod 101 and
    lumped 103 drift more (2.15 -> 2.94, 0.69 -> 1.80, 0 -> 0.78 deg) and lumped 103 phi1
    after a bend with the relation tracks 2.21 x fresh instead of 1.11: off until those are
    understood."""
    speed_ratio_max: float = 2.0
    """A ramp whose knob speed is beyond this factor of the reference ramps' (median) measures
    nothing (``odd_speed_ramps``) unless it reads outward beyond the gate: the sheath's
    friction depends on the speed, so the level the reference learned at the edge does not
    hold at another (coilpipe 1 without a change, the reference at 16-21 deg/s: strokes at
    3.9-7.2 deg/s read -1.0..-2.4 deg; lumped 5-6, at 5-10 deg/s, +0.4..+2.5), while a slack
    or a bend widens the dead zone and may show first on such ramps (lumped 1, 60 deg bend: a
    hard gate delayed phi1's follow by 22 s, on / fresh 0.92 -> 1.11). 0: off (until session
    16)."""
    slopes_at_reference_speed: bool = True
    """A ramp at a knob speed beyond ``speed_ratio_max`` of the reference's feeds the slopes
    (the slope in use, knee mode, the gain) only once the knob's last ramp at the reference's
    speed (either edge) changed slope the same way by more than ``same_slope_tolerance``: a
    slow stroke's steeper ramp is the friction's speed dependence, not the sheath's (coilpipe
    2 without a change: ramps at 8.7-9 deg/s against the reference's 21, 1.58-1.86 x, put
    phi1 in knee mode and into the slope in use; a knee +3.25 deg out and a crossing +1.87
    were followed, the tip's edge stayed within +-0.3 deg), while after a bend the ramps at
    the reference's speed steepen too (lumped 1, 60 deg: 1.13-1.18 x) and the slow ones then
    count (with none of them counting, phi1 followed 30 s later, 0.87 -> 1.38 x fresh). Off:
    every ramp's slope counts (until session 17)."""
    odd_speed_slopes_need_both: bool = True
    """With ``slopes_at_reference_speed``: a ramp at an odd speed feeds the slopes only once
    both tendons' last ramps at the reference's speed changed slope its way beyond
    ``same_slope_tolerance`` (a sheath's friction changes both alike). With either tendon's,
    one ramp at the edge of the speed band (planetwist 1 without a change: 1.35 x at 33 deg/s,
    the reference's ~19; coilpipe 1: 1.17 x at 11 deg/s) let slow ramps at 1.26-2.02 x into
    the slope in use, which rose 9-10 %, and ordinary ramps then read +1.6..+2.5 deg: phi1
    followed without a change on both. Off: either tendon's (until session 24)."""
    odd_speed_not_refused: bool = True
    """A ramp beyond ``slope_ratio_max`` of the reference run at a knob speed beyond
    ``speed_ratio_max`` of the reference's measures nothing (``odd_speed_ramps``) instead of
    being refused with a warning: its slope is not the reference's friction (planetwist 1
    without a change: a ramp at 113 deg/s, 0.3 x), and a stuck knob lags its command and
    freezes the edge anyway. Off: refused (until session 24)."""
    window: int = 5
    gate_deg: float = 1.5
    other_knob_confirms: bool = False
    """A change is followed on a knob only once the other knob's edges show it too
    (:mod:`tsmd.online.cross_knob`): a slack or sheath change moves both knobs' edges, while
    the coil-pipe plant's phi1 crossings read 2-3 deg out for minutes on their own (units 1,
    2 without a change: followed, tracking worse than with online off). Off by default:
    with it (and ``other_knob_lean``) coilpipe 1-2 without a change follow less (2.05 -> 0.58,
    3.00 -> 2.20 deg), but coilpipe 2's +0.5 mm slack on phi2 tracked 2.37 x fresh instead of
    1.37 (phi1 read the slack 40 s late; docs/online.md, Session 16)."""
    other_knob_lean: float = 0.5
    """With ``other_knob_confirms``, the other knob also shows a change when both its edges'
    latest readings lie that way from their estimates by at least this fraction of
    ``gate_deg`` (:func:`tsmd.online.cross_knob.knob_shows`): a change that moves all four
    edges may read on one knob below its gate first (coilpipe 1, +0.5 mm slack: phi1 read
    +0.83/+0.92 deg while phi2 was followed; without the lean phi2 waited 31 s). 0: off."""
    partner_confirms: bool = True
    """An edge leaves the profile's value (its first followed change, or an estimate within
    the gate beyond the dead band) only once the knob's other edge shows a change too
    (:mod:`tsmd.online.partner`; the same way for a followed change with
    ``partner_confirms_same_way``, else either way): a shape change moves both edges of a
    knob, one edge's readings wander on their own (coilpipe 1 without a change: phi1 pos
    followed to +2.04 deg while phi1 neg read -0.17/+0.68, tracking 0.6-1.3 deg worse for 250
    s). Off: each edge on its own (until session 16)."""
    partner_lean: float = 0.5
    """With ``partner_confirms``: the other edge shows a change when its latest reading lies
    this fraction of ``gate_deg`` or more from its estimate (or it followed one)."""
    partner_confirms_same_way: bool = True
    """With ``partner_confirms``: the first change an edge follows on its own suspects needs
    the other edge's latest reading to lie the same way (both outward: a widening, both
    inward: a narrowing), not either way: a slack or a bend widens both edges, while a
    catheter's ring seat relaxing after its calibration moves the whole dead zone (pronyring
    1 without a change, calibrated start: phi1's negative edge read +2.0..+3.0 deg outward
    from 47 s on, its positive edge -0.9..-1.9 inward; both followed, phi1 tracked 3.42
    against 2.98 with online off). Two edges whose suspects agree (:meth:`agrees_with`) are
    not affected. On since session 27; off: either way."""
    gain_after_follow: bool = True
    """The backlash gain moves only once an edge of the knob has followed a change: without
    one the loaded ramps' slopes follow the knob's speed (coilpipe 1 and lumped 6 without a
    change: gains 1.10-1.13 for 10-60 s, lumped 6's phi1 0.58 deg worse over that window);
    a bend, which is what moves beta, widens the edges. Off: the gain follows the slopes
    whenever they moved (until session 16)."""
    confirm: int = 2
    confirm_spread_deg: float = 2.0
    max_offset_deg: float = 12.0
    deadband_deg: float = 0.4
    slope_ratio_max: float = 3.0
    freeze_ramps: int = 2
    same_slope_tolerance: float = 0.15
    slope_in_use_tolerance: float = 0.05
    """The slope a crossing uses moves with the slope change both edges of the knob agree on:
    none of it within this tolerance, in full beyond twice it (:func:`slopes.shrunk_ratio`).
    0.15 until session 10: a 60 deg bend steepens the lumped plant's ramps 1.04-1.21 x and
    moves its edges +2.75..+3.4 deg; with the change shrunk to none the crossing, 15 deg out,
    read ~2 deg short and the ramps beyond 15 % measured nothing (lumped 1, 2: offsets
    0-1.8 deg; docs/online.md, Session 10)."""
    refuse_inward_on_steeper: bool = True
    """A crossing inward beyond the gate while the friction rose (the knob's slope change, or
    this ramp's slope against the slope in use, beyond ``slope_in_use_tolerance``) measures
    nothing, as the knee does in knee mode (session 12, stickslip 101 phi2). On since session
    13: with ``fresh_agreement`` the one run it made worse (lumped 102 without a change) is
    the same with it, and stickslip 104's bend went from 2.02 to 1.02 x fresh (docs/online.md)."""
    flatter_reads_between: bool = True
    """Ramps flatter than the reference (the slope in use below it) read the crossing with
    both slopes, the reference's and the one in use, and take the point between the two
    nearest the estimate: a slack or a bend does not flatten the ramps, a softer catheter
    does without moving the edge (twistshaft 1-2 warming in the patient: ramps 0.86-0.93 x,
    crossings -0.6..-1.8 deg with the slope in use, +0.5..+0.8 with the reference's, while
    the tip's edge stayed within +-0.3 deg; followed, phi2 tracked 0.3-1.6 deg worse than
    with online off). Off: the slope in use alone (until session 17)."""
    within_gate_reads_own: bool = True
    """A crossing within the gate of a ramp whose slope differs from the slope in use reads
    the point between it and the ramp's own slope's crossing nearest the estimate: the slope
    in use is shrunk towards the reference (``slope_in_use_tolerance``) and the line runs
    through the window's centre ~15 deg out, so a ramp flatter than it reads outward and a
    steeper one inward, and under a softening catheter the readings creep (twistshaft 3
    without a change, 600 s: ramps 0.83-0.96 x, crossings +1.0..+1.8 deg with the
    reference's slope, -1.6..+0.9 with their own; phi1 left the dead band to +0.46/+0.79 deg
    and tracked worse than with online off). Both ways, not only flatter ramps: those alone
    leave the steeper ramps' inward readings, and coilpipe 1 without a change ended at
    -0.45 deg instead of -0.03. Beyond the gate nothing changes (a change's suspects). Off:
    the slope in use alone (until session 20)."""
    followed_reads_own: bool = False
    """Once the edge has followed a change, a crossing within the gate of a ramp whose slope
    differs from the slope in use reads its own slope's crossing (when that lies within the
    gate too) instead of the point between the two nearest the estimate: the reference slope
    was learned before the change, and a change moves each tendon's path on its own (the
    knob's common slope change, shrunk to none within ``slope_in_use_tolerance``, does not
    show one tendon's), so the nearest point pins the estimate where the follow put it
    (twistshaft 1, +0.5 mm slack, calibrated start: phi1's positive ramps 1.02-1.07 x the
    reference after the change read +3.2..+3.7 deg with the slope in use, +3.6..+4.5 with
    their own, the estimate stayed at the follow's +3.30). Off: the nearest point (session
    27: built, left off with ``refine_after_follow``; docs/online.md)."""
    suspect_reads_learned_share: bool = True
    """A crossing beyond the gate that the rules above leave at the slope in use's reads at
    the share of the way to the ramp's own slope's crossing that this edge's crossings within
    the gate took before any change was followed (:mod:`tsmd.online.slope_share`): a slack
    moves the line without turning it, and the tendon's ramps that ran steeper or flatter than
    its reference before the change do after it (twistshaft 2, +0.5 mm slack: phi1's positive
    ramps 1.05 x before and after; the follow read +2.82 deg with the slope in use, +3.74
    with its own, the tip wanted +3.3..+3.8, and the ramps before the change had landed on
    the edge with their own slope). Off: the slope in use's crossing."""
    refine_after_follow: bool = False
    """For ``window`` measurements within the gate after a followed change, a reading in an
    other-knob bin still learning counts towards the estimate too (not only the bin), and the
    applied offset is the estimate, not held by ``deadband_deg``: a follow places the edge
    from one or two ramps, and the ramps after it fall in bins still learning (twistshaft 2,
    +0.5 mm slack: phi1's positive edge followed to +2.82 deg from one ramp, later read
    +3.60, +3.81, +3.19, +2.74, +2.71 in learning bins, the estimate stayed +2.82; the tip
    wanted +3.3..+3.8). Off (session 27: with ``followed_reads_own`` twistshaft 1-2's phi1
    got better, unit 1's phi2 0.31 deg worse; docs/online.md)."""
    suspect_needs_own_slope: bool = True
    """A crossing outward beyond the gate with the slope in use that the ramp's own slope
    (within ``same_slope_tolerance`` of it) does not put outward beyond the gate reads the
    point between the two nearest the estimate, as within the gate (``within_gate_reads_own``),
    unless the knob's other edge holds an outward suspect (then it confirms it, a slack's first
    ramps: coilpipe 1): a widening moves the crossing whatever the slope, while a ramp
    a few per cent off the slope in use moves the slope-in-use crossing by ~15 deg x its
    slope's error (planetwist 101 without a change, 600 s: phi2's negative ramps at 0.91-0.93
    x read +1.82/+2.13 deg with the slope in use, +0.40/+1.11 with their own, became two
    suspects and phi2 was followed to +1.9/+2.1 deg). Off: the slope in use's crossing (until
    session 25)."""
    flatter_suspect_reads_own: bool = False
    """A crossing outward beyond the gate with the slope in use, on a ramp flatter than the
    slope in use while the knob's pooled slope change is below -``slope_in_use_tolerance`` (a
    friction that fell on both tendons), whose own slope's crossing lies outward beyond the
    gate too, reads at its own slope's crossing (the nearer): such a fall flattens the ramp
    about its foot, and the slope in use puts the foot too far out (notchclutch 1, +0.5 mm
    slack while its liner still soaks: ramps 0.76-0.92 x, crossings with the slope in use
    +4.8..+5.3 deg, with their own +3.5..+4.4, the edges' true move +3.58). Off (session 25,
    docs/online.md "Session 25, round 2"): closed loop on notchclutch 1 phi1 got worse (a
    knee-mode follow back came inside the RMSE window) and coilpipe 1's slack (phi1 negative
    edge, one noisy 0.89 x ramp) read 2.19 deg instead of 3.90 in replay; notchclutch's miss
    is mostly the bench's run starting on a dry liner after the calibration."""
    cut_window_drop: float = 0.5
    """A ramp whose loaded window's current falls below its running maximum by more than this
    fraction of the line's rise (:attr:`tsmd.online.features.LoadedRamp.load_drop`) gives no
    suspect: a reading of it beyond the gate measures nothing, while its slope still counts
    as any ramp's and a reading within the gate reads as any. A knob moving outward on a
    loaded tendon only adds load, so the fall is the load path changing during the stroke,
    and the line fitted through it crosses the level far from either edge (wormeyelet 4,
    +0.5 mm slack at 80 s in the middle of phi2's positive stroke: the current 0.148 ->
    0.036 A, the line read +5.73 deg, the edge's later ramps +4.8, the follow stayed at
    +5.73). Refusing the whole ramp instead (``RampOptions.load_drop_fraction``) also took its
    slope from the knob's slopes and moved coilpipe 1's and notchclutch 1-2's later phi2
    readings (session 27). 0: off (until session 28)."""
    learning_bin_lean_holds: bool = True
    """A reading beyond the gate in an other-knob bin one measurement short of ``bin_min``,
    whose measurements so far all lie the reading's way, is referred to their median; within
    the gate so referred it teaches the bin as any reading of a learning bin does
    (:meth:`tsmd.online.other_knob.OtherKnobBins.learning_lean_deg`): the current's edge
    depends on the other knob beyond the profile's coupling, and a bin's third reading that
    lies further out than its first two is the bin, not a change (planetwist 3, no change,
    600 s: phi2's negative edge +1.43, +1.37, +2.53 deg at phi1 -37..-46 deg, the last a
    suspect that its positive edge's agreed with: followed to +3.12/+2.53, phi2 4.78 against
    2.76 off). Beyond the gate so referred the reading stays a suspect at its own value (a
    change moves every bin). Off: until session 26."""
    odd_slopes_read_widening: bool = True
    """A ramp whose slope disagrees with the slope in use beyond ``same_slope_tolerance``
    (measuring nothing otherwise) is a suspect when its crossings with the reference's slope
    and with its own both lie outward beyond the gate, at the nearer of the two
    (:meth:`EdgeTracker._widening_read`): a slack or a bend widens the dead zone whatever the
    slope, while the slope in use lags a change by two ramps per edge (coilpipe 1, +0.5 mm
    slack: phi1 pos passed over ramps reading +2.6/+3.7 deg, followed 34 s later, on / fresh
    2.43 x). Off: such a ramp measures nothing (until session 18)."""
    steeper_knob_reads_own: bool = True
    """A ramp at the reference's speed steeper than the slope in use beyond
    ``same_slope_tolerance``, while the knob's other tendon's last ramp was steeper than its
    reference by as much, reads the crossing with its own slope (a suspect when outward beyond
    the gate): both tendons' friction rose, a bend, and the slope in use lags it (coilpipe 1,
    60 deg bend: phi1 ramps 1.16-1.34 x passed over for 40 s, on / fresh 2.13 x). Off: such a
    ramp is read as any odd slope (``odd_slopes_read_widening``; until session 19)."""
    leaning_steeper_reads_own: bool = True
    """A crossing of a ramp steeper than the slope in use beyond ``slope_in_use_tolerance``,
    at the reference's speed, while the knob's other tendon's last ramp was steeper than its
    reference by as much, that leans outward by ``partner_lean`` of the gate with the slope in
    use and lies outward beyond the gate with its own slope, is a suspect at its own slope's
    crossing (:meth:`EdgeTracker._leaning_steeper_read`): the first ramps after a bend are
    5-15 % steeper, the slope in use follows two ramps per edge late and reads a third of the
    widening inside the gate (lumped 1, 60 deg bend: phi2 +0.96/+1.33/+1.00 deg on ramps
    1.08-1.15 x, the fresh edges +2.9/+3.1; followed 52 s after the bend, 19 s into the
    scoring). Both edges' suspects must agree (or two in a row) as for any change. Off: such
    a crossing reads inside the gate (until session 22)."""
    reread_on_slope_change: bool = False
    """The last crossing ramp is read again when the slope in use has moved beyond
    ``slope_in_use_tolerance`` since it was read; outward beyond the gate it becomes a
    suspect (:meth:`EdgeTracker._reread`; session 14, lumped 103 phi2 after a bend)."""
    fresh_agreement: bool = True
    """Both edges of a knob agree only on suspects each taken after the other edge's last
    measurement within the gate (:meth:`EdgeTracker.agrees_with`; session 13, lumped 102
    without a change). Off: any two last suspects within ``confirm_spread_deg`` (until
    session 12)."""
    pooled_slope_change: bool = True
    """The slope in use (and the gain from it, and the bend share) moves with the median of
    both tendons' last ramps' slope ratios, not with one edge's change as far as the other's
    confirms it (:func:`slopes.common_change`)."""
    gain_from_slope_in_use: bool = True
    """Where no ramp was fitted past its knee (outside knee mode, or a plant without a
    knee), the backlash gain follows the slope in use (beta = compliance x the current's
    slope; the lumped plant's bend: ramps 1.04-1.21 x, the fresh calibrations' beta
    1.17-1.25 x). Off: the gain moves in knee mode only (until session 10)."""
    slope_window: int = 3
    """The slope a measurement uses comes from the median of this edge's last
    ``slope_window`` ramps, never from one ramp alone (see :meth:`EdgeTracker.update`)."""
    other_bin_deg: float = 30.0
    """Width of the other knob's angle bins in which the current's own edge is learned
    relative to the profile's (:meth:`tsmd.online.other_knob.OtherKnobBins.bias_deg`)."""
    bin_min: int = 3
    """Measurements a bin needs before its bias counts."""
    bin_window: int = 7
    learning_bins_count: bool = False
    """A measurement in a bin still learning counts for the estimate too (unreferred: the
    bins' shared part is the estimate's). Off (until session 11) it only taught its bin: a
    knob engaged at other-knob angles spread over several bins, one ramp per side every
    ~20 s, then measured nothing for minutes (lumped 103 phi2 after a bend: 4 of 5 ramps of
    the negative edge taught bins, the edge stayed at 0)."""
    shared_slope_ratio_max: float = 8.0
    """A slope change both edges of the knob show (a sheath's friction) is followed up to this
    ratio; beyond ``slope_ratio_max`` on one edge alone it is a stuck knob or a blocked tip."""
    follow_bend_at_once: bool = False
    """On: an edge's first knee beyond the gate while both tendons' last ramps changed slope
    the same way by more than twice ``same_slope_tolerance`` is followed at once on both edges
    of the knob (a bend widens both sides alike), not after a second suspect. Off by default:
    it follows ~10 s sooner but one knee's scatter (+-1.5 deg) made capstan units 1-2 track
    worse after a bend (docs/online.md, Session 9)."""
    gain_from_bend: bool = True
    """With a bend relation (:class:`tsmd.online.bend.BendRelation`), the backlash gain follows
    the relation (its growth per degree of the release line's move, on the data sheet's unit)
    instead of the loaded slope (which over-reads beta 1.29-1.43 x against the fresh
    calibrations' 1.18-1.27 on capstan unit 1, session 9)."""
    bend_in_knee_mode: bool = False
    """With a bend relation: it also places the release line and beta of an edge the knee
    placed. Off: a knee-placed edge keeps x0 moving with it and beta from its past-knee
    slopes (what sessions 7-9 settled on for the capstan bend: the knee reads the edge
    0.5-1.5 deg short, and with the relation on it capstan 1, 2 tracked worse after a 60 deg
    bend, on / fresh mean 1.99 against 1.70; docs/online.md, Session 11)."""
    knee_places_edge: bool = True
    """Off: in knee mode no ramp measures (counted in ``odd_knee_ramps``). The worker turns it
    off for a product whose bend relation says its bends move no edge
    (:attr:`tsmd.online.bend.BendRelation.gain_per_slope`): there the knee is the grown
    engagement, not the edge (ratestate unit 0 at 60 deg, edges -0.38..-0.12 deg, knees read
    -1.5..+2.0 deg and followed phi2 to +1.75; development 1 to +2.0; session 22)."""
    keep_zero_load_in_bend: bool = False
    """On: a change the knee placed moves the edge, not the zero-load point (what a bend does
    on the capstan plant). Off by default: with the knee's edges (~1 deg short of a fresh
    calibration's) moving x0 with the edge tracks better, and the lumped plant's x0 moves
    further than its edge (docs/online.md, Session 9)."""
