"""Matched-condition protocol and its contrast tests: effects as differences inside the data."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from tsmd import cli
from tsmd.gap import contrast
from tsmd.gap.contrast import collect_tests, contrast_scores, product_reference
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.errors import GapError
from tsmd.gap.loops import Loops, contrast_of, loop_contrast, noise_ss, smooth_along
from tsmd.gap.protocol import Segment, decode_table, encode_table, protocol
from tsmd.gap.reference import LoopReference, beyond_reference, measured_windows, own_scale
from tsmd.gap.sensor import lag_share
from tsmd.gap.signature import SignatureScore
from tsmd.gap.structure import rank_scores, spread_note
from tsmd.recording import Recording, read_trajectory

RATE_HZ = 25.0
Arr = NDArray[np.float64]
Effect = Callable[[Arr, Arr], Arr]


@functools.cache
def _design() -> tuple[Arr, Arr, NDArray[np.int64], tuple[Segment, ...]]:
    t, q, seg, table = protocol(RATE_HZ)
    return t, q, seg.astype(np.int64), tuple(table)


def _play(x: Arr, width: Arr) -> Arr:
    """A play operator whose half-width may change from row to row."""
    out = np.empty(len(x))
    y = float(x[0])
    for k, (xk, w) in enumerate(zip(x.tolist(), width.tolist(), strict=True)):
        y = min(max(y, xk - w), xk + w)
        out[k] = y
    return out


def _simulated(t: Arr, q: Arr) -> Arr:
    """The simulator's tip and current: a play of 2 deg, tip 1:1, 10 mA per degree."""
    loops = np.column_stack([_play(q[:, j], np.full(len(t), 2.0)) for j in range(2)])
    return np.column_stack([loops, 0.01 * loops])


def _base_mismatch(t: Arr, q: Arr) -> Arr:
    """Residual of a simulator with other base physics: a different play and dead zone."""
    out = np.empty((len(t), 4))
    for j in range(2):
        dead = np.sign(q[:, j]) * np.maximum(np.abs(q[:, j]) - 6.0, 0.0)
        out[:, j] = 0.8 * _play(dead, np.full(len(t), 5.0)) - _play(q[:, j], np.full(len(t), 2.0))
        out[:, 2 + j] = 0.002 * out[:, j]
    return out


def _session(effect: Effect | None = None, seed: int = 0,
             looped_only: bool = False) -> tuple[list[GapSeries], list[Arr]]:
    t, q, seg, table = _design()
    rng = np.random.default_rng(seed)
    series, residuals = [], []
    for config in ("straight", "looped"):
        res = _base_mismatch(t, q)
        if effect is not None and (config == "looped" or not looped_only):
            res = res + effect(t, q)
        res[:, :2] += rng.normal(0.0, 0.1, (len(t), 2))
        res[:, 2:] += rng.normal(0.0, 0.004, (len(t), 2))
        sim = _simulated(t, q)  # what the simulator predicts; the data are it plus the residual
        series.append(GapSeries(f"p-{config}", t, q, sim[:, 2:] + res[:, 2:],
                                sim[:, :2] + res[:, :2], "pos", config=config, segment=seg,
                                segments=table))
        residuals.append(res)
    return series, residuals


def _scores(effect: Effect | None = None, seed: int = 0,
            looped_only: bool = False) -> dict[str, SignatureScore]:
    series, residuals = _session(effect, seed, looped_only)
    return {s.name: s for s in contrast_scores(series, residuals, n_tried=6)}


def _named(scores: dict[str, SignatureScore]) -> set[str]:
    return {n for n, s in scores.items() if s.significant}


def test_matched_segments_of_every_speed_sample_the_same_knob_angles() -> None:
    _, q, seg, table = _design()
    angles: dict[str, list[set[float]]] = {}
    for i, s in enumerate(table):
        if s.test == "rate":
            angles.setdefault(s.level, []).append(set(np.round(q[seg == i, 0], 9)))
    fast = angles["fast"][0]
    assert fast == angles["fast"][1]
    assert fast <= angles["slow"][0] and fast <= angles["slow"][1]


def test_each_level_sits_at_the_same_mean_time_so_a_linear_drift_cancels() -> None:
    t, _, seg, table = _design()
    for test in ("rate", "coupling"):
        for knob in (-1, 0, 1):
            means: dict[str, list[float]] = {}
            for i, s in enumerate(table):
                if s.test == test and s.knob == knob:
                    means.setdefault(s.level, []).append(float(t[seg == i].mean()))
            centres = [np.mean(v) for v in means.values()]
            if centres:
                assert np.ptp(centres) < 0.05 * (t[-1] - t[0])


