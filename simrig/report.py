"""Print (and plot) the signature of a plant on the paper's sweep: +-90 deg at 0.04 Hz.

``python -m simrig.report [--plant lumped] [--plot docs/img/plant_sweep.png] [--set coupling=1.0]``

For each knob in turn (the other held at 0 deg) it runs two cycles at 250 Hz and reports the
tip-based dead zone and backlash (:mod:`simrig.analysis`), the tip slopes, the knob-torque
signature and the plant's CPU time per step. Figures in ``docs/plant.md`` come from here.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.analysis import (
    DeadZoneBacklash,
    loaded_slope,
    measure_dead_zone_backlash,
    releasing_slope,
)
from simrig.family import PLANT_SPECS
from simrig.plant import Plant, PlantLoadError, as_plant_step, load_plant

FloatArray = NDArray[np.float64]


@dataclass
class SweepRecord:
    """One knob swept, the other held."""

    t_s: FloatArray
    knob_deg: FloatArray
    tip_deg: FloatArray
    torque_Nm: FloatArray
    cpu_s: float


def run_sweep(
    plant: Plant,
    knob: int,
    freq_hz: float = 0.04,
    amp_deg: float = 90.0,
    cycles: float = 2.0,
    dt_s: float = 0.004,
    other_deg: float = 0.0,
) -> SweepRecord:
    """Sine sweep of one knob from 0 deg; CPU time counts the plant steps only."""
    t = np.arange(0.0, cycles / freq_hz, dt_s)
    q = amp_deg * np.sin(2.0 * np.pi * freq_hz * t)
    tip = np.empty_like(t)
    tau = np.empty_like(t)
    cmd = np.zeros(2)
    cmd[1 - knob] = other_deg
    plant.reset()
    cpu = 0.0
    for i, qi in enumerate(q):
        cmd[knob] = qi
        c0 = time.process_time()
        step = as_plant_step(plant.step(dt_s, cmd))
        cpu += time.process_time() - c0
        tip[i] = step.tip_deg[knob]
        tau[i] = step.knob_torque_Nm[knob]
    return SweepRecord(t, q, tip, tau, cpu)


@dataclass
class Signature:
    """What the paper's Figure (a)(b) show, measured on one sweep (knob degrees, Nm)."""

    dz_bl: DeadZoneBacklash
    loading_slope: tuple[float, float]
    releasing_slope: tuple[float, float]
    tip_range_deg: tuple[float, float]
    torque_peak_Nm: float
    dead_zone_torque_Nm: float
    reversal_dip_Nm: float
    released_torque_Nm: float
    torque_settled_deg: float
    """Knob travel after the reversal until the torque is within 2 % of its peak of the released
    level: about the backlash with a straight handle, a few degrees with a routed one."""
    loop_area_deg2: float
    """Area of the tip-vs-knob loop over the second cycle."""


def signature(rec: SweepRecord) -> Signature:
    """Measure the sweep's signature; the torque figures are for the positive reversal."""
    q, y, tau, t = rec.knob_deg, rec.tip_deg, rec.torque_Nm, rec.t_s
    period = float(t[-1] + t[1] - t[0]) / 2.0  # two cycles
    # D and B from the passes after the first -90 deg reversal: the first release starts from
    # a tension-free (virgin) plant and rests higher, which is not the product's behaviour.
    conditioned = t >= 0.6 * period
    m = measure_dead_zone_backlash(q[conditioned], y[conditioned])
    moving_up = np.gradient(q) > 0
    in_dz = moving_up & (np.abs(q) < 10.0) & (t > period / 2)
    # Second positive reversal: the torque dips below the released level right after it.
    i_rev = int(np.argmax(np.where(t > period, q, -np.inf)))
    after = (t > t[i_rev]) & (t < t[i_rev] + period / 4) & (q > m.dead_zone_pos_deg + 5.0)
    released = after & (q < 90.0 - m.backlash_pos_deg - 2.0)
    level = float(np.median(tau[released])) if released.any() else float("nan")  # tip locked
    peak = float(np.max(np.abs(tau)))
    settled = np.flatnonzero(after & (np.abs(tau - level) < 0.02 * peak))
    return Signature(
        dz_bl=m,
        loading_slope=loaded_slope(q, y, 40.0, 85.0),
        releasing_slope=releasing_slope(q, y, 40.0, 70.0),
        tip_range_deg=(float(y.min()), float(y.max())),
        torque_peak_Nm=float(np.max(np.abs(tau))),
        dead_zone_torque_Nm=float(np.median(tau[in_dz])),
        reversal_dip_Nm=float(tau[after].min()),
        released_torque_Nm=level,
        torque_settled_deg=float(q[i_rev] - q[settled[0]]) if settled.size else float("nan"),
        loop_area_deg2=float(abs(np.trapezoid(y[t >= period], q[t >= period]))),
    )


