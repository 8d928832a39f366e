"""`tsmd datasheet`'s options: what each stage measures and what it costs on the rig.

Kept apart from the command's stages (:mod:`tsmd.commands.datasheet`) because the option list
grows with every product constant a session adds.
"""

from __future__ import annotations

import argparse

from tsmd.config import DEFAULT_CONFIG_PATH
from tsmd.datasheet_rule import RULE_NOISE_SEEDS
from tsmd.datasheet_start import DEFAULT_SHEET_START, SHEET_STARTS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--plant", metavar="MODULE:FACTORY",
                        help="measure on the simulated rig with this plant")
    source.add_argument("--from-recording", nargs="+", metavar="FILE",
                        help="a tracked real unit's sweep recordings, one per knob")
    parser.add_argument("--params", metavar="JSON", help="the plant factory's keyword parameters")
    parser.add_argument("--device-model", metavar="NAME",
                        help="the catheter type's name in the data sheet (required unless "
                             "--update)")
    parser.add_argument("--description", default="", help="one line describing the device")
    parser.add_argument("--out", required=True, metavar="FILE", help="device YAML to write")
    parser.add_argument("--config", metavar="FILE",
                        help=f"configuration whose limits go into the data sheet (default: "
                             f"packaged sim config with --plant, else {DEFAULT_CONFIG_PATH})")
    parser.add_argument("--seed", type=int, default=2000, help="simulated rig's noise seed")
    parser.add_argument("--torque-ripple-period-deg", type=float, metavar="DEG",
                        help="the handle's torque ripple period (a detent's notch spacing, "
                             "cogging), a design constant of the product: every edge fit, the "
                             "sheet unit's included, averages the current over it; written to "
                             "both knobs (docs/calibration.md Session 22: a ripple in the knob's "
                             "torque)")
    parser.add_argument("--edge-rise", action="store_true",
                        help="the product reads its dead-zone edges where the current starts "
                             "to rise, the sheet unit's included (a handle whose current steps "
                             "up at the take-up, then climbs a rippled ramp); written to both "
                             "knobs as edge_rise (docs/calibration.md Session 25)")
    parser.add_argument("--loaded-shape", action="store_true",
                        help="also write each knob's loaded-branch template (ours then bends its "
                             "loaded lines by it; off by default, docs/model.md Session 10) and, "
                             "with --plant, its templates over the other knob's angle (the "
                             "calibration grid, 14 more sweeps; Session 15)")
    parser.add_argument("--choose-loaded-shape", action="store_true",
                        help="with --plant and without --loaded-shape: measure each knob's "
                             "loaded-branch template and keep it where the sheet's unit, "
                             "calibrated once more and tracked, shows the bent line nearer its "
                             "tip (one more calibration; docs/model.md Session 22)")
    parser.add_argument("--tip-backlash-gain", action="store_true",
                        help="with --plant: also track the tip's backlash after reversals at "
                             "+-60 and +-90 deg (2 sweeps more per knob); method ours then takes "
                             "the release-path ratio against the gain reading nearer it (opt-in "
                             "per product, docs/model.md Session 16)")
    parser.add_argument("--tip-line-backlash-gain", action="store_true",
                        help="with --plant: the same sweeps with the tip's backlash read at the "
                             "corners of the paper's lines instead of at the 1 deg threshold; "
                             "the ratio's gain is then chosen against it (a tip with rounded "
                             "corners; opt-in per product, docs/model.md Session 17)")
    parser.add_argument("--release-end-offset", action="store_true",
                        help="with --plant: also calibrate the unit once more, tracked, and read "
                             "where the release ends in the current and on the tip; method ours "
                             "then draws each unit's release line to the end its current shows "
                             "(opt-in per product, docs/model.md Session 18)")
    parser.add_argument("--release-round", action="store_true",
                        help="with --plant: also calibrate the unit once more, tracked, and fit "
                             "the tip's rounded start after a reversal (release_round, "
                             "release_shift; opt-in per product, docs/model.md Session 20)")
    parser.add_argument("--release-end-shape", action="store_true",
                        help="with --plant: also sweep the unit at 45-90 deg, read where the "
                             "tip's release ends after each reversal, and keep that shape on a "
                             "knob where the unit, calibrated once, tracks better with a release "
                             "line per reversal (release_end_shape; opt-in per product, "
                             "docs/model.md Session 23)")
    parser.add_argument("--level-grid", action="store_true",
                        help="with --plant: also calibrate the unit once more, tracked, and read "
                             "how far each side's loaded level moves with the other knob's angle "
                             "(loaded_level_grid; opt-in per product, docs/model.md Session 21; "
                             "with --update: added to that sheet, measured under it, session 26)")
    parser.add_argument("--home-hold", action="store_true",
                        help="with --plant: also calibrate the unit once more and play the rows "
                             "where one knob rests at 0 while the other sweeps, tracked, with "
                             "that knob's hold at home off and on; the knob keeps the hold where "
                             "every row's tip error falls (hold_at_home; opt-in per product, "
                             "docs/model.md Session 27; with --update: added to that sheet, "
                             "measured under it)")
    parser.add_argument("--plateau-gap", action="store_true",
                        help="with --plant: also play the dead-zone loop on the sheet's unit and "
                             "write its plateau gap and flats per gap degree (plateau_gap_deg, "
                             "plateau_gap_factor; opt-in per product: each unit's calibration "
                             "then plays the loop, ~2 min, and moves its plateau heights; "
                             "with --update adds only those; docs/model.md Session 25)")
    parser.add_argument("--unit-edges", action="store_true",
                        help="with --plant: also calibrate the sheet's unit as every unit is and "
                             "write the dead-zone edges its profile holds at the other knob's 0 "
                             "(calibrated_dead_zone_pos_deg / _neg_deg): method ours' plateau "
                             "heights are then drawn through edges read the way each unit's "
                             "are (opt-in per product; with --update adds only those; "
                             "docs/model.md Session 26)")
    parser.add_argument("--flat-heights", action="store_true",
                        help="with --plant: also calibrate the sheet's unit, tracked, read the "
                             "tip's flats where the knob crosses 0 each way, and keep them as "
                             "method ours' plateau heights on a knob where they fit the unit's "
                             "loaded branches better than the heights drawn back from the "
                             "reference points (flat_height_pos_deg / _neg_deg; opt-in per "
                             "product; with --update adds only those; docs/model.md Session 28)")
    parser.add_argument("--flat-sample", metavar="LIST",
                        help="with --update --flat-heights: the product's sample units (values "
                             "of --unit-key, e.g. 201-204) whose own rows judge the flats "
                             "instead of the sheet's unit")
    parser.add_argument("--unit-edges-move", action="store_true",
                        help="with --unit-edges: write those edges less how far the sheet "
                             "unit's tip lines moved between the fresh and the calibrated unit "
                             "(its tracked sweep played on both): the move every unit's own "
                             "edges carry into the state it is used in stays in its line "
                             "(docs/model.md Session 28)")
    parser.add_argument("--edge-level-share", action="store_true",
                        help="with --plant: also calibrate the unit once more, tracked, and read "
                             "the share of the current's edge movement over the other knob's "
                             "angle the tip's loaded level does not follow (edge_level_share; "
                             "opt-in per product, docs/model.md Session 23)")
    parser.add_argument("--rule-seeds", default=",".join(map(str, RULE_NOISE_SEEDS)),
                        metavar="LIST",
                        help="with --plant: noise seeds of the unit's fast calibrations under "
                             "each backlash rule; the better rule per knob goes into the sheet "
                             "(docs/calibration.md, session 11), then the unit calibrated with "
                             "it once per seed chooses each knob's curved-hinge check "
                             "(edge_curve, session 21) and, with the check where taken, the "
                             "product's reading offset (session 14; "
                             "'none': no choice and no offset, the sheet keeps the rule its "
                             "shares imply)")
    parser.add_argument("--no-ratio-gain", action="store_true",
                        help="with --plant: skip the choice of the gain each knob's release "
                             "ratio is taken against (release_ratio_gain; by default the unit "
                             "is calibrated and tracked under each, docs/model.md Session 22)")
    parser.add_argument("--ratio-gain-none", action="store_true",
                        help="with --plant: the ratio-gain choice also offers each knob no "
                             "tracked release (release_omega left out: every unit's release line "
                             "the locus its own current gives; opt-in per product, docs/model.md "
                             "Session 22)")
    parser.add_argument("--recovery-rule", action="store_true",
                        help="with --plant: also offer the backlash rule 'recovery' (a "
                             "self-locking handle): its lag and bend gain measured on the unit's "
                             "fast calibrations under it (one more run per rule seed), kept on a "
                             "knob that chooses it (docs/calibration.md, session 16)")
    parser.add_argument("--unit-sample", metavar="LIST",
                        help="with --plant: also calibrate the sheet's unit and these declared "
                             "sample units (values of --unit-key, e.g. 201,202,203; never units "
                             "scored elsewhere) with the fast protocol, noise seed the first "
                             "rule seed, against their tracked tips, and write each knob's "
                             "dead_zone_unit_u95_deg and backlash_unit_u95_deg "
                             "(docs/calibration.md, session 19)")
    parser.add_argument("--update", metavar="FILE",
                        help="with --plant/--params of the sheet's unit and --unit-sample: add "
                             "the sample's part to this existing sheet, calibrating the sample "
                             "under it, and write it to --out with no other field changed (its "
                             "header records the command; docs/calibration.md, session 20)")
    parser.add_argument("--slope-sample", metavar="LIST",
                        help="with --update, --plant/--params of the sheet's unit: calibrate it "
                             "and these declared sample units (as --unit-sample) from current "
                             "as every unit is, track each knob's loaded slope, and write the "
                             "share of the gain readings' slope change the tips followed "
                             "(slope_gain_weight; docs/model.md, session 27)")
    parser.add_argument("--stick-end", action="store_true",
                        help="with --plant and rule seeds: also calibrate the sheet's unit with "
                             "each backlash ended where the current's steep fall after the "
                             "reversal levels off (the stick phase), keep it on a knob whose B "
                             "values then scatter less about the tip, and measure the reading "
                             "offset again under it (backlash_stick_end; opt-in per product; "
                             "with --update: added to that sheet, docs/calibration.md, "
                             "session 25)")
    parser.add_argument("--settle-gain-check", action="store_true",
                        help="with --plant and rule seeds: also calibrate the sheet's unit as "
                             "every unit is and read its settle-rule backlash gain the units' "
                             "way; where the slope ratio that gives is not 1 within its 95 %% "
                             "half-width, the units' omega takes no settle reading "
                             "(settle_gain_read: false; with --update: added to that sheet, "
                             "docs/model.md, session 25)")
    parser.add_argument("--start", choices=SHEET_STARTS, default=DEFAULT_SHEET_START,
                        help="with --plant: the state the sheet's unit is swept in: 'fresh' "
                             "(the default, every sheet before session 28) or 'calibrated': "
                             "after the same calibration run a clinical unit gets, under the "
                             "sheet (a full measurement: under the one its fresh sweeps give "
                             "first), each sweep and the dead-zone loop (--plateau-gap) on a "
                             "copy of the plant it left (the benches' start); the stages that "
                             "calibrate the unit start it fresh as before (docs/model.md, "
                             "session 28)")
    parser.add_argument("--sweep-constants", action="store_true",
                        help="with --update: measure the sheet unit's +-90 deg sweeps again on "
                             "--start and write the fields they give (omega, reference points "
                             "and backlash, release slope and shares, reference edges) that "
                             "the sheet carries; every other field as it was")
    parser.add_argument("--unit-key", default="unit",
                        help="--unit-sample: the plant factory's parameter naming a unit")
    parser.add_argument("--bend-relation", action="store_true",
                        help="with --plant: also calibrate the unit straight and with its sheath "
                             "bent 30/60/90 deg and write the product's bend relation for online "
                             "re-estimation (four fast calibrations, minutes; docs/online.md)")
    parser.add_argument("--bend-slopes", action="store_true",
                        help="with --bend-relation: also drive the unit under its straight "
                             "calibration through each bend (the online bench's mixed motion) "
                             "and read the loaded ramps' slope rise, for a product whose bends "
                             "move no edge (gain_per_slope, omega_per_gain; docs/online.md "
                             "Session 22)")


__all__ = ["add_arguments"]
