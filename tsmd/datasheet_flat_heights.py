"""The product's plateau heights read off the sheet unit's tracked flats (session 28).

Method ours' plateau heights are product constants, drawn from the sheet's reference point at
the knob's end (+-90 deg) back along the sheet's one ``omega`` to the sheet unit's edge. Where a
product's two loaded branches have different slopes (a section cut deeper on one side) the one
``omega`` fits one side at best, and on the other the line drawn back over 70 knob deg lands
degrees off the flat the tip really stands on (beltbraid's unit 0, phi1: H_pos -5.5 deg against
a flat at -10.3; loaded slopes 1.32 / 1.25): every loaded and release line of every unit then
sits that far off through the dead zone's neighbourhood. The tracker on the sheet's unit reads
the flats directly: the unit calibrated by ``tsmd calibrate``'s own protocol under the sheet, and
on its sweeps at the other knob's 0 the tip where the knob crosses 0 coming up (the flat the
positive branch leaves: ``H_pos``) and coming down (``H_neg``). Flats at the line's inner end
trade against the line's far end (a straight line of the unit's ``omega`` through the flat can
miss the reference point instead), so whether a product takes them is decided by what it is
used for, on the same unit: the rows where the knob moves alone (the paper's quick 1-DOF rows,
conditioned as the bench plays them) tracked with the drawn heights and with the flats. A knob
keeps the flats where in no row its tip error rises by more than that row's seed noise (the
drawn row played once more with the next noise seed) and their squared sum falls: the hold at
home's rule (:mod:`tsmd.datasheet_home_hold`), no margin tuned. The calibration then takes them
as every unit's heights (``flat_height_pos_deg`` / ``_neg_deg``;
:mod:`tsmd.calibration.tension_play_fit`).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from simrig.plant import Plant
from tsmd.config import TsmdConfig
from tsmd.datasheet_home_hold import tip_rms
from tsmd.datasheet_level_grid import SETTLE_FRACTION, TrackedSweep, tracked_sweeps
from tsmd.datasheet_unit_run import SHEET_UNIT_SEED, calibrate_sheet_unit
from tsmd.errors import TsmdError
from tsmd.profile import CatheterProfile, DeviceModel
from tsmd.tracking_scenarios import Scenario, scenarios

STAGE = "flat heights"

FLAT_HEIGHT_KEYS = ("flat_height_pos_deg", "flat_height_neg_deg")
"""The sheet's fields this stage writes (per knob); only method ours' plateau heights read them."""
FLAT_BAND_DEG = 2.0
"""Samples with the knob within this of 0 read the flat (every product's dead zone is wider:
its edges lie 10-25 deg out)."""
MIN_FLAT_SAMPLES = 10
"""Fewer samples crossing 0 one way give no flat."""


@dataclass(frozen=True)
class FlatRow:
    """One row with this knob moving alone: its tip's RMS error (deg) with the drawn heights,
    with the flats, and how far the drawn row's error moves with the next noise seed."""

    name: str
    drawn_deg: float
    flat_deg: float
    noise_deg: float


def flats_kept(rows: Sequence[FlatRow]) -> bool:
    """The flats stay where no row (of any judging unit) rises beyond its seed noise and the
    rows' squared sum falls. Session 28's first rule let a row rise up to the worst drawn row:
    the sample's unit 202 lost 2 deg per phi1 row under 201's worse drawn rows (and so did
    held-out 101), a unit traded against the others."""
    if not rows or any(r.flat_deg - r.drawn_deg > r.noise_deg for r in rows):
        return False
    return sum(r.flat_deg ** 2 for r in rows) < sum(r.drawn_deg ** 2 for r in rows)


def tracked_flats(sweeps: Sequence[TrackedSweep]) -> tuple[float, float]:
    """(coming up, coming down): the median tip where the knob crosses 0 each way, over the
    sweeps (the first :data:`SETTLE_FRACTION` of each left out); NaN where too few samples."""
    up: list[float] = []
    down: list[float] = []
    for sweep in sweeps:
        x = np.asarray(sweep.knob_deg, dtype=float)
        tip = np.asarray(sweep.tip_deg, dtype=float)
        a = int(len(x) * SETTLE_FRACTION)
        x, tip = x[a:], tip[a:]
        moving = np.sign(np.gradient(x))
        near = np.abs(x) <= FLAT_BAND_DEG
        up.extend(tip[near & (moving > 0)])
        down.extend(tip[near & (moving < 0)])
    return (float(np.median(up)) if len(up) >= MIN_FLAT_SAMPLES else float("nan"),
            float(np.median(down)) if len(down) >= MIN_FLAT_SAMPLES else float("nan"))


def flats_at_zero(sweeps: Sequence[tuple[float, TrackedSweep]]) -> tuple[float, float] | None:
    """The flats of the sweeps ``(other knob's angle, sweep)`` at the other knob's 0 (where the
    heights are read); None without a flat each way, or with the flats crossed."""
    up, down = tracked_flats([s for other, s in sweeps if other == 0.0])
    if not (np.isfinite(up) and np.isfinite(down)) or not down > up:
        return None
    return up, down


