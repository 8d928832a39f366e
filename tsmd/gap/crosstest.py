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
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.current_sensor import CurrentSensor
from simrig.family import PLANT_SPECS, family_member
from simrig.plant import load_plant
from simrig.tracker import EmTracker
from tsmd.gap.compliance import reference_deg_per_A
from tsmd.gap.contrast import product_reference
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.diagnose import diagnose
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.protocol import Segment, encode_table, protocol
from tsmd.gap.reference import ProductReference
from tsmd.gap.result import GapConfig
from tsmd.gap.selftest import (
    BUILTIN_FIT_SPECS,
    BUILTIN_PLANT,
    EFFECTS,
    SelftestCase,
    SelftestResult,
    _cur_rmse,
    _tip_rmse,
    drive_plant,
    trajectory,
)
from tsmd.recording import Recording

FloatArray = NDArray[np.float64]

OTHER_CAPSTAN_KNOBS: tuple[dict[str, float], ...] = (
    {"sheath_friction": 0.12, "sheath_wrap_deg": 300.0, "slack_pos_mm": 1.2, "slack_neg_mm": 1.5,
     "tendon_stiffness_N": 5500.0, "bend_friction_Nm": 0.0012,
     "bend_stiffness_Nm_per_rad": 0.009, "handle_friction_Nm": 0.02, "routing_wrap_deg": 180.0,
     "sheath_drag_N": 0.3, "pulley_radius_mm": 5.0},
    {"sheath_friction": 0.15, "sheath_wrap_deg": 330.0, "slack_pos_mm": 1.0, "slack_neg_mm": 1.4,
     "tendon_stiffness_N": 5000.0, "bend_friction_Nm": 0.001,
     "bend_stiffness_Nm_per_rad": 0.008, "handle_friction_Nm": 0.018, "routing_wrap_deg": 180.0,
     "sheath_drag_N": 0.25, "pulley_radius_mm": 5.0},
)
"""The stand-in 'other catheter' until an independently formulated plant lands: the capstan
plant with strongly different physics (half the sheath friction over less wrap, a routed handle,
smaller pulley, more drag, stiffer and more frictional bending joints, half the slack). Its
tendon stiffness stays near the default (5000-5500 N against 6000 N): a tendon twice as
compliant *is* the compliance effect, so a base that differs along one of the six effect axes
would make the self-test's truth ambiguous ("none" data that need compliance)."""


LUMPED_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 1.0},
    "rate": {"viscous_N_s_per_m": 20.0},
    "compliance": {"tendon_compliance": 1.0},
    "curvature": {"sheath_curvature_deg": 120.0},
    "creep": {"creep_compliance_mm_per_N": 0.05},
}
"""The self-test effects in the lumped plant's own physics (its keywords), at strengths that move
the tip about as much as the capstan plant's do (2 x 120 s of the experiment motion, unit 1,
noise-free, effect on minus off, capstan / lumped): coupling 1.5 / 1.6 deg, rate 1.7 / 1.9 deg,
compliance 9.8 / 7.6 deg, curvature 12.0 / 8.5 deg, creep 0.35 / 0.42 deg (docs/gap.md)."""

SEGMENTS_BASE: dict[str, Any] = {"coupling": 0.0}
"""The segments plant couples its two planes by default; its "none" units and its simulator have
the coupling off, as the other plants' have every effect off."""

SEGMENTS_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 1.0},
    "rate": {"viscous_N_s_per_m": 90.0},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The self-test effects in the segments plant's own physics, sized like the lumped ones (tip
RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz; capstan
coupling 1.47, rate 1.70 deg): its nominal coupling 1.40 deg, lumen drag 90 N s/m (nominal 2)
1.72 deg, a 120 deg bend 6.91 deg. It has no creep: that case is not run on it."""

SEGMENTS_KNOB_EFFECTS: dict[str, dict[str, float]] = {"compliance": {"tendon_stiffness_N": 0.5}}
"""Compliance on segments: the unit's tendon EA halved (no keyword of its own; the other plants'
``tendon_compliance`` 1.0 is exactly that, docs/gap.md). Tip moved 6.42 deg (unit 1)."""


COILPIPE_BASE: dict[str, Any] = {"coupling_mm_per_rad2": 0.0}
"""The coilpipe plant shortens a tendon's path with the other plane's bend by default (0.25
mm/rad^2); its "none" units and its simulator have that off. What stays on is base physics: the
shaft's compression under all four tensions (a load coupling of both knobs), LuGre friction
with Stribeck and viscous terms (a rate dependence of its own) and the tip's relaxing stiffness
(2 s: a creep of its own); docs/gap.md "Session 11"."""

COILPIPE_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling_mm_per_rad2": 0.55},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The self-test effects in the coilpipe plant's own keywords, sized like the others before any
diagnosis (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at
50 Hz): path coupling 0.55 mm/rad^2 1.51 deg, a 120 deg bend 5.14 deg."""

COILPIPE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"viscous_N_s_per_mm": 8.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"bend_creep_time_s": 2.0},
}
"""Coilpipe effects without a keyword, as factors on the unit's knob constants (same sizing):
lumen viscosity x8 1.56 deg, tendon EA halved 4.47 deg, the tip cover relaxing twice as slowly
(2 -> 4 s, its one creep branch) 0.58 deg."""


STICKSLIP_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The stickslip plant's one effect keyword: a 120 deg sheath bend moves its tip by 1.99 deg (tip
RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz; the
other plants' 5-12 deg). Its knobs' coupling (each tendon rubs round the whole bent section) is
base physics with no constant of its own: that case is not run on it (as segments' creep)."""

STICKSLIP_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"creep_fast_share": 5.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"creep_slow_share": 1.5},
}
"""Stickslip effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): its only rate-dependent physics is the tendons' relaxation, so rate is the fast
(0.5 s) Maxwell branch five times as stiff, 1.11 deg (x3: 0.65; the protocol's 20 against 80
deg/s loops then differ by 0.36 / 0.16 deg RMS, the nominal unit's own 0.16 / 0.09); creep the
slow (12 s) branch 1.5 times as stiff, 0.38 deg (the other plants' creep 0.35-0.42 deg); the
tendon EA halved, 3.73 deg. "None" is the nominal physics as written: relaxing tendons,
stick-slip, the brake and the bend's coupling are its base (docs/gap.md "Session 12")."""


TWISTSHAFT_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The twistshaft plant's one effect keyword: a 120 deg sheath bend, 12.8 deg of tip (tip RMSE
effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz). The plant is
quasi-static with no load relaxation: no rate or creep physics, those cases are not run. Its
warm-up (24 -> 37 C in 60 s from every reset) is base physics: every recording, the data
sheet's included, starts at insertion (docs/gap.md "Session 13")."""

TWISTSHAFT_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"lumen_angle_error_deg": 4.5},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Twistshaft effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): its lumens sit off their planes (1.5 deg) and the shaft's twist turns the planes, a
coupling of its base; the case puts the lumens 4.5 times as far off, 1.53 deg (the others'
coupling 1.5 deg); the tendon EA halved, 3.59 deg."""


@dataclass(frozen=True)
class PlantSpec:
    """A plant as ``module:factory`` + fixed keyword parameters + what to fit as a simulator.

    ``family`` names a :mod:`simrig.family` plant: its units (scatter by unit number: 1-8
    development, 101-108 held out) are built from the family's draw; otherwise a unit is the
    factory's own ``unit_variation``/``seed``. ``effects`` maps a self-test case to the plant's
    effect keywords (default: :data:`tsmd.gap.selftest.EFFECTS`, the capstan plant's).
    """

    factory: str
    params: dict[str, Any] = field(default_factory=dict)
    fit: tuple[ParamSpec, ...] = ()
    name: str = ""
    family: str = ""
    effects: dict[str, dict[str, float]] | None = None
    knob_effects: dict[str, dict[str, float]] = field(default_factory=dict)
    """Case -> factors on every knob's constants (a family unit's), for an effect the plant has
    no keyword for."""

    def build(self, **extra: Any) -> Any:
        return load_plant(self.factory, {**self.params, **extra})

    def supports(self, case: str) -> bool:
        """Whether the plant can put this case's effect in its own physics (the sensor lag is
        the rig's, every plant has it)."""
        return (self.effects is None or case in ("none", "sensor") or case in self.effects
                or case in self.knob_effects)

    def case_effects(self, case: str) -> dict[str, float]:
        if self.effects is None:
            return dict(EFFECTS[case][0])
        return dict(self.effects.get(case, {}))

    def build_unit(self, unit: int, unit_variation: float, case: str = "none",
                   **effects: float) -> Any:
        """Catheter ``unit`` of this plant with ``effects`` (and ``case``'s knob factors)."""
        if self.family:
            member = family_member(self.family, unit)
            params = {**member.params, **self.params, **effects}
            factors = self.knob_effects.get(case, {})
            if factors:
                params["knobs"] = [{k: v * factors.get(k, 1.0) for k, v in knob.items()}
                                   for knob in member.params["knobs"]]
            return load_plant(member.spec, params)
        return self.build(unit_variation=unit_variation, seed=unit, **effects)


