"""The rule choice's candidate for a knob whose release share is settled (session 22)."""

from __future__ import annotations

import dataclasses

import pytest
from support.profiles import DEVICE

from tsmd.calibration.options import IdentifyOptions, for_product
from tsmd.calibration.run import device_options
from tsmd.datasheet_rule import RuleScore, choose_rules, knee_choice, with_rule
from tsmd.datasheet_rule_settled import SWING_KNEE, offered
from tsmd.profile import DeviceModel, ProfileError, load_device_model
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping

SETTLED = 0.99


def sheet(shares: tuple[float, float] = (SETTLED, 0.95)) -> DeviceModel:
    """The packaged sheet with a swing share per knob and no line share."""
    base = load_device_model(DEVICE)
    knobs = tuple(dataclasses.replace(k, backlash_settle_fraction=s, backlash_settle_lag_deg=0.5,
                                      backlash_release_line_share=None)
                  for k, s in zip(base.knobs, shares, strict=True))
    return dataclasses.replace(base, knobs=(knobs[0], knobs[1]))


def scored(rule: str, knob: int, within: int, misread: int = 0) -> RuleScore:
    return RuleScore(rule, knob, within, 56, 1.0, 3.0, 2, 2, half_misread=misread)


def test_a_settled_share_read_at_its_share_is_the_fraction_rule() -> None:
    opts = for_product(IdentifyOptions(), SETTLED, settle_lag_deg=0.5, rule="swing",
                       settled_share=True)
    assert (opts.backlash, opts.release_level, opts.backlash_fraction) == (
        "fraction", "median", SETTLED)


def test_a_settled_share_without_the_flag_keeps_the_settle_rule() -> None:
    opts = for_product(IdentifyOptions(), SETTLED, settle_lag_deg=0.5, rule="swing")
    assert (opts.backlash, opts.backlash_settle_lag_deg) == ("settle", 0.5)


@pytest.mark.parametrize(("share", "line_share", "on"), [
    (0.99, None, True), (0.998, None, True), (0.985, None, False), (0.985, 1.05, True),
    (1.0, 1.05, False), (None, 1.05, False)])
def test_offered_where_a_rule_reads_the_settle_rule_and_the_swing_leaves_a_crossing(
        share: float | None, line_share: float | None, on: bool) -> None:
    knob = dataclasses.replace(sheet().knobs[0], backlash_settle_fraction=share,
                               backlash_release_line_share=line_share)
    assert offered(knob) is on


def test_below_a_settled_share_the_candidate_is_swing_with_the_knee_and_no_flag() -> None:
    base = sheet((0.99, 0.985))
    line_settled = dataclasses.replace(base.knobs[1], backlash_release_line_share=1.05)
    device = dataclasses.replace(base, knobs=(base.knobs[0], line_settled))
    scores = [scored("line", 1, 50), scored("swing", 1, 50), scored(SWING_KNEE, 1, 56)]
    phi2 = choose_rules(device, scores).knobs[1]
    assert (phi2.backlash_release_rule, phi2.backlash_knee, phi2.backlash_settled_share) == (
        "swing", True, None)


def test_the_settled_candidate_wins_where_it_places_more_values() -> None:
    scores = [scored("swing", 0, 50), scored("swing", 1, 54), scored(SWING_KNEE, 0, 56)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["swing", "swing"]
    assert [k.backlash_settled_share for k in chosen.knobs] == [True, None]
    assert [k.backlash_knee for k in chosen.knobs] == [True, None]
    phi1, phi2 = device_options(None, chosen)
    assert (phi1.backlash, phi1.backlash_knee, phi2.backlash) == ("fraction", True, "fraction")


def test_a_tie_keeps_the_settle_rule() -> None:
    scores = [scored("swing", 0, 56), scored(SWING_KNEE, 0, 56)]
    chosen = choose_rules(sheet(), scores)
    assert (chosen.knobs[0].backlash_settled_share, chosen.knobs[0].backlash_knee) == (None, None)
    assert device_options(None, chosen)[0].backlash == "settle"


def test_the_settled_candidate_misreading_more_half_cycles_is_not_chosen() -> None:
    scores = [scored("swing", 0, 50), scored(SWING_KNEE, 0, 56, misread=1)]
    assert choose_rules(sheet(), scores).knobs[0].backlash_settled_share is None


def test_the_settled_candidate_keeps_its_knee_whatever_the_knee_run_scored() -> None:
    rules = [scored("swing", 0, 50), scored(SWING_KNEE, 0, 56), scored("swing", 1, 50)]
    chosen = choose_rules(sheet(), rules)
    knee = [scored("knee", 0, 40), scored("knee", 1, 50)]
    after = knee_choice(chosen, rules, knee)
    assert [k.backlash_knee for k in after.knobs] == [True, True]
    assert [k.backlash_settled_share for k in after.knobs] == [True, None]


def test_a_plain_rule_drops_the_settled_flag() -> None:
    chosen = choose_rules(sheet(), [scored(SWING_KNEE, 0, 56)])
    assert with_rule(chosen, "swing").knobs[0].backlash_settled_share is None


def test_the_flag_survives_the_sheets_yaml_and_needs_the_swing_rule() -> None:
    chosen = choose_rules(sheet(), [scored(SWING_KNEE, 0, 56)])
    mapping = device_model_to_mapping(chosen)
    assert mapping["knobs"]["phi1"]["backlash_settled_share"] is True
    assert "backlash_settled_share" not in mapping["knobs"]["phi2"]
    assert device_model_from_mapping(mapping).knobs[0].backlash_settled_share is True
    mapping["knobs"]["phi1"]["backlash_release_rule"] = "local"
    mapping["knobs"]["phi1"]["backlash_release_local_share"] = 0.99
    with pytest.raises(ProfileError, match="phi1.backlash_settled_share: needs "
                                           "backlash_release_rule: swing") as err:
        device_model_from_mapping(mapping)
    assert "\n" not in str(err.value)
