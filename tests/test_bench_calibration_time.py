"""`tsmd bench calibration --time`: the paced plant and the per-layer split of a tick."""

from __future__ import annotations

import argparse
import time

import numpy as np
import pytest

from simrig.plant import load_plant
from simrig.rig import DEFAULT_PLANT
from tsmd.bench import calibration
from tsmd.bench.calibration_time import SPLIT_ORDER, PacedPlant, split_ticks
from tsmd.config import default_sim_config
from tsmd.errors import TsmdError


def test_a_paced_plant_step_lasts_its_pace_and_answers_as_the_plant() -> None:
    paced = PacedPlant(load_plant(DEFAULT_PLANT), step_us=2000.0)
    plain = load_plant(DEFAULT_PLANT)
    paced.reset()
    plain.reset()
    knob = np.array([5.0, -3.0])
    t0 = time.perf_counter()
    answer = paced.step(0.004, knob)
    assert time.perf_counter() - t0 >= 2e-3
    want = plain.step(0.004, knob)
    assert np.array_equal(answer.tip_deg, want.tip_deg)
    assert np.array_equal(answer.knob_torque_Nm, want.knob_torque_Nm)


def test_the_split_puts_a_paced_plant_step_in_the_plant_share() -> None:
    split, timed_us, _ = split_ticks(default_sim_config(), 40, plant_step_us=500.0)
    assert list(split) == list(SPLIT_ORDER)
    assert split["plant"] >= 500.0
    assert split["plant"] < timed_us


def test_time_with_both_protocols_is_a_one_line_error() -> None:
    parser = argparse.ArgumentParser()
    calibration.add_arguments(parser)
    args = parser.parse_args(["--time", "--protocol", "both"])
    with pytest.raises(TsmdError, match="--protocol paper or fast"):
        calibration.main(args)


def test_time_without_a_protocol_times_the_paper_protocol(monkeypatch: pytest.MonkeyPatch
                                                          ) -> None:
    asked: dict[str, object] = {}

    def fake_main_time(device: object, **kwargs: object) -> list[str]:
        asked.update(kwargs)
        return []

    monkeypatch.setattr(calibration, "main_time", fake_main_time)
    parser = argparse.ArgumentParser()
    calibration.add_arguments(parser)
    assert calibration.main(parser.parse_args(["--time"])) == 0
    assert asked["fast"] is False


def test_a_cpu_paced_plant_step_costs_its_pace_in_cpu_time() -> None:
    paced = PacedPlant(load_plant(DEFAULT_PLANT), step_us=2000.0, cpu=True)
    paced.reset()
    c0 = time.thread_time()
    paced.step(0.004, np.array([5.0, -3.0]))
    assert time.thread_time() - c0 >= 2e-3


def _burn_cpu(seconds: float) -> None:
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass


def test_a_worker_shut_down_without_waiting_has_its_cpu_counted() -> None:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from tsmd.bench.calibration_time import _children_cpu_s, _wait_for_children

    before = _children_cpu_s()
    pool = ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("fork"))
    pool.submit(_burn_cpu, 0.3).result()
    pool.shutdown(wait=False)
    _wait_for_children()
    assert _children_cpu_s() - before >= 0.25