def test_a_base_mismatch_alone_makes_no_contrast_significant() -> None:
    scores = _scores()
    assert set(scores) == {"rate", "coupling", "drift", "curvature"}
    assert _named(scores) == set()


def _speed(t: Arr, q: Arr) -> Arr:
    return np.abs(np.gradient(q, t, axis=0))


def test_a_play_that_widens_with_speed_is_named_rate() -> None:
    def rate(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        sp = _speed(t, q)
        for j in range(2):
            out[:, j] = _play(q[:, j], 0.02 * sp[:, j]) - q[:, j]
        return out
    scores = _scores(rate)
    assert _named(scores) == {"rate"}
    assert scores["rate"].share > 0.5


def test_a_rate_dependence_within_one_samples_tracker_noise_is_not_named() -> None:
    def slight(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        sp = _speed(t, q)
        for j in range(2):
            out[:, j] = _play(q[:, j], 0.002 * sp[:, j]) - q[:, j]
        return out
    series, residuals = _session(slight)
    found = {s.name: s for s in contrast_scores(series, residuals, n_tried=6)}
    assert found["rate"].significant  # enough repeats find it ...
    sized = {s.name: s for s in contrast_scores(series, residuals, n_tried=6,
                                                 tip_noise_deg=0.1)}
    assert not sized["rate"].significant  # ... but it is smaller than one sample's noise


def test_a_tip_that_follows_the_other_knob_is_named_coupling() -> None:
    def coupling(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        out[:, 0], out[:, 1] = 0.02 * q[:, 1], 0.02 * q[:, 0]
        return out
    scores = _scores(coupling)
    assert _named(scores) == {"coupling"}
    assert scores["coupling"].share > 0.5


def test_a_loop_that_is_wider_in_one_configuration_is_named_curvature() -> None:
    def wider(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        for j in range(2):
            out[:, j] = _play(q[:, j], np.full(len(t), 3.0)) - q[:, j]
        return out
    scores = _scores(wider, looped_only=True)
    assert _named(scores) == {"curvature"}
    assert scores["curvature"].share > 0.5


def test_a_loop_with_a_lower_gain_in_one_configuration_is_explained_as_curvature() -> None:
    def flatter(t: Arr, q: Arr) -> Arr:
        """The bent sheath's friction takes a tenth of the loaded branches' tip/knob slope."""
        out = np.zeros((len(t), 4))
        for j in range(2):
            out[:, j] = -0.1 * q[:, j]
        return out
    scores = _scores(flatter, looped_only=True)
    assert _named(scores) == {"curvature"}
    assert scores["curvature"].share > 0.9


def _other_knob_bend_looped(t: Arr, q: Arr) -> Arr:
    """A looped sheath whose plane loses gain with the other plane bent beyond the rate loops'
    amplitude: seen only where the other knob is held far out (the coupling test's levels)."""
    out = np.zeros((len(t), 4))
    for j in range(2):
        out[:, j] = -0.02 * q[:, j] * np.maximum(np.abs(q[:, 1 - j]) - 45.0, 0.0)
    return out


def test_the_curvature_test_on_couplings_level_0_loops_ignores_the_held_levels(
        monkeypatch: pytest.MonkeyPatch) -> None:
    everything = _scores(_other_knob_bend_looped, looped_only=True)["curvature"]
    monkeypatch.setattr(contrast, "CURVATURE_LEVELS", {"rate": None, "coupling": ("+0",)})
    level_0 = _scores(_other_knob_bend_looped, looped_only=True)["curvature"]
    assert everything.z > 5.0
    assert not level_0.significant
    assert level_0.z < 3.0


def _creep(t: Arr, q: Arr) -> Arr:
    """Current relaxing in proportion to the time spent under load (slack creeping)."""
    dt = np.diff(t, prepend=t[0])
    load = np.maximum(np.abs(q) - 6.0, 0.0)
    out = np.zeros((len(t), 4))
    out[:, 2:] = -2e-5 * np.cumsum(load * dt[:, None], axis=0) * np.sign(q)
    return out


def test_creep_under_load_is_named_drift() -> None:
    scores = _scores(_creep)
    assert _named(scores) == {"drift"}


def test_a_tracker_drifting_in_time_alone_is_not_creep() -> None:
    def tracker(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        out[:, :2] = 0.004 * t[:, None]
        return out
    assert "drift" not in _named(_scores(tracker))


def test_a_tip_springing_back_in_the_unloaded_dwells_is_not_creep() -> None:
    """A viscoelastic tip cover relaxes back while the knob rests at 0 (the coilpipe plant):
    the tip drifts in the unloaded dwells, the tension does not creep."""
    def spring_back(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        rest = np.all(np.abs(q) < 0.5, axis=1)
        out[:, :2] = np.where(rest, -0.05 * t, 0.0)[:, None]
        return out
    assert "drift" not in _named(_scores(spring_back))


def _tip_creep(t: Arr, q: Arr, toward_rest: bool = True) -> Arr:
    """Tips falling back (or moving on) in proportion to the time spent under load, the
    currents unchanged: a tendon slipping at its far end behind a friction node."""
    dt = np.diff(t, prepend=t[0])
    load = np.maximum(np.abs(q) - 6.0, 0.0)
    out = np.zeros((len(t), 4))
    out[:, :2] = (-3e-4 if toward_rest else 3e-4) * np.cumsum(load * dt[:, None], axis=0) \
        * np.sign(q)
    return out


def test_a_tip_falling_back_at_a_held_knob_is_named_drift() -> None:
    series, residuals = _session(_tip_creep)
    scores = {s.name: s for s in contrast_scores(series, residuals, n_tried=6,
                                                 tip_noise_deg=0.1, current_noise_A=0.004)}
    assert _named(scores) == {"drift"}


def test_a_tip_moving_on_under_load_is_not_creep() -> None:
    """A bending section creeping on under a held tension (the coilpipe plant's cover) moves
    the tip away from rest, not back: no tendon's creep."""
    series, residuals = _session(lambda t, q: _tip_creep(t, q, toward_rest=False))
    scores = {s.name: s for s in contrast_scores(series, residuals, n_tried=6,
                                                 tip_noise_deg=0.1, current_noise_A=0.004)}
    assert "drift" not in _named(scores)


def test_creep_within_one_samples_current_noise_is_not_named() -> None:
    """Over six noise draws: found (median z), but about 3 mA over a dwell is named at most
    once. One draw's z scatters from below 1 to above 4 (docs/gap.md "Session 28": the heavy
    cycles lengthened the protocol and so changed the draw of seed 0 from z 3.1 to 0.9)."""
    def faint(t: Arr, q: Arr) -> Arr:
        return 0.15 * _creep(t, q)
    drift = []
    for seed in range(6):
        series, residuals = _session(faint, seed)
        drift.append({s.name: s for s in contrast_scores(series, residuals, n_tried=6,
                                                         current_noise_A=0.004)}["drift"])
    assert float(np.median([s.z for s in drift])) > 2.5
    assert sum(s.significant for s in drift) <= 1


def _dead_zone(x: Arr, width: Arr) -> Arr:
    return np.sign(x) * np.maximum(np.abs(x) - width, 0.0)


def test_a_dead_zone_widening_with_the_other_knob_is_explained_as_coupling() -> None:
    """The other plane's bend shortens the tendon path: more slack on both sides of this knob
    (the coilpipe plant's coupling), which neither a shift nor a backlash widening takes."""
    def wider_dead_zone(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        for j in range(2):
            extra = 3.0 * (q[:, 1 - j] / 50.0) ** 2
            out[:, j] = 0.8 * (_dead_zone(q[:, j], 6.0 + extra) - _dead_zone(q[:, j], 6.0))
        return out
    scores = _scores(wider_dead_zone)
    assert _named(scores) == {"coupling"}
    assert scores["coupling"].share > 0.8


def _lagged_current(t: Arr, q: Arr) -> Arr:
    """A current sensor lagging by 0.1 s: its reading minus the true current."""
    true = _simulated(t, q)[:, 2]
    a = np.exp(-np.diff(t, prepend=t[0]) / 0.1)
    lagged = true.copy()
    for k in range(1, len(t)):
        lagged[k] = a[k] * lagged[k - 1] + (1.0 - a[k]) * true[k]
    out = np.zeros((len(t), 4))
    out[:, 2] = lagged - true
    return out


def test_a_lagging_current_is_explained_by_a_lag_of_the_matched_loops() -> None:
    share = lag_share(*_session(_lagged_current))
    assert share is not None and share[0] > 0.5


def test_without_a_current_contrast_there_is_no_lag_share() -> None:
    assert lag_share(*_session()) is None


def _recording(**meta: str) -> Recording:
    t, q, seg, _ = _design()
    n = 200
    cols = {"t": t[:n], "pos1": q[:n, 0], "pos2": q[:n, 1], "cur1": 0.01 * q[:n, 0],
            "cur2": 0.01 * q[:n, 1], "tip1": q[:n, 0], "tip2": q[:n, 1],
            "segment": seg[:n].astype(float)}
    return Recording({k: np.asarray(v, dtype=float) for k, v in cols.items()}, dict(meta))


def test_the_segments_header_reaches_the_series() -> None:
    table = list(_design()[3])
    s = series_from_recording(_recording(segments=encode_table(table)), "p")
    assert s.segment is not None and list(s.segments) == table


def test_a_segment_column_without_its_header_is_one_line() -> None:
    with pytest.raises(GapError, match="needs both"):
        series_from_recording(_recording(), "p")


def test_a_malformed_segments_entry_is_one_line() -> None:
    with pytest.raises(GapError, match="entry 1"):
        decode_table("rate:slow:0:-1;rate:fast:x:-1", "p")


def test_a_lag_along_the_loop_matches_the_same_lag_in_time() -> None:
    """At constant knob speed a first-order lag of tau s is one of speed * tau deg of knob
    travel, corners included (the lag model's basis relies on it)."""
    amp_deg, speed_deg_s, rate_hz, tau_s = 40.0, 80.0, 50.0, 0.1
    step = speed_deg_s / rate_hz
    leg = np.arange(amp_deg, -amp_deg, -step)
    knob = np.tile(np.concatenate([leg, -leg]), 4)  # +A -> -A -> +A, four laps
    true = np.where(np.diff(knob, prepend=knob[0] + 1.0) < 0, -1.0, 1.0)  # square corners
    alpha = np.exp(-1.0 / (rate_hz * tau_s))
    lagged = true.copy()
    for k in range(1, len(knob)):
        lagged[k] = alpha * lagged[k - 1] + (1.0 - alpha) * true[k]
    lap = slice(len(knob) - 2 * len(leg), len(knob))  # the last lap: periodic by now
    x, y, y_true = knob[lap], lagged[lap], true[lap]
    falling = np.arange(len(x)) < len(leg)
    loops = Loops(np.zeros((2, 2, len(x))), y_true, x / amp_deg,
                  np.where(falling, -1.0, 1.0), np.zeros(len(x)), amp_deg)
    assert np.allclose(smooth_along(loops, y_true, speed_deg_s * tau_s), y, atol=1e-9)


def test_the_protocol_command_writes_a_trajectory_replay_reads_with_its_labels(
        tmp_path: Path) -> None:
    out = tmp_path / "protocol.csv"
    assert cli.main(["gap", "protocol", "--out", str(out), "--rate-hz", "50",
                     "--configuration", "looped"]) == 0
    traj = read_trajectory(out)
    t, q, seg, table = protocol(50.0)
    assert np.array_equal(traj["segment"], seg)
    assert np.allclose(traj["q1"], q[:, 0]) and np.allclose(traj["t"], t)
    assert decode_table(traj.metadata["segments"], "x") == table
    assert traj.metadata["configuration"] == "looped"


def test_of_two_significant_loop_contrasts_the_larger_ranks_first() -> None:
    def score(name: str, share: float, size_deg: float = float("nan")) -> SignatureScore:
        return SignatureScore(name, name, "", share, (share, share), True, share, 0.0,
                              size_deg=size_deg)

    ranked = rank_scores([score("rate", 0.97, 0.3), score("sensor", 0.95),
                          score("coupling", 0.90, 0.8)])
    assert [s.name for s in ranked] == ["coupling", "sensor", "rate"]


def _widening(gain: float) -> Effect:
    """A play that widens with speed by ``gain`` deg per deg/s (rate dependence)."""
    def rate(t: Arr, q: Arr) -> Arr:
        out = np.zeros((len(t), 4))
        sp = _speed(t, q)
        for j in range(2):
            out[:, j] = _play(q[:, j], gain * sp[:, j]) - q[:, j]
        return out
    return rate


def _against_model(unit: Effect, model: Effect) -> dict[str, SignatureScore]:
    """Scores of a unit with ``unit`` against a model whose reference unit has ``model``."""
    reference = product_reference(_session(model, seed=7)[0])
    series, residuals = _session(unit)
    return {s.name: s for s in contrast_scores(series, residuals, n_tried=6, tip_noise_deg=0.1,
                                               current_noise_A=0.004, reference=reference)}


def test_a_rate_dependence_the_model_has_always_is_not_named_against_its_reference() -> None:
    assert "rate" in _named(_scores(_widening(0.02)))
    assert "rate" not in _named(_against_model(_widening(0.02), _widening(0.02)))


def test_a_unit_with_more_rate_dependence_than_its_model_is_named_rate() -> None:
    scores = _against_model(_widening(0.06), _widening(0.02))
    assert _named(scores) == {"rate"}
    assert scores["rate"].share > 0.5


def test_creep_the_model_has_always_is_not_named_against_its_reference() -> None:
    assert "drift" not in _named(_against_model(_creep, _creep))


def test_more_creep_than_the_model_has_is_named_drift() -> None:
    def more(t: Arr, q: Arr) -> Arr:
        return 3.0 * _creep(t, q)
    assert _named(_against_model(more, _creep)) == {"drift"}


def test_a_subtracted_reference_counts_its_own_repeat_noise() -> None:
    reference = product_reference(_session(_widening(0.02), seed=7)[0])
    assert reference.loops["rate"].noise_per_point > 0.0
    series, residuals = _session(_widening(0.02))
    meas = collect_tests(series, [measured_windows(s) for s in series])
    res = collect_tests(series, residuals)
    data = res["straight"]["rate"]
    plain = loop_contrast(data.loops, data.levels)
    own = loop_contrast(meas["straight"]["rate"].loops, data.levels)
    assert plain is not None and own is not None
    beyond = beyond_reference(plain, own, data.levels, reference.loops["rate"])
    assert noise_ss(beyond) > noise_ss(plain)


def _units(*models: Effect) -> list[GapSeries]:
    """Protocol series of several catheters of a model, one per ``models`` entry."""
    return [dataclasses.replace(s, catheter=f"unit-{u}")
            for u, m in enumerate(models) for s in _session(m, seed=20 + u)[0]]


def test_a_reference_from_one_unit_has_no_spread_and_from_scattered_units_their_spread() -> None:
    one = product_reference(_units(_widening(0.02)))
    alike = product_reference(_units(_widening(0.02), _widening(0.02), _widening(0.02)))
    scattered = product_reference(_units(_widening(0.01), _widening(0.03), _widening(0.05)))
    assert one.units == 1 and scattered.units == 3
    assert one.loops["rate"].scatter_per_point == 0.0
    assert scattered.loops["rate"].scatter_per_point > 10.0 * alike.loops["rate"].scatter_per_point


def test_a_unit_within_its_models_spread_is_not_named_but_one_beyond_it_is() -> None:
    reference = product_reference(_units(_widening(0.01), _widening(0.03), _widening(0.05)))

    def scores(unit: Effect) -> set[str]:
        series, residuals = _session(unit)
        return _named({s.name: s for s in contrast_scores(
            series, residuals, n_tried=6, tip_noise_deg=0.1, current_noise_A=0.004,
            reference=reference)})

    assert "rate" in _named(_against_model(_widening(0.05), _widening(0.03)))
    assert "rate" not in scores(_widening(0.05))
    assert "rate" in scores(_widening(0.15))


def test_creep_the_models_units_scatter_over_counts_as_noise_of_its_reference() -> None:
    def creep(gain: float) -> Effect:
        return lambda t, q: gain * _creep(t, q)

    one = product_reference(_units(creep(1.0)))
    scattered = product_reference(_units(creep(0.0), creep(1.0), creep(2.0)))
    assert one.creep is not None and scattered.creep is not None
    currents = slice(0, 2)  # the tips' relaxation columns do not creep here
    assert float(scattered.creep[1][:, currents].mean()) > 10.0 * float(
        one.creep[1][:, currents].mean())


def test_a_unit_with_less_of_its_models_own_contrast_is_not_named_but_more_is() -> None:
    # a twistshaft unit with halved tendons keeps 0.5-0.7 of its model's coupling contrast
    assert "rate" not in _named(_against_model(_widening(0.01), _widening(0.04)))
    assert "rate" in _named(_against_model(_widening(0.12), _widening(0.04)))


def test_the_own_scale_is_the_units_projection_on_its_models_contrast_at_most_one() -> None:
    own = np.array([[1.0, -2.0, 0.5], [-1.0, 2.0, -0.5]])
    assert own_scale(0.6 * own, own) == pytest.approx(0.6)
    assert own_scale(2.5 * own, own) == 1.0
    assert own_scale(-own, own) == 0.0


def _two_knob_loops(contrast: Arr) -> Loops:
    """Noise-free loops of two knobs' parts whose level contrast is ``contrast`` (levels x K)."""
    k = contrast.shape[1]
    y = np.repeat(contrast[:, None, :], 2, axis=1)
    knob = np.tile(np.linspace(-0.9, 0.9, k // 2), 2)
    part = np.repeat([0.0, 1.0], k // 2)
    return Loops(y, np.zeros(k), knob, np.ones(k), part, span_deg=40.0)


def test_a_units_shortfall_of_its_models_contrast_on_one_knob_is_no_excess_on_the_other() -> None:
    own = np.vstack([np.linspace(-1.0, 1.0, 8), -np.linspace(-1.0, 1.0, 8)])
    lp = _two_knob_loops(own)
    ref = LoopReference(("minus", "plus"), own, lp.knob * lp.span_deg, lp.dirn, lp.part, 0.0)
    unit = own * np.where(lp.part == 0, 0.7, 1.5)  # helixbelt unit 1: 0.71 and 1.48
    residual = _two_knob_loops(np.zeros_like(own))  # the simulator has none of it
    beyond = contrast_of(beyond_reference(residual, _two_knob_loops(unit), ["minus", "plus"],
                                          ref))
    assert np.allclose(beyond[:, lp.part == 0], 0.0)
    assert np.allclose(beyond[:, lp.part == 1], 0.5 * own[:, lp.part == 1])


def test_a_unit_inside_its_models_spread_counted_over_both_levels_is_not_named() -> None:
    # units 0.01-0.05 and a unit of 0.11: inside their spread counted over both levels, as the
    # repeats' noise is; beyond it counted on one level (before session 16: named rate)
    reference = product_reference(_units(_widening(0.01), _widening(0.03), _widening(0.05)))
    series, residuals = _session(_widening(0.11))
    scores = {s.name: s for s in contrast_scores(series, residuals, n_tried=6, tip_noise_deg=0.1,
                                                 current_noise_A=0.004, reference=reference)}
    assert "rate" not in _named(scores)


def test_a_current_lag_its_model_has_always_explains_nothing_beyond_its_reference() -> None:
    lagged = product_reference(_units(_lagged_current, _lagged_current, _lagged_current))
    assert lagged.currents is not None
    assert lag_share(*_session(_lagged_current), reference=lagged.currents) == (0.0, 0.0, 0.0)


def test_a_current_lag_its_model_has_not_is_explained_beyond_its_reference() -> None:
    def nothing(t: Arr, q: Arr) -> Arr:
        return np.zeros((len(t), 4))

    plain = product_reference(_units(nothing, nothing, nothing))
    assert plain.currents is not None
    share = lag_share(*_session(_lagged_current), reference=plain.currents)
    assert share is not None and share[0] > 0.5


def _spread_scores(unit: Effect) -> dict[str, SignatureScore]:
    """Scores of a unit against a reference of three units scattered 0.01-0.05 deg per deg/s."""
    reference = product_reference(_units(_widening(0.01), _widening(0.03), _widening(0.05)))
    series, residuals = _session(unit)
    return {s.name: s for s in contrast_scores(series, residuals, n_tried=6, tip_noise_deg=0.1,
                                               current_noise_A=0.004, reference=reference)}


def test_a_unit_beyond_its_models_mean_but_inside_its_spread_reads_within_the_spread() -> None:
    rate = _spread_scores(_widening(0.11))["rate"]
    assert not rate.significant
    assert rate.within_spread_deg > 0.1
    assert rate.spread_deg > 0.0


def test_a_unit_at_its_models_mean_does_not_read_within_the_spread() -> None:
    assert np.isnan(_spread_scores(_widening(0.03))["rate"].within_spread_deg)


def test_a_named_effect_is_not_also_read_within_the_spread() -> None:
    rate = _spread_scores(_widening(0.3))["rate"]
    assert rate.significant and np.isnan(rate.within_spread_deg)


def test_the_verdict_says_an_effect_inside_the_spread_cannot_be_told_from_unit_scatter() -> None:
    scores = list(_spread_scores(_widening(0.11)).values())
    note = spread_note(scores)
    assert "rate dependence" in note.lower() and "unit scatter" in note
    assert spread_note([s for s in scores if s.name != "rate"]) == ""
