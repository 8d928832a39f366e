"""The rule choice's candidate for a knob whose release share is settled (session 22)."""

from __future__ import annotations

import dataclasses

import pytest
from support.profiles import DEVICE

from tsmd.calibration.options import IdentifyOptions, for_product
from tsmd.calibration.run import device_options
from tsmd.datasheet_rule import RuleScore, choose_rules, knee_choice, with_rule
from tsmd.datasheet_rule_settled import SETTLED_SHARE, candidate_of, settled_swing
from tsmd.profile import DeviceModel, ProfileError, load_device_model
from tsmd.profile.schema import device_model_from_mapping, device_model_to_mapping

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


@pytest.mark.parametrize(("share", "offered"), [(0.99, True), (0.998, True), (0.985, False),
                                                (1.0, False), (None, False)])
def test_only_a_settled_share_short_of_the_whole_swing_is_offered(
        share: float | None, offered: bool) -> None:
    knob = dataclasses.replace(sheet().knobs[0], backlash_settle_fraction=share)
    assert settled_swing(knob) is offered


def test_the_settled_candidate_wins_where_it_places_more_values() -> None:
    scores = [scored("swing", 0, 50), scored("swing", 1, 54), scored(SETTLED_SHARE, 0, 56)]
    chosen = choose_rules(sheet(), scores)
    assert [candidate_of(k) for k in chosen.knobs] == [SETTLED_SHARE, "swing"]
    assert chosen.knobs[0].backlash_knee is True
    phi1, phi2 = device_options(None, chosen)
    assert (phi1.backlash, phi1.backlash_knee, phi2.backlash) == ("fraction", True, "fraction")


def test_a_tie_keeps_the_settle_rule() -> None:
    scores = [scored("swing", 0, 56), scored(SETTLED_SHARE, 0, 56)]
    chosen = choose_rules(sheet(), scores)
    assert candidate_of(chosen.knobs[0]) == "swing"
    assert device_options(None, chosen)[0].backlash == "settle"


def test_the_settled_candidate_misreading_more_half_cycles_is_not_chosen() -> None:
    scores = [scored("swing", 0, 50), scored(SETTLED_SHARE, 0, 56, misread=1)]
    assert candidate_of(choose_rules(sheet(), scores).knobs[0]) == "swing"


def test_the_settled_candidate_keeps_its_knee_whatever_the_knee_run_scored() -> None:
    rules = [scored("swing", 0, 50), scored(SETTLED_SHARE, 0, 56), scored("swing", 1, 50)]
    chosen = choose_rules(sheet(), rules)
    knee = [scored("knee", 0, 40), scored("knee", 1, 50)]
    after = knee_choice(chosen, rules, knee)
    assert [candidate_of(k) for k in after.knobs] == [SETTLED_SHARE, "swing"]
    assert after.knobs[0].backlash_knee is True


def test_a_plain_rule_drops_the_settled_flag() -> None:
    chosen = choose_rules(sheet(), [scored(SETTLED_SHARE, 0, 56)])
    assert with_rule(chosen, "swing").knobs[0].backlash_settled_share is None


def test_the_flag_survives_the_sheets_yaml_and_needs_the_swing_rule() -> None:
    chosen = choose_rules(sheet(), [scored(SETTLED_SHARE, 0, 56)])
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
