"""The accuracy benchmark's protocol and metrics (tsmd.bench.accuracy), without simulating."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pytest

from simrig.family import PLANT_SPECS
from tsmd import cli
from tsmd.bench import accuracy, family_accuracy
from tsmd.compensation.ours import OursCompensator
from tsmd.config import resolve_data_path
from tsmd.profile import load_device_model, load_profile
from tsmd.tracking_scenarios import PERIOD_S, conditioned, scenarios, tracking_errors


def test_protocol_has_the_papers_scenarios() -> None:
    groups = {s.group for s in scenarios()}
    assert groups == {"1-DOF periodic", "1-DOF non-periodic", "2-DOF periodic",
                      "2-DOF non-periodic"}
    fixed = sorted({s.q_deg[0, 1] for s in scenarios() if s.group == "1-DOF periodic"
                    and s.knobs == (0,)})
    assert fixed == [-60.0, -30.0, 0.0, 30.0, 60.0]


def test_periodic_input_is_60_deg_at_0_04_hz() -> None:
    s = next(s for s in scenarios() if s.group == "1-DOF periodic")
    q = s.q_deg[:, s.knobs[0]]
    assert q.max() == pytest.approx(60.0, abs=0.01)
    crossings = np.flatnonzero(np.diff(np.sign(q)) > 0)
    assert (crossings[1] - crossings[0]) * PERIOD_S == pytest.approx(25.0, abs=0.01)


def test_two_dof_second_knob_runs_twice_as_fast() -> None:
    s = next(s for s in scenarios() if s.group == "2-DOF periodic")
    ups = [np.count_nonzero(np.diff(np.sign(s.q_deg[:, k])) > 0) for k in (0, 1)]
    assert ups[1] == pytest.approx(2 * ups[0], abs=1)


def test_non_periodic_input_sums_two_incommensurate_sines() -> None:
    s = next(s for s in scenarios() if s.group == "1-DOF non-periodic")
    t = s.t_s
    expected = (30 * np.sin(2 * math.pi * 0.02 * t)
                + 30 * np.sin(2 * math.pi * 0.02 * math.sqrt(3) * t))
    assert np.allclose(s.q_deg[:, 0], expected)


def test_quick_protocol_is_shorter() -> None:
    full = sum(s.t_s.size for s in scenarios())
    quick = sum(s.t_s.size for s in scenarios(quick=True))
    assert quick < full / 3


def test_ptpe_and_rmse() -> None:
    ptpe, rmse = tracking_errors(np.array([1.0, -1.0, 3.0, math.nan]), np.zeros(4))
    assert ptpe == 4.0 and rmse == pytest.approx(math.sqrt(11.0 / 3.0))


def test_conditioned_start_adds_one_unscored_full_cycle_of_both_knobs() -> None:
    s = next(s for s in scenarios() if s.group == "2-DOF periodic")
    _, plain, skip = conditioned(s.t_s, s.q_deg, False)
    t, cond, skip_c = conditioned(s.t_s, s.q_deg, True)
    lead = cond[:skip_c - skip]
    assert np.allclose(cond[skip_c - skip:], plain)  # the scored part is unchanged
    assert np.allclose(cond[skip_c:], s.q_deg) and np.allclose(plain[skip:], s.q_deg)
    for k in (0, 1):
        assert lead[:, k].max() == pytest.approx(90.0, abs=0.01)
        assert lead[:, k].min() == pytest.approx(-90.0, abs=0.01)
    assert np.all(np.abs(np.diff(cond, axis=0)) / PERIOD_S < 120.0)  # within the drive's limit
    assert np.allclose(np.diff(t), PERIOD_S)


def test_accuracy_with_family_options_runs_the_family_bench_with_them(
        monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[argparse.Namespace] = []
    monkeypatch.setattr(family_accuracy, "main", lambda ns: seen.append(ns) or 0)
    assert cli.main(["bench", "accuracy", "--family", "lumped", "--units", "101,103",
                     "--quick", "--no-extra"]) == 0
    (ns,) = seen
    assert (ns.family, ns.units, ns.quick, ns.no_extra) == ("lumped", "101,103", True, True)
    assert ns.methods == "none,paper,ours" and ns.unit_seeds == "1,2,3"  # the family's defaults


@pytest.mark.parametrize("plant", sorted(PLANT_SPECS))
def test_accuracy_takes_every_family_plant(plant: str, monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[argparse.Namespace] = []
    monkeypatch.setattr(family_accuracy, "main", lambda ns: seen.append(ns) or 0)
    assert cli.main(["bench", "accuracy", "--family", plant, "--units", "101"]) == 0
    assert seen[0].family == plant


def test_accuracy_without_family_options_stays_the_single_catheter_bench(
        monkeypatch: pytest.MonkeyPatch) -> None:
    ran: list[str] = []
    monkeypatch.setattr(family_accuracy, "main", lambda ns: ran.append("family") or 0)
    monkeypatch.setattr(accuracy, "main", lambda ns: ran.append("accuracy") or 0)
    assert cli.main(["bench", "accuracy", "--quick"]) == 0
    assert ran == ["accuracy"]


def test_planned_compute_time_includes_the_preview_of_every_tick(
        monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[int] = []
    original = OursCompensator.preview

    def counting(self: OursCompensator, plan_deg: object, index: int) -> None:
        calls.append(index)
        original(self, plan_deg, index)  # type: ignore[arg-type]

    monkeypatch.setattr(OursCompensator, "preview", counting)
    profile = load_profile(resolve_data_path("profiles/example-sim.yaml"))
    median_us, p99_us = accuracy.compute_time_us(profile, "ours", n_ticks=300, planned=True)
    assert calls == list(range(300))
    assert 0.0 < median_us <= p99_us
    calls.clear()
    accuracy.compute_time_us(profile, "ours", n_ticks=300)
    assert calls == []


def _refusing_unit_two(monkeypatch: pytest.MonkeyPatch) -> None:
    profile = load_profile(resolve_data_path("profiles/example-sim.yaml"))

    def unit_profile(unit: int, *_: object) -> object:
        if unit == 2:
            raise family_accuracy.CalibrationError("calibration refused (1 problem): x")
        return profile, object()  # the plant its calibration left

    def run(s: object, method: str, *_: object) -> object:
        rmse = {"none": 10.0, "paper": 4.0, "ours": 1.0}[method]
        return argparse.Namespace(rmse_deg=rmse, ptpe_deg=2 * rmse)

    monkeypatch.setattr(family_accuracy, "unit_profile", unit_profile)
    monkeypatch.setattr(family_accuracy, "run_scenario", run)
    monkeypatch.setattr(family_accuracy, "compute_time_us", lambda *a, **k: (1.0, 2.0))


def test_family_bench_scores_the_other_units_when_one_calibration_is_refused(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    _refusing_unit_two(monkeypatch)
    args = family_accuracy.namespace_from(argparse.Namespace(
        unit_seeds="1,2,3", quick=True, no_extra=True))
    assert family_accuracy.main(args) == 0
    out = capsys.readouterr().out
    assert "| 2 | no profile: calibration refused (1 problem): x |" in out
    assert "| 3 | 1-DOF" in out
    assert "for 1 of 3 units: [2]" in out


def test_family_bench_fails_when_no_unit_could_be_scored(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    _refusing_unit_two(monkeypatch)
    args = family_accuracy.namespace_from(argparse.Namespace(unit_seeds="2", quick=True,
                                                             no_extra=True))
    assert family_accuracy.main(args) == 1
    assert "no unit was scored" in capsys.readouterr().out


@pytest.mark.parametrize("plant", sorted(set(PLANT_SPECS) - {"capstan"}))
def test_family_bench_uses_the_plant_s_shipped_sheet_by_default(plant: str) -> None:
    path = family_accuracy.sheet_path(plant, None)
    assert path.name == f"{plant}.yaml" and path.exists()
    assert load_device_model(path).device_model == f"family-{plant}"


def test_family_bench_uses_the_sheet_it_is_given(tmp_path: Path) -> None:
    given = tmp_path / "sheet.yaml"
    assert family_accuracy.sheet_path("nitinol", given) == given


def test_family_bench_scores_capstan_with_its_built_in_sheet() -> None:
    assert family_accuracy.sheet_path("capstan", None).name == "sim-catheter.yaml"
    assert family_accuracy.sheet_path(None, None).name == "sim-catheter.yaml"