def with_heights(profile: CatheterProfile, knob: int, move_pos_deg: float, move_neg_deg: float
                 ) -> CatheterProfile:
    """The profile with ``knob``'s plateau heights moved (each unit's heights move by what the
    flats move the sheet unit's: a unit's own plateau move, its dead-zone loop's, stays)."""
    knobs = list(profile.knobs)
    tension = knobs[knob].tension_play
    if tension is None:
        raise TsmdError(f"{STAGE}: the sheet's unit has no parameters for method ours")
    knobs[knob] = dataclasses.replace(knobs[knob], tension_play=dataclasses.replace(
        tension, height_pos_deg=tension.height_pos_deg + move_pos_deg,
        height_neg_deg=tension.height_neg_deg + move_neg_deg))
    return dataclasses.replace(profile, knobs=(knobs[0], knobs[1]))


def own_rows(knob: int) -> list[Scenario]:
    """The paper's quick rows where ``knob`` alone moves and is scored."""
    return [s for s in scenarios(True) if s.knobs == (knob,)]


def score_flats(profile: CatheterProfile, knob: int, move_pos_deg: float, move_neg_deg: float,
                factory: Callable[[], Plant], seed: int) -> tuple[FlatRow, ...]:
    """``knob``'s own rows tracked with the drawn heights, with them moved to the flats, and
    drawn once more with the next noise seed."""
    flat = with_heights(profile, knob, move_pos_deg, move_neg_deg)
    rows = []
    for s in own_rows(knob):
        drawn = float(tip_rms(profile, s, factory(), seed)[knob])
        moved = float(tip_rms(flat, s, factory(), seed)[knob])
        noise = abs(float(tip_rms(profile, s, factory(), seed + 1)[knob]) - drawn)
        rows.append(FlatRow(f"{s.group} {s.name}", drawn, moved, noise))
    return tuple(rows)


def with_flat_heights(device: DeviceModel, config: TsmdConfig,
                      plant_factory: Callable[[], Plant], seed: int = SHEET_UNIT_SEED,
                      sample: Sequence[tuple[str, Callable[[], Plant]]] = ()) -> DeviceModel:
    """The sheet with each knob's flats, read on its unit, where the units that judge them
    track their own rows better with them (fields absent elsewhere): the product's ``sample``
    ``(name, plant factory)`` where given, else the sheet's unit itself (whose drawn heights
    pass its own reference points: it leans to them). One line per knob and unit."""
    t0 = time.monotonic()
    plain = [dataclasses.replace(k, flat_height_pos_deg=None, flat_height_neg_deg=None)
             for k in device.knobs]  # measured against the drawn heights
    drawn = dataclasses.replace(device, knobs=(plain[0], plain[1]))
    result = calibrate_sheet_unit(plant_factory, drawn, STAGE, seed, config)
    flats: list[tuple[float, float] | None] = []
    moves: list[tuple[float, float]] = []
    for i, name in enumerate(("phi1", "phi2")):
        tension = result.profile.knobs[i].tension_play
        if tension is None:
            raise TsmdError(f"{STAGE}: the sheet's unit has no parameters for method ours")
        flats.append(flats_at_zero(tracked_sweeps(result, i, STAGE)))
        f = flats[-1]
        moves.append((0.0, 0.0) if f is None else (f[0] - tension.height_pos_deg,
                                                   f[1] - tension.height_neg_deg))
        print(f"  {name} flats on the sheet's unit: " + (
            "none each way at the other knob's 0" if flats[-1] is None else
            f"{flats[-1][0]:+.2f} / {flats[-1][1]:+.2f} (drawn {tension.height_pos_deg:+.2f} / "
            f"{tension.height_neg_deg:+.2f})"), flush=True)
    judges = [(name, calibrate_sheet_unit(make, drawn, STAGE, seed, config).profile, make)
              for name, make in sample] or [("sheet", result.profile, plant_factory)]
    rows: list[list[FlatRow]] = [[], []]
    for unit, profile, make in judges:
        for i, f in enumerate(flats):
            if f is None:
                continue
            mine = score_flats(profile, i, *moves[i], make, seed)
            rows[i].extend(mine)
            print(f"  unit {unit} phi{i + 1} tip rms deg drawn -> flats (noise): " + "; ".join(
                f"{r.name} {r.drawn_deg:.3f} -> {r.flat_deg:.3f} ({r.noise_deg:.3f})"
                for r in mine), flush=True)
    for i, f in enumerate(flats):
        keep = f is not None and flats_kept(rows[i])
        if keep and f is not None:
            plain[i] = dataclasses.replace(plain[i], flat_height_pos_deg=round(f[0], 2),
                                           flat_height_neg_deg=round(f[1], 2))
        print(f"  phi{i + 1}: {'flats' if keep else 'drawn heights'}")
    print(f"  flat heights: {time.monotonic() - t0:.0f} s")
    return dataclasses.replace(device, knobs=(plain[0], plain[1]))
