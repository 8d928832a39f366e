"""Uncertainty per grid point, the tip-cost gate, and re-sweeps instead of refusals.

The estimates pool one half-cycle's scatter over the sweeps of a knob (tsmd.calibration.estimate);
a grid point whose 95 % uncertainty costs more than the gate allows on the tip is swept again
within the protocol's budget (tsmd.calibration.resweep, run.run_sweeps).
"""

from __future__ import annotations

import dataclasses
import math
import threading
from pathlib import Path

import numpy as np
import pytest
from support.calibration import LockstepPlantRunner

from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant
from tsmd.calibration import (
    CalibrationCancelledError,
    Protocol,
    QualityLimits,
    Sweep,
    run_calibration,
)
from tsmd.calibration import run as run_module
from tsmd.calibration.assemble import GridPoint, check_quality
from tsmd.calibration.errors import CalibrationRefusedError
from tsmd.calibration.estimate import estimate, point_estimates, pooled_sigma
from tsmd.calibration.protocol import fast_protocol, paper_protocol
from tsmd.calibration.report import _plot_currents
from tsmd.calibration.resweep import Choice, Uncertain, choose_resweep, uncertain_points
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import PARAMETERS, HalfCycle, SweepResult
from tsmd.profile import ProfileStore, load_device_model

PERIOD_S = 0.004
DEVICE = Path(__file__).resolve().parent.parent / "profiles" / "devices" / "sim-catheter.yaml"
ODD = "phi1 sweep, phi2 at +0 deg"
PROTO = Protocol("test", tuple(Sweep(k, o, 90.0, 0.1, 2.0, "triangle")
                               for k in (0, 1) for o in (-30.0, 0.0, 30.0)),
                 resweep_cycles=2.0, resweep_budget_s=40.0)


def _result(**values: tuple[float, ...]) -> SweepResult:
    full = {name: values.get(name, (10.0, 10.5)) for name in PARAMETERS}
    return SweepResult(None, (), full)  # type: ignore[arg-type]


def test_one_sweep_that_disagrees_does_not_inflate_the_pooled_scatter() -> None:
    agree = [_result(backlash_pos_deg=(20.0, 20.0 + d)) for d in (0.5, -0.8, 1.0, 0.3)]
    odd = _result(backlash_pos_deg=(15.0, 25.0))
    sigma, dof = pooled_sigma([*agree, odd], ("backlash_pos_deg",))
    assert dof == 5
    assert sigma < 1.0


def test_cycles_that_disagree_widen_their_own_uncertainty() -> None:
    near = estimate((20.0, 20.5), sigma_pool=0.6, pool_dof=6)
    far = estimate((15.0, 25.0), sigma_pool=0.6, pool_dof=6)
    assert far.u95_deg > 2.5 * near.u95_deg
    assert far.value == pytest.approx(20.0)


def test_more_half_cycles_narrow_the_uncertainty() -> None:
    two = estimate((20.0, 21.0), sigma_pool=0.7, pool_dof=6)
    four = estimate((20.0, 21.0, 20.4, 20.6), sigma_pool=0.7, pool_dof=6)
    assert four.u95_deg < two.u95_deg


def test_one_more_half_cycle_narrows_a_two_value_point_by_a_sixth() -> None:
    # The point's value is a robust mean, not a median (whose third value would buy ~nothing).
    two = estimate((20.0, 21.0), sigma_pool=0.7, pool_dof=6)
    assert two.tip_cost_with_deg(1.32, 1) < 0.85 * two.tip_cost_deg(1.32)


def test_one_stray_half_cycle_among_four_moves_the_value_by_little() -> None:
    assert _result(backlash_pos_deg=(20.0, 28.0, 20.4, 19.8)).estimate(
        "backlash_pos_deg") == pytest.approx(20.2, abs=0.6)


def test_the_budget_goes_where_a_resweep_removes_most_tip_cost_not_to_the_worst_point() -> None:
    swept = (14.0, 26.0, 16.0, 24.0, 20.0, 13.0, 27.0, 22.0)  # already swept 3 times
    points = [GridPoint(0, -30.0, _result(backlash_pos_deg=(20.0, 26.0))),
              GridPoint(0, 0.0, _result(backlash_pos_deg=swept)),
              *(GridPoint(k, o, _result()) for k, o in ((0, 30.0), (1, -30.0), (1, 0.0)))]
    todo = uncertain_points(points, omegas=(1.32, 1.32))
    assert {u.index for u in todo} == {0, 1}
    assert max(todo, key=lambda u: u.worst_tip_cost_deg).index == 1
    assert todo[0].index == 0


def test_a_parameter_no_half_cycle_gave_is_infinitely_uncertain() -> None:
    (est,) = point_estimates([_result(dead_zone_pos_deg=())])
    assert est["dead_zone_pos_deg"].n == 0
    assert math.isinf(est["dead_zone_pos_deg"].tip_cost_deg(1.3))


