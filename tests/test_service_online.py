"""Online re-estimation wired into the daemon (simulated rig): config, status, switch, save."""

from __future__ import annotations

import dataclasses
import shutil
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from tsmd.api.client import ApiClient, ApiClientError
from tsmd.config import TsmdConfig, default_sim_config, resolve_data_path
from tsmd.daemon import SIM_EXAMPLE_PROFILE, Daemon
from tsmd.online import RECORDING_COLUMNS
from tsmd.online.apply import edges_at
from tsmd.online.bend import BendRelation
from tsmd.online.worker import OnlineWorker
from tsmd.profile import device_model_to_mapping, load_device_model, load_profile
from tsmd.recording import REQUIRED_COLUMNS, read_recording
from tsmd.stack import make_compensator

CATHETER = "example-sim"
OTHER_KNOB_DEG = (-40.0, 0.0, 25.0)


def sim_config(tmp_path: Path, *, online: bool, recording: bool = False) -> TsmdConfig:
    """The packaged sim config with the example profile in a store of its own."""
    store = tmp_path / "profiles"
    store.mkdir(exist_ok=True)
    shutil.copy(resolve_data_path(SIM_EXAMPLE_PROFILE), store / f"{CATHETER}.yaml")
    base = default_sim_config()
    return dataclasses.replace(
        base, profiles=dataclasses.replace(base.profiles, dir=str(store), active=CATHETER),
        online=dataclasses.replace(base.online, enabled=online),
        recording=dataclasses.replace(base.recording, enabled=recording,
                                      dir=str(tmp_path / "rec"), flush_interval_s=0.1))


@pytest.fixture
def start_daemon(tmp_path: Path) -> Iterator[Callable[..., Daemon]]:
    started: list[Daemon] = []

    def start(online: bool, recording: bool = False) -> Daemon:
        d = Daemon(sim_config(tmp_path, online=online, recording=recording), sim=True,
                   socket_path=str(tmp_path / "d.sock"))
        started.append(d)
        d.start()
        return d

    yield start
    for d in started:
        d.stop()


def client(daemon: Daemon) -> ApiClient:
    assert daemon.socket_path is not None
    return ApiClient(daemon.socket_path, timeout_s=10.0)


def running_worker(daemon: Daemon) -> OnlineWorker:
    assert daemon.online is not None and daemon.online.worker is not None
    return daemon.online.worker


def applied_edges(worker: OnlineWorker, knob: int) -> list[tuple[float, float]]:
    return [edges_at(worker.compensator.knobs[knob], o) for o in OTHER_KNOB_DEG]


def flat(pairs: list[tuple[float, float]]) -> list[float]:
    """pytest.approx compares flat sequences only (nested ones raise in pytest >= 9)."""
    return [v for pair in pairs for v in pair]


def profile_edges(daemon: Daemon, knob: int) -> list[tuple[float, float]]:
    assert daemon.service is not None
    fresh = make_compensator(daemon.service.profile, "ours", daemon.config)
    return [edges_at(fresh.knobs[knob], o) for o in OTHER_KNOB_DEG]  # type: ignore[attr-defined]


def estimate(worker: OnlineWorker, offset_deg: float, timeout_s: float = 10.0) -> None:
    """Make phi1's D_pos estimator hold ``offset_deg`` and wait until it is in force.

    (A real estimate needs minutes of motion; the estimator's output is what the wiring moves.)
    """
    worker.trackers[(0, 1)].applied_deg = offset_deg
    deadline = time.monotonic() + timeout_s
    while worker.offsets()[0][0] != offset_deg and time.monotonic() < deadline:
        time.sleep(0.05)
    assert worker.offsets()[0][0] == offset_deg
    time.sleep(0.1)  # a few ticks: the loop thread hands the published knobs over


def test_status_shows_online_disabled_by_default(start_daemon: Callable[..., Daemon]
                                                 ) -> None:
    daemon = start_daemon(False)
    with client(daemon) as c:
        assert c.call("status")["online"] == {"enabled": False}
    assert daemon.loop is not None and daemon.loop.observer is None


