"""The creep test's one-sided reading of the currents beyond the model's own (the default since
session 26): a held knob's current relaxing faster than the model's units' is creep, one relaxing
more slowly is not (a softer rope in front of a section that relaxes, the pronyring plant)."""

from __future__ import annotations

import numpy as np
import pytest

from tsmd.gap import reference
from tsmd.gap.dwell import CURRENT_COLUMNS, RELAX_COLUMNS, Drift

OWN_A_PER_S = -0.001
"""The model's units' current slope over a loaded + dwell (its section relaxes)."""


def _measured(current_slope_A_per_s: float) -> Drift:
    """Two dwell pairs, loaded + then -, both knobs; the tips do not relax."""
    slope = np.array([current_slope_A_per_s, -current_slope_A_per_s])[:, None]
    diff = np.hstack([np.tile(slope, (1, 2)), np.zeros((2, 2))])
    return Drift(diff, np.full((2, 4), 1e-8), np.full(2, 19.0),
                 np.array([[1.0, 1.0], [-1.0, -1.0]]))


def _own() -> tuple[np.ndarray, np.ndarray]:
    own = _measured(OWN_A_PER_S)
    return own.diff, np.full((2, 4), 1e-8)


def test_the_one_sided_reading_is_the_default() -> None:
    assert reference.ONE_SIDED_CREEP is True


@pytest.mark.parametrize(("slope", "creeps"), [(3.0 * OWN_A_PER_S, True),
                                               (0.5 * OWN_A_PER_S, False)])
def test_only_a_current_relaxing_faster_than_the_models_is_read(
        monkeypatch: pytest.MonkeyPatch, slope: float, creeps: bool) -> None:
    meas = _measured(slope)
    monkeypatch.setattr(reference, "ONE_SIDED_CREEP", False)
    two_sided = reference.drift_beyond_reference(meas, meas, _own())
    assert np.all(np.abs(two_sided.diff[:, CURRENT_COLUMNS]) > 0.0)  # either way
    monkeypatch.setattr(reference, "ONE_SIDED_CREEP", True)
    one_sided = reference.drift_beyond_reference(meas, meas, _own())
    beyond = one_sided.diff[:, CURRENT_COLUMNS]
    assert bool(np.all(beyond > 0.0)) is creeps
    assert bool(np.all(beyond == 0.0)) is not creeps
    np.testing.assert_array_equal(one_sided.diff[:, RELAX_COLUMNS],
                                  two_sided.diff[:, RELAX_COLUMNS])
