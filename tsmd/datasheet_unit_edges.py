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

Session 28: those edges also carry what the catheter changed over the calibration, and every
unit is used (the tracking bench scores it) in the state its calibration leaves, with its own
calibrated edges carrying the same change; drawing the heights through the sheet unit's
calibrated edges took the change out of every unit's line. On warmgear's unit 0 the tip's
loaded lines lie 1.4-2.0 deg inside the fresh unit's after a calibration; on cyclopebax's 2.4
deg outside (the ropes' set), while its calibration read edges only 0.4-0.8 deg outside the
tracked ones (in the fit's frame: the sheet's reading offset of 1.6-1.8 deg applied). With
``less_move`` (``--unit-edges-move``) the edges written are the calibration's less the move of
the sheet unit's tip lines between its fresh and calibrated state
(:mod:`tsmd.datasheet_state_move`): what stays is how the calibration reads an edge against the
tracked sweep, which every unit's calibration shares. It is a choice per product: it helped
cyclopebax's development rows and cost warmgear's and twistshaft's (docs/model.md, session
28).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from simrig.plant import Plant
from tsmd.calibration.reading_offset import reference_edge_deg
from tsmd.compensation.paper import at_other_knob_zero
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import TsmdConfig
from tsmd.datasheet_state_move import state_moves_deg
from tsmd.datasheet_unit_run import SHEET_UNIT_SEED, calibrate_sheet_unit
from tsmd.profile import CatheterProfile, DeviceModel

UNIT_EDGE_KEYS = ("calibrated_dead_zone_pos_deg", "calibrated_dead_zone_neg_deg")
"""The sheet's fields this stage writes (per knob); only method ours' plateau heights read them."""


def edges_at_zero(params: TensionPlayParams) -> tuple[float, float]:
    """(D_pos, D_neg) of a profile's tension play at the other knob's 0 (deg): the edges
    its plateau heights would be drawn through on a unit."""
    return (at_other_knob_zero(params.other_knob_deg, params.dead_zone_pos_deg),
            at_other_knob_zero(params.other_knob_deg, params.dead_zone_neg_deg))


def with_edges_of(device: DeviceModel, profiles: Sequence[CatheterProfile],
                  moves: Sequence[Sequence[tuple[float, float]]] = ()) -> DeviceModel:
    """``device`` with each knob's calibrated edges: the mean over the sheet unit's
    ``profiles`` (one per noise seed: the sheet's edge is every unit's reference, so its
    reading scatter, 0.5-0.7 deg between two seeds on warmgear's unit 0, would be every unit's
    bias), less the mean of ``moves`` (per run, per knob: the tip lines' (pos, neg) move from the
    fresh to the calibrated state, :func:`tsmd.datasheet_state_move.state_moves_deg`; none:
    nothing subtracted). A knob without a tension play in every profile keeps the sheet's
    reference edges."""
    if not profiles:
        raise ValueError("needs at least one calibration of the sheet's unit")
    if moves and len(moves) != len(profiles):
        raise ValueError(f"{len(moves)} state moves for {len(profiles)} calibrations")
    knobs = []
    for i, k in enumerate(device.knobs):
        plays = [p.knobs[i].tension_play for p in profiles]
        if any(tp is None for tp in plays):
            knobs.append(k)
            continue
        edges = np.array([edges_at_zero(tp) for tp in plays if tp is not None])
        pos, neg = (float(v) for v in edges.mean(axis=0))
        if moves:
            move_pos, move_neg = (float(v) for v in np.array([m[i] for m in moves]).mean(axis=0))
            pos, neg = pos - move_pos, neg - move_neg
        knobs.append(dataclasses.replace(k, calibrated_dead_zone_pos_deg=round(pos, 2),
                                         calibrated_dead_zone_neg_deg=round(neg, 2)))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def fit_frame_edges(knob: Any) -> tuple[float | None, float | None]:
    """The sheet's tracked edges as the fit compares them with a unit's (the product's
    reading offset of 1 deg and more applied, :func:`reference_edge_deg`): the printed
    comparison of session 27 set the raw ones beside corrected calibrated ones (cyclopebax's
    "2.4 deg" move was 0.5-0.75 in the fit's frame)."""
    offset = getattr(knob, "reading_offset", None)
    return (reference_edge_deg(offset, "dead_zone_pos_deg", knob.reference_dead_zone_pos_deg),
            reference_edge_deg(offset, "dead_zone_neg_deg", knob.reference_dead_zone_neg_deg))


def _deg(value: float | None) -> str:
    return "none" if value is None else f"{value:.2f}"


def with_unit_edges(device: DeviceModel, config: TsmdConfig,
                    plant_factory: Callable[[], Plant], seeds: Sequence[int] = (SHEET_UNIT_SEED,),
                    less_move: bool = False) -> DeviceModel:
    """The sheet with its unit's calibrated edges (one calibration under ``device`` per noise
    seed), with ``less_move`` less its tip lines' move over each calibration (session 28;
    without it session 26's stage as it was), each run's printed beside the tracked edges in
    the fit's frame."""
    t0 = time.monotonic()
    profiles, moves = [], []
    for s in seeds:
        built: list[Plant] = []

        def keep(built: list[Plant] = built) -> Plant:
            built.append(plant_factory())
            return built[-1]

        profiles.append(calibrate_sheet_unit(keep, device, "unit edges", s, config).profile)
        if less_move:
            moves.append(state_moves_deg(plant_factory, built[-1], s, config))
    out = with_edges_of(device, profiles, moves)
    for i, (name, old, new) in enumerate(zip(("phi1", "phi2"), device.knobs, out.knobs,
                                             strict=True)):
        read = [edges_at_zero(tp) for tp in (p.knobs[i].tension_play for p in profiles)
                if tp is not None]
        runs = ", ".join(f"{pos:.2f} / {neg:.2f}" + (f" (tip lines moved {m[i][0]:+.2f} / "
                                                      f"{m[i][1]:+.2f})" if m else "")
                         for (pos, neg), m in zip(read, moves or [()] * len(read),
                                                  strict=False))
        ref_pos, ref_neg = fit_frame_edges(old)
        print(f"  {name} edges of the sheet unit's calibration (noise seeds "
              f"{','.join(map(str, seeds))}: {runs}): written"
              f"{' less the move' if less_move else ''} "
              f"{new.calibrated_dead_zone_pos_deg} / {new.calibrated_dead_zone_neg_deg} deg "
              f"(the tracked sweep's in the fit's frame: {_deg(ref_pos)} / {_deg(ref_neg)}; "
              f"as read: "
              f"{old.reference_dead_zone_pos_deg} / {old.reference_dead_zone_neg_deg})")
    print(f"  unit edges: {time.monotonic() - t0:.0f} s")
    return out
