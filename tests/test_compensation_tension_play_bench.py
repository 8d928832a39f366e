"""The family benchmark's scenarios and argument checks (tsmd.bench.family_accuracy)."""

from __future__ import annotations

import argparse

import numpy as np
import pytest

from tsmd.bench.family_accuracy import add_arguments, extra_scenarios, main
from tsmd.errors import TsmdError


def test_extra_scenarios_start_at_rest_and_stay_in_range() -> None:
    for s in extra_scenarios():
        assert np.allclose(s.q_deg[0], 0.0, atol=1e-9), s.name
        assert np.all(np.abs(s.q_deg) <= 90.0), s.name
        assert s.t_s.size == s.q_deg.shape[0]


def test_point_to_point_scenario_dwells_at_each_target() -> None:
    p2p = next(s for s in extra_scenarios() if "point" in s.group)
    still = np.abs(np.diff(p2p.q_deg[:, 1])) == 0.0
    assert still.mean() > 0.5


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args(list(argv))


def test_invalid_plant_params_are_a_one_line_error() -> None:
    with pytest.raises(TsmdError, match="--params is not valid JSON"):
        main(parse("--params", "{unit"))


def test_invalid_unit_seeds_are_a_one_line_error() -> None:
    with pytest.raises(TsmdError, match="--unit-seeds must be integers"):
        main(parse("--unit-seeds", "a,b"))
