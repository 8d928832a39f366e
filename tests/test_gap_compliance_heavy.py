"""The compliance figure from loads further apart (opt-in): the protocol's heavy warm-up cycles,
the load contrast read light against heavy, the premise and the release kept on the usual pair."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from support.gap_play import play_at_light_load

from tsmd.gap import compliance, session
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.presets import PRESETS
from tsmd.gap.protocol import ProtocolDesign, protocol
from tsmd.gap.reversal import TRAVEL_GRID_DEG, Reversals, _reversal_pairs

RATE_HZ = 50.0
HEAVY = ProtocolDesign(heavy_amp_deg=75.0)


def _reversal_angles(knob_deg: np.ndarray) -> np.ndarray:
    return np.array([knob_deg[a] for a, _ in _reversal_pairs(knob_deg)])


def test_the_protocol_is_unchanged_unless_a_heavy_load_is_asked_for() -> None:
    default, heavy = protocol(RATE_HZ), protocol(RATE_HZ, HEAVY)
    np.testing.assert_array_equal(default[1], protocol(RATE_HZ, ProtocolDesign())[1])
    assert not np.any(np.isclose(np.abs(_reversal_angles(default[1][:, 0])), 75.0))
    at = _reversal_angles(heavy[1][:, 0])
    for side in (75.0, -75.0):
        assert np.sum(np.isclose(at, side)) == 2  # two heavy cycles, both knobs together


def _reversals(lost_deg: dict[float, float], load_A: dict[float, float]) -> Reversals:
    """Four repeats per side and load: the tip leaves its rest after ``lost_deg`` of travel,
    the motor current before the reversal is ``load_A`` and falls to 0 at once."""
    curves, before, at = [], [], []
    for level, lost in lost_deg.items():
        for side in (1.0, -1.0):
            for _ in range(4):
                curves.append(np.clip(TRAVEL_GRID_DEG - lost, 0.0, None))
                before.append(side * load_A[level])
                at.append(side * level)
    n = len(curves)
    return Reversals(np.array(curves), np.zeros((n, len(TRAVEL_GRID_DEG))), np.array(before),
                     np.array(at), np.zeros(n, dtype=np.int64))


def test_the_load_contrast_reads_the_light_load_against_the_heavy_one(
        monkeypatch: pytest.MonkeyPatch) -> None:
    r = _reversals({40.0: 3.0, 60.0: 4.0, 75.0: 6.0}, {40.0: 0.10, 60.0: 0.15, 75.0: 0.20})
    rows = np.arange(len(r.at_deg))
    usual = compliance._contrast(r, rows)
    assert usual is not None and usual.slope == pytest.approx(1.0 / 0.05, rel=0.02)
    monkeypatch.setattr(compliance, "CONTRAST_LEVELS_DEG", (40.0, 75.0))
    far = compliance._contrast(r, rows)
    assert far is not None and far.slope == pytest.approx(3.0 / 0.10, rel=0.02)


@functools.cache
def _heavy_series(unit: int) -> tuple[GapSeries, ...]:
    made = session.make_session(PRESETS["capstan"], "none", 4.0, RATE_HZ, unit,
                                unit_variation=0.0 if unit == 0 else 0.1)
    return tuple(series_from_recording(r, f"heavy-{unit}-{i}")
                 for i, r in enumerate(made) if "segments" in r.metadata)


def test_a_played_light_load_still_sends_the_sheet_to_the_release(
        monkeypatch: pytest.MonkeyPatch) -> None:
    with monkeypatch.context() as m:
        m.setattr(session, "protocol", lambda rate_hz, design=None: protocol(rate_hz, HEAVY))
        units = [list(_heavy_series(0)), play_at_light_load(_heavy_series(5)),
                 list(_heavy_series(6))]
    monkeypatch.setattr(compliance, "CONTRAST_LEVELS_DEG", (40.0, 75.0))
    sheet = compliance.sheet_from_units(units)
    assert sheet is not None and sheet.figure == "release"


def test_the_heavy_cycles_leave_every_earlier_sample_as_it_was() -> None:
    default, heavy = protocol(RATE_HZ), protocol(RATE_HZ, HEAVY)
    n = len(default[0])
    np.testing.assert_array_equal(heavy[1][:n], default[1])
    np.testing.assert_array_equal(heavy[2][:n], default[2])
