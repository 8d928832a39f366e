"""The product's hold at home (``hold_at_home``), chosen on the data sheet's own unit by its tip.

Method ours moves a resting knob's command when the other knob moves its branches (a level
grid or an edge share shifts the loaded branch with the other knob's angle). Where the other
plane's load holds the resting tip where it was (pronyring's ring seat, its friction grown with
the other ropes' load) that follow pulls a rope whose tip does not move, and the hold
(:func:`tsmd.compensation.ours._keep_at_home`) keeps the command; where the tip does follow
(jawcrimp development 1, session 26: two rows 0.05 deg worse with the hold) it must not. So
no setting holds for every product, and which one a product needs is seen on the sheet's unit,
tracked: calibrated under the sheet as every unit is, it plays the rows where one knob rests at
0 while the other sweeps (the paper's 1-DOF periodic and non-periodic rows, conditioned as the
bench plays them) once with the resting knob's hold off and once on, everything else the
same. The tip's error of both planes counts: the resting knob's own, and what its rope does to
the moving plane through the shared sheath. A knob takes the hold where in every row neither
plane's error rises by more than the row's seed noise (the same row without the hold played
once more with the next noise seed: how far that plane's error moves by chance) and their
squared sum falls: no margin is tuned, and a hold that never fires changes nothing and stays
off. Without the noise a rise of 1e-4 deg decided (planetwist unit 0's phi2 at rest, its moving
plane 2.052 -> 2.052). A rule on the sum alone would trade: on unit 0 the hold brought
pronyring's resting phi1 2.40 -> 1.09 deg while the moving phi2 went 2.71 -> 2.94, and
jawcrimp's resting phi2 2.13 -> 1.64 while phi1 went 1.30 -> 1.35, the very rows (the moving
plane's) that development units lost with the hold in session 26.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from simrig.plant import Plant
from tsmd.config import TsmdConfig
from tsmd.datasheet_unit_run import SHEET_UNIT_SEED, calibrate_sheet_unit
from tsmd.errors import TsmdError
from tsmd.profile import CatheterProfile, DeviceModel
from tsmd.replay import run_trajectory
from tsmd.tracking_scenarios import Scenario, conditioned, scenarios

STAGE = "home hold"


@dataclass(frozen=True)
class RestRow:
    """One row with this knob at rest at 0: the tip's RMS error per plane (resting knob's,
    moving knob's), deg, with the hold off and on."""

    name: str
    rest_off_deg: float
    rest_on_deg: float
    moving_off_deg: float
    moving_on_deg: float
    rest_noise_deg: float = 0.0
    """How far the resting plane's error moves with the next noise seed (hold off)."""
    moving_noise_deg: float = 0.0

    @property
    def mse_change(self) -> float:
        """Both planes' mean squared error with the hold less without it (negative: better)."""
        return (self.rest_on_deg ** 2 + self.moving_on_deg ** 2
                - self.rest_off_deg ** 2 - self.moving_off_deg ** 2)

    @property
    def costs_nothing(self) -> bool:
        """Neither plane's error rises beyond its seed noise and their squared sum falls."""
        return (self.rest_on_deg - self.rest_off_deg <= self.rest_noise_deg
                and self.moving_on_deg - self.moving_off_deg <= self.moving_noise_deg
                and self.mse_change < 0.0)


@dataclass(frozen=True)
class HomeHoldScore:
    """One knob's rows at rest on the sheet's unit."""

    knob: int
    rows: tuple[RestRow, ...]

    @property
    def chosen(self) -> bool:
        return bool(self.rows) and all(r.costs_nothing for r in self.rows)

    def text(self) -> str:
        rows = "; ".join(f"{r.name}: resting {r.rest_off_deg:.3f} -> {r.rest_on_deg:.3f} "
                         f"(seed noise {r.rest_noise_deg:.3f}), moving {r.moving_off_deg:.3f} -> "
                         f"{r.moving_on_deg:.3f} ({r.moving_noise_deg:.3f})" for r in self.rows)
        return f"tip rms deg without -> with the hold, {rows} -> {'on' if self.chosen else 'off'}"


def rest_rows(knob: int) -> list[Scenario]:
    """The paper's quick rows where ``knob`` rests at 0 while the other knob moves."""
    return [s for s in scenarios(True)
            if s.knobs == (1 - knob,) and not np.any(s.q_deg[:, knob])]


def with_hold(profile: CatheterProfile, on: tuple[bool, bool]) -> CatheterProfile:
    """The unit's profile with each knob's hold as ``on`` says."""
    knobs = []
    for k, o in zip(profile.knobs, on, strict=True):
        if k.tension_play is None:
            raise TsmdError(f"{STAGE}: the sheet's unit has no parameters for method ours")
        knobs.append(dataclasses.replace(
            k, tension_play=dataclasses.replace(k.tension_play, hold_at_home=o)))
    return dataclasses.replace(profile, knobs=(knobs[0], knobs[1]))


def tip_rms(profile: CatheterProfile, s: Scenario, plant: Plant, seed: int
            ) -> NDArray[np.float64]:
    """Both planes' RMS tip error of ours on ``s``, conditioned as the bench plays it."""
    tt, qq, skip = conditioned(s.t_s, s.q_deg, True)
    rec = run_trajectory(tt, qq, profile=profile, method="ours", seed=seed, plant=plant)
    err = np.column_stack([rec["tip1"], rec["tip2"]])[skip:] - qq[skip:]
    return np.sqrt(np.nanmean(err * err, axis=0))


def score_knob(profile: CatheterProfile, knob: int, factory: Callable[[], Plant], seed: int
               ) -> HomeHoldScore:
    """``knob``'s rows at rest played without and with its hold (the other knob's off), and
    without it once more with the next noise seed."""
    plain = with_hold(profile, (False, False))
    held = with_hold(profile, (knob == 0, knob == 1))
    rows = []
    for s in rest_rows(knob):
        off = tip_rms(plain, s, factory(), seed)
        on = tip_rms(held, s, factory(), seed)
        noise = np.abs(tip_rms(plain, s, factory(), seed + 1) - off)
        rows.append(RestRow(f"{s.group} {s.name}", float(off[knob]), float(on[knob]),
                            float(off[1 - knob]), float(on[1 - knob]), float(noise[knob]),
                            float(noise[1 - knob])))
    return HomeHoldScore(knob, tuple(rows))


def measure_home_hold(factory: Callable[[], Plant], device: DeviceModel,
                      seed: int = SHEET_UNIT_SEED, config: TsmdConfig | None = None
                      ) -> tuple[HomeHoldScore, HomeHoldScore]:
    """Both knobs' scores on the sheet's unit calibrated under ``device`` (its hold off)."""
    plain = device.with_knob_flag("hold_at_home", (False, False))
    profile = calibrate_sheet_unit(factory, plain, STAGE, seed, config).profile
    return score_knob(profile, 0, factory, seed), score_knob(profile, 1, factory, seed)


def with_home_hold(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                   seed: int) -> DeviceModel:
    """The sheet with each knob's ``hold_at_home`` where its unit's tip says so."""
    t0 = time.monotonic()
    scores = measure_home_hold(factory, device, seed, config)
    for name, s in zip(("phi1", "phi2"), scores, strict=True):
        print(f"  {name} at rest: {s.text()}")
    print(f"  home hold: {time.monotonic() - t0:.0f} s")
    return device.with_knob_flag("hold_at_home", chosen(scores))


def chosen(scores: Sequence[HomeHoldScore]) -> tuple[bool, bool]:
    return scores[0].chosen, scores[1].chosen