PRESETS: dict[str, PlantSpec] = {
    "capstan": PlantSpec(BUILTIN_PLANT, {}, BUILTIN_FIT_SPECS, "capstan"),
    "capstan-other": PlantSpec(BUILTIN_PLANT, {"knobs": [dict(k) for k in OTHER_CAPSTAN_KNOBS]},
                               BUILTIN_FIT_SPECS, "capstan-other"),
    "lumped": PlantSpec(PLANT_SPECS["lumped"], {}, (), "lumped", family="lumped",
                        effects=LUMPED_EFFECTS),
    "segments": PlantSpec(PLANT_SPECS["segments"], dict(SEGMENTS_BASE), (), "segments",
                          family="segments", effects=SEGMENTS_EFFECTS,
                          knob_effects=SEGMENTS_KNOB_EFFECTS),
    "coilpipe": PlantSpec(PLANT_SPECS["coilpipe"], dict(COILPIPE_BASE), (), "coilpipe",
                          family="coilpipe", effects=COILPIPE_EFFECTS,
                          knob_effects=COILPIPE_KNOB_EFFECTS),
    "stickslip": PlantSpec(PLANT_SPECS["stickslip"], {}, (), "stickslip", family="stickslip",
                           effects=STICKSLIP_EFFECTS, knob_effects=STICKSLIP_KNOB_EFFECTS),
    "twistshaft": PlantSpec(PLANT_SPECS["twistshaft"], {}, (), "twistshaft", family="twistshaft",
                            effects=TWISTSHAFT_EFFECTS, knob_effects=TWISTSHAFT_KNOB_EFFECTS),
}
"""Named plants for ``--data-plant``/``--sim-plant``."""


def parse_plant_spec(text: str) -> PlantSpec:
    """A preset name, or ``module:factory`` optionally followed by ``@`` and a JSON object."""
    text = text.strip()
    if text in PRESETS:
        return PRESETS[text]
    factory, _, raw = text.partition("@")
    if ":" not in factory:
        raise GapError(f"plant {text!r}: give a preset ({', '.join(PRESETS)}) or "
                       "module:factory[@{json parameters}]")
    params: dict[str, Any] = {}
    if raw:
        try:
            loaded = json.loads(raw)
        except json.JSONDecodeError as exc:
            raise GapError(f"plant {text!r}: parameters after '@' are not JSON: {exc}") from None
        if not isinstance(loaded, dict):
            raise GapError(f"plant {text!r}: parameters after '@' must be a JSON object")
        params = loaded
    load_plant(factory, params)  # fail early, with the loader's message
    return PlantSpec(factory, params, (), text)


def cross_config(fit: Sequence[ParamSpec], method: str = "signature") -> GapConfig:
    """The self-test's diagnosis settings. The signature method fits no plant parameters: the
    structural layer takes the base mismatch (and a physics fit of a plant with other physics
    costs most of the time); the candidate method fits ``fit`` as `tsmd gap` does."""
    return GapConfig(fit_specs=() if method == "signature" else tuple(fit), method=method)


CONFIGS: tuple[str, str] = ("straight", "looped")


def make_session(data: PlantSpec, case: str, duration_s: float, rate_hz: float, seed: int,
                 unit_variation: float = 0.1, tip_noise_deg: float = 0.1,
                 current_noise_A: float = 0.004, matched: bool = True) -> list[Recording]:
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
                            tip_noise_deg, current_noise_A)
            if seg is not None:
                cols["segment"] = np.asarray(seg, dtype=float)
                meta["segments"] = encode_table(table)
            out.append(Recording(cols, meta))
    return out


