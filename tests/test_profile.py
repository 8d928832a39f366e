"""Catheter profiles and device models: validation, round trip, atomic save (tsmd.profile)."""

from __future__ import annotations

import copy
import math
import os
from pathlib import Path
from typing import Any

import pytest
import yaml
from support.profiles import DEVICE, ROOT, make_profile

from tsmd.compensation.release_ratio import RELEASE_RATIO_RANGE
from tsmd.profile import (
    DEFAULT_HANDLE_SLIP_DEG,
    ProfileError,
    ProfileStore,
    device_model_from_mapping,
    device_model_to_mapping,
    load_device_model,
    load_profile,
    profile_from_mapping,
    profile_to_mapping,
    save_profile,
)


def mapping() -> dict[str, Any]:
    return profile_to_mapping(make_profile())


def test_round_trip_keeps_every_value(tmp_path: Path) -> None:
    profile = make_profile()
    path = tmp_path / "p.yaml"
    save_profile(profile, path)
    assert load_profile(path) == profile


def test_height_follows_reference_point_and_dead_zone_at_zero() -> None:
    knob = make_profile(d0=20.0).knobs[0]
    assert knob.height_pos_deg == pytest.approx(
        knob.reference_pos.tip_deg - knob.omega * (knob.reference_pos.knob_deg - 20.0))


def test_example_profile_and_device_model_load() -> None:
    assert load_profile(ROOT / "profiles" / "example-sim.yaml").device_model == "sim-catheter"
    assert load_device_model(DEVICE).limits[0].max_deg > 0


@pytest.mark.parametrize(("edit", "message"), [
    (lambda m: m.pop("catheter_id"), "catheter_id: missing key"),
    (lambda m: m["knobs"]["phi1"].pop("backlash_pos_deg"), "knobs.phi1.backlash_pos_deg: missing"),
    (lambda m: m["knobs"].pop("phi2"), "knobs.phi2: missing key"),
    (lambda m: m.update(schema_version=2), "unknown schema version 2"),
    (lambda m: m.update(schema_version="1"), "schema_version: must be an integer"),
    (lambda m: m["knobs"]["phi1"]["dead_zone_pos_deg"].__setitem__(2, float("nan")),
     r"dead_zone_pos_deg\[2\]: is NaN"),
    (lambda m: m["knobs"]["phi1"]["backlash_neg_deg"].__setitem__(0, float("inf")),
     r"backlash_neg_deg\[0\]: is infinite"),
    (lambda m: m["knobs"]["phi2"].__setitem__("other_knob_deg", [-90, -30, -60, 0, 30, 60, 90]),
     "not sorted"),
    (lambda m: m["knobs"]["phi1"].__setitem__("omega", 0.023), "omega: .* outside"),
    (lambda m: m["knobs"]["phi1"]["dead_zone_pos_deg"].__setitem__(1, 0.35), None),
    (lambda m: m["knobs"]["phi1"]["dead_zone_neg_deg"].__setitem__(1, 12.0),
     r"dead_zone_neg_deg\[1\]: 12.0 deg is outside"),
    (lambda m: m["knobs"]["phi1"]["backlash_pos_deg"].pop(), "must have 7 values"),
    (lambda m: m["knobs"]["phi1"]["backlash_pos_deg"].__setitem__(0, "15"), "must be a number"),
    (lambda m: m.update(interpolation="spline9"), "interpolation: 'spline9' is not one of"),
    (lambda m: m["knobs"].update(phi3={}), "knobs.phi3: unknown knob"),
    (lambda m: m["knobs"]["phi1"]["reference_pos"].__setitem__("knob_deg", -90.0),
     "reference_pos.knob_deg must be > 0"),
    (lambda m: m["knobs"]["phi1"]["tension_play"].__setitem__("lag_s", -0.1),
     r"tension_play: lag_s: -0.1 is outside"),
    (lambda m: m["knobs"]["phi1"]["tension_play"].pop("backlash_gain_pos"),
     "tension_play: backlash_gain_pos: missing key"),
    (lambda m: m["knobs"]["phi1"]["tension_play"]["zero_load_neg_deg"].__setitem__(3, math.nan),
     r"zero_load_neg_deg\[3\]: is not finite"),
    (lambda m: m["knobs"]["phi1"]["tension_play"].update(extra=1),
     "tension_play: extra: unknown key"),
    (lambda m: m.update(catheter_id="../etc/passwd"), "catheter_id"),
])
def test_bad_profile_is_refused_naming_the_problem(edit: Any, message: str | None) -> None:
    m = copy.deepcopy(mapping())
    edit(m)
    if message is None:  # a plausible edit stays valid
        profile_from_mapping(m)
        return
    with pytest.raises(ProfileError, match=message):
        profile_from_mapping(m, "p.yaml")


