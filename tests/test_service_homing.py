"""Knob zero reference and bus events at the daemon level, on the simulated rig."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from drivers.can_errors import CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING
from tsmd.api.client import ApiClient
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.daemon import Daemon, DaemonError


def config_with_homing(tmp_path: Path, **homing: Any) -> TsmdConfig:
    base = default_sim_config()
    drives = [dict(d) for d in base.drives]
    drives[0]["homing"] = {"method": "current_position", "home_offset_deg": 0.0, **homing}
    return dataclasses.replace(base, drives=drives, profiles=dataclasses.replace(
        base.profiles, dir=str(tmp_path / "profiles"), active=None))


def start(config: TsmdConfig, tmp_path: Path, **kwargs: Any) -> Daemon:
    daemon = Daemon(config, sim=True, socket_path=str(tmp_path / "d.sock"), **kwargs)
    daemon.start()
    return daemon


@pytest.fixture
def required(tmp_path: Path) -> Iterator[Daemon]:
    daemon = start(config_with_homing(tmp_path, required=True), tmp_path)
    yield daemon
    daemon.stop()


def code_of(response: dict[str, Any]) -> str:
    assert response.get("ok") is False, response
    return str(response["error"]["code"])


def test_status_reports_homing_zero_reference_and_bus_state(required: Daemon,
                                                            tmp_path: Path) -> None:
    with ApiClient(tmp_path / "d.sock") as client:
        status = client.call("status")
    assert status["zero_referenced"] is False
    assert [h["method"] for h in status["homing"]] == ["current_position", "none"]
    assert [h["required"] for h in status["homing"]] == [True, False]
    assert isinstance(status["bus_state"], str)


def test_enable_is_refused_until_the_required_knob_is_homed(required: Daemon,
                                                            tmp_path: Path) -> None:
    with ApiClient(tmp_path / "d.sock") as client:
        refused = client.request("enable")
        assert code_of(refused) == "not_homed"
        assert "drive(s) 0" in refused["error"]["message"]
        homed = client.call("home")
        assert homed["zero_referenced"] is True
        assert homed["homing"][0]["homed"] is True
        assert client.call("enable")["state"] == "ENABLED"
        client.call("set", q=[5.0, 0.0])


def test_home_is_refused_while_enabled(tmp_path: Path) -> None:
    daemon = start(config_with_homing(tmp_path), tmp_path)
    try:
        with ApiClient(tmp_path / "d.sock") as client:
            client.call("enable")
            assert code_of(client.request("home")) == "not_disabled"
            assert code_of(client.request("home", drives=[7])) == "bad_param"
            assert code_of(client.request("home", drives="all")) == "bad_param"
    finally:
        daemon.stop()


def test_homing_is_not_forced_a_drive_without_a_method_needs_none(tmp_path: Path) -> None:
    base = default_sim_config()
    config = dataclasses.replace(base, profiles=dataclasses.replace(
        base.profiles, dir=str(tmp_path / "profiles"), active=None))
    daemon = start(config, tmp_path)
    try:
        with ApiClient(tmp_path / "d.sock") as client:
            status = client.call("status")
            assert status["zero_referenced"] is True
            assert all(h["method"] == "none" for h in status["homing"])
            assert client.call("enable")["state"] == "ENABLED"
    finally:
        daemon.stop()


def test_homing_at_start_gives_the_zero_reference_before_ready(tmp_path: Path) -> None:
    daemon = start(config_with_homing(tmp_path, required=True, at_start=True), tmp_path)
    try:
        assert daemon.drives is not None
        assert daemon.drives.zero_referenced()
    finally:
        daemon.stop()


def test_run_home_homes_every_drive_with_a_method_at_start(tmp_path: Path) -> None:
    daemon = start(config_with_homing(tmp_path, required=True), tmp_path, home_at_start=True)
    try:
        assert daemon.drives is not None and daemon.drives.zero_referenced()
    finally:
        daemon.stop()


def test_a_homing_failure_at_start_fails_the_start_with_a_clear_message(tmp_path: Path) -> None:
    config = config_with_homing(tmp_path, method="hard_stop_positive", at_start=True,
                                timeout_s=0.05)
    daemon = Daemon(config, sim=True, socket_path=str(tmp_path / "d.sock"))
    with pytest.raises(DaemonError, match=r"homing failed: drive 0") as info:
        daemon.start()
    assert info.value.code == "homing"
    assert "\n" not in str(info.value)


def test_a_failed_home_command_answers_homing_naming_the_drive(tmp_path: Path) -> None:
    config = config_with_homing(tmp_path, method="hard_stop_positive", timeout_s=0.05)
    daemon = start(config, tmp_path)
    try:
        with ApiClient(tmp_path / "d.sock") as client:
            response = client.request("home", drives=[0])
            assert code_of(response) == "homing"
            assert "drive 0 (node 1)" in response["error"]["message"]
            status = client.call("status")
            assert status["state"] == "DISABLED" and status["homing"][0]["homed"] is False
    finally:
        daemon.stop()


def test_a_drive_reboot_loses_the_zero_reference_and_set_points_wait_for_homing(
        required: Daemon, tmp_path: Path) -> None:
    assert required.rig is not None
    with ApiClient(tmp_path / "d.sock") as client:
        client.call("home")
        client.call("enable")
        required.rig.inject_fault("reboot", drive=0)
        deadline = time.monotonic() + 10
        while client.call("status")["state"] != "FAULT" and time.monotonic() < deadline:
            time.sleep(0.05)
        assert client.call("status")["zero_referenced"] is False
        deadline = time.monotonic() + 10  # the drive answers again once it has booted
        while client.request("reset").get("ok") is not True and time.monotonic() < deadline:
            time.sleep(0.2)
        assert client.call("status")["state"] == "DISABLED"
        assert code_of(client.request("enable")) == "not_homed"


def test_can_bus_events_are_logged_at_a_limited_rate(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    daemon = start(config_with_homing(tmp_path), tmp_path)
    try:
        assert daemon.rig is not None
        for _ in range(20):
            daemon.rig.inject_fault("error_frame", classes=CAN_ERR_CRTL,
                                    data=bytes([0, CAN_ERR_CRTL_RX_WARNING]))
        deadline = time.monotonic() + 5
        seen = 0
        while seen < 20 and time.monotonic() < deadline:
            time.sleep(0.1)
            seen += daemon.log_bus_events()
        assert seen == 20
    finally:
        daemon.stop()
    out = capsys.readouterr().out
    assert 1 <= out.count("CAN bus event") <= 5
    assert "log lines suppressed" in out
