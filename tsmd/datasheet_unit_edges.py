"""The sheet unit's dead-zone edges as its own calibration reads them (session 26).

Method ours draws each unit's loaded line through the product's plateau heights at the unit's
own edges, so the line moves by the unit's edge *minus the sheet unit's*. The sheet unit's
edges (``reference_dead_zone_*_deg``) come from its long tracked sweep, read in its first
minutes after switching on; a unit's come from its calibration, whose knob-2 sweeps run after
nine minutes. Where the catheter changes over those minutes the difference is not the unit's:
warmgear's shaft warms to body temperature and takes up slack, so the calibration read unit 0's
own edges 1.3-3.2 deg inside its sheet's and moved every unit's knob-2 line outward by as much
(development 1 phi2: tip 4-6 deg short of ours' model on both branches; docs/model.md, session
26). Here the sheet's unit is calibrated as a unit is (the paper protocol, under the sheet) and
the edges its profile's tension play holds at the other knob's 0 are written as
``calibrated_dead_zone_pos_deg`` / ``_neg_deg``; the plateau heights are then drawn through
them (:func:`tsmd.calibration.reading_offset.calibrated_edges`).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

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


def with_edges_of(device: DeviceModel, profile: CatheterProfile) -> DeviceModel:
    """``device`` with each knob's calibrated edges from the sheet unit's ``profile`` (a knob
    whose profile has no tension play keeps the sheet's reference edges)."""
    knobs = []
    for k, pk in zip(device.knobs, profile.knobs, strict=True):
        if pk.tension_play is None:
            knobs.append(k)
            continue
        pos, neg = edges_at_zero(pk.tension_play)
        knobs.append(dataclasses.replace(k, calibrated_dead_zone_pos_deg=round(pos, 2),
                                         calibrated_dead_zone_neg_deg=round(neg, 2)))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def with_unit_edges(device: DeviceModel, config: TsmdConfig,
                    plant_factory: Callable[[], Plant], seed: int = SHEET_UNIT_SEED
                    ) -> DeviceModel:
    """The sheet with its unit's calibrated edges (one calibration under ``device``), printed
    beside the reference edges they replace for the plateau heights."""
    t0 = time.monotonic()
    cal = calibrate_sheet_unit(plant_factory, device, "unit edges", seed, config)
    out = with_edges_of(device, cal.profile)
    for name, old, new in zip(("phi1", "phi2"), device.knobs, out.knobs, strict=True):
        print(f"  {name} edges of the sheet unit's calibration: {new.calibrated_dead_zone_pos_deg}"
              f" / {new.calibrated_dead_zone_neg_deg} deg (tracked sweep's, as read: "
              f"{old.reference_dead_zone_pos_deg} / {old.reference_dead_zone_neg_deg})")
    print(f"  unit edges: {time.monotonic() - t0:.0f} s")
    return out
