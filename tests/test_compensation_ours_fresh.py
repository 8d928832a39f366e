"""Method ours on a fresh catheter: the first release's hold (``fresh_hold_deg``), its end, and
that nothing changes without it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tsmd.compensation.fresh_play import fresh_branches
from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import ours_knobs
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play import PlayState, branches, model_step
from tsmd.compensation.tension_play_params import (
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)
from tsmd.config import load_config
from tsmd.profile import load_profile
from tsmd.stack import make_compensator

PERIOD_S = 0.004
LIMITS = KnobLimits(-90.0, 90.0, 120.0, 2000.0)
OMEGA, H_POS, H_NEG, D_POS, D_NEG = 1.5, -3.0, 4.0, 20.0, -22.0


def params(hold_deg: float) -> TensionPlayParams:
    grid = (-90.0, 90.0)
    return TensionPlayParams(OMEGA, H_POS, H_NEG, grid, (D_POS,) * 2, (D_NEG,) * 2, (0.3,) * 2,
                             (0.3,) * 2, (12.0,) * 2, (-13.0,) * 2, 0.0, hold_deg)


def conditioned_branches():  # type: ignore[no-untyped-def]
    return branches(OMEGA, H_POS, H_NEG, D_POS, D_NEG, 0.3, 0.3, 12.0, -13.0)


def drive(b, path):  # type: ignore[no-untyped-def]
    state = PlayState(0.0, b.rising(0.0), 1, b.rising(0.0))
    out = []
    for x in path:
        state = model_step(state, float(x), b)
        out.append(state.y_deg)
    return np.array(out)


def test_a_fresh_first_release_holds_where_the_other_loaded_line_is_hold_deg_inside() -> None:
    b = fresh_branches(conditioned_branches(), OMEGA, D_POS, D_NEG, H_POS, H_NEG, 10.0, side=1)
    down = np.linspace(70.0, -60.0, 1301)
    y = drive(b, np.concatenate([np.linspace(0.0, 70.0, 701), down]))[701:]
    hold = H_NEG + OMEGA * 10.0
    inside = (down < 20.0) & (down > D_NEG + 10.0)
    assert np.allclose(y[inside], hold, atol=1e-3)
    beyond = down < D_NEG + 9.0
    assert np.allclose(y[beyond], H_NEG + OMEGA * (down[beyond] - D_NEG), atol=1e-3)


def test_a_fresh_release_from_below_the_hold_stays_at_its_peak() -> None:
    b = fresh_branches(conditioned_branches(), OMEGA, D_POS, D_NEG, H_POS, H_NEG, 10.0, side=1)
    y = drive(b, np.concatenate([np.linspace(0.0, 28.0, 281), np.linspace(28.0, -5.0, 331)]))
    assert y[280] < H_NEG + OMEGA * 10.0
    assert np.allclose(y[281:], y[280], atol=1e-3)


def test_a_fresh_negative_first_release_holds_mirrored() -> None:
    b = fresh_branches(conditioned_branches(), OMEGA, D_POS, D_NEG, H_POS, H_NEG, 10.0, side=-1)
    y = drive(b, np.concatenate([np.linspace(0.0, -70.0, 701), np.linspace(-70.0, 5.0, 751)]))
    assert y[-1] == pytest.approx(H_POS - OMEGA * 10.0, abs=1e-3)


def test_without_a_fresh_hold_the_branches_are_the_conditioned_ones() -> None:
    b = conditioned_branches()
    assert fresh_branches(b, OMEGA, D_POS, D_NEG, H_POS, H_NEG, 0.0) is b


def test_a_fresh_first_loading_leaves_straight_at_the_delayed_edge() -> None:
    b = fresh_branches(conditioned_branches(), OMEGA, D_POS, D_NEG, H_POS, H_NEG, 10.0, 1.0)
    x = np.linspace(0.0, 60.0, 601)
    state = PlayState(0.0, 0.0, 1, 0.0)  # straight, at rest
    y = []
    for xi in x:
        state = model_step(state, float(xi), b)
        y.append(state.y_deg)
    loaded = x > D_POS + 2.0
    assert np.allclose(np.array(y)[loaded], OMEGA * (x[loaded] - D_POS - 1.0), atol=1e-3)
    assert np.allclose(np.array(y)[x < D_POS + 1.0], 0.0, atol=1e-3)


def run(hold_deg: float, q: np.ndarray, fresh_catheter: bool = True) -> np.ndarray:
    comp = OursCompensator(ours_knobs([params(hold_deg)] * 2), PERIOD_S, (LIMITS, LIMITS),
                           fresh_catheter=fresh_catheter)
    comp.reset(np.zeros(2))
    return np.array([comp.command(np.array([v, 0.0]), PERIOD_S)[0] for v in q])


def cycles(n: int) -> np.ndarray:
    t = np.arange(0.0, n * 10.0, PERIOD_S)
    return 50.0 * np.sin(2.0 * np.pi * 0.1 * t)


def test_after_reset_the_first_release_crosses_the_fresh_hold() -> None:
    q = cycles(1)
    fresh, conditioned = run(10.0, q), run(0.0, q)
    # going down through the hold the fresh command is lower by up to the hold
    assert np.min(fresh - conditioned) < -8.0


def test_a_catheter_not_said_to_be_fresh_starts_conditioned_whatever_the_profile() -> None:
    q = cycles(1)
    assert np.array_equal(run(10.0, q, fresh_catheter=False), run(0.0, q))


def test_after_the_first_release_the_commands_are_the_conditioned_ones() -> None:
    q = cycles(3)
    fresh, conditioned = run(10.0, q), run(0.0, q)
    last = slice(len(q) // 3 * 2, None)
    assert np.allclose(fresh[last], conditioned[last], atol=1e-6)


def test_a_profile_without_the_fresh_hold_reads_and_writes_as_before() -> None:
    m = tension_play_to_mapping(params(0.0))
    assert "fresh_hold_deg" not in m
    assert tension_play_from_mapping(m).fresh_hold_deg == 0.0
    p = dataclasses.replace(params(0.0), fresh_hold_deg=7.5)
    assert tension_play_from_mapping(tension_play_to_mapping(p)).fresh_hold_deg == 7.5


def test_a_negative_fresh_hold_is_refused_naming_the_key() -> None:
    m = tension_play_to_mapping(params(0.0)) | {"fresh_hold_deg": -1.0}
    with pytest.raises(ValueError, match="fresh_hold_deg"):
        tension_play_from_mapping(m)


def test_the_configuration_tells_the_stack_that_the_catheter_is_fresh(tmp_path) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "tsmd.yaml"
    path.write_text("compensation: {method: ours, fresh_catheter: true}\n")
    config = load_config(path)
    assert config.compensation.fresh_catheter is True
    profile = load_profile("profiles/example-sim.yaml")
    comp = make_compensator(profile, "ours", config)
    assert getattr(comp, "fresh_catheter", None) is True
