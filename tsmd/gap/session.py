"""One self-test session: a plant unit driven along the identification motion and the
matched-condition protocol in two sheath configurations, read by the rig's tracker and current
sensors (noise and lag). Shared by the cross-plant self-test and the footprints that score it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.current_sensor import CurrentSensor
from simrig.tracker import EmTracker
from tsmd.gap.presets import PlantSpec
from tsmd.gap.protocol import Segment, encode_table, protocol
from tsmd.gap.selftest import EFFECTS, drive_plant, trajectory
from tsmd.recording import Recording

FloatArray = NDArray[np.float64]

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
