"""Blind cross-plant self-test: one plant makes the 'real' data, another is the simulator.

A real catheter is never the simulator plus one effect. So the data here come from one plant
(any ``module:factory`` with its own physics, unit scatter from ``unit_variation``/``seed``, and
the effect switched on through the plant's own keyword), and the diagnosis uses a *different*
plant as its simulator. Every case is a session in two sheath configurations (header
``configuration: straight`` / ``looped``; only the curvature effect makes them differ), so
curvature has the condition it depends on. Scores: top-1 over the effect classes, confusion
matrix, false alarms on "none", and the held-out shrink of the named effect's excess.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.current_sensor import CurrentSensor
from simrig.tracker import EmTracker
from tsmd.gap.compliance import reference_deg_per_A
from tsmd.gap.contrast import collect_tests, product_reference
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.detectable import Footprint, footprint
from tsmd.gap.diagnose import diagnose
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.loops import contrast_of, loop_contrast
from tsmd.gap.presets import PlantSpec
from tsmd.gap.protocol import Segment, encode_table, protocol
from tsmd.gap.reference import ProductReference, measured_windows
from tsmd.gap.result import GapConfig
from tsmd.gap.score import SelftestCase, SelftestResult
from tsmd.gap.selftest import EFFECTS, _cur_rmse, _tip_rmse, drive_plant, trajectory
from tsmd.recording import Recording

FloatArray = NDArray[np.float64]



def cross_config(fit: Sequence[ParamSpec], method: str = "signature") -> GapConfig:
    """The self-test's diagnosis settings. The signature method fits no plant parameters: the
    structural layer takes the base mismatch (and a physics fit of a plant with other physics
    costs most of the time); the candidate method fits ``fit`` as `tsmd gap` does."""
    return GapConfig(fit_specs=() if method == "signature" else tuple(fit), method=method)


CONFIGS: tuple[str, str] = ("straight", "looped")

TIP_NOISE_DEG = 0.1
CURRENT_NOISE_A = 0.004
"""The sessions' tracker and current-sensor noise per sample (the rig's)."""


def make_session(data: PlantSpec, case: str, duration_s: float, rate_hz: float, seed: int,
                 unit_variation: float = 0.1, tip_noise_deg: float = TIP_NOISE_DEG,
                 current_noise_A: float = CURRENT_NOISE_A,
                 matched: bool = True) -> list[Recording]:
    """One unit's session: half the time in each sheath configuration, the effect switched on.

    The same unit (``seed``) in both configurations; curvature bends the sheath of the looped
    one only. With ``matched`` each configuration also gets a recording of the
    matched-condition protocol (:mod:`tsmd.gap.protocol`), the identification experiment's
    second part. Tracker and current noise differ per recording.
    """
    effects = data.case_effects(case)
    t_e, q_e = trajectory(duration_s / 2.0, rate_hz)
    motions: list[tuple[str, FloatArray, FloatArray, FloatArray | None, list[Segment]]] = [
        ("experiment", t_e, q_e, None, [])]
    if matched:
        motions.append(("protocol", *protocol(rate_hz)))
    out = []
    for i, config in enumerate(CONFIGS):
        eff = {k: v for k, v in effects.items()
               if k != "sheath_curvature_deg" or config == "looped"}
        for m, (kind, t, q, seg, table) in enumerate(motions):
            plant = data.build_unit(seed, unit_variation, case, **eff)
            meta = {"source": f"gap cross-plant selftest ({data.name or data.factory}, {kind})",
                    "catheter": f"unit-{seed}", "configuration": config}
            cols = _measure(plant, t, q, rate_hz, EFFECTS[case][1], 10 * seed + i + 2 * m,
                            tip_noise_deg, current_noise_A, data.max_step_s)
            if seg is not None:
                cols["segment"] = np.asarray(seg, dtype=float)
                meta["segments"] = encode_table(table)
            out.append(Recording(cols, meta))
    return out


def _measure(plant: Any, t: FloatArray, q: FloatArray, rate_hz: float, lag_s: float,
             noise_seed: int, tip_noise_deg: float,
             current_noise_A: float, max_step_s: float = 0.0) -> dict[str, FloatArray]:
    """Drive ``plant`` along ``q``; the recording's columns as tracker and sensors read them."""
    true_tip, true_A = drive_plant(plant, q, rate_hz, max_step_s)
    tracker = EmTracker(noise_deg=tip_noise_deg, seed=noise_seed)
    sensors = [CurrentSensor(lag_s=lag_s, offset_A=0.003 * (1 - 2 * k),
                             noise_A=current_noise_A, seed=7 * noise_seed + k)
               for k in range(2)]
    dt = 1.0 / rate_hz
    tip = np.array([tracker.measure(row) for row in true_tip])
    cur = np.array([[sensors[j].measure(dt, float(row[j])) for j in range(2)]
                    for row in true_A])
    cols = {"t": t, "q1": q[:, 0], "q2": q[:, 1], "cmd1": q[:, 0], "cmd2": q[:, 1],
            "pos1": q[:, 0], "pos2": q[:, 1], "cur1": cur[:, 0], "cur2": cur[:, 1],
            "tip1": tip[:, 0], "tip2": tip[:, 1]}
    return {k: np.array(v, dtype=float) for k, v in cols.items()}


