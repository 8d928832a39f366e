"""Catheter profiles to and from plain mappings (the YAML documents), validated: every defect is
one :class:`ProfileError` naming the origin, the key path and the reason. Data sheets have their
own schema (:mod:`tsmd.profile.sheet_schema`)."""

from __future__ import annotations

import dataclasses
import itertools
import logging
from typing import Any

import numpy as np

from tsmd.compensation.grid import INTERPOLATION_METHODS
from tsmd.compensation.tension_play_params import tension_play_from_mapping, tension_play_to_mapping
from tsmd.profile.device import ReferencePoint
from tsmd.profile.reader import Reader
from tsmd.profile.types import (
    ANGLE_RANGE_DEG,
    ID_PATTERN,
    KNOB_NAMES,
    PROFILE_SCHEMA_VERSION,
    CatheterProfile,
    KnobProfile,
)

_log = logging.getLogger("tsmd.profile")
PAPER_FIELDS = ("height_pos_deg", "height_neg_deg", "dead_zone_pos_deg", "dead_zone_neg_deg",
                "backlash_pos_deg", "backlash_neg_deg")
"""What a knob's ``paper`` entry holds (:attr:`tsmd.profile.types.KnobProfile.paper`)."""


def check_references(r: Reader, key: str, pos: ReferencePoint, neg: ReferencePoint) -> None:
    """Both schemas' reference points: one on each side of the knob's zero, ordered on the tip."""
    if not (pos.knob_deg > 0 > neg.knob_deg):
        raise r.fail(key, "reference_pos.knob_deg must be > 0 and reference_neg.knob_deg < 0")
    if not pos.tip_deg > neg.tip_deg:
        raise r.fail(key, "reference_pos.tip_deg must be above reference_neg.tip_deg")


def reference_to_mapping(p: ReferencePoint) -> dict[str, float]:
    return {"knob_deg": p.knob_deg, "tip_deg": p.tip_deg}


def _knob_from_mapping(r: Reader, raw: Any, key: str) -> KnobProfile:
    k = r.mapping(raw, key)
    p = key + "."
    omega = r.omega(r.get(k, "omega", p), p + "omega")
    pos = r.reference(r.get(k, "reference_pos", p), p + "reference_pos")
    neg = r.reference(r.get(k, "reference_neg", p), p + "reference_neg")
    check_references(r, key, pos, neg)
    h_pos = r.number(r.get(k, "height_pos_deg", p), p + "height_pos_deg", -90, 90, "deg")
    h_neg = r.number(r.get(k, "height_neg_deg", p), p + "height_neg_deg", -90, 90, "deg")
    grid = r.numbers(r.get(k, "other_knob_deg", p), p + "other_knob_deg", None,
                     -ANGLE_RANGE_DEG, ANGLE_RANGE_DEG, "deg")
    if len(grid) < 2:
        raise r.fail(p + "other_knob_deg", "needs at least two grid points")
    if any(b <= a for a, b in itertools.pairwise(grid)):
        raise r.fail(p + "other_knob_deg", f"grid is not sorted strictly increasing: {list(grid)}")
    n = len(grid)
    d_pos = r.numbers(r.get(k, "dead_zone_pos_deg", p), p + "dead_zone_pos_deg", n, 0, 90, "deg")
    d_neg = r.numbers(r.get(k, "dead_zone_neg_deg", p), p + "dead_zone_neg_deg", n, -90, 0, "deg")
    b_pos = r.numbers(r.get(k, "backlash_pos_deg", p), p + "backlash_pos_deg", n, 0, 90, "deg")
    b_neg = r.numbers(r.get(k, "backlash_neg_deg", p), p + "backlash_neg_deg", n, 0, 90, "deg")
    if k.get("ours") is not None:
        _log.warning("%s: %sours: parameters of the former 'ours' compensator ignored "
                     "(recalibrate for method 'ours')", r.origin, p)
    tension = None
    if k.get("tension_play") is not None:
        try:
            tension = tension_play_from_mapping(r.mapping(k["tension_play"], p + "tension_play"))
        except ValueError as exc:
            raise r.fail(p + "tension_play", str(exc)) from None
    knob = KnobProfile(omega, pos, neg, h_pos, h_neg, grid, d_pos, d_neg, b_pos, b_neg, tension)
    if k.get("paper") is not None:
        knob = dataclasses.replace(knob, paper=_paper_from_mapping(r, k["paper"], p + "paper",
                                                                     knob))
    return knob