def plant_spec(name: str) -> str:
    """A family plant name (``capstan``, ``lumped``) or a ``module:factory`` spec."""
    return PLANT_SPECS.get(name, name)


def coupling_grid(
    params: dict[str, Any],
    knob: int = 0,
    others_deg: Sequence[float] = tuple(range(-90, 91, 30)),
    spec: str = PLANT_SPECS["capstan"],
) -> list[DeadZoneBacklash]:
    """D/B of one knob with the other held at each angle (the calibration protocol's grid)."""
    return [
        measure_dead_zone_backlash(
            *_knob_tip(run_sweep(load_plant(spec, params), knob, other_deg=o))
        )
        for o in others_deg
    ]


def _knob_tip(rec: SweepRecord) -> tuple[FloatArray, FloatArray]:
    return rec.knob_deg, rec.tip_deg


def plot_grid(others_deg: Sequence[float], grid: Sequence[DeadZoneBacklash], path: str) -> None:
    """D and B of knob 1 over the other knob's angle."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    arr = np.array(grid)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9.0, 3.4))
    ax1.plot(others_deg, arr[:, 0], "o-", label="D_pos")
    ax1.plot(others_deg, -arr[:, 1], "s-", label="-D_neg")
    ax1.set_ylabel("dead zone (deg)")
    ax2.plot(others_deg, arr[:, 2], "o-", label="B_pos")
    ax2.plot(others_deg, arr[:, 3], "s-", label="B_neg")
    ax2.set_ylabel("backlash (deg)")
    for ax in (ax1, ax2):
        ax.set_xlabel("other knob angle (deg)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Knob 1 with coupling=1.0, +-90 deg at 0.04 Hz (tip-based D/B)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def routing_study(
    params: dict[str, Any], wraps_deg: Sequence[float] = (0.0, 90.0, 180.0, 360.0), knob: int = 0
) -> list[tuple[float, SweepRecord, Signature]]:
    """One knob's sweep per handle routing wrap (both knobs routed alike, the rest as given)."""
    out = []
    for wrap in wraps_deg:
        knobs = [dict(k) for k in params.get("knobs", [{}, {}])]
        for k in knobs:
            k["routing_wrap_deg"] = wrap
        rec = run_sweep(load_plant(PLANT_SPECS["capstan"], {**params, "knobs": knobs}), knob)
        out.append((wrap, rec, signature(rec)))
    return out


