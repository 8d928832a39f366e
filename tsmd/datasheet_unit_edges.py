"""The sheet unit's dead-zone edges as its own calibration reads them (session 26).

Method ours draws each unit's loaded line through the product's plateau heights at the unit's
own edges, so the line moves by the unit's edge *minus the sheet unit's*. The sheet unit's
edges (``reference_dead_zone_*_deg``) come from its long tracked sweep, read in its first
minutes after switching on; a unit's come from its calibration, whose knob-2 sweeps run after
nine minutes. Where the catheter changes over those minutes the difference is not the unit's:
warmgear's shaft warms to body temperature and takes up slack, so the calibration read unit 0's
own edges 1.3-3.2 deg inside its sheet's and moved every unit's knob-2 line outward by as much
(development 1 phi2: tip 4-6 deg short of ours' model on both branches; docs/model.md, session
26). Here the sheet's unit is calibrated as a unit is (the paper protocol, under the sheet; once
per noise seed) and the mean of the edges its profiles' tension play holds at the other
knob's 0 is written as
``calibrated_dead_zone_pos_deg`` / ``_neg_deg``; the plateau heights are then drawn through
them (:func:`tsmd.calibration.reading_offset.calibrated_edges`).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence

import numpy as np

from simrig.plant import Plant
from tsmd.compensation.paper import at_other_knob_zero
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import TsmdConfig
from tsmd.datasheet_unit_run import SHEET_UNIT_SEED, calibrate_sheet_unit
from tsmd.profile import CatheterProfile, DeviceModel

UNIT_EDGE_KEYS = ("calibrated_dead_zone_pos_deg", "calibrated_dead_zone_neg_deg")
"""The sheet's fields this stage writes (per knob); only method ours' plateau heights read them."""


def edges_at_zero(params: TensionPlayParams) -> tuple[float, float]:
    """(D_pos, D_neg) of a profile's tension play at the other knob's 0 (deg): the edges
    its plateau heights would be drawn through on a unit."""
    return (at_other_knob_zero(params.other_knob_deg, params.dead_zone_pos_deg),
            at_other_knob_zero(params.other_knob_deg, params.dead_zone_neg_deg))


def with_edges_of(device: DeviceModel, profiles: Sequence[CatheterProfile]) -> DeviceModel:
    """``device`` with each knob's calibrated edges: the mean over the sheet unit's
    ``profiles`` (one per noise seed: the sheet's edge is every unit's reference, so its
    reading scatter, 0.5-0.7 deg between two seeds on warmgear's unit 0, would be every unit's
    bias). A knob without a tension play in every profile keeps the sheet's reference edges."""
    if not profiles:
        raise ValueError("needs at least one calibration of the sheet's unit")
    knobs = []
    for i, k in enumerate(device.knobs):
        plays = [p.knobs[i].tension_play for p in profiles]
        if any(tp is None for tp in plays):
            knobs.append(k)
            continue
        edges = np.array([edges_at_zero(tp) for tp in plays if tp is not None])
        pos, neg = (float(v) for v in edges.mean(axis=0))
        knobs.append(dataclasses.replace(k, calibrated_dead_zone_pos_deg=round(pos, 2),
                                         calibrated_dead_zone_neg_deg=round(neg, 2)))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def with_unit_edges(device: DeviceModel, config: TsmdConfig,
                    plant_factory: Callable[[], Plant], seeds: Sequence[int] = (SHEET_UNIT_SEED,)
                    ) -> DeviceModel:
    """The sheet with its unit's calibrated edges (one calibration under ``device`` per noise
    seed), each run's printed beside the reference edges they replace for the heights."""
    t0 = time.monotonic()
    profiles = [calibrate_sheet_unit(plant_factory, device, "unit edges", s, config).profile
                for s in seeds]
    out = with_edges_of(device, profiles)
    for i, (name, old, new) in enumerate(zip(("phi1", "phi2"), device.knobs, out.knobs,
                                             strict=True)):
        runs = ", ".join(f"{pos:.2f} / {neg:.2f}" for pos, neg in
                         (edges_at_zero(tp) for tp in (p.knobs[i].tension_play for p in profiles)
                          if tp is not None))
        print(f"  {name} edges of the sheet unit's calibration (noise seeds "
              f"{','.join(map(str, seeds))}: {runs}): {new.calibrated_dead_zone_pos_deg} / "
              f"{new.calibrated_dead_zone_neg_deg} deg (the tracked sweep's, as read: "
              f"{old.reference_dead_zone_pos_deg} / {old.reference_dead_zone_neg_deg})")
    print(f"  unit edges: {time.monotonic() - t0:.0f} s")
    return out
