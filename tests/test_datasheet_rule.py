"""The product's backlash rule in the data sheet (tsmd.datasheet_rule, session 11): the sheet
names it, calibration follows it, and a sheet without it keeps the rule its shares imply."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from support.profiles import DEVICE

from tsmd.calibration.options import IdentifyOptions, for_product
from tsmd.calibration.run import device_options
from tsmd.cli import main
from tsmd.datasheet_rule import (
    RuleScore,
    backlash_errors,
    choose_rules,
    knee_choice,
    with_rule,
)
from tsmd.profile import DeviceModel, ProfileError, load_device_model
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping

LINE_SHARE = 0.94
SWING_SHARE = 0.95


def sheet(line_share: float | None = LINE_SHARE, rule: str | None = None) -> DeviceModel:
    """The packaged sheet with fraction-rule shares on both knobs and none of the rule stage's
    choices (the packaged sheet carries them since session 26)."""
    base = load_device_model(DEVICE)
    knobs = tuple(dataclasses.replace(k, backlash_settle_fraction=SWING_SHARE,
                                      backlash_release_slope_ratio=0.1,
                                      backlash_release_line_share=line_share,
                                      backlash_release_rule=rule, backlash_knee=None,
                                      reference_rule_backlash_gain=None) for k in base.knobs)
    return dataclasses.replace(base, knobs=(knobs[0], knobs[1]))


def scored(rule: str, knob: int, within: int, mean: float = 1.0, accepted: int = 2
           ) -> RuleScore:
    return RuleScore(rule, knob, within, 56, mean, 3.0, accepted, 2)


def test_a_sheet_naming_swing_ends_the_backlash_at_the_share_of_the_swing() -> None:
    opts = device_options(None, sheet(rule="swing"))[0]
    assert (opts.backlash, opts.release_level, opts.backlash_fraction) == (
        "fraction", "median", SWING_SHARE)


def test_a_sheet_naming_line_ends_the_backlash_against_the_release_line() -> None:
    opts = device_options(None, sheet(rule="line"))[0]
    assert (opts.backlash, opts.release_level, opts.backlash_fraction) == (
        "fraction", "line", LINE_SHARE)


def test_a_sheet_without_the_choice_keeps_the_rule_its_shares_imply() -> None:
    with_line, without_line = sheet(), sheet(line_share=None)
    assert device_options(None, with_line) == device_options(None, sheet(rule="line"))
    assert device_options(None, without_line) == device_options(None, sheet(None, "swing"))
    assert device_options(None, with_line) != device_options(None, without_line)


def test_a_sheet_naming_local_ends_the_backlash_against_the_branch_just_beyond() -> None:
    device = sheet(rule="local")
    device = dataclasses.replace(device, knobs=tuple(
        dataclasses.replace(k, backlash_release_local_share=0.99) for k in device.knobs))
    opts = device_options(None, device)[1]
    assert (opts.backlash, opts.release_level, opts.backlash_fraction) == (
        "fraction", "local", 0.99)


def test_swing_with_a_settled_share_keeps_the_settle_rule() -> None:
    opts = for_product(IdentifyOptions(), 0.995, settle_lag_deg=0.5, line_share=LINE_SHARE,
                       rule="swing")
    assert (opts.backlash, opts.backlash_settle_lag_deg) == ("settle", 0.5)


def test_the_rule_survives_the_sheets_yaml() -> None:
    mapping = device_model_to_mapping(sheet(rule="swing"))
    assert mapping["knobs"]["phi2"]["backlash_release_rule"] == "swing"
    assert device_model_from_mapping(mapping).knobs[1].backlash_release_rule == "swing"
    assert "backlash_release_rule" not in device_model_to_mapping(sheet())["knobs"]["phi1"]


@pytest.mark.parametrize(("rule", "line_share", "message"), [
    ("median", LINE_SHARE, "not one of line, swing, local"),
    ("line", None, "needs backlash_release_line_share"),
    ("local", LINE_SHARE, "needs backlash_release_local_share"),
])
def test_a_bad_rule_in_the_sheet_is_one_line_naming_the_key(
        rule: str, line_share: float | None, message: str) -> None:
    mapping = device_model_to_mapping(sheet(line_share=line_share))
    mapping["knobs"]["phi1"]["backlash_release_rule"] = rule
    with pytest.raises(ProfileError, match=message) as err:
        device_model_from_mapping(mapping)
    assert "phi1.backlash_release_rule" in str(err.value)
    assert "\n" not in str(err.value)


def test_each_knob_gets_the_rule_that_reproduced_the_tip_better() -> None:
    scores = [scored("line", 0, 50), scored("swing", 0, 54),
              scored("line", 1, 55), scored("swing", 1, 52)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["swing", "line"]


def test_the_rule_is_chosen_on_the_backlash_values_it_ends_not_on_the_edges() -> None:
    scores = [dataclasses.replace(scored("line", k, 54), backlash_within=26) for k in (0, 1)]
    scores += [dataclasses.replace(scored("swing", 0, 50), backlash_within=28),
               dataclasses.replace(scored("swing", 1, 56), backlash_within=25)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["swing", "line"]


def test_a_tie_in_backlash_values_keeps_line_whatever_the_edges() -> None:
    scores = [dataclasses.replace(scored("line", k, 50), backlash_within=27) for k in (0, 1)]
    scores += [dataclasses.replace(scored("swing", k, 56), backlash_within=27) for k in (0, 1)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["line", "line"]


def test_a_tie_in_count_keeps_line_whatever_the_mean_errors() -> None:
    scores = [scored("line", 0, 50, mean=1.2), scored("swing", 0, 50, mean=0.9),
              scored("line", 1, 50), scored("swing", 1, 49, mean=0.5)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["line", "line"]


def test_a_tie_in_count_goes_to_the_rule_whose_runs_were_accepted() -> None:
    scores = [scored("line", 0, 50, accepted=1), scored("swing", 0, 50, accepted=2),
              scored("line", 1, 50), scored("swing", 1, 50)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["swing", "line"]


def test_a_knob_without_a_line_share_cannot_be_given_the_line_rule() -> None:
    scores = [scored("line", k, 56) for k in (0, 1)] + [scored("swing", k, 10) for k in (0, 1)]
    chosen = choose_rules(sheet(line_share=None), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["swing", "swing"]
    assert all(k.backlash_release_rule is None
               for k in with_rule(sheet(line_share=None), "line").knobs)


def test_bad_rule_seeds_are_one_line_before_anything_is_measured(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["datasheet", "--plant", "simrig.plants.capstan:make_tendon_sheath_plant",
                 "--device-model", "x", "--out", str(tmp_path / "d.yaml"),
                 "--rule-seeds", "one"])
    assert code == 2
    assert "--rule-seeds" in capsys.readouterr().err
    assert not (tmp_path / "d.yaml").exists()


def test_the_knee_is_dropped_only_on_the_knob_where_it_placed_fewer_values() -> None:
    rules = [scored("line", 0, 50), scored("line", 1, 55)]
    knee = [scored("knee", 0, 56), scored("knee", 1, 54)]
    chosen = knee_choice(sheet(rule="line"), rules, knee)
    assert [k.backlash_knee for k in chosen.knobs] == [True, None]


def test_a_tie_keeps_the_knee() -> None:
    rules = [scored("line", 0, 56), scored("line", 1, 56)]
    knee = [scored("knee", 0, 56, mean=1.5), scored("knee", 1, 56)]
    chosen = knee_choice(sheet(rule="line"), rules, knee)
    assert [k.backlash_knee for k in chosen.knobs] == [True, True]


def test_the_knee_is_chosen_on_the_backlash_values_it_moves_not_on_the_edges() -> None:
    rules = [dataclasses.replace(scored("line", k, 34), backlash_within=25) for k in (0, 1)]
    knee = [dataclasses.replace(scored("knee", 0, 30), backlash_within=28),
            dataclasses.replace(scored("knee", 1, 40), backlash_within=22)]
    chosen = knee_choice(sheet(rule="line"), rules, knee)
    assert [k.backlash_knee for k in chosen.knobs] == [True, None]


def test_the_backlash_errors_are_the_knobs_b_rows() -> None:
    errors = [float(i) for i in range(56)]
    assert list(backlash_errors(errors, 1)) == [float(i) for i in range(42, 56)]


def test_the_knee_that_costs_an_accepted_run_stays_off() -> None:
    rules = [scored("line", 0, 50), scored("line", 1, 50)]
    knee = [scored("knee", 0, 50, accepted=1), scored("knee", 1, 49)]
    chosen = knee_choice(sheet(rule="line"), rules, knee)
    assert [k.backlash_knee for k in chosen.knobs] == [None, None]


def test_a_sheet_with_the_knee_turns_it_on_for_that_knob_only() -> None:
    base = sheet(rule="line")
    knobs = (dataclasses.replace(base.knobs[0], backlash_knee=True), base.knobs[1])
    phi1, phi2 = device_options(None, dataclasses.replace(base, knobs=knobs))
    assert phi1.backlash_knee and phi1.backlash == "fraction"
    assert not phi2.backlash_knee


def test_the_knee_survives_the_sheets_yaml_and_a_bad_value_is_one_line() -> None:
    base = sheet(rule="line")
    knobs = (base.knobs[0], dataclasses.replace(base.knobs[1], backlash_knee=True))
    mapping = device_model_to_mapping(dataclasses.replace(base, knobs=knobs))
    assert mapping["knobs"]["phi2"]["backlash_knee"] is True
    assert "backlash_knee" not in mapping["knobs"]["phi1"]
    assert device_model_from_mapping(mapping).knobs[1].backlash_knee is True
    mapping["knobs"]["phi2"]["backlash_knee"] = "yes"
    with pytest.raises(ProfileError, match="phi2.backlash_knee: must be true or false") as err:
        device_model_from_mapping(mapping)
    assert "\n" not in str(err.value)


def test_the_sheet_records_the_gain_its_chosen_rule_and_knee_read() -> None:
    rules = [dataclasses.replace(scored("line", k, 50), backlash_gain=0.21) for k in (0, 1)]
    rules += [dataclasses.replace(scored("swing", k, 40), backlash_gain=0.33) for k in (0, 1)]
    knee = [dataclasses.replace(scored("knee", 0, 56), backlash_gain=0.25),
            dataclasses.replace(scored("knee", 1, 30), backlash_gain=0.27)]
    chosen = knee_choice(sheet(rule="line"), rules, knee)
    assert [k.backlash_knee for k in chosen.knobs] == [True, None]
    assert [k.reference_rule_backlash_gain for k in chosen.knobs] == [0.25, 0.21]


def test_the_rule_gain_survives_the_sheets_yaml_and_a_bad_value_is_one_line() -> None:
    base = sheet(rule="line")
    knobs = (dataclasses.replace(base.knobs[0], reference_rule_backlash_gain=0.123),
             base.knobs[1])
    mapping = device_model_to_mapping(dataclasses.replace(base, knobs=knobs))
    assert mapping["knobs"]["phi1"]["reference_rule_backlash_gain"] == 0.123
    assert "reference_rule_backlash_gain" not in mapping["knobs"]["phi2"]
    assert device_model_from_mapping(mapping).knobs[0].reference_rule_backlash_gain == 0.123
    mapping["knobs"]["phi1"]["reference_rule_backlash_gain"] = 1.5
    with pytest.raises(ProfileError, match="phi1.reference_rule_backlash_gain") as err:
        device_model_from_mapping(mapping)
    assert "\n" not in str(err.value)