def test_the_gate_weighs_the_same_uncertainty_by_what_it_costs_on_the_tip() -> None:
    results = [_result(backlash_pos_deg=(20.0, 20.0 + d)) for d in (0.4, 2.4, -0.6, 0.9)]
    points = [GridPoint(0, o, r) for o, r in zip((-60.0, -30.0, 0.0, 30.0), results,
                                                  strict=True)]
    flat = uncertain_points(points, omegas=(1.0, 1.0))
    steep = uncertain_points(points, omegas=(4.0, 4.0))
    assert len(steep) > len(flat)


def test_after_the_budget_a_large_tip_cost_is_refused_naming_it() -> None:
    odd = _result(dead_zone_pos_deg=(12.0, 24.0))
    points = [GridPoint(k, o, odd if (k, o) == (0, 0.0) else _result())
              for k in (0, 1) for o in (-30.0, 0.0, 30.0)]
    report = check_quality(points, omegas=(1.32, 1.32))
    assert any("dead_zone_pos_deg" in p and "on the tip" in p for p in report.problems)


def test_the_fast_protocol_with_its_whole_budget_stays_within_a_third_of_the_papers() -> None:
    fast = fast_protocol()
    assert fast.max_sweep_time_s <= paper_protocol().sweep_time_s / 3 + 1e-6
    assert fast.resweep_budget_s >= fast.resweep(fast.sweeps[0]).duration_s


def _disagree_once(monkeypatch: pytest.MonkeyPatch, apart_deg: float = 8.0) -> list[str]:
    """The first identification of ODD finds its cycles ``apart_deg`` apart on D_pos; later
    ones are what the sweep really shows."""
    seen: list[str] = []
    real = run_module.identify_recording

    def identify(rec, options=None, source="recording"):  # type: ignore[no-untyped-def]
        point = real(rec, options, source)
        seen.append(source)
        if source == ODD and seen.count(ODD) == 1:
            d = point.result.values["dead_zone_pos_deg"]
            values = {**point.result.values, "dead_zone_pos_deg": (d[0], d[0] + apart_deg)}
            point = dataclasses.replace(point, result=dataclasses.replace(point.result,
                                                                          values=values))
        return point
    monkeypatch.setattr(run_module, "identify_recording", identify)
    return seen


def test_a_sweep_that_disagrees_once_and_then_agrees_is_accepted(
        monkeypatch: pytest.MonkeyPatch) -> None:
    seen = _disagree_once(monkeypatch)
    runner = LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S)
    progress: list[str] = []
    # These quick triangle sweeps scatter more than the protocol's: refuse only far beyond.
    cal = run_calibration(runner, "cat-r", load_device_model(DEVICE), protocol=PROTO,
                          progress=lambda f, text: progress.append(text),
                          limits=QualityLimits(refuse_tip_error_deg=10.0))
    assert seen.count(ODD) == 2
    assert any(f"{ODD}: D_pos" in note for note in cal.notes)
    assert any(text.startswith("re-sweep 1:") for text in progress)
    odd = next(p for p in cal.points if p.name == ODD)
    assert odd.result.resweeps == 1 and len(odd.result.values["dead_zone_pos_deg"]) == 4
    first, bogus, *again = odd.result.values["dead_zone_pos_deg"]
    genuine = float(np.median([first, *again]))
    # The pooled median follows the genuine values, not the cycle that disagreed (+8 deg).
    assert cal.profile.knobs[0].dead_zone_pos_deg[1] == pytest.approx(genuine, abs=1.0)
    assert abs(cal.profile.knobs[0].dead_zone_pos_deg[1] - bogus) > 4.0
    assert cal.sweep_time_s == pytest.approx(PROTO.sweep_time_s + 20.0 * len(cal.notes))


def test_when_the_budget_is_spent_the_uncertain_point_is_reported_not_refused(
        monkeypatch: pytest.MonkeyPatch) -> None:
    real = run_module.identify_recording

    def identify(rec, options=None, source="recording"):  # type: ignore[no-untyped-def]
        point = real(rec, options, source)
        if source.startswith(ODD):  # every sweep of ODD, re-sweeps too: cycles 10 deg apart
            d = point.result.values["dead_zone_pos_deg"]
            values = {**point.result.values, "dead_zone_pos_deg": (d[0], d[0] + 10.0)}
            point = dataclasses.replace(point, result=dataclasses.replace(point.result,
                                                                          values=values))
        return point
    monkeypatch.setattr(run_module, "identify_recording", identify)
    runner = LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S)
    cal = run_calibration(runner, "cat-b", load_device_model(DEVICE),
                          protocol=dataclasses.replace(PROTO, resweep_budget_s=20.0),
                          limits=QualityLimits(refuse_tip_error_deg=10.0))
    assert sum(note.startswith("re-sweep ") and "budget" not in note for note in cal.notes) == 1
    assert any("budget (20 s) spent" in note and f"{ODD}: D_pos" in note for note in cal.notes)
    assert any("dead_zone_pos_deg" in w for w in cal.quality.warnings)