_SHEET_SERIES: dict[str, list[GapSeries]] = {}


def _sheet_series(data: PlantSpec, rate_hz: float, unit: int) -> list[GapSeries]:
    """The protocol recordings of the data sheet's unit (noise as in the sessions): by default
    the nominal unit 0 (no scatter); another number is a scattered unit, as a real data sheet
    is measured on some unit of the model. Never a scored unit. Made once per plant, rate and
    unit."""
    key = f"{data.name or data.factory}@{rate_hz:g}#{unit}"
    if key not in _SHEET_SERIES:
        recs = make_session(data, "none", 4.0, rate_hz, unit,
                            unit_variation=0.0 if unit == 0 else 0.1)
        _SHEET_SERIES[key] = [series_from_recording(r, f"datasheet-{i}")
                              for i, r in enumerate(recs) if "segments" in r.metadata]
    return _SHEET_SERIES[key]


def datasheet_reference(data: PlantSpec, rate_hz: float,
                        unit: int = 0) -> tuple[float, float] | None:
    """The data sheet of the data plant's catheter model: lost motion per ampere on the
    protocol recorded with the data sheet's unit (:func:`_sheet_series`)."""
    return reference_deg_per_A(_sheet_series(data, rate_hz, unit))


REFERENCE_UNITS: tuple[int, ...] = (0, 5, 6, 7, 8)
"""The units the model reference is measured on by default: the data sheet's unit and four
development units (the scored units are 101 and up; development diagnoses use 1-4), so their
spread gives the allowance a unit of the model has (docs/gap.md "Session 13")."""


def model_reference(data: PlantSpec, rate_hz: float,
                    units: Sequence[int] = REFERENCE_UNITS) -> ProductReference:
    """What the data plant's catheter model has always (its own rate, coupling and creep
    contrasts) and how far its units scatter about that, from the protocol recorded on
    ``units`` as on the data sheet's unit (:func:`_sheet_series`)."""
    return product_reference([s for u in units for s in _sheet_series(data, rate_hz, u)])


def run_cross_case(data: PlantSpec, sim: PlantSpec, case: str, duration_s: float, seed: int,
                   rate_hz: float = 50.0, config: GapConfig | None = None,
                   matched: bool = True, sheet_unit: int = 0,
                   reference_units: Sequence[int] = REFERENCE_UNITS) -> SelftestCase:
    """Make one session and diagnose it blind with the other plant as the simulator; the
    case carries its effect's footprint on the ground truth (scoring only)."""
    recs = make_session(data, case, duration_s, rate_hz, seed, matched=matched)
    out = diagnose_session(recs, data, sim, case, duration_s, seed, rate_hz, config,
                           matched, sheet_unit, reference_units)
    if EFFECTS[case][2] is None:
        return out
    fp = (speed_footprint(data, seed, rate_hz) if case == "rate"
          else footprint(data, case, seed, duration_s, rate_hz))
    return dataclasses.replace(out, footprint_tip_deg=fp.tip_deg, footprint_cur_A=fp.cur_A,
                               detectable=fp.detectable(TIP_NOISE_DEG, CURRENT_NOISE_A))


