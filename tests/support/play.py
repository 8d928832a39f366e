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


def assert_model_continuous_within_its_play(b: Branches, xs: Sequence[float], steepest: float,
                                            tol: float = 1e-9) -> None:
    """As :func:`assert_model_continuous_between_branches` for a model whose release may leave
    the static play (a release line per reversal): each step no faster than ``steepest`` or the
    state's line; the output never beyond the hold in the direction of motion, and between
    the rising branch or the hold and the falling branch or the hold."""
    state = rest_state(0.0, b)
    for x in xs:
        nxt = model_step(state, x, b)
        fastest = max(steepest, nxt.line_slope, state.line_slope)
        assert abs(nxt.y_deg - state.y_deg) <= fastest * abs(x - state.x_deg) + tol
        assert min(b.rising(x), nxt.held_deg) - 1e-9 <= nxt.y_deg
        assert nxt.y_deg <= max(b.falling(x), nxt.held_deg) + 1e-9
        assert (nxt.y_deg - nxt.held_deg) * nxt.direction >= -1e-9
        state = nxt
