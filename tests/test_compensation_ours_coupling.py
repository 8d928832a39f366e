"""Method ours with the product's coupling of the tip planes (``other_tip_gain``, session 14):
each knob aims at its desired angle less the gain times the other knob's."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml
from support.profiles import DEVICE

from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import ours_knobs
from tsmd.compensation.tension_play_params import (
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)
from tsmd.profile import ProfileError, device_model_from_mapping, device_model_to_mapping

PERIOD_S = 0.004
GAIN = -0.09


def params(gain: float = 0.0) -> TensionPlayParams:
    grid = (-90.0, 0.0, 90.0)
    return TensionPlayParams(1.4, -4.0, 4.0, grid, (20.0, 21.0, 22.0), (-21.0, -20.0, -22.0),
                             (0.2,) * 3, (0.22,) * 3, (5.0,) * 3, (-6.0,) * 3,
                             other_tip_gain=gain)


def path() -> np.ndarray:
    t = np.arange(0.0, 6.0, PERIOD_S)
    return np.column_stack([60.0 * np.sin(2 * math.pi * 0.1 * t),
                            70.0 * np.sin(2 * math.pi * 0.17 * t + 0.5)])


def commands(comp: OursCompensator, q: np.ndarray, plan: bool = False) -> np.ndarray:
    comp.reset(q[0])
    rows = q.tolist()
    out = []
    for i, row in enumerate(q):
        if plan:
            comp.preview(rows, i)
        out.append(comp.command(row, PERIOD_S))
    return np.array(out)


@pytest.mark.parametrize("plan", [False, True])
def test_a_knob_aims_at_its_desired_angle_less_the_other_planes_share(plan: bool) -> None:
    q = path()
    coupled = OursCompensator(ours_knobs([params(GAIN), params()]), PERIOD_S)
    plain = OursCompensator(ours_knobs([params(), params()]), PERIOD_S)
    aimed = q.copy()
    aimed[:, 0] = q[:, 0] - GAIN * q[:, 1]
    got, want = commands(coupled, q, plan), commands(plain, aimed, plan)
    np.testing.assert_array_equal(got, want)
    assert np.max(np.abs(got[:, 0] - commands(plain, q, plan)[:, 0])) > 1.0


def test_a_non_finite_other_angle_leaves_the_knob_on_its_own_desired_angle() -> None:
    q = path()[:500]
    coupled = OursCompensator(ours_knobs([params(GAIN), params()]), PERIOD_S)
    plain = OursCompensator(ours_knobs([params(), params()]), PERIOD_S)
    broken = q.copy()
    broken[200:, 1] = math.nan
    got, want = commands(coupled, broken), commands(plain, broken)
    assert np.all(np.isfinite(got))
    np.testing.assert_allclose(got[300:, 0], want[300:, 0], rtol=0.0, atol=1e-6)


def test_the_gain_is_kept_by_a_profile_and_an_old_section_has_none() -> None:
    m = tension_play_to_mapping(params(GAIN))
    assert tension_play_from_mapping(m).other_tip_gain == GAIN
    old = tension_play_to_mapping(params())
    assert "other_tip_gain" not in old
    assert tension_play_from_mapping(old).other_tip_gain == 0.0


def test_a_data_sheets_gain_is_read_and_written_back() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi2"]["other_tip_gain"] = 0.087
    device = device_model_from_mapping(data)
    assert [k.other_tip_gain for k in device.knobs] == [None, 0.087]
    assert device_model_from_mapping(device_model_to_mapping(device)) == device


def test_an_implausible_gain_is_refused_in_one_line_naming_the_key() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi1"]["other_tip_gain"] = 0.9
    with pytest.raises(ProfileError, match=r"knobs.phi1.other_tip_gain") as err:
        device_model_from_mapping(data)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="other_tip_gain"):
        tension_play_from_mapping({**tension_play_to_mapping(params()), "other_tip_gain": 0.9})


def test_the_fit_takes_the_gain_from_the_data_sheet() -> None:
    from tsmd.calibration import tension_play_fit as tpf

    device = device_model_from_mapping(yaml.safe_load(DEVICE.read_text()))
    knob = dataclasses.replace(device.knobs[0], other_tip_gain=GAIN)
    t = np.arange(0.0, 50.0, PERIOD_S)
    pos = 90.0 * np.sin(2 * math.pi * 0.04 * t)
    load = np.where(pos > 20.0, pos - 20.0, np.where(pos < -20.0, pos + 20.0, 0.0))
    cur = 0.01 * load + 0.02 * np.sign(np.gradient(pos))
    sweeps = [tpf.SweepCurrent(other, t, pos, pos, cur, 20.0, -20.0, 12.0, 12.0)
              for other in (-90.0, 0.0, 90.0)]
    assert tpf.fit_tension_play(sweeps, knob).other_tip_gain == GAIN
    assert tpf.fit_tension_play(sweeps, device.knobs[0]).other_tip_gain == 0.0
