"""The gain the release ratio is taken against, chosen by tracking on the sheet's unit
(tsmd.datasheet_ratio_gain, session 22)."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from tsmd.compensation.release_ratio import ratio_gain
from tsmd.compensation.safety import KnobLimits
from tsmd.datasheet_ratio_gain import (
    MIN_RMSE_GAIN,
    NO_RELEASE,
    SHEET,
    alternatives,
    candidate,
    choose,
    default_gain,
    measure_gain_scores,
)
from tsmd.profile import DeviceKnob, DeviceModel, ReferencePoint

SETTLE, RULE, OMEGA, RELEASE = 0.319, 0.22, 1.36, 1.62
KNOB = DeviceKnob(OMEGA, ReferencePoint(90.0, 80.0), ReferencePoint(-90.0, -80.0),
                  KnobLimits(-90.0, 90.0, 120.0, 2000.0), release_omega=RELEASE,
                  reference_backlash_gain=SETTLE, reference_rule_backlash_gain=RULE)
# cyclopebax phi1's case: its tracked release 1.59 gives 0.69 against the settle gain (left out)
DROPPED = dataclasses.replace(KNOB, omega=1.33, release_omega=None, reference_backlash_gain=0.425,
                              reference_rule_backlash_gain=0.21)


def test_the_default_gain_is_the_one_the_sheet_takes_without_the_field() -> None:
    assert default_gain(KNOB) == "settle"
    assert default_gain(dataclasses.replace(KNOB, release_ratio_gain="rule")) == "settle"
    assert default_gain(DROPPED) is None


def test_a_knob_is_offered_the_gain_it_does_not_take() -> None:
    assert alternatives(KNOB, None) == ["rule"]
    assert alternatives(dataclasses.replace(KNOB, reference_rule_backlash_gain=None), None) == []


def test_no_tracked_release_is_offered_only_when_asked_and_drops_the_release() -> None:
    assert NO_RELEASE not in alternatives(KNOB, None)
    assert alternatives(KNOB, None, offer_none=True) == ["rule", NO_RELEASE]
    bare = candidate(dataclasses.replace(KNOB, release_ratio_gain="rule"), NO_RELEASE, None)
    assert bare is not None and bare.release_omega is None and bare.release_ratio_gain is None
    assert alternatives(DROPPED, 1.59, offer_none=True) == ["rule"]  # it has none already


def test_a_left_out_release_comes_back_only_against_a_gain_that_makes_it_usable() -> None:
    assert alternatives(DROPPED, None) == []
    assert alternatives(DROPPED, 1.59) == ["rule"]  # 1.59 x 0.79 / 1.33 = 0.94
    back = candidate(DROPPED, "rule", 1.59)
    assert back is not None and back.release_omega == 1.59 and ratio_gain(back) == 0.21
    assert candidate(DROPPED, "settle", 1.59) is None  # 0.69: outside the range


def test_the_other_gain_is_written_only_when_it_tracks_clearly_better() -> None:
    assert choose({SHEET: 1.0, "rule": 0.6}) == "rule"
    assert choose({SHEET: 1.0, "rule": 1.0 - 0.5 * MIN_RMSE_GAIN}) is None
    assert choose({SHEET: 0.6, "rule": 1.0}) is None
    assert choose({}) is None


def test_each_knob_is_tracked_as_the_sheet_stands_and_under_its_other_gain() -> None:
    """One run set for the sheet as it stands (the field dropped), one with each knob switched;
    the knobs scored are those with another gain."""
    device = DeviceModel("x", (dataclasses.replace(KNOB, release_ratio_gain="rule"), DROPPED))
    seen: list[tuple[tuple[str | None, str | None], tuple[float | None, float | None],
                     list[int]]] = []

    def track(factory: Any, trial: DeviceModel, config: Any, seed: int,
              knobs: Sequence[int]) -> dict[int, float]:
        gains = (trial.knobs[0].release_ratio_gain, trial.knobs[1].release_ratio_gain)
        seen.append((gains, (trial.knobs[0].release_omega, trial.knobs[1].release_omega),
                     list(knobs)))
        return {k: (2.0 if gains[k] is None else 1.0) for k in knobs}

    scores = measure_gain_scores(lambda: None, device, (None, 1.59), None, 0,  # type: ignore
                                 track=track)
    assert seen == [((None, None), (RELEASE, None), [0, 1]),
                    (("rule", "rule"), (RELEASE, 1.59), [0, 1])]
    assert scores == ({SHEET: 2.0, "rule": 1.0}, {SHEET: 2.0, "rule": 1.0})
