"""The compensator's opt-in ``hold_at_home`` (tsmd.compensation.ours): a knob at rest inside
its plateau band keeps its position while the other knob moves its branches (the other plane's
load holds that tip where it was); a knob loaded beyond the band still follows its moved branch,
and without the hold the knob on the plateau's edge follows it too (the shipped behaviour)."""

from __future__ import annotations

import numpy as np
from test_compensation_level_grid import params

from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import OursKnob

PERIOD_S = 0.01


def knob0_commands_while_knob1_sweeps(q0_deg: float, hold: bool = True) -> np.ndarray:
    """Knob 0 held at ``q0_deg`` (settled first), knob 1 sweeping +-80 deg over 8 s (the
    level grid shifts knob 0's loaded branches by up to 4 deg)."""
    knob = OursKnob.from_params(params())
    comp = OursCompensator((knob, knob), PERIOD_S, hold_at_home=hold)
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