def plot_routing(study: Sequence[tuple[float, SweepRecord, Signature]], path: str) -> None:
    """Torque and tip after the second positive reversal, against knob travel since it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9.0, 3.6), sharex=True)
    for wrap, rec, sig in study:
        t, q = rec.t_s, rec.knob_deg
        period = float(t[-1] + t[1] - t[0]) / 2.0
        i_rev = int(np.argmax(np.where(t > period, q, -np.inf)))
        w = slice(i_rev, i_rev + round(period / 4 / (t[1] - t[0])))
        travel = q[i_rev] - q[w]
        tau = rec.torque_Nm[w]
        level, peak = sig.released_torque_Nm, tau[0]
        (line,) = ax1.plot(travel, (tau - level) / (peak - level), lw=1.2, label=f"{wrap:.0f} deg")
        ax2.plot(travel, rec.tip_deg[i_rev] - rec.tip_deg[w], lw=1.2, color=line.get_color())
        for ax in (ax1, ax2):
            ax.axvline(sig.dz_bl.backlash_pos_deg, color=line.get_color(), lw=0.7, ls="--")
    ax1.set_ylabel("(torque - released) / (peak - released)")
    ax2.set_ylabel("tip travel back (deg)")
    ax2.set_ylim(-2.0, 40.0)
    for ax in (ax1, ax2):
        ax.set_xlabel("knob travel since the +90 deg reversal (deg)")
        ax.set_xlim(0.0, 40.0)
        ax.grid(alpha=0.3)
    ax1.legend(title="routing_wrap_deg", fontsize=8)
    fig.suptitle(
        "Handle routing: knob 1 after a reversal (dashed: tip backlash B_pos)", fontsize=10
    )
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def protocol_cpu_s(
    params: dict[str, Any], dt_s: float = 0.004, spec: str = PLANT_SPECS["capstan"]
) -> tuple[int, float]:
    """CPU time of the plant over the 700 s calibration protocol (14 sweeps of 50 s)."""
    plant = load_plant(spec, params)
    t = np.arange(0.0, 50.0, dt_s)
    sweep = 90.0 * np.sin(2.0 * np.pi * 0.04 * t)
    steps = 0
    c0 = time.process_time()
    for knob in (0, 1):
        for other in range(-90, 91, 30):
            cmd = np.zeros(2)
            cmd[1 - knob] = other
            for qi in sweep:
                cmd[knob] = qi
                plant.step(dt_s, cmd)
                steps += 1
    return steps, time.process_time() - c0


def _parse_set(items: Sequence[str]) -> dict[str, Any]:
    params: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise PlantLoadError(f"--set expects KEY=VALUE, got {item!r}")
        params[key] = json.loads(value)
    return params


def plot(
    records: Sequence[SweepRecord],
    sigs: Sequence[Signature],
    path: str,
    title: str = "Default tendon-sheath plant",
) -> None:
    """Tip vs knob and knob torque vs knob, one column per knob."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(9.0, 6.0), sharex=True)
    for col, (rec, sig) in enumerate(zip(records, sigs, strict=True)):
        m = sig.dz_bl
        ax = axes[0, col]
        ax.plot(rec.knob_deg, rec.tip_deg, lw=1.0)
        ax.plot([-90, 90], [-90 * 1.32, 90 * 1.32], ":", color="grey", lw=0.8, label="paper: 1.32")
        for x in (m.dead_zone_pos_deg, m.dead_zone_neg_deg):
            ax.axvline(x, color="tab:orange", lw=0.8, ls="--")
        for x in (90.0 - m.backlash_pos_deg, -90.0 + m.backlash_neg_deg):
            ax.axvline(x, color="tab:green", lw=0.8, ls="--")
        ax.set_title(
            f"knob {col + 1}: D {m.dead_zone_pos_deg:.1f}/{m.dead_zone_neg_deg:.1f}, "
            f"B {m.backlash_pos_deg:.1f}/{m.backlash_neg_deg:.1f} deg",
            fontsize=9,
        )
        ax.set_ylabel("tip angle (deg)")
        ax.set_ylim(-120, 120)
        ax.legend(loc="upper left", fontsize=8)
        ax.grid(alpha=0.3)
        ax = axes[1, col]
        ax.plot(rec.knob_deg, rec.torque_Nm, lw=1.0, color="tab:red")
        ax.axhline(0.0, color="grey", lw=0.6)
        ax.set_xlabel("knob angle (deg)")
        ax.set_ylabel("knob torque (Nm)")
        ax.grid(alpha=0.3)
    fig.suptitle(f"{title}, +-90 deg sine at 0.04 Hz, 2 cycles", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m simrig.report", description=__doc__)
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=JSON",
        help="plant parameter, e.g. coupling=1.0 or knobs='[{...},{}]'",
    )
    parser.add_argument(
        "--plant",
        default="capstan",
        help="capstan (default), lumped, or a module:factory spec",
    )
    parser.add_argument("--freq", type=float, default=0.04, help="sweep frequency (Hz)")
    parser.add_argument("--other", type=float, default=0.0, help="other knob's angle (deg)")
    parser.add_argument("--plot", metavar="PNG", help="write the sweep figure here")
    parser.add_argument(
        "--grid",
        metavar="PNG",
        help="also sweep knob 1 with the other at -90..90 step 30 and plot D/B",
    )
    parser.add_argument(
        "--routing",
        metavar="PNG",
        help="also sweep knob 1 with routing_wrap_deg 0/90/180/360 on both knobs and plot",
    )
    parser.add_argument(
        "--protocol",
        action="store_true",
        help="also time the plant over the 700 s calibration protocol",
    )
    args = parser.parse_args(argv)
    spec = plant_spec(args.plant)
    if args.routing and spec != PLANT_SPECS["capstan"]:
        print("error: --routing studies the capstan plant's routing_wrap_deg", file=sys.stderr)
        return 2
    try:
        params = _parse_set(args.set)
        records = [
            run_sweep(load_plant(spec, params), k, args.freq, other_deg=args.other)
            for k in (0, 1)
        ]
    except (PlantLoadError, json.JSONDecodeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    sigs = [signature(r) for r in records]
    for k, (rec, sig) in enumerate(zip(records, sigs, strict=True)):
        m = sig.dz_bl
        print(f"knob {k + 1}: sweep +-90 deg at {args.freq} Hz, other knob {args.other} deg")
        print(
            f"  dead zone D_pos/D_neg     {m.dead_zone_pos_deg:7.1f} {m.dead_zone_neg_deg:7.1f} deg"
        )
        print(
            f"  backlash  B_pos/B_neg     {m.backlash_pos_deg:7.1f} {m.backlash_neg_deg:7.1f} deg"
        )
        print(
            f"  loading slope +/-         {sig.loading_slope[0]:7.3f} {sig.loading_slope[1]:7.3f}"
        )
        rel = sig.releasing_slope
        print(f"  releasing slope +/-       {rel[0]:7.3f} {rel[1]:7.3f}")
        lo, hi = sig.tip_range_deg
        print(f"  tip range                 {lo:7.1f} {hi:7.1f} deg")
        print(f"  loop area (2nd cycle)     {sig.loop_area_deg2:7.0f} deg^2")
        print(f"  torque peak               {sig.torque_peak_Nm:7.3f} Nm")
        print(f"  torque in dead zone       {sig.dead_zone_torque_Nm:7.4f} Nm")
        print(f"  torque min after reversal {sig.reversal_dip_Nm:7.4f} Nm")
        print(f"  torque while released     {sig.released_torque_Nm:7.4f} Nm")
        print(f"  torque settled after      {sig.torque_settled_deg:7.1f} deg (of the reversal)")
        us = rec.cpu_s / rec.t_s.size * 1e6
        print(f"  plant CPU time            {us:7.1f} us/step ({rec.t_s.size} steps)")
    if args.plot:
        plot(records, sigs, args.plot, f"{args.plant} plant")
        print(f"wrote {args.plot}")
    if args.grid:
        others = [float(o) for o in range(-90, 91, 30)]
        grid = coupling_grid(params, 0, others, spec)
        print("knob 1 over the other knob's angle: other  D_pos  D_neg  B_pos  B_neg (deg)")
        for o, m in zip(others, grid, strict=True):
            print(f"  {o:6.0f} {m[0]:6.1f} {m[1]:6.1f} {m[2]:6.1f} {m[3]:6.1f}")
        plot_grid(others, grid, args.grid)
        print(f"wrote {args.grid}")
    if args.routing:
        study = routing_study(params)
        print("knob 1 per routing_wrap_deg: wrap  B_pos  B_neg (deg)  peak (Nm)  settled (deg)")
        for wrap, _, sig in study:
            m = sig.dz_bl
            print(
                f"  {wrap:6.0f} {m.backlash_pos_deg:6.1f} {m.backlash_neg_deg:6.1f}"
                f" {sig.torque_peak_Nm:8.3f} {sig.torque_settled_deg:8.1f}"
            )
        plot_routing(study, args.routing)
        print(f"wrote {args.routing}")
    if args.protocol:
        steps, cpu = protocol_cpu_s(params, spec=spec)
        print(
            f"700 s protocol: {steps} steps, plant CPU {cpu:.2f} s, {cpu / steps * 1e6:.1f} us/step"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