def _paper_from_mapping(r: Reader, raw: Any, key: str, knob: KnobProfile) -> KnobProfile:
    """The paper's frame of a knob (``KnobProfile.paper``): its heights and grids only, on the
    knob's own grid, slope and reference points."""
    k = r.mapping(raw, key)
    p = key + "."
    n = len(knob.other_knob_deg)
    return dataclasses.replace(
        knob, tension_play=None, paper=None,
        height_pos_deg=r.number(r.get(k, "height_pos_deg", p), p + "height_pos_deg", -90, 90,
                                "deg"),
        height_neg_deg=r.number(r.get(k, "height_neg_deg", p), p + "height_neg_deg", -90, 90,
                                "deg"),
        dead_zone_pos_deg=r.numbers(r.get(k, "dead_zone_pos_deg", p), p + "dead_zone_pos_deg",
                                    n, 0, 90, "deg"),
        dead_zone_neg_deg=r.numbers(r.get(k, "dead_zone_neg_deg", p), p + "dead_zone_neg_deg",
                                    n, -90, 0, "deg"),
        backlash_pos_deg=r.numbers(r.get(k, "backlash_pos_deg", p), p + "backlash_pos_deg", n,
                                   0, 90, "deg"),
        backlash_neg_deg=r.numbers(r.get(k, "backlash_neg_deg", p), p + "backlash_neg_deg", n,
                                   0, 90, "deg"))


def profile_from_mapping(data: Any, origin: str = "profile") -> CatheterProfile:
    """Validate a parsed YAML document and build the profile (ProfileError on any problem)."""
    r = Reader(origin)
    m = r.mapping(data, "top level")
    version = r.version(m, PROFILE_SCHEMA_VERSION)
    catheter_id = r.text(r.get(m, "catheter_id", ""), "catheter_id")
    if not ID_PATTERN.match(catheter_id):
        raise r.fail("catheter_id", f"{catheter_id!r} must be letters, digits, '.', '_' or '-'")
    device = r.text(r.get(m, "device_model", ""), "device_model")
    calibrated_at = r.text(str(r.get(m, "calibrated_at", "")), "calibrated_at")
    software = r.text(r.get(m, "software_version", ""), "software_version")
    method = r.get(m, "interpolation", "")
    if method not in INTERPOLATION_METHODS:
        raise r.fail("interpolation", f"{method!r} is not one of {list(INTERPOLATION_METHODS)}")
    source = str(m.get("source", "calibration"))
    quality_raw = r.mapping(m.get("quality", {}) or {}, "quality")
    quality = {str(q): r.number(v, f"quality.{q}") for q, v in quality_raw.items()}
    knobs = [_knob_from_mapping(r, raw, f"knobs.{name}") for name, raw in r.knob_map(m, "")]
    return CatheterProfile(catheter_id, device, calibrated_at, software, method,
                           (knobs[0], knobs[1]), source, quality, version)


def profile_to_mapping(profile: CatheterProfile) -> dict[str, Any]:
    knobs: dict[str, Any] = {}
    for name, k in zip(KNOB_NAMES, profile.knobs, strict=True):
        entry: dict[str, Any] = {
            "omega": k.omega,
            "reference_pos": reference_to_mapping(k.reference_pos),
            "reference_neg": reference_to_mapping(k.reference_neg),
            "height_pos_deg": k.height_pos_deg,
            "height_neg_deg": k.height_neg_deg,
            "other_knob_deg": list(k.other_knob_deg),
            "dead_zone_pos_deg": list(k.dead_zone_pos_deg),
            "dead_zone_neg_deg": list(k.dead_zone_neg_deg),
            "backlash_pos_deg": list(k.backlash_pos_deg),
            "backlash_neg_deg": list(k.backlash_neg_deg),
        }
        if k.tension_play is not None:
            entry["tension_play"] = tension_play_to_mapping(k.tension_play)
        if k.paper is not None:
            entry["paper"] = {name: (list(v) if isinstance(v, tuple) else v)
                              for name, v in ((n, getattr(k.paper, n)) for n in PAPER_FIELDS)}
        knobs[name] = entry
    return {
        "schema_version": profile.schema_version,
        "catheter_id": profile.catheter_id,
        "device_model": profile.device_model,
        "calibrated_at": profile.calibrated_at,
        "software_version": profile.software_version,
        "source": profile.source,
        "interpolation": profile.interpolation,
        "quality": dict(profile.quality),
        "knobs": knobs,
    }


def plain_values(obj: Any) -> Any:
    """numpy scalars -> Python floats so the YAML stays readable by safe_load."""
    if isinstance(obj, dict):
        return {k: plain_values(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [plain_values(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj
