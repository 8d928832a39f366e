"""Data sheets (a product's constants, :class:`DeviceModel`) to and from plain mappings, validated
like profiles (:mod:`tsmd.profile.schema`): every defect is one :class:`ProfileError` naming the
origin, the key path and the reason."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, TypeVar

from tsmd.compensation.level_grid import (
    EDGE_LEVEL_SHARE_RANGE,
    level_grid_from_mapping,
    level_grid_to_mapping,
)
from tsmd.compensation.loaded_shape import (
    shape_from_mapping,
    shape_grid_from_mapping,
    shape_grid_to_mapping,
    shape_to_mapping,
)
from tsmd.compensation.release_ratio import release_ratio_problem
from tsmd.compensation.release_round import RELEASE_ROUND_RANGE, RELEASE_SHIFT_RANGE
from tsmd.compensation.reversal_release import (
    release_end_shape_from_mapping,
    release_end_shape_to_mapping,
)
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play_params import (
    OTHER_TIP_GAIN_RANGE,
)
from tsmd.profile.device import (
    BEND_GAIN_PER_RELEASE_RANGE,
    BEND_GAIN_PER_SLOPE_RANGE,
    BEND_OMEGA_PER_GAIN_RANGE,
    BEND_RELEASE_PER_EDGE_RANGE,
    DEFAULT_HANDLE_SLIP_DEG,
    DEVICE_SCHEMA_VERSION,
    RATIO_GAINS,
    RELEASE_RULES,
    DeviceKnob,
    DeviceModel,
)
from tsmd.profile.reader import Reader
from tsmd.profile.reading_offset import offset_from_mapping, offset_to_mapping
from tsmd.profile.schema import check_references, reference_to_mapping
from tsmd.profile.types import ANGLE_RANGE_DEG, KNOB_NAMES, ProfileError

OPTIONAL_KNOB_RANGES: dict[str, tuple[float, float, str]] = {
    "reference_backlash_pos_deg": (0.0, 90.0, "deg"),
    "reference_backlash_neg_deg": (0.0, 90.0, "deg"),
    "dead_zone_offset_deg": (-20.0, 20.0, "deg"),
    "reference_dead_zone_pos_deg": (0.0, 90.0, "deg"),
    "reference_dead_zone_neg_deg": (-90.0, 0.0, "deg"),
    "reference_backlash_gain": (0.0, 0.8, ""),
    "backlash_settle_fraction": (0.5, 1.0, ""),
    "backlash_release_slope_ratio": (-1.0, 1.0, ""),
    "reference_release_swing_A": (0.0, 100.0, "A"),
    "backlash_settle_lag_deg": (-10.0, 10.0, "deg"),
    "backlash_release_line_share": (0.5, 1.5, ""),
    "backlash_release_local_share": (0.5, 1.5, ""),
    "backlash_recovery_lag_deg": (-10.0, 10.0, "deg"),
    "backlash_bend_gain": (0.5, 2.0, ""),
    "reference_rule_backlash_gain": (0.0, 0.8, ""),
    "reference_tip_backlash_gain": (0.0, 0.8, ""),
    "reference_tip_line_backlash_gain": (0.0, 0.8, ""),
    "reference_release_end_offset_deg": (-10.0, 10.0, "deg"),
    "reference_release_plateau_deg": (0.0, 45.0, "deg"),
    "other_tip_gain": (*OTHER_TIP_GAIN_RANGE, ""),
    "loaded_knee_pos_deg": (0.0, 90.0, "deg"),
    "loaded_knee_neg_deg": (0.0, 90.0, "deg"),
    "dead_zone_unit_u95_deg": (0.0, 20.0, "deg"),
    "backlash_unit_u95_deg": (0.0, 20.0, "deg"),
    "sample_offset_dead_zone_pos_deg": (-5.0, 5.0, "deg"),
    "sample_offset_dead_zone_neg_deg": (-5.0, 5.0, "deg"),
    "sample_offset_backlash_pos_deg": (-5.0, 5.0, "deg"),
    "sample_offset_backlash_neg_deg": (-5.0, 5.0, "deg"),
    "release_round": (*RELEASE_ROUND_RANGE, ""),
    "release_shift": (*RELEASE_SHIFT_RANGE, ""),
    "torque_ripple_period_deg": (1.0, 90.0, "deg"),
    "edge_level_share": (*EDGE_LEVEL_SHARE_RANGE, ""),
    "plateau_gap_deg": (0.0, 45.0, "deg"),
    "plateau_gap_factor": (0.1, 10.0, ""),
    "slope_gain_weight": (0.0, 1.0, ""),
    "calibrated_dead_zone_pos_deg": (0.0, 90.0, "deg"),
    "calibrated_dead_zone_neg_deg": (-90.0, 0.0, "deg"),
    "flat_height_pos_deg": (-45.0, 45.0, "deg"),
    "flat_height_neg_deg": (-45.0, 45.0, "deg"),
}
"""The data sheet's optional measured numbers per knob and their plausible ranges: the schema
reads them with these, and ``tsmd datasheet`` leaves out a measured one outside its range
(:func:`tsmd.datasheet.readable`)."""

_SHAPE_KEYS = ("loaded_shape_pos", "loaded_shape_neg")
_BACKLASH_KEYS = ("reference_backlash_gain", "backlash_settle_fraction",
                  "backlash_release_slope_ratio", "reference_release_swing_A",
                  "backlash_settle_lag_deg", "reference_rule_backlash_gain",
                  "reference_tip_backlash_gain", "reference_tip_line_backlash_gain",
                  "reference_release_end_offset_deg", "reference_release_plateau_deg")
"""Optional data-sheet numbers written only when measured (the backlash rules' constants)."""
_RELEASE_RULE_KEYS = ("backlash_release_line_share", "backlash_release_local_share",
                      "backlash_recovery_lag_deg", "backlash_bend_gain", "backlash_release_rule",
                      "backlash_settled_share", "backlash_knee", "edge_curve", "edge_rise",
                      "release_ratio_gain", "backlash_stick_end", "settle_gain_read",
                      "hold_at_home")
_COUPLING_KEYS = ("other_tip_gain", "loaded_knee_pos_deg", "loaded_knee_neg_deg",
                  "edge_level_share")
"""Optional data-sheet numbers of the planes' coupling, written only when measured."""
_SAMPLE_KEYS = ("dead_zone_unit_u95_deg", "backlash_unit_u95_deg",
                "sample_offset_dead_zone_pos_deg", "sample_offset_dead_zone_neg_deg",
                "sample_offset_backlash_pos_deg", "sample_offset_backlash_neg_deg")
"""Optional data-sheet numbers measured on the product's sample, written only when measured."""
_ROUND_KEYS = ("release_round", "release_shift")
"""Optional data-sheet numbers of the rounded release (session 20), written only when set."""
_HANDLE_KEYS = ("torque_ripple_period_deg",)
"""Optional numbers of the handle's own make (session 22), written only when set."""
_LOOP_KEYS = ("plateau_gap_deg", "plateau_gap_factor")
"""Optional numbers of the dead-zone loop (session 25), written only when measured."""
_UNIT_EDGE_KEYS = ("calibrated_dead_zone_pos_deg", "calibrated_dead_zone_neg_deg")
"""Optional edges of the sheet unit's own calibration (session 26), written only when measured."""
_FLAT_KEYS = ("flat_height_pos_deg", "flat_height_neg_deg")
"""Optional plateau heights from the sheet unit's tracked flats (session 28), when measured."""
_SLOPE_KEYS = ("slope_gain_weight",)
"""Optional share of the gain reading a unit's slope takes, from the product's sample (s27)."""


_Block = TypeVar("_Block")


def _nested(r: Reader, value: Any, where: str,
            parse: Callable[[Any, str], _Block]) -> _Block | None:
    """A nested block read by its own module's parser, its error re-raised as the schema's."""
    if value is None:
        return None
    try:
        return parse(value, where)
    except ValueError as exc:
        raise r.fail(where, str(exc).removeprefix(where + ": ")) from None


def _ratio_gain(r: Reader, k: Mapping[str, Any], key: str) -> str | None:
    value = k.get("release_ratio_gain")
    if value is None:
        return None
    gain = r.text(value, f"{key}.release_ratio_gain")
    if gain not in RATIO_GAINS:
        raise r.fail(f"{key}.release_ratio_gain",
                     f"{gain!r} is not one of {', '.join(RATIO_GAINS)}")
    needs = "reference_backlash_gain" if gain == "settle" else "reference_rule_backlash_gain"
    if k.get(needs) is None:
        raise r.fail(f"{key}.release_ratio_gain", f"'{gain}' needs {needs}")
    return gain


def _release_rule(r: Reader, k: Mapping[str, Any], key: str) -> str | None:
    value = k.get("backlash_release_rule")
    if value is None:
        return None
    rule = r.text(value, f"{key}.backlash_release_rule")
    if rule not in RELEASE_RULES:
        raise r.fail(f"{key}.backlash_release_rule",
                     f"{rule!r} is not one of {', '.join(RELEASE_RULES)}")
    for needs, share in (("line", "backlash_release_line_share"),
                         ("local", "backlash_release_local_share"),
                         ("recovery", "backlash_recovery_lag_deg")):
        if rule == needs and k.get(share) is None:
            raise r.fail(f"{key}.backlash_release_rule", f"'{needs}' needs {share}")
    return rule


def _settled_share(r: Reader, k: Mapping[str, Any], key: str) -> bool | None:
    """``backlash_settled_share``: a flag, and only with the rule whose share it reads."""
    value = _knee(r, k.get("backlash_settled_share"), f"{key}.backlash_settled_share")
    if value and k.get("backlash_release_rule") != "swing":
        raise r.fail(f"{key}.backlash_settled_share", "needs backlash_release_rule: swing")
    return value


def _knee(r: Reader, value: Any, where: str) -> bool | None:
    if value is None or isinstance(value, bool):
        return value
    raise r.fail(where, f"must be true or false, got {value!r}")


def device_model_from_mapping(data: Any, origin: str = "device model") -> DeviceModel:
    r = Reader(origin)
    m = r.mapping(data, "top level")
    version = r.version(m, DEVICE_SCHEMA_VERSION)
    name = r.text(r.get(m, "device_model", ""), "device_model")
    knobs: list[DeviceKnob] = []
    for knob_name, raw in r.knob_map(m, ""):
        key = f"knobs.{knob_name}"
        k = r.mapping(raw, key)
        lim = r.mapping(r.get(k, "limits", key + "."), key + ".limits")
        lk = key + ".limits."
        try:
            limits = KnobLimits(
                r.number(r.get(lim, "min_deg", lk), lk + "min_deg", -ANGLE_RANGE_DEG, 0, "deg"),
                r.number(r.get(lim, "max_deg", lk), lk + "max_deg", 0, ANGLE_RANGE_DEG, "deg"),
                r.number(r.get(lim, "max_velocity_deg_s", lk), lk + "max_velocity_deg_s",
                         1e-3, 1e4, "deg/s"),
                r.number(r.get(lim, "max_accel_deg_s2", lk), lk + "max_accel_deg_s2",
                         1e-3, 1e6, "deg/s^2"))
        except ValueError as exc:
            if isinstance(exc, ProfileError):
                raise
            raise r.fail(key + ".limits", str(exc)) from None
        pos = r.reference(r.get(k, "reference_pos", key + "."), key + ".reference_pos")
        neg = r.reference(r.get(k, "reference_neg", key + "."), key + ".reference_neg")
        check_references(r, key, pos, neg)
        release = k.get("release_omega")
        b_pos, b_neg = k.get("reference_backlash_pos_deg"), k.get("reference_backlash_neg_deg")
        if (b_pos is None) != (b_neg is None) or (release is not None and b_pos is None):
            raise r.fail(key, "reference_backlash_pos_deg and reference_backlash_neg_deg go "
                         "together, and release_omega needs them")

        def optional(name: str, k: Mapping[str, Any] = k, key: str = key) -> float | None:
            lo, hi, unit = OPTIONAL_KNOB_RANGES[name]
            value = k.get(name)
            return None if value is None else r.number(value, f"{key}.{name}", lo, hi, unit)

        knobs.append(DeviceKnob(
            r.omega(r.get(k, "omega", key + "."), key + ".omega"), pos, neg, limits,
            None if release is None else r.omega(release, key + ".release_omega"),
            optional("reference_backlash_pos_deg"),
            optional("reference_backlash_neg_deg"),
            optional("dead_zone_offset_deg"),
            optional("reference_dead_zone_pos_deg"),
            optional("reference_dead_zone_neg_deg"),
            r.number(k.get("handle_slip_deg", DEFAULT_HANDLE_SLIP_DEG), key + ".handle_slip_deg",
                     0.01, 45.0, "deg"),
            optional("reference_backlash_gain"),
            optional("backlash_settle_fraction"),
            optional("backlash_release_slope_ratio"),
            optional("reference_release_swing_A"),
            optional("backlash_settle_lag_deg"),
            backlash_release_line_share=optional("backlash_release_line_share"),
            backlash_release_local_share=optional("backlash_release_local_share"),
            backlash_recovery_lag_deg=optional("backlash_recovery_lag_deg"),
            backlash_bend_gain=optional("backlash_bend_gain"),
            backlash_release_rule=_release_rule(r, k, key),
            backlash_settled_share=_settled_share(r, k, key),
            backlash_knee=_knee(r, k.get("backlash_knee"), f"{key}.backlash_knee"),
            edge_curve=_knee(r, k.get("edge_curve"), f"{key}.edge_curve"),
            edge_rise=_knee(r, k.get("edge_rise"), f"{key}.edge_rise"),
            backlash_stick_end=_knee(r, k.get("backlash_stick_end"),
                                     f"{key}.backlash_stick_end"),
            settle_gain_read=_knee(r, k.get("settle_gain_read"), f"{key}.settle_gain_read"),
            hold_at_home=_knee(r, k.get("hold_at_home"), f"{key}.hold_at_home"),
            release_ratio_gain=_ratio_gain(r, k, key),
            reference_rule_backlash_gain=optional("reference_rule_backlash_gain"),
            reference_tip_backlash_gain=optional("reference_tip_backlash_gain"),
            reference_tip_line_backlash_gain=optional("reference_tip_line_backlash_gain"),
            reference_release_end_offset_deg=optional("reference_release_end_offset_deg"),
            reference_release_plateau_deg=optional("reference_release_plateau_deg"),
            other_tip_gain=optional("other_tip_gain"),
            loaded_knee_pos_deg=optional("loaded_knee_pos_deg"),
            loaded_knee_neg_deg=optional("loaded_knee_neg_deg"),
            dead_zone_unit_u95_deg=optional("dead_zone_unit_u95_deg"),
            backlash_unit_u95_deg=optional("backlash_unit_u95_deg"),
            sample_offset_dead_zone_pos_deg=optional("sample_offset_dead_zone_pos_deg"),
            sample_offset_dead_zone_neg_deg=optional("sample_offset_dead_zone_neg_deg"),
            sample_offset_backlash_pos_deg=optional("sample_offset_backlash_pos_deg"),
            sample_offset_backlash_neg_deg=optional("sample_offset_backlash_neg_deg"),
            release_round=optional("release_round"),
            release_shift=optional("release_shift"),
            torque_ripple_period_deg=optional("torque_ripple_period_deg"),
            edge_level_share=optional("edge_level_share"),
            plateau_gap_deg=optional("plateau_gap_deg"),
            plateau_gap_factor=optional("plateau_gap_factor"),
            calibrated_dead_zone_pos_deg=optional("calibrated_dead_zone_pos_deg"),
            calibrated_dead_zone_neg_deg=optional("calibrated_dead_zone_neg_deg"),
            flat_height_pos_deg=optional("flat_height_pos_deg"),
            flat_height_neg_deg=optional("flat_height_neg_deg"),
            slope_gain_weight=optional("slope_gain_weight"),
            reading_offset=_nested(r, k.get("reading_offset"), f"{key}.reading_offset",
                                   offset_from_mapping),
            **{name: _nested(r, k.get(name), f"{key}.{name}", shape_from_mapping)
               for name in _SHAPE_KEYS},
            loaded_shape_grid=_nested(r, k.get("loaded_shape_grid"),
                                      f"{key}.loaded_shape_grid", shape_grid_from_mapping),
            loaded_level_grid=_nested(r, k.get("loaded_level_grid"),
                                      f"{key}.loaded_level_grid", level_grid_from_mapping),
            release_end_shape=_nested(r, k.get("release_end_shape"),
                                      f"{key}.release_end_shape",
                                      release_end_shape_from_mapping)))
    for knob_name, knob in zip(KNOB_NAMES, knobs, strict=True):
        problem = release_ratio_problem(knob)
        if problem is not None:  # a sheet error, shown when it is read, not on a patient's unit
            raise r.fail(f"knobs.{knob_name}.release_omega", problem)
    desc = m.get("description", "")
    bend = _bend_relation(r, m.get("bend_relation"))
    return DeviceModel(name, (knobs[0], knobs[1]), str(desc), version, *bend)


def _bend_relation(r: Reader, raw: Any) -> tuple[Any, ...]:
    """The sheet's optional bend relation (both numbers or the key absent; the slope terms
    optional within it)."""
    if raw is None:
        return None, None, None, None
    m = r.mapping(raw, "bend_relation")
    slope, omega = m.get("gain_per_slope"), m.get("omega_per_gain")
    return (r.number(r.get(m, "release_per_edge", "bend_relation."),
                     "bend_relation.release_per_edge", *BEND_RELEASE_PER_EDGE_RANGE, ""),
            r.number(r.get(m, "gain_per_release_deg", "bend_relation."),
                     "bend_relation.gain_per_release_deg", *BEND_GAIN_PER_RELEASE_RANGE,
                     "per deg"),
            None if slope is None else r.number(slope, "bend_relation.gain_per_slope",
                                                *BEND_GAIN_PER_SLOPE_RANGE, ""),
            None if omega is None else r.number(omega, "bend_relation.omega_per_gain",
                                                *BEND_OMEGA_PER_GAIN_RANGE, ""))


def device_model_to_mapping(device: DeviceModel) -> dict[str, Any]:
    knobs: dict[str, Any] = {}
    for name, k in zip(KNOB_NAMES, device.knobs, strict=True):
        knobs[name] = {
            "omega": k.omega,
            "reference_pos": reference_to_mapping(k.reference_pos),
            "reference_neg": reference_to_mapping(k.reference_neg),
            "limits": {"min_deg": k.limits.min_deg, "max_deg": k.limits.max_deg,
                       "max_velocity_deg_s": k.limits.max_velocity_deg_s,
                       "max_accel_deg_s2": k.limits.max_accel_deg_s2},
        }
        if k.release_omega is not None:
            knobs[name]["release_omega"] = k.release_omega
        if k.reference_backlash_pos_deg is not None:
            knobs[name]["reference_backlash_pos_deg"] = k.reference_backlash_pos_deg
            knobs[name]["reference_backlash_neg_deg"] = k.reference_backlash_neg_deg
        if k.dead_zone_offset_deg is not None:
            knobs[name]["dead_zone_offset_deg"] = k.dead_zone_offset_deg
        for key in ("reference_dead_zone_pos_deg", "reference_dead_zone_neg_deg"):
            if getattr(k, key) is not None:
                knobs[name][key] = getattr(k, key)
        knobs[name]["handle_slip_deg"] = k.handle_slip_deg
        for key in _BACKLASH_KEYS:
            if getattr(k, key) is not None:
                knobs[name][key] = getattr(k, key)
        for key in _SHAPE_KEYS:
            shape = getattr(k, key)
            if shape is not None:
                knobs[name][key] = shape_to_mapping(shape)
        if k.loaded_shape_grid is not None:
            knobs[name]["loaded_shape_grid"] = shape_grid_to_mapping(*k.loaded_shape_grid)
        if k.loaded_level_grid is not None:
            knobs[name]["loaded_level_grid"] = level_grid_to_mapping(k.loaded_level_grid)
        if k.release_end_shape is not None:
            knobs[name]["release_end_shape"] = release_end_shape_to_mapping(k.release_end_shape)
        for key in (_RELEASE_RULE_KEYS + _COUPLING_KEYS + _SAMPLE_KEYS + _ROUND_KEYS
                    + _HANDLE_KEYS + _LOOP_KEYS + _UNIT_EDGE_KEYS + _FLAT_KEYS
                    + _SLOPE_KEYS):
            if getattr(k, key) is not None:
                knobs[name][key] = getattr(k, key)
        if k.reading_offset is not None:
            knobs[name]["reading_offset"] = offset_to_mapping(k.reading_offset)
    out: dict[str, Any] = {"schema_version": device.schema_version,
                           "device_model": device.device_model,
                           "description": device.description, "knobs": knobs}
    if device.bend_release_per_edge is not None:
        out["bend_relation"] = {"release_per_edge": device.bend_release_per_edge,
                                "gain_per_release_deg": device.bend_gain_per_release_deg}
        for key in ("gain_per_slope", "omega_per_gain"):
            if getattr(device, f"bend_{key}") is not None:
                out["bend_relation"][key] = getattr(device, f"bend_{key}")
    return out
