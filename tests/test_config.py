"""The configuration file: defaults, and every kind of mistake refused with its key path."""

from __future__ import annotations

import re
import typing
from pathlib import Path

import pytest
import yaml

from tsmd import config as config_module
from tsmd.compensation import METHODS
from tsmd.config import (
    CompensationMethod,
    ConfigError,
    TsmdConfig,
    default_sim_config,
    drive_configs,
    load_config,
    parse_config,
)
from tsmd.online import EstimatorOptions


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "tsmd.yaml"
    path.write_text(text)
    return path


def test_an_empty_file_gives_every_default(tmp_path: Path) -> None:
    config = load_config(write(tmp_path, ""))
    assert config == TsmdConfig()
    assert config.loop.rate_hz == 250.0
    assert config.api.socket_path == "/run/tsmd/tsmd.sock"
    assert config.api.socket_mode == 0o660


def test_the_packaged_sim_config_is_valid_and_builds_two_drive_configs() -> None:
    config = default_sim_config()
    assert config.bus.interface == "virtual"
    drives = drive_configs(config)
    assert [d.node_id for d in drives] == [1, 2]


@pytest.mark.parametrize(("text", "key", "reason"), [
    ("loop: {rate_hz: 2000}", "loop.rate_hz", "out of range"),
    ("loop: {rate_hz: fast}", "loop.rate_hz", "expected a number"),
    ("loop: {rate_hz: .nan}", "loop.rate_hz", "finite"),
    ("loop: {rate_hz: true}", "loop.rate_hz", "expected a number"),
    ("loop: {rte_hz: 100}", "loop.rte_hz", "unknown key"),
    ("loop: {realtime: {priority: 120}}", "loop.realtime.priority", "out of range"),
    ("loop: {overrun_fault_streak: 2.5}", "loop.overrun_fault_streak", "integer"),
    ("bus: {bitrate: null}", "bus.bitrate", "null"),
    ("compensation: {method: magic}", "compensation.method", "not one of"),
    ("api: [1, 2]", "api", "mapping"),
    ("limits: {phi1: {min_deg: 10, max_deg: 0}}", "limits.phi1", "below max_deg"),
    ("drives: [{node_id: 1}, {node_id: 300}]", "drives[1]", "node_id"),
    ("drives: [{node_id: 1}, {gear_ratio: 10}]", "drives[1]", "missing"),
    ("drives: [{node_id: 1}]", "drives", "expected 2"),
    ("recording: {flush_interval_s: 0}", "recording.flush_interval_s", "out of range"),
    ("foo: 1", "foo", "unknown key"),
    ("drives: [{node_id: 1, homing: {method: spiral}}, {node_id: 2}]", "drives[0]",
     "homing.method"),
    ("drives: [{node_id: 1, homing: {required: true}}, {node_id: 2}]", "drives[0]",
     "homing.required"),
    ("api: {idle_timeout_s: 0}", "api.idle_timeout_s", "out of range"),
    ("api: {partial_line_timeout_s: -1}", "api.partial_line_timeout_s", "out of range"),
    ("api: {accepts_per_s: 0}", "api.accepts_per_s", "out of range"),
    ("bus: {timeouts: {sdo_s: 0}}", "bus.timeouts.sdo_s", "out of range"),
    ("bus: {timeouts: {boot: 2}}", "bus.timeouts.boot", "unknown key"),
    ("online: {enabled: maybe}", "online.enabled", "true or false"),
    ("online: {max_offset_deg: 0}", "online.max_offset_deg", "out of range"),
    ("online: {window: 3}", "online.window", "unknown key"),
])
def test_bad_value_is_refused_naming_key_and_reason(tmp_path: Path, text: str, key: str,
                                                    reason: str) -> None:
    with pytest.raises(ConfigError) as exc:
        load_config(write(tmp_path, text))
    message = str(exc.value)
    assert f"{key}:" in message or f"{key} " in message
    assert reason in message


def test_limits_wider_than_the_drive_are_refused(tmp_path: Path) -> None:
    text = yaml.safe_dump({"drives": [{"node_id": 1, "max_deg": 60}, {"node_id": 2}]})
    with pytest.raises(ConfigError, match=r"limits\.phi1.*drives\[0\]"):
        load_config(write(tmp_path, text))


