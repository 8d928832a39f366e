"""`tsmd bench realism`: the paper's signatures checked automatically on family members."""

from __future__ import annotations

import argparse

import numpy as np
import pytest

from simrig.family import family_member
from simrig.report import run_sweep
from tsmd.bench import realism, realism_tee
from tsmd.compensation.paper import PaperParams, initial_state, model_step
from tsmd.tee import default_tee_dir, knob_from_filename, load_tee_acquisition

TEE_DIR = default_tee_dir()


@pytest.fixture(scope="module")
def lumped_sweep() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rec = run_sweep(family_member("lumped", 0).build(), 0, dt_s=0.008)
    return rec.knob_deg, rec.tip_deg, rec.torque_Nm, rec.t_s


def test_nominal_lumped_plant_shows_every_torque_signature(
        lumped_sweep: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]) -> None:
    checks = realism.torque_signature(*lumped_sweep)
    assert [c.name for c in checks if not c.ok] == []


def test_a_torque_that_never_rises_fails_the_engagement_check(
        lumped_sweep: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]) -> None:
    q, tip, _, t = lumped_sweep
    flat = 0.01 * np.sign(np.gradient(q)) + 1e-4 * q  # knob friction only, no tendon load
    failed = {c.name for c in realism.torque_signature(q, tip, flat, t) if not c.ok}
    assert any(name.startswith("rise on engagement") for name in failed)


def test_reversal_shape_reads_a_current_drop_and_a_tip_hold_on_a_textbook_loop() -> None:
    up = np.linspace(-50.0, 50.0, 1001)
    q = np.concatenate([up, up[::-1][1:]])
    # Tip: play of 10 deg (10 % of the range) after the top reversal, slope 1 elsewhere.
    tip = np.concatenate([up, np.minimum(up[::-1][1:] + 10.0, 50.0)])
    current = np.concatenate([np.where(up > 0, up / 50.0, 0.0), np.zeros(1000)])
    fall_pct, hold_pct = realism_tee.reversal_shape(q, tip, current)
    assert fall_pct < 1.0
    assert hold_pct == pytest.approx(10.0 + 3.0, abs=0.5)  # the play + the 3 % tip threshold


def test_bench_prints_one_row_per_member_and_names_what_is_outside(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    few = realism.scenarios(True)[:1]
    monkeypatch.setattr(realism, "scenarios", lambda quick: few)
    args = argparse.Namespace(plant=["lumped"], units=1, held_out=True, variants=False,
                              quick=True, calibrate=False, tee=None, tee_plot=None,
                              skip_checks=False, device=None)
    assert realism.main(args) == 0
    out = capsys.readouterr().out
    assert "lumped unit 0 (nominal)" in out and "lumped unit 101 (held-out)" in out
    assert "held-out plant" in out


def test_bench_refuses_more_units_than_the_family_has() -> None:
    args = argparse.Namespace(units=9)
    with pytest.raises(realism.TsmdError, match="--units must be in 0..8"):
        realism.main(args)


def _paper_loop(q: np.ndarray) -> np.ndarray:
    """The paper's one-slope model (omega 1.3, D 20, B 20 deg) driven through q."""
    p = PaperParams(20.0, -20.0, 20.0, 20.0, 0.0, 0.0, 1.3)
    state = initial_state(float(q[0]), p)
    out = np.empty_like(q)
    for i, x in enumerate(q):
        state, _ = model_step(state, float(x), p)
        out[i] = state.y_deg
    return out


def _triangle() -> np.ndarray:
    leg = np.linspace(-90.0, 90.0, 1801)
    return np.concatenate([leg, leg[::-1][1:], leg[1:]])


def test_a_one_slope_loop_releases_at_its_loaded_slope() -> None:
    q = _triangle()
    assert realism_tee.release_load_ratio(q, _paper_loop(q)) == pytest.approx(1.0, abs=0.02)


def test_a_tip_that_releases_steeper_than_it_loads_fails_the_ratio_range() -> None:
    q = _triangle()
    tip = _paper_loop(q)
    toward_zero = np.sign(np.gradient(q)) != np.sign(q)
    tip = np.where(toward_zero, 1.5 * tip, tip)
    ratio = realism_tee.release_load_ratio(q, tip)
    assert ratio == pytest.approx(1.5, abs=0.05)
    assert not realism.RELEASE_RATIO_RANGE[0] <= ratio <= realism.RELEASE_RATIO_RANGE[1]


def test_the_ratio_is_measured_about_the_sweeps_own_middle() -> None:
    q = _triangle()
    tip = _paper_loop(q)
    shifted = realism_tee.release_load_ratio(0.3 * q + 1600.0, tip + 12.0)
    assert shifted == pytest.approx(realism_tee.release_load_ratio(q, tip), abs=1e-9)


@pytest.mark.skipif(not TEE_DIR.is_dir(), reason=f"TEE data not found at {TEE_DIR}")
def test_the_real_probe_releases_inside_the_ratio_range() -> None:
    for f in sorted(TEE_DIR.glob("motor*_*.csv")):
        knob = knob_from_filename(f)
        rec = load_tee_acquisition(f)
        ratio = realism_tee.release_load_ratio(rec[f"pos{knob}"], rec[f"tip{knob}"])
        assert realism.RELEASE_RATIO_RANGE[0] <= ratio <= realism.RELEASE_RATIO_RANGE[1], f.name


def test_a_compliant_tendon_releases_steeper_than_the_real_probe() -> None:
    """The development plant's nominal unit before session 5 (docs/plant.md), kept visible."""
    member = family_member("capstan", 0, "compliant-tendon")
    rec = run_sweep(member.build(), 0, cycles=2.0, dt_s=0.008)
    ratio = realism_tee.release_load_ratio(rec.knob_deg, rec.tip_deg)
    assert ratio > realism.RELEASE_RATIO_RANGE[1]


def test_the_capstan_plant_releases_inside_the_ratio_range() -> None:
    rec = run_sweep(family_member("capstan", 0).build(), 0, cycles=2.0, dt_s=0.008)
    ratio = realism_tee.release_load_ratio(rec.knob_deg, rec.tip_deg)
    assert realism.RELEASE_RATIO_RANGE[0] <= ratio <= realism.RELEASE_RATIO_RANGE[1]


def test_the_lumped_plant_releases_inside_the_ratio_range(
        lumped_sweep: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]) -> None:
    q, tip, _, _ = lumped_sweep
    ratio = realism_tee.release_load_ratio(q, tip)
    assert realism.RELEASE_RATIO_RANGE[0] <= ratio <= realism.RELEASE_RATIO_RANGE[1]
