"""The tension-play model's exactness check shared by the property tests of its variants."""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from tsmd.compensation.tension_play import Branches, inverse_step, model_step, rest_state


def assert_model_of_inverse_follows(b: Branches, path: Sequence[float]) -> None:
    """From rest at 0, the model fed the inverse's knob angles gives each desired output."""
    inv = rest_state(0.0, b)
    fwd = inv
    for y in path:
        inv = inverse_step(inv, y, b)
        fwd = model_step(fwd, inv.x_deg, b)
        assert fwd.y_deg == pytest.approx(y, abs=1e-6 * max(1.0, abs(y)))


def assert_model_continuous_between_branches(b: Branches, xs: Sequence[float], steepest: float,
                                             tol: float = 1e-9) -> None:
    """From rest at 0, each step moves the output no faster than ``steepest`` times the input's
    step (plus ``tol``) and keeps it between the rising and falling branches."""
    state = rest_state(0.0, b)
    for x in xs:
        nxt = model_step(state, x, b)
        assert abs(nxt.y_deg - state.y_deg) <= steepest * abs(x - state.x_deg) + tol
        assert b.rising(x) - 1e-9 <= nxt.y_deg <= b.falling(x) + 1e-9
        state = nxt