def _measure(plant: Any, t: FloatArray, q: FloatArray, rate_hz: float, lag_s: float,
             noise_seed: int, tip_noise_deg: float,
             current_noise_A: float) -> dict[str, FloatArray]:
    """Drive ``plant`` along ``q``; the recording's columns as tracker and sensors read them."""
    true_tip, true_A = drive_plant(plant, q, rate_hz)
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


def model_reference(data: PlantSpec, rate_hz: float, unit: int = 0) -> ProductReference:
    """What the data plant's catheter model has always (its own rate, coupling and creep
    contrasts), from the same recordings as its data sheet."""
    return product_reference(_sheet_series(data, rate_hz, unit))


def run_cross_case(data: PlantSpec, sim: PlantSpec, case: str, duration_s: float, seed: int,
                   rate_hz: float = 50.0, config: GapConfig | None = None,
                   matched: bool = True, sheet_unit: int = 0,
                   reference: bool = True) -> SelftestCase:
    """Make one session and diagnose it blind with the other plant as the simulator."""
    recs = make_session(data, case, duration_s, rate_hz, seed, matched=matched)
    return diagnose_session(recs, data, sim, case, duration_s, seed, rate_hz, config,
                            matched, sheet_unit, reference)


def diagnose_session(recs: Sequence[Recording], data: PlantSpec, sim: PlantSpec, case: str,
                     duration_s: float, seed: int, rate_hz: float = 50.0,
                     config: GapConfig | None = None, matched: bool = True,
                     sheet_unit: int = 0, reference: bool = True) -> SelftestCase:
    """Diagnose one made session (:func:`make_session`) with ``sim`` as the simulator: a
    session of a slow plant is made once and diagnosed with several simulators. With the
    protocol the diagnosis gets the model's data sheet and, with ``reference``, what the model
    has always (:func:`model_reference`), both from the data sheet's unit."""
    series = [series_from_recording(r, f"{case}-{seed}-{r.metadata['configuration']}-{i}")
              for i, r in enumerate(recs)]
    cfg = config or GapConfig(fit_specs=sim.fit, seed=seed)
    if matched and cfg.compliance_reference is None:
        cfg = dataclasses.replace(
            cfg, compliance_reference=datasheet_reference(data, rate_hz, sheet_unit))
    if matched and reference and cfg.product_reference is None:
        cfg = dataclasses.replace(
            cfg, product_reference=model_reference(data, rate_hz, sheet_unit))

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
    figures = structure.get("figures", {})
    layer = figures.get("layer", result.before)
    before_tip, before_cur = _tip_rmse(layer), _cur_rmse(layer)
    assert before_tip is not None and before_cur is not None
    return SelftestCase(case, duration_s, seed, EFFECTS[case][2], result.verdict, top, share,
                        before_tip, _tip_rmse(result.after_top), before_cur,
                        _cur_rmse(result.after_top), wall, excess_shrink=shrink,
                        physics_tip_rmse=_tip_rmse(figures.get("physics")))


def run_crosstest(data: PlantSpec, sim: PlantSpec, cases: Sequence[str],
                  sizes_s: Sequence[float], seeds: Sequence[int], rate_hz: float = 50.0,
                  config: GapConfig | None = None,
                  progress: Callable[[SelftestCase], None] | None = None,
                  matched: bool = True, sheet_unit: int = 0,
                  reference: bool = True) -> SelftestResult:
    if sheet_unit < 0:
        raise GapError(f"data-sheet unit {sheet_unit}: a unit number is 0 or more")
    if sheet_unit in seeds:
        raise GapError(f"data-sheet unit {sheet_unit} is also scored: a data sheet is measured "
                       "on another unit than those diagnosed")
    result = SelftestResult()
    for size in sizes_s:
        for seed in seeds:
            for case in [c for c in cases if data.supports(c)]:
                c = run_cross_case(data, sim, case, size, seed, rate_hz, config, matched,
                                   sheet_unit, reference)
                result.cases.append(c)
                if progress is not None:
                    progress(c)
    return result
