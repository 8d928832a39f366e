"""The paper's compensator is fed D/B in our fit's frame (session 27): the reported values keep
every sure reading offset, the paper's frame only those of 1 deg and more."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from tsmd.calibration.paper_frame import with_paper_frame
from tsmd.compensation import paper_compensator
from tsmd.config import resolve_data_path
from tsmd.errors import TsmdError
from tsmd.online.apply import profile_with_offsets
from tsmd.profile import CatheterProfile, KnobProfile, load_profile, save_profile
from tsmd.profile.types import make_knob_profile

EXAMPLE = resolve_data_path("profiles/example-sim.yaml")


def moved(knob: KnobProfile, d_pos: float = 0.0, b_neg: float = 0.0) -> KnobProfile:
    """The knob with D_pos and B_neg moved at every grid point (heights redrawn, as the
    calibration draws them)."""
    fresh = make_knob_profile(
        knob, knob.other_knob_deg, [v + d_pos for v in knob.dead_zone_pos_deg],
        knob.dead_zone_neg_deg, knob.backlash_pos_deg, [v + b_neg for v in knob.backlash_neg_deg],
        knob.tension_play)
    return fresh


def with_knob(profile: CatheterProfile, index: int, knob: KnobProfile) -> CatheterProfile:
    knobs = list(profile.knobs)
    knobs[index] = knob
    return dataclasses.replace(profile, knobs=(knobs[0], knobs[1]))


@pytest.fixture
def example() -> CatheterProfile:
    base = load_profile(EXAMPLE)
    # make_knob_profile takes a data-sheet knob: the profile's knob has the same fields it reads
    return dataclasses.replace(base, knobs=tuple(  # type: ignore[arg-type]
        moved(k) for k in base.knobs))


def test_a_knob_whose_model_frame_differs_gets_it_as_the_papers_frame(
        example: CatheterProfile) -> None:
    model = with_knob(example, 0, moved(example.knobs[0], d_pos=-0.9, b_neg=-0.6))
    out = with_paper_frame(example, model)
    paper = out.knobs[0].paper
    assert paper is not None
    assert paper.dead_zone_pos_deg == model.knobs[0].dead_zone_pos_deg
    assert paper.backlash_neg_deg == model.knobs[0].backlash_neg_deg
    assert paper.height_pos_deg == pytest.approx(model.knobs[0].height_pos_deg)
    assert out.knobs[0].dead_zone_pos_deg == example.knobs[0].dead_zone_pos_deg  # reported kept


def test_a_knob_read_alike_in_both_frames_gets_no_papers_frame(example: CatheterProfile) -> None:
    model = with_knob(example, 0, moved(example.knobs[0], d_pos=-0.9))
    out = with_paper_frame(example, model)
    assert out.knobs[1].paper is None
    assert out.knobs[1].for_paper() is out.knobs[1]


def test_the_papers_compensator_takes_the_papers_frame(example: CatheterProfile) -> None:
    model = with_knob(example, 0, moved(example.knobs[0], d_pos=-0.9, b_neg=-0.6))
    fed = paper_compensator(with_paper_frame(example, model)).knobs[0].params(0.0)
    reported = paper_compensator(example).knobs[0].params(0.0)
    own = paper_compensator(model).knobs[0].params(0.0)
    assert fed == own
    assert fed != reported


def test_the_papers_frame_survives_the_profile_file(example: CatheterProfile,
                                                    tmp_path: Path) -> None:
    model = with_knob(example, 1, moved(example.knobs[1], d_pos=0.7))
    out = with_paper_frame(example, model)
    save_profile(out, tmp_path / "p.yaml")
    back = load_profile(tmp_path / "p.yaml")
    assert back.knobs[1].paper is not None
    assert back.knobs[1].paper.dead_zone_pos_deg == pytest.approx(
        model.knobs[1].dead_zone_pos_deg)
    assert back.knobs[0].paper is None
    assert paper_compensator(back).knobs[1].params(30.0) == pytest.approx(
        paper_compensator(model).knobs[1].params(30.0))


def test_a_papers_frame_with_a_grid_of_the_wrong_length_is_refused(
        example: CatheterProfile, tmp_path: Path) -> None:
    out = with_paper_frame(example, with_knob(example, 0, moved(example.knobs[0], d_pos=0.5)))
    save_profile(out, tmp_path / "p.yaml")
    text = (tmp_path / "p.yaml").read_text()
    start = text.index("paper:")
    line = text.index("dead_zone_pos_deg: [", start)
    end = text.index("]", line)
    (tmp_path / "p.yaml").write_text(text[:line] + "dead_zone_pos_deg: [10.0" + text[end:])
    with pytest.raises(TsmdError, match="paper.dead_zone_pos_deg"):
        load_profile(tmp_path / "p.yaml")


def test_an_online_shift_moves_the_papers_frame_with_the_reported_edges(
        example: CatheterProfile) -> None:
    out = with_paper_frame(example, with_knob(example, 0, moved(example.knobs[0], d_pos=-0.9)))
    shifted = profile_with_offsets(out, ((1.0, 2.0), (0.0, 0.0)))
    before, after = out.knobs[0].paper, shifted.knobs[0].paper
    assert before is not None and after is not None
    assert after.dead_zone_pos_deg == pytest.approx([v + 1.0 for v in before.dead_zone_pos_deg])
    assert after.dead_zone_neg_deg == pytest.approx([v - 2.0 for v in before.dead_zone_neg_deg])