def test_online_enabled_in_the_config_starts_a_worker_on_the_loop(
        start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(True)
    worker = running_worker(daemon)
    assert daemon.loop is not None and daemon.loop.observer == worker.observe
    with client(daemon) as c:
        online = c.call("status")["online"]
    assert online["enabled"] is True
    assert online["offsets_deg"] == [[0.0, 0.0], [0.0, 0.0]]
    assert set(online["edges"]) == {"phi1_pos", "phi1_neg", "phi2_pos", "phi2_neg"}


def test_an_estimate_moves_the_compensators_edge(start_daemon: Callable[..., Daemon]
                                                 ) -> None:
    daemon = start_daemon(True)
    worker = running_worker(daemon)
    estimate(worker, 2.0)
    moved = applied_edges(worker, 0)
    for (d_pos, d_neg), (p_pos, p_neg) in zip(moved, profile_edges(daemon, 0), strict=True):
        assert d_pos == pytest.approx(p_pos + 2.0)
        assert d_neg == pytest.approx(p_neg)


def test_the_online_command_off_restores_the_profiles_edges(
        start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(True)
    worker = running_worker(daemon)
    estimate(worker, 2.0)
    with client(daemon) as c:
        answer = c.call("online", enabled=False)
        time.sleep(0.1)
        assert c.call("status")["online"]["offsets_deg"] == [[0.0, 0.0], [0.0, 0.0]]
    assert answer["enabled"] is False
    for knob in (0, 1):
        assert flat(applied_edges(worker, knob)) == pytest.approx(flat(profile_edges(daemon, knob)))


def test_the_online_command_on_starts_a_worker_not_configured_at_start(
        start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(False)
    with client(daemon) as c:
        assert c.call("online", enabled=True)["enabled"] is True
        assert c.call("status")["online"]["enabled"] is True
    assert daemon.loop is not None and daemon.loop.observer == running_worker(daemon).observe


def test_online_without_a_compensator_it_can_re_estimate_is_refused(
        start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(False)
    with client(daemon) as c:
        c.call("compensation", enabled=False)
        with pytest.raises(ApiClientError) as exc:
            c.call("online", enabled=True)
        assert c.call("status")["online"]["enabled"] is False
    assert exc.value.code == "online"
    assert "ours" in str(exc.value) and "\n" not in str(exc.value)


def test_a_new_profile_rebuilds_the_worker_on_the_new_compensator(
        start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(True)
    old = running_worker(daemon)
    estimate(old, 2.0)
    with client(daemon) as c:
        c.call("profile", catheter=CATHETER)
        online = c.call("status")["online"]
    new = running_worker(daemon)
    assert new is not old and new.compensator is not old.compensator
    assert daemon.loop is not None and daemon.loop.observer == new.observe
    assert online["enabled"] is True and online["offsets_deg"] == [[0.0, 0.0], [0.0, 0.0]]
    assert flat(applied_edges(new, 0)) == pytest.approx(flat(profile_edges(daemon, 0)))


def test_subscribe_samples_carry_the_offsets_in_force(start_daemon: Callable[..., Daemon]
                                                    ) -> None:
    daemon = start_daemon(True)
    estimate(running_worker(daemon), 2.0)
    with client(daemon) as c:
        c.request("subscribe", rate_hz=50)
        samples = [c.read_message()["sample"] for _ in range(3)]
        c.call("unsubscribe")
        assert c.call("get")["sample"]["online_offsets_deg"] == [[2.0, 0.0], [0.0, 0.0]]
    assert all(s["online_offsets_deg"] == [[2.0, 0.0], [0.0, 0.0]] for s in samples)


def test_subscribe_samples_say_null_offsets_while_online_is_off(
        start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(False)
    with client(daemon) as c:
        c.request("subscribe", rate_hz=50)
        sample = c.read_message()["sample"]
    assert "online_offsets_deg" in sample and sample["online_offsets_deg"] is None


def test_online_save_writes_a_new_version_and_leaves_the_calibrated_profile_intact(
        start_daemon: Callable[..., Daemon], tmp_path: Path) -> None:
    daemon = start_daemon(True)
    calibrated = tmp_path / "profiles" / f"{CATHETER}.yaml"
    before = calibrated.read_bytes()
    estimate(running_worker(daemon), 2.0)
    with client(daemon) as c:
        answer = c.call("online_save")
        second = c.call("online_save")
        path = Path(answer["path"])
        loaded = c.call("profile", catheter=path.stem)
    assert calibrated.read_bytes() == before
    assert path.parent == calibrated.parent and path != calibrated and path.exists()
    assert Path(second["path"]) != path
    saved, original = load_profile(path), load_profile(calibrated)
    assert saved.catheter_id == CATHETER
    assert saved.knobs[0].dead_zone_pos_deg == pytest.approx(
        [v + 2.0 for v in original.knobs[0].dead_zone_pos_deg])
    assert saved.knobs[1].dead_zone_pos_deg == pytest.approx(original.knobs[1].dead_zone_pos_deg)
    assert loaded["profile"] == path.stem


def test_online_save_while_online_is_off_is_refused(start_daemon: Callable[..., Daemon],
                                                    tmp_path: Path) -> None:
    daemon = start_daemon(False)
    with client(daemon) as c, pytest.raises(ApiClientError) as exc:
        c.call("online_save")
    assert exc.value.code == "online"
    assert sorted(p.name for p in (tmp_path / "profiles").iterdir()) == [f"{CATHETER}.yaml"]


def test_online_enabled_must_be_a_boolean(start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(False)
    with client(daemon) as c, pytest.raises(ApiClientError) as exc:
        c.call("online", enabled="yes")
    assert exc.value.code == "bad_param"


def test_shutdown_stops_the_worker(start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(True)
    worker = running_worker(daemon)
    thread = worker._thread
    daemon.stop()
    assert thread is not None and not thread.is_alive()
    assert daemon.loop is not None and daemon.loop.observer is None


def test_a_recording_with_online_on_carries_the_offsets_in_force(
        start_daemon: Callable[..., Daemon], tmp_path: Path) -> None:
    daemon = start_daemon(True, recording=True)
    estimate(running_worker(daemon), 2.0)
    daemon.stop()
    (path,) = (tmp_path / "rec").glob("tsmd-*.csv")
    rec = read_recording(path)
    assert tuple(rec.columns) == REQUIRED_COLUMNS + RECORDING_COLUMNS
    assert rec["dz_off_pos1"][0] == 0.0 and rec["dz_off_pos1"][-1] == 2.0
    assert not rec["dz_off_neg1"].any() and not rec["dz_off_pos2"].any()


def test_a_recording_with_online_off_keeps_the_required_columns_only(
        start_daemon: Callable[..., Daemon], tmp_path: Path) -> None:
    daemon = start_daemon(False, recording=True)
    daemon.stop()
    (path,) = (tmp_path / "rec").glob("tsmd-*.csv")
    assert tuple(read_recording(path).columns) == REQUIRED_COLUMNS


def daemon_with_sheet(tmp_path: Path, edit: Callable[[dict[str, Any]], None]) -> Daemon:
    """A started sim daemon with online on whose data sheet is the packaged one after ``edit``."""
    config = sim_config(tmp_path, online=True)
    assert config.profiles.device_model is not None
    sheet = device_model_to_mapping(load_device_model(resolve_data_path(
        config.profiles.device_model)))
    edit(sheet)
    (tmp_path / "sheet.yaml").write_text(yaml.safe_dump(sheet))
    config = dataclasses.replace(config, profiles=dataclasses.replace(
        config.profiles, device_model=str(tmp_path / "sheet.yaml")))
    daemon = Daemon(config, sim=True, socket_path=str(tmp_path / "d.sock"))
    daemon.start()
    return daemon


def test_the_worker_takes_the_handle_slip_from_the_data_sheet(tmp_path: Path) -> None:
    def slips(sheet: dict[str, Any]) -> None:
        sheet["knobs"]["phi1"]["handle_slip_deg"] = 4.5
        sheet["knobs"]["phi2"]["handle_slip_deg"] = 2.0

    daemon = daemon_with_sheet(tmp_path, slips)
    try:
        ramps = running_worker(daemon)._knob_ramp
        assert [r.handle_slip_deg for r in ramps] == [4.5, 2.0]
    finally:
        daemon.stop()


def test_the_worker_takes_the_bend_relation_from_the_data_sheet(tmp_path: Path) -> None:
    def relation(sheet: dict[str, Any]) -> None:
        sheet["bend_relation"] = {"release_per_edge": 0.61, "gain_per_release_deg": 0.064}

    daemon = daemon_with_sheet(tmp_path, relation)
    try:
        worker = running_worker(daemon)
        assert worker.bend == BendRelation(0.61, 0.064)
        assert worker.status()["bend_relation"] == {"release_per_edge": 0.61,
                                                     "gain_per_release_deg": 0.064,
                                                     "gain_per_slope": 0.0,
                                                     "omega_per_gain": None}
    finally:
        daemon.stop()


def test_a_data_sheet_without_a_bend_relation_gives_the_worker_none(
        start_daemon: Callable[..., Daemon]) -> None:
    worker = running_worker(start_daemon(True))
    assert worker.bend is None and worker.status()["bend_relation"] is None


def test_the_worker_reads_the_loops_fault_reason(start_daemon: Callable[..., Daemon]) -> None:
    daemon = start_daemon(True)
    worker = running_worker(daemon)
    assert daemon.loop is not None and worker.fault_reason is not None
    daemon.loop.fault_reason = "drive 1 (node 2) silent"
    assert worker.fault_reason() == "drive 1 (node 2) silent"