def speed_footprint(data: PlantSpec, unit: int, rate_hz: float,
                    unit_variation: float = 0.1) -> Footprint:
    """The rate case's footprint where a rate dependence is defined, on the change of the
    response with speed: the protocol's fast-minus-slow loop contrast of the true tips and
    currents (noise-free, both configurations), effect on minus off, RMS over the matched
    points (session 17). A rate case's physics may move the tip over the whole motion by
    far more than it changes with speed (stickslip's fast relaxation branch x5: 1.1 deg of tip,
    0.09 deg of speed contrast on unit 1; ratestate's ageing x10, docs/gap.md "Session 16,
    round 2"); no one can name a rate dependence whose speed contrast is below the noise."""
    def contrasts(case: str) -> tuple[FloatArray, FloatArray]:
        recs = make_session(data, case, 4.0, rate_hz, unit, unit_variation, 0.0, 0.0)
        series = [series_from_recording(r, f"footprint-{i}") for i, r in enumerate(recs)
                  if "segments" in r.metadata]
        tests = collect_tests(series, [measured_windows(s) for s in series])
        tip: list[FloatArray] = []
        cur: list[FloatArray] = []
        for by_test in tests.values():
            t = by_test["rate"]
            for found, out in ((loop_contrast(t.loops, t.levels), tip),
                               (loop_contrast(t.currents, t.levels), cur)):
                if found is not None:
                    out.append(contrast_of(found))
        return np.array(tip), np.array(cur)

    (tip0, cur0), (tip1, cur1) = contrasts("none"), contrasts("rate")
    return Footprint(float(np.sqrt(np.mean((tip1 - tip0) ** 2))),
                     float(np.sqrt(np.mean((cur1 - cur0) ** 2))))


def diagnose_session(recs: Sequence[Recording], data: PlantSpec, sim: PlantSpec, case: str,
                     duration_s: float, seed: int, rate_hz: float = 50.0,
                     config: GapConfig | None = None, matched: bool = True,
                     sheet_unit: int = 0,
                     reference_units: Sequence[int] = REFERENCE_UNITS) -> SelftestCase:
    """Diagnose one made session (:func:`make_session`) with ``sim`` as the simulator: a
    session of a slow plant is made once and diagnosed with several simulators. With the
    protocol the diagnosis gets the model's data sheet (from ``sheet_unit``) and, unless
    ``reference_units`` is empty, what the model has always (:func:`model_reference`)."""
    series = [series_from_recording(r, f"{case}-{seed}-{r.metadata['configuration']}-{i}")
              for i, r in enumerate(recs)]
    cfg = config or GapConfig(fit_specs=sim.fit, seed=seed)
    if matched and cfg.compliance_reference is None:
        cfg = dataclasses.replace(
            cfg, compliance_reference=datasheet_reference(data, rate_hz, sheet_unit))
    if matched and reference_units and cfg.product_reference is None:
        cfg = dataclasses.replace(
            cfg, product_reference=model_reference(data, rate_hz, reference_units))

    def factory(params: dict[str, Any]) -> Any:
        return sim.build(**params)

    start = time.perf_counter()
    result = diagnose(series, factory, {}, cfg)
    wall = time.perf_counter() - start
    top = result.top[0] if result.top else None
    structure = result.structure or {}
    share = next((s["share"] for s in structure.get("signatures", []) if s["name"] == top),
                 None)
    shrink = next((s["raw_share"] for s in structure.get("signatures", [])
                   if s["name"] == top), None)
    inside = [s["name"] for s in structure.get("signatures", [])
              if np.isfinite(s.get("within_spread_deg", float("nan")))]
    figures = structure.get("figures", {})
    layer = figures.get("layer", result.before)
    before_tip, before_cur = _tip_rmse(layer), _cur_rmse(layer)
    assert before_tip is not None and before_cur is not None
    return SelftestCase(case, duration_s, seed, EFFECTS[case][2], result.verdict, top, share,
                        before_tip, _tip_rmse(result.after_top), before_cur,
                        _cur_rmse(result.after_top), wall, excess_shrink=shrink,
                        physics_tip_rmse=_tip_rmse(figures.get("physics")),
                        within_spread=inside[0] if inside and top is None else None)


def run_crosstest(data: PlantSpec, sim: PlantSpec, cases: Sequence[str],
                  sizes_s: Sequence[float], seeds: Sequence[int], rate_hz: float = 50.0,
                  config: GapConfig | None = None,
                  progress: Callable[[SelftestCase], None] | None = None,
                  matched: bool = True, sheet_unit: int = 0,
                  reference_units: Sequence[int] = REFERENCE_UNITS) -> SelftestResult:
    for unit, what in [(sheet_unit, "data-sheet unit")] + [(u, "reference unit")
                                                         for u in reference_units]:
        if unit < 0:
            raise GapError(f"{what} {unit}: a unit number is 0 or more")
        if unit in seeds:
            raise GapError(f"{what} {unit} is also scored: a data sheet or model reference is "
                           "measured on other units than those diagnosed")
    result = SelftestResult()
    for size in sizes_s:
        for seed in seeds:
            for case in [c for c in cases if data.supports(c)]:
                c = run_cross_case(data, sim, case, size, seed, rate_hz, config, matched,
                                   sheet_unit, reference_units)
                result.cases.append(c)
                if progress is not None:
                    progress(c)
    return result
