"""`tsmd bench bus` reports the whole stack's time per tick split into stack and plant."""

from __future__ import annotations

import re

from tsmd.bench.bus import measure_stack


def test_stack_split_runs_both_plants_for_the_asked_ticks_and_names_the_plant_share() -> None:
    lines = measure_stack(0.4, seed=0)
    stack_lines = [line for line in lines if line.startswith("whole stack")]
    assert [line.split(":")[0] for line in stack_lines] == [
        "whole stack, null plant (spring stand-in)", "whole stack, tendon-sheath plant"]
    for line in stack_lines:
        assert "100 ticks" in line
        plant_us, stack_us = (float(x) for x in re.findall(r"(?:plant.step|stack) ([\d.]+)",
                                                             line))
        assert plant_us > 0.0 and stack_us > 0.0
