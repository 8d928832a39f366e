"""The product's per-knob ``hold_at_home`` (tsmd.compensation.ours): a knob at rest inside
its plateau band keeps its position while the other knob moves its branches (the other plane's
load holds that tip where it was); a knob loaded beyond the band still follows its moved branch,
and without the hold the knob on the plateau's edge follows it too (the shipped behaviour).
The product chooses it per knob (``OursKnob.hold_at_home``, from the profile's tension play,
copied there from the data sheet, session 27)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_compensation_level_grid import params

from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import OursKnob
from tsmd.compensation.tension_play_params import (
    tension_play_from_mapping,
    tension_play_to_mapping,
)

PERIOD_S = 0.01


def knob0_commands_while_knob1_sweeps(q0_deg: float, hold: bool = True) -> np.ndarray:
    """Knob 0 held at ``q0_deg`` (settled first), knob 1 sweeping +-80 deg over 8 s (the
    level grid shifts knob 0's loaded branches by up to 4 deg)."""
    knob = OursKnob.from_params(dataclasses.replace(params(), hold_at_home=hold))
    comp = OursCompensator((knob, knob), PERIOD_S)
    comp.reset(np.array([q0_deg, 0.0]))
    for _ in range(100):
        comp.command(np.array([q0_deg, 0.0]), PERIOD_S)
    t = np.arange(0.0, 8.0, PERIOD_S)
    other = 80.0 * np.sin(2.0 * np.pi * t / 8.0)
    return np.array([comp.command(np.array([q0_deg, q]), PERIOD_S)[0] for q in other])


def test_a_knob_at_rest_on_the_plateau_edge_keeps_its_command_while_the_other_knob_sweeps() -> None:
    for q0 in (4.5, -3.5):  # inside the band (plateaus -3 / +4, margin 1), on a loaded branch
        cmd = knob0_commands_while_knob1_sweeps(q0)
        assert abs(cmd[0]) > 20.0  # the knob is out on its branch, not at 0
        assert np.ptp(cmd) < 1e-9


def test_a_knob_at_rest_in_the_dead_zone_stays_at_its_rest_command() -> None:
    assert np.ptp(knob0_commands_while_knob1_sweeps(0.0)) < 1e-9


def test_a_knob_loaded_beyond_the_band_still_follows_its_moved_branch() -> None:
    assert np.ptp(knob0_commands_while_knob1_sweeps(10.0)) > 1.0


def test_without_the_hold_a_knob_on_the_plateau_edge_follows_its_moved_branch() -> None:
    assert np.ptp(knob0_commands_while_knob1_sweeps(4.5, hold=False)) > 1.0


def commands_with_product_hold(hold: tuple[bool, bool]) -> np.ndarray:
    """Both knobs at rest at 4.5 deg (on the plateau's edge) while the desired angles stand,
    then each knob in turn at rest while the other sweeps +-80 deg; each knob's hold as its
    product chose (``OursKnob.hold_at_home``)."""
    knobs = tuple(OursKnob.from_params(dataclasses.replace(params(), hold_at_home=h))
                  for h in hold)
    comp = OursCompensator((knobs[0], knobs[1]), PERIOD_S)
    t = np.arange(0.0, 8.0, PERIOD_S)
    sweep = 80.0 * np.sin(2.0 * np.pi * t / 8.0)
    out = []
    for rest in (0, 1):
        comp.reset(np.array([4.5, 4.5]))
        for _ in range(100):
            comp.command(np.array([4.5, 4.5]), PERIOD_S)
        q = np.full((t.size, 2), 4.5)
        q[:, 1 - rest] = sweep
        out.append([comp.command(row, PERIOD_S)[rest] for row in q])
    return np.array(out)


def test_a_knob_whose_product_chose_the_hold_keeps_its_command_and_the_other_follows() -> None:
    cmd = commands_with_product_hold((True, False))
    assert np.ptp(cmd[0]) < 1e-9  # knob 1 at rest, held
    assert np.ptp(cmd[1]) > 1.0  # knob 2 at rest, not chosen: follows its moved branch


def test_the_product_hold_is_per_knob() -> None:
    cmd = commands_with_product_hold((False, True))
    assert np.ptp(cmd[0]) > 1.0
    assert np.ptp(cmd[1]) < 1e-9


def test_the_hold_is_written_to_a_profile_only_when_set_and_read_back() -> None:
    held = dataclasses.replace(params(), hold_at_home=True)
    assert "hold_at_home" not in tension_play_to_mapping(params())
    assert tension_play_to_mapping(held)["hold_at_home"] is True
    assert tension_play_from_mapping(tension_play_to_mapping(held)).hold_at_home
    assert not tension_play_from_mapping(tension_play_to_mapping(params())).hold_at_home


def test_a_profile_hold_that_is_not_a_flag_is_refused() -> None:
    m = tension_play_to_mapping(params())
    m["hold_at_home"] = 1
    with pytest.raises(ValueError, match="hold_at_home"):
        tension_play_from_mapping(m)
