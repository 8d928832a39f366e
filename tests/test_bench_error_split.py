"""The split of ours' error by the branch the model is on (tsmd.bench.error_split)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pytest

from tsmd.bench import family_accuracy
from tsmd.bench.error_split import delayed, split_error, split_run
from tsmd.compensation.model_parts import model_parts
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import resolve_data_path
from tsmd.profile import load_profile
from tsmd.tracking_scenarios import Scenario, scenarios

OMEGA, H_POS, H_NEG, D_POS, D_NEG = 1.4, -4.0, 4.0, 20.0, -20.0


def _params(lag_s: float = 0.0) -> TensionPlayParams:
    grid = (-90.0, 90.0)
    return TensionPlayParams(OMEGA, H_POS, H_NEG, grid, (D_POS,) * 2, (D_NEG,) * 2, (0.3,) * 2,
                             (0.3,) * 2, (5.0,) * 2, (-5.0,) * 2, lag_s=lag_s)


def _out_and_back() -> np.ndarray:
    """0 -> 70 -> -70 -> 0 deg, 0.1 deg steps."""
    return np.concatenate([np.arange(0.0, 70.0, 0.1), np.arange(70.0, -70.0, -0.1),
                           np.arange(-70.0, 0.0, 0.1)])


def test_loading_past_the_edge_is_loaded_and_its_reversal_is_backlash_then_release() -> None:
    x = _out_and_back()
    y, parts = model_parts(x, np.zeros_like(x), _params(), H_POS)
    first_turn = int(np.argmax(x))
    assert parts[int(np.searchsorted(x[:first_turn], 40.0))] == "loaded"
    assert parts[first_turn + 20] == "backlash"  # 2 deg after the turn: inside the play
    back = first_turn + int(np.argmin(np.abs(x[first_turn:] - 35.0)))
    assert parts[back] == "release"
    assert y[back] < y[first_turn]


def test_the_dead_zone_is_the_plateau() -> None:
    x = _out_and_back()
    _, parts = model_parts(x, np.zeros_like(x), _params(), H_POS)
    assert parts[int(np.searchsorted(x[:600], 10.0))] == "plateau"


def test_shares_sum_to_one_and_the_errors_part_carries_it() -> None:
    q = np.zeros(4)
    tip = np.array([0.0, 3.0, 0.0, 0.0])
    s = split_error(q, tip, q, ["loaded", "release", "plateau", "backlash"], 0)
    assert sum(p.time_share for p in s.parts.values()) == pytest.approx(1.0)
    assert s.parts["release"].mse_share == pytest.approx(1.0)
    assert s.parts["loaded"].mse_share == 0.0


def test_overshoot_is_positive_outward_on_either_side() -> None:
    q = np.array([50.0, -50.0])
    tip = np.array([53.0, -53.0])  # beyond the desired angle on both sides
    s = split_error(q, tip, q, ["loaded", "loaded"], 0)
    assert s.parts["loaded"].outward_deg == pytest.approx(3.0)


def test_a_tip_that_follows_the_model_leaves_no_model_error() -> None:
    x = _out_and_back()
    p = _params()
    y, _ = model_parts(x, np.zeros_like(x), p, H_POS)
    cmd = np.column_stack([x, np.zeros_like(x)])
    tip = np.column_stack([y, np.zeros_like(x)])
    (s,) = split_run(tip + 1.0, cmd, tip, [p, p], (0,), 0.004)
    assert s.model_rmse_deg == pytest.approx(0.0, abs=1e-9)
    assert s.inverse_rmse_deg == pytest.approx(1.0)


def test_the_command_is_delayed_by_the_drive_lag() -> None:
    assert delayed(np.array([1.0, 2.0, 3.0]), 1).tolist() == [1.0, 1.0, 2.0]


def test_series_of_different_lengths_are_refused() -> None:
    with pytest.raises(ValueError, match="equally long"):
        split_error(np.zeros(3), np.zeros(2), np.zeros(3), ["loaded"] * 3, 0)


def test_the_family_bench_prints_a_split_per_scored_knob_when_asked(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    profile = load_profile(resolve_data_path("profiles/example-sim.yaml"))

    def run(s: Scenario, method: str, *_: object) -> object:
        n = 50
        ramp = np.linspace(0.0, 40.0, n)
        return argparse.Namespace(rmse_deg=1.0, ptpe_deg=2.0, scenario=s,
                                  q_deg=np.column_stack([ramp, ramp]),
                                  cmd_deg=np.column_stack([ramp, ramp]),
                                  tip_deg=np.column_stack([ramp + 1.0, ramp + 1.0]))

    monkeypatch.setattr(family_accuracy, "unit_profile", lambda *_: (profile, object()))
    monkeypatch.setattr(family_accuracy, "run_scenario", run)
    monkeypatch.setattr(family_accuracy, "compute_time_us", lambda *a, **k: (1.0, 2.0))
    for split in (False, True):
        args = family_accuracy.namespace_from(argparse.Namespace(
            unit_seeds="1", quick=True, no_extra=True, split=split, report=tmp_path / "r.md"))
        assert family_accuracy.main(args) == 0
        report = (tmp_path / "r.md").read_text(encoding="utf-8")
        lines = [ln for ln in report.splitlines() if "split of ours" in ln]
        knobs = sum(len(s.knobs) for s in scenarios(True))
        assert len(lines) == (knobs if split else 0)