def test_a_point_that_would_refuse_is_swept_again_beyond_the_budget(
        monkeypatch: pytest.MonkeyPatch) -> None:
    seen = _disagree_once(monkeypatch, 30.0)
    runner = LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S)
    cal = run_calibration(runner, "cat-s", load_device_model(DEVICE),
                          protocol=dataclasses.replace(PROTO, resweep_budget_s=0.0,
                                                       rescue_budget_s=40.0),
                          limits=QualityLimits(refuse_tip_error_deg=5.0))
    assert seen.count(ODD) == 2
    assert any(f"{ODD}: D_pos" in n and "it would refuse the calibration" in n
               for n in cal.notes)


def test_without_a_rescue_budget_the_point_that_would_refuse_is_refused(
        monkeypatch: pytest.MonkeyPatch) -> None:
    _disagree_once(monkeypatch, 30.0)
    runner = LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S)
    with pytest.raises(CalibrationRefusedError, match="dead_zone_pos_deg"):
        run_calibration(runner, "cat-n", load_device_model(DEVICE),
                        protocol=dataclasses.replace(PROTO, resweep_budget_s=0.0,
                                                     rescue_budget_s=0.0),
                        limits=QualityLimits(refuse_tip_error_deg=5.0))


class _CancelOnRun(LockstepPlantRunner):
    def __init__(self, on_run: int, cancel: threading.Event) -> None:
        super().__init__(make_tendon_sheath_plant(), PERIOD_S)
        self.on_run = on_run
        self.cancel_event = cancel

    def run(self, t_s, q_deg, compensate=False, cancel=None, progress=None):  # type: ignore
        if self.runs + 1 == self.on_run:
            self.cancel_event.set()
        return super().run(t_s, q_deg, compensate, cancel, progress)


def test_cancel_during_a_resweep_returns_the_knobs_and_leaves_the_old_profile(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    seen = _disagree_once(monkeypatch)
    device = load_device_model(DEVICE)
    store = ProfileStore(tmp_path)
    old = run_calibration(LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S), "cat-c",
                          device, protocol=dataclasses.replace(PROTO, resweep_budget_s=0.0),
                          limits=QualityLimits(refuse_tip_error_deg=10.0)).profile
    store.save(old)
    before = (tmp_path / "cat-c.yaml").read_bytes()
    seen.clear()
    cancel = threading.Event()
    runner = _CancelOnRun(len(PROTO.sweeps) + 1, cancel)  # the re-sweep is the 7th run
    with pytest.raises(CalibrationCancelledError, match="re-sweep 1 .*nothing saved"):
        run_calibration(runner, "cat-c", device, protocol=PROTO, cancel=cancel)
    assert np.allclose(runner.trajectories[-1][-1], 0.0)
    assert (tmp_path / "cat-c.yaml").read_bytes() == before
    assert store.load("cat-c").calibrated_at == old.calibrated_at


def test_the_report_plots_a_resweeps_half_cycles_only_on_their_own_recording(
        tmp_path: Path) -> None:
    # a re-sweep longer than the first sweep: its half-cycles index past the first's signals
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    plt = pytest.importorskip("matplotlib.pyplot")
    t = np.arange(100) * 0.01
    data = Conditioned(t, t, t, t, t, 100.0, 1e-3, 1e-3, ())
    first = SweepResult(data, (HalfCycle(1, 0, 100, True, backlash_end_index=50),), {})
    again = SweepResult(data, (HalfCycle(1, 0, 300, True, backlash_end_index=250),), {})
    merged = first.merged(again)
    assert merged.data_half_cycles == first.half_cycles
    _plot_currents(plt, [GridPoint(0, 0.0, merged)], tmp_path / "currents.png")
    assert (tmp_path / "currents.png").exists()


def test_beyond_the_resweep_budget_only_a_point_that_would_refuse_is_swept_again() -> None:
    todo = [Uncertain(0, ("backlash_pos_deg",), 4.0, 1.0),
            Uncertain(1, ("backlash_neg_deg",), 6.0, 0.5)]

    def choose(spent_s: float) -> Choice:
        return choose_resweep(todo, spent_s, lambda i: 25.0, 50.0, 100.0, 5.0)

    within = choose(0.0)
    assert within.point is todo[0] and not within.rescue
    rescued = choose(50.0)
    assert rescued.point is todo[1] and rescued.rescue
    spent = choose(140.0)
    assert spent.point is None and spent.budget_s == 150.0
    assert choose_resweep(todo[:1], 50.0, lambda i: 25.0, 50.0, 100.0, 5.0).point is None
