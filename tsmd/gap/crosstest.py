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

from tsmd.gap.compliance import reference_deg_per_A
from tsmd.gap.contrast import product_reference
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.detectable import condition_footprint, footprint
from tsmd.gap.diagnose import diagnose
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.presets import PlantSpec
from tsmd.gap.reference import ProductReference
from tsmd.gap.result import GapConfig
from tsmd.gap.score import SelftestCase, SelftestResult
from tsmd.gap.selftest import EFFECTS, _cur_rmse, _tip_rmse
from tsmd.gap.session import CURRENT_NOISE_A, TIP_NOISE_DEG, make_session
from tsmd.recording import Recording


def cross_config(fit: Sequence[ParamSpec], method: str = "signature") -> GapConfig:
    """The self-test's diagnosis settings. The signature method fits no plant parameters: the
    structural layer takes the base mismatch (and a physics fit of a plant with other physics
    costs most of the time); the candidate method fits ``fit`` as `tsmd gap` does."""
    return GapConfig(fit_specs=() if method == "signature" else tuple(fit), method=method)


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
    fp = (condition_footprint(data, case, seed, rate_hz) if case in ("rate", "creep")
          else footprint(data, case, seed, duration_s, rate_hz))
    return dataclasses.replace(out, footprint_tip_deg=fp.tip_deg, footprint_cur_A=fp.cur_A,
                               detectable=fp.detectable(TIP_NOISE_DEG, CURRENT_NOISE_A))


def diagnose_session(recs: Sequence[Recording], data: PlantSpec, sim: PlantSpec, case: str,
                     duration_s: float, seed: int, rate_hz: float = 50.0,
                     config: GapConfig | None = None, matched: bool = True,
                     sheet_unit: int = 0,
                     reference_units: Sequence[int] = REFERENCE_UNITS) -> SelftestCase:
    """Diagnose one made session (:func:`make_session`) with ``sim`` as the simulator: a
    session of a slow plant is made once and diagnosed with several simulators. With the
    protocol the diagnosis gets the model's data sheet (from ``sheet_unit``) and, unless
    ``reference_units`` is empty, what the model has always (:func:`model_reference`).
    Without ``config`` the self-test's settings (:func:`cross_config`: no simulator parameter
    fitted, seed 0), so a script gets the verdicts of `tsmd gap selftest`: fitting the
    capstan simulator's slacks and friction and seeding by unit read warmgear 101's rate case
    as sensor (docs/gap.md "Session 27, round 2")."""
    series = [series_from_recording(r, f"{case}-{seed}-{r.metadata['configuration']}-{i}")
              for i, r in enumerate(recs)]
    cfg = config or cross_config(sim.fit)
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