def test_profile_that_is_not_a_mapping_is_refused() -> None:
    with pytest.raises(ProfileError, match="must be a mapping"):
        profile_from_mapping([1, 2, 3])


def test_invalid_yaml_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("knobs: [unclosed\n")
    with pytest.raises(ProfileError, match="broken.yaml: not valid YAML"):
        load_profile(path)


def test_missing_file_is_a_profile_error(tmp_path: Path) -> None:
    with pytest.raises(ProfileError, match="no such file"):
        load_profile(tmp_path / "absent.yaml")


def test_save_keeps_previous_profile_as_backup(tmp_path: Path) -> None:
    path = tmp_path / "p.yaml"
    save_profile(make_profile(d0=20.0), path)
    save_profile(make_profile(d0=22.0), path)
    assert load_profile(path).knobs[0].dead_zone_pos_deg[3] == pytest.approx(22.0)
    assert load_profile(path.with_name("p.yaml.bak")).knobs[0].dead_zone_pos_deg[3] == 20.0


def test_save_interrupted_before_rename_leaves_old_profile_intact(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "p.yaml"
    save_profile(make_profile(d0=20.0), path)
    before = path.read_bytes()

    def crash(*args: object, **kwargs: object) -> None:
        raise OSError("power lost")

    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(OSError, match="power lost"):
        save_profile(make_profile(d0=25.0), path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")] == []


def test_save_refuses_an_invalid_profile_before_touching_disk(tmp_path: Path) -> None:
    path = tmp_path / "p.yaml"
    save_profile(make_profile(), path)
    before = path.read_bytes()
    bad = make_profile()
    object.__setattr__(bad, "interpolation", "nope")
    with pytest.raises(ProfileError):
        save_profile(bad, path)
    assert path.read_bytes() == before


def test_saved_file_is_plain_yaml(tmp_path: Path) -> None:
    path = tmp_path / "p.yaml"
    save_profile(make_profile(), path)
    data = yaml.safe_load(path.read_text())
    assert data["schema_version"] == 1 and data["knobs"]["phi1"]["other_knob_deg"][0] == -90.0


def test_a_profile_that_is_not_utf8_is_one_line_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_bytes(b"catheter_id: x\n# \xff\xfe\xc3\n")
    with pytest.raises(ProfileError) as exc:
        load_profile(path)
    assert str(exc.value).startswith(f"{path}: not UTF-8 text")
    assert "\n" not in str(exc.value) and "xff" not in str(exc.value)


def test_a_profile_nested_500_levels_deep_is_one_line(tmp_path: Path) -> None:
    path = tmp_path / "deep.yaml"
    path.write_text("knobs: " + "[" * 500 + "]" * 500 + "\n")
    with pytest.raises(ProfileError, match="nested too deeply") as exc:
        load_profile(path)
    assert str(path) in str(exc.value) and "\n" not in str(exc.value)


def test_a_truncated_profile_is_one_line_wherever_it_is_cut(tmp_path: Path) -> None:
    text = (tmp_path / "whole.yaml")
    save_profile(make_profile("cath-t"), text)
    full = text.read_text()
    path = tmp_path / "cut.yaml"
    for cut in range(1, len(full), max(1, len(full) // 60)):
        path.write_text(full[:cut])
        try:
            load_profile(path)
        except ProfileError as exc:
            assert "\n" not in str(exc) and str(exc).startswith(str(path)), (cut, str(exc))


def test_store_list_excludes_directories_and_other_files(tmp_path: Path) -> None:
    store = ProfileStore(tmp_path)
    store.save(make_profile("cath-a"))
    (tmp_path / "cath-dir.yaml").mkdir()
    (tmp_path / "notes.txt").write_text("x")
    (tmp_path / ".hidden.yaml").write_text("x")
    assert store.list() == ["cath-a"]


def test_store_lists_saves_and_loads_by_catheter_id(tmp_path: Path) -> None:
    store = ProfileStore(tmp_path / "profiles")
    assert store.list() == []
    store.save(make_profile("cath-a"))
    store.save(make_profile("cath-b"))
    assert store.list() == ["cath-a", "cath-b"]
    assert store.load("cath-b").catheter_id == "cath-b"
    with pytest.raises(ProfileError, match="no profile for catheter 'cath-c'"):
        store.load("cath-c")
    with pytest.raises(ProfileError, match="must be letters"):
        store.load("../x")


def test_bad_device_model_is_refused(tmp_path: Path) -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi2"]["limits"]["max_deg"] = -10.0
    path = tmp_path / "dev.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ProfileError, match=r"knobs.phi2.limits.max_deg"):
        load_device_model(path)


def _release_at_ratio(knob: dict[str, Any], ratio: float) -> float:
    """The tracked release_omega that gives ``ratio`` against the knob's settle-rule gain."""
    return ratio * knob["omega"] / (1.0 - knob["reference_backlash_gain"])


def test_a_sheet_whose_release_ratio_the_calibration_cannot_use_is_refused_naming_it() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    phi2 = data["knobs"]["phi2"]
    phi2["release_omega"] = _release_at_ratio(phi2, RELEASE_RATIO_RANGE[0] - 0.05)
    with pytest.raises(ProfileError, match=r"knobs.phi2.release_omega: .*outside"):
        device_model_from_mapping(data)


def test_a_sheet_keeps_its_reference_backlash_without_the_tracked_release() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi2"].pop("release_omega")
    knob = device_model_from_mapping(data).knobs[1]
    assert knob.release_omega is None
    assert knob.reference_backlash_pos_deg == data["knobs"]["phi2"]["reference_backlash_pos_deg"]


def test_device_model_round_trip_keeps_our_optional_constants(tmp_path: Path) -> None:
    device = load_device_model(DEVICE)
    assert device.knobs[0].release_omega is not None
    assert device_model_from_mapping(device_model_to_mapping(device)) == device


def test_a_data_sheet_without_handle_slip_gets_the_default() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    for knob in data["knobs"].values():
        knob.pop("handle_slip_deg", None)
    device = device_model_from_mapping(data)
    assert [k.handle_slip_deg for k in device.knobs] == [DEFAULT_HANDLE_SLIP_DEG] * 2


def test_the_data_sheets_handle_slip_is_read_per_knob_and_written_back() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi2"]["handle_slip_deg"] = 1.25
    device = device_model_from_mapping(data)
    assert device.knobs[1].handle_slip_deg == 1.25
    assert device_model_to_mapping(device)["knobs"]["phi2"]["handle_slip_deg"] == 1.25


def test_a_non_positive_handle_slip_is_refused_naming_the_key() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi1"]["handle_slip_deg"] = 0.0
    with pytest.raises(ProfileError, match=r"knobs.phi1.handle_slip_deg"):
        device_model_from_mapping(data)


def test_device_release_constants_go_together(tmp_path: Path) -> None:
    data = yaml.safe_load(DEVICE.read_text())
    del data["knobs"]["phi1"]["reference_backlash_neg_deg"]
    path = tmp_path / "dev.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ProfileError, match="knobs.phi1: reference_backlash_pos_deg and"):
        load_device_model(path)


def test_store_loads_a_version_file_of_the_same_catheter(tmp_path: Path) -> None:
    store = ProfileStore(tmp_path)
    save_profile(make_profile("cath-a"), tmp_path / "cath-a.online-20261123T190000.yaml")
    assert store.load("cath-a.online-20261123T190000").catheter_id == "cath-a"


def test_store_refuses_a_file_named_for_another_catheter(tmp_path: Path) -> None:
    store = ProfileStore(tmp_path)
    save_profile(make_profile("cath-b"), tmp_path / "cath-a.online-1.yaml")
    save_profile(make_profile("cath"), tmp_path / "cath-a.yaml")
    for name in ("cath-a.online-1", "cath-a"):
        with pytest.raises(ProfileError, match="expected"):
            store.load(name)


def test_former_ours_block_is_ignored_with_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    m = copy.deepcopy(mapping())
    m["knobs"]["phi1"]["ours"] = {"lag_s": 0.0, "release_slope_pos": [2.25] * 7}
    with caplog.at_level("WARNING", logger="tsmd.profile"):
        profile = profile_from_mapping(m, "old.yaml")
    assert profile == profile_from_mapping(mapping(), "old.yaml")
    assert "old.yaml: knobs.phi1.ours: parameters of the former 'ours'" in caplog.text


def test_a_store_that_cannot_be_written_is_a_profile_error(tmp_path: Path) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    with pytest.raises(ProfileError, match="cannot save"):
        ProfileStore(blocker / "profiles").save(make_profile())


def test_a_data_sheets_loaded_shape_is_read_and_written_back() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi1"]["loaded_shape_neg"] = {"travel_deg": [0.0, 5.0, 60.0],
                                                 "shaped_deg": [0.0, 6.5, 66.0]}
    device = device_model_from_mapping(data)
    shape = device.knobs[0].loaded_shape_neg
    assert shape is not None and shape.at(5.0) == 6.5
    assert device.knobs[0].loaded_shape_pos is None and device.knobs[1].loaded_shape_neg is None
    assert device_model_from_mapping(device_model_to_mapping(device)) == device


def test_a_non_monotone_loaded_shape_is_refused_naming_the_key() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi2"]["loaded_shape_pos"] = {"travel_deg": [0.0, 5.0, 60.0],
                                                 "shaped_deg": [0.0, 6.5, 6.0]}
    with pytest.raises(ProfileError, match=r"knobs.phi2.loaded_shape_pos: slope") as err:
        device_model_from_mapping(data)
    assert "\n" not in str(err.value)
