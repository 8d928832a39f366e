"""The data sheet's optional bend relation (release-line move per edge move, gain growth)."""

from __future__ import annotations

import pytest
import yaml
from support.profiles import DEVICE

from tsmd.profile import ProfileError, device_model_from_mapping, device_model_to_mapping


def _sheet_with(relation: object) -> dict[str, object]:
    data: dict[str, object] = yaml.safe_load(DEVICE.read_text())
    data["bend_relation"] = relation
    return data


def test_a_data_sheet_without_a_bend_relation_has_none() -> None:
    device = device_model_from_mapping(yaml.safe_load(DEVICE.read_text()))
    assert (device.bend_release_per_edge, device.bend_gain_per_release_deg) == (None, None)
    assert "bend_relation" not in device_model_to_mapping(device)


def test_the_bend_relation_is_read_and_written_back() -> None:
    device = device_model_from_mapping(_sheet_with(
        {"release_per_edge": 1.17, "gain_per_release_deg": 0.063}))
    assert (device.bend_release_per_edge, device.bend_gain_per_release_deg) == (1.17, 0.063)
    assert device_model_from_mapping(device_model_to_mapping(device)) == device


@pytest.mark.parametrize(("relation", "key"), [
    ({"release_per_edge": 0.0, "gain_per_release_deg": 0.06}, "bend_relation.release_per_edge"),
    ({"release_per_edge": 1.1, "gain_per_release_deg": "x"},
     "bend_relation.gain_per_release_deg"),
    ({"release_per_edge": 1.1}, "bend_relation.gain_per_release_deg: missing key"),
    ([1.1, 0.06], "bend_relation: must be a mapping"),
])
def test_a_bad_bend_relation_is_refused_in_one_line_naming_the_key(relation: object,
                                                                   key: str) -> None:
    with pytest.raises(ProfileError, match=key) as err:
        device_model_from_mapping(_sheet_with(relation))
    assert "\n" not in str(err.value)