def test_invalid_yaml_names_the_line(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="line 2"):
        load_config(write(tmp_path, "loop:\n  rate_hz: 1: 2\n"))


def test_missing_file_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read"):
        load_config(tmp_path / "absent.yaml")


def test_top_level_must_be_a_mapping(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="top level"):
        load_config(write(tmp_path, "- 1\n- 2\n"))


def test_nested_values_are_read(tmp_path: Path) -> None:
    config = load_config(write(tmp_path, "loop: {rate_hz: 1000, realtime: {cpu: 1}}\n"
                                         "sim: {params: {coupling: false}, seed: 7}\n"))
    assert config.loop.rate_hz == 1000.0
    assert config.loop.period_s == pytest.approx(0.001)
    assert config.loop.realtime.cpu == 1
    assert config.sim.params == {"coupling": False}
    assert config.sim.seed == 7


def test_api_limits_and_master_timeouts_are_read(tmp_path: Path) -> None:
    config = load_config(write(tmp_path, "api: {idle_timeout_s: 60, partial_line_timeout_s: 2, "
                                         "accepts_per_s: 50}\n"
                                         "bus: {timeouts: {sdo_s: 1.5, boot_s: 10}}\n"))
    assert (config.api.idle_timeout_s, config.api.partial_line_timeout_s,
            config.api.accepts_per_s) == (60.0, 2.0, 50.0)
    timeouts = config.bus.timeouts.master()
    assert (timeouts.sdo_s, timeouts.boot_s, timeouts.enable_s) == (1.5, 10.0, 0.5)


def test_homing_is_read_per_drive_and_defaults_to_none(tmp_path: Path) -> None:
    config = load_config(write(tmp_path, yaml.safe_dump({"drives": [
        {"node_id": 1, "homing": {"method": "current_position", "required": True}},
        {"node_id": 2}]})))
    first, second = drive_configs(config)
    assert first.homing.method_name == "current_position" and first.homing.required
    assert second.homing.method_name == "none" and not second.homing.at_start


def test_yaml_nested_500_levels_is_a_one_line_error(tmp_path: Path) -> None:
    path = write(tmp_path, "a: " + "[" * 500 + "]" * 500 + "\n")
    with pytest.raises(ConfigError, match="nested too deeply") as exc:
        load_config(path)
    assert str(path) in str(exc.value) and "\n" not in str(exc.value)


def test_a_config_that_is_not_utf8_is_a_one_line_error(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_bytes(b"loop: {rate_hz: 100}\n# \xff\xfe\n")
    with pytest.raises(ConfigError, match="not UTF-8"):
        load_config(path)


def test_the_example_in_docs_configuration_is_valid() -> None:
    doc = Path(__file__).resolve().parent.parent / "docs" / "configuration.md"
    if not doc.exists():
        pytest.skip("docs/configuration.md is not there")
    match = re.search(r"## Example \(robot\)\n\n```yaml\n(.*?)```", doc.read_text(), re.S)
    assert match is not None
    config = parse_config(yaml.safe_load(match.group(1)), "docs example")
    assert [d["node_id"] for d in config.drives] == [1, 2]
    assert config.loop.realtime.cpu == 1


def test_the_config_accepts_exactly_the_compensation_methods_there_are() -> None:
    assert set(typing.get_args(CompensationMethod)) == set(METHODS)


def test_online_re_estimation_is_off_by_default() -> None:
    assert TsmdConfig().online.enabled is False


def test_the_online_defaults_are_the_estimators_own() -> None:
    online, options = TsmdConfig().online, EstimatorOptions()
    assert (online.gate_deg, online.max_offset_deg, online.deadband_deg) == (
        options.gate_deg, options.max_offset_deg, options.deadband_deg)


def test_a_missing_default_config_says_how_to_run_without_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    missing = tmp_path / "tsmd.yaml"
    monkeypatch.setattr(config_module, "DEFAULT_CONFIG_PATH", missing)
    with pytest.raises(ConfigError, match=r"pass --config FILE, or --sim"):
        load_config(missing)
