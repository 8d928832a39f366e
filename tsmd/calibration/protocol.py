"""Calibration protocols: which sweeps to run, and the knob trajectories that run them.

The paper's protocol: for each knob, a sinusoidal sweep over +-90 deg at 0.04 Hz, two cycles,
with the other knob held at each of -90..90 deg in 30 deg steps (2 x 7 x 50 s = 700 s of
sweeping). Each sweep starts at -A (reached moving down, so the first rise follows a reversal)
and the knob is sent there by a smooth move; repositioning moves are not counted as sweeping.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.errors import CalibrationError

GRID_DEG: tuple[float, ...] = (-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0)
WAVEFORMS: tuple[str, ...] = ("sine", "triangle", "two-speed")
TWO_SPEED_SLOW_BAND_DEG = 35.0
"""two-speed: slow within +-35 deg (the dead-zone edges)..."""
TWO_SPEED_REVERSAL_BAND_DEG = 10.0
"""... and within 10 deg of each reversal (the backlash transient) ..."""
TWO_SPEED_RATIO = 3.0
"""... and this many times faster in between (where the current only follows the load)."""


@dataclass(frozen=True)
class Sweep:
    """One knob swept between -A and +A while the other knob is held at ``other_deg``."""

    knob: int
    """0 for phi1, 1 for phi2."""
    other_deg: float
    amplitude_deg: float = 90.0
    frequency_hz: float = 0.04
    cycles: float = 2.0
    waveform: str = "sine"

    @property
    def duration_s(self) -> float:
        return self.cycles / self.frequency_hz

    @property
    def label(self) -> str:
        return f"phi{self.knob + 1} sweep, phi{2 - self.knob} at {self.other_deg:+.0f} deg"

    def position_deg(self, t_s: NDArray[np.float64]) -> NDArray[np.float64]:
        """Knob angle over the sweep, starting and (for whole cycles) ending at -A."""
        phase = (self.frequency_hz * t_s) % 1.0
        if self.waveform == "sine":
            return np.asarray(-self.amplitude_deg * np.cos(2 * np.pi * phase), dtype=float)
        if self.waveform == "two-speed":
            x, cum = _two_speed_stroke(self.amplitude_deg)
            up = np.interp(2.0 * phase, cum, x)
            down = -np.interp(2.0 * phase - 1.0, cum, x)
            return np.asarray(np.where(phase < 0.5, up, down), dtype=float)
        tri = np.where(phase < 0.5, 4.0 * phase - 1.0, 3.0 - 4.0 * phase)
        return np.asarray(self.amplitude_deg * tri, dtype=float)


def _two_speed_stroke(amplitude_deg: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One stroke -A..A as (angle, fraction of the stroke's time): slow near the dead-zone
    edges and the reversals, ``TWO_SPEED_RATIO`` times faster in between."""
    x = np.linspace(-amplitude_deg, amplitude_deg, 4001)
    slow = (np.abs(x) < TWO_SPEED_SLOW_BAND_DEG) | (
        np.abs(x) > amplitude_deg - TWO_SPEED_REVERSAL_BAND_DEG)
    dt = np.where(slow, 1.0, 1.0 / TWO_SPEED_RATIO)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (dt[1:] + dt[:-1]) * np.diff(x))])
    return x, cum / cum[-1]


RESCUE_BUDGET_S = 100.0
"""Six one-cycle re-sweeps of the fast protocol (0.06 Hz): what a calibration may add to avoid
a refusal (screwrod, session 13: half-cycles 4 deg apart refused 2 of 4 healthy units with no
re-sweep of the refused points, the budget spent elsewhere)."""


@dataclass(frozen=True)
class Protocol:
    """An ordered list of sweeps plus how the knobs move between them."""

    name: str
    sweeps: tuple[Sweep, ...]
    move_speed_deg_s: float = 45.0
    settle_s: float = 0.5
    resweep_cycles: float = 2.0
    """Cycles of a re-sweep of a grid point whose estimates are too uncertain."""
    resweep_budget_s: float = 0.0
    """Extra sweeping allowed for re-sweeps, in seconds (0: none)."""
    rescue_budget_s: float = RESCUE_BUDGET_S
    """Sweeping beyond ``resweep_budget_s``, spent only on grid points whose uncertainty would
    otherwise refuse the calibration: a refused healthy catheter leaves the robot unusable, a
    minute more of sweeping does not."""

    def resweep(self, sweep: Sweep) -> Sweep:
        """The sweep that measures ``sweep``'s grid point again."""
        return dataclasses.replace(sweep, cycles=self.resweep_cycles)

    @property
    def max_sweep_time_s(self) -> float:
        """Sweeping including the whole re-sweep budget: the protocol's worst case for a catheter
        it accepts without the rescue budget (spent only where a refusal would follow)."""
        return self.sweep_time_s + self.resweep_budget_s

    @property
    def sweep_time_s(self) -> float:
        """Time spent sweeping (what the paper's 700 s counts)."""
        return float(sum(s.duration_s for s in self.sweeps))

    def validate(self, limits_deg: tuple[tuple[float, float], tuple[float, float]]) -> None:
        """Refuse a protocol that would command a knob outside its limits."""
        if not self.sweeps:
            raise CalibrationError(f"protocol {self.name!r} has no sweeps")
        for s in self.sweeps:
            if s.knob not in (0, 1):
                raise CalibrationError(f"{s.label}: knob must be 0 or 1")
            if s.waveform not in WAVEFORMS:
                raise CalibrationError(f"{s.label}: waveform {s.waveform!r} not in {WAVEFORMS}")
            if not (s.frequency_hz > 0 and s.cycles >= 1 and s.amplitude_deg > 0):
                raise CalibrationError(f"{s.label}: frequency, cycles and amplitude must be > 0")
            lo, hi = limits_deg[s.knob]
            if -s.amplitude_deg < lo or s.amplitude_deg > hi:
                raise CalibrationError(
                    f"{s.label}: +-{s.amplitude_deg:g} deg exceeds the knob limits [{lo}, {hi}]")
            olo, ohi = limits_deg[1 - s.knob]
            if not olo <= s.other_deg <= ohi:
                raise CalibrationError(
                    f"{s.label}: the other knob at {s.other_deg:g} deg is outside [{olo}, {ohi}]")


def paper_protocol(grid_deg: tuple[float, ...] = GRID_DEG,
                   amplitude_deg: float = 90.0) -> Protocol:
    """The published protocol: sine, 0.04 Hz, two cycles, each knob at each grid point."""
    sweeps = tuple(Sweep(knob, other, amplitude_deg, 0.04, 2.0, "sine")
                   for knob in (0, 1) for other in grid_deg)
    # Re-sweeps (beyond the paper): up to four grid points measured again, two cycles each.
    return Protocol("paper", sweeps, resweep_cycles=2.0, resweep_budget_s=200.0)


FAST_GRID_DEG: tuple[float, ...] = (-90.0, 0.0, 90.0)
FAST_MAX_SWEEP_S = 700.0 / 3.0
"""The fast protocol's sweeping, re-sweeps included, stays within a third of the paper's."""


def fast_protocol(grid_deg: tuple[float, ...] = FAST_GRID_DEG, amplitude_deg: float = 90.0,
                  frequency_hz: float = 0.06, cycles: float = 2.0) -> Protocol:
    """Beyond the paper: fewer sweeps, a little faster: the paper's sine at 0.06 Hz (1.5x),
    two cycles, with the other knob at -90, 0 and +90 deg only (6 sweeps, 200 s of sweeping);
    re-sweeps of one cycle fill the rest of a third of the paper's 700 s (two of them). The
    profile interpolates D and B over the other knob's angle between the three grid points as
    it does between the paper's seven.

    Why not simply faster sweeps: the backlash end is a slanted join of the current to its
    release level, read over the 25-30 deg after each reversal; the faster the knob speeds up
    through it, the more the motor's speed-dependent friction tilts that level, and B scatters
    (sine at 0.125 Hz over the paper's grid: B off the tip by up to 5.3 deg; the two-speed
    waveform, slow at the edges and reversals and 3x faster between, steps the current inside
    the backlash: 6 deg early). Two cycles keep the agreement check on every parameter.
    """
    sweeps = tuple(Sweep(knob, other, amplitude_deg, frequency_hz, cycles, "sine")
                   for knob in (0, 1) for other in grid_deg)
    sweeping = sum(s.duration_s for s in sweeps)
    return Protocol("fast", sweeps, resweep_cycles=1.0,
                    resweep_budget_s=max(0.0, FAST_MAX_SWEEP_S - sweeping))


PROTOCOLS = {"paper": paper_protocol, "fast": fast_protocol}


def move_trajectory(start_deg: NDArray[np.float64], end_deg: NDArray[np.float64],
                    period_s: float, speed_deg_s: float) -> NDArray[np.float64]:
    """A smooth (raised-cosine) move of both knobs; peak speed at most ``speed_deg_s``."""
    start = np.asarray(start_deg, dtype=float)
    end = np.asarray(end_deg, dtype=float)
    distance = float(np.max(np.abs(end - start)))
    if distance < 1e-9:
        return np.empty((0, 2))
    duration = max(0.5, math.pi / 2 * distance / speed_deg_s)
    n = max(2, math.ceil(duration / period_s))
    s = 0.5 - 0.5 * np.cos(np.pi * np.arange(1, n + 1) / n)
    return np.asarray(start + s[:, None] * (end - start), dtype=float)


@dataclass(frozen=True)
class SweepRun:
    """The trajectory that runs one sweep from wherever the knobs are."""

    sweep: Sweep
    t_s: NDArray[np.float64]
    q_deg: NDArray[np.float64]
    sweep_start: int
    """Index where the sweep proper starts (after the move and settle)."""


def sweep_run(sweep: Sweep, start_deg: NDArray[np.float64], period_s: float,
              protocol: Protocol) -> SweepRun:
    """Move to (+A, other) and down to (-A, other) (or, already at -A, move the other knob
    only), wait ``settle_s``, sweep."""
    first = np.zeros(2)
    first[sweep.knob] = -sweep.amplitude_deg
    first[1 - sweep.knob] = sweep.other_deg
    start = np.asarray(start_deg, dtype=float)
    if abs(start[sweep.knob] + sweep.amplitude_deg) < 1e-6:
        # The previous sweep of this knob ended at -A going down: only the other knob moves.
        parts = [move_trajectory(start, first, period_s, protocol.move_speed_deg_s)]
    else:
        # Precondition: visit +A, then come down to -A. The tendons then have a full loading
        # history (the first stroke after rest differs) and the sweep's first rise follows a
        # reversal. Moves are not identified and not counted as sweeping time.
        top = first.copy()
        top[sweep.knob] = sweep.amplitude_deg
        parts = [move_trajectory(start, top, period_s, protocol.move_speed_deg_s),
                 move_trajectory(top, first, period_s, protocol.move_speed_deg_s)]
    n_settle = round(protocol.settle_s / period_s)
    parts.append(np.repeat(first[None, :], n_settle, axis=0))
    move = np.concatenate(parts)
    n_sweep = round(sweep.duration_s / period_s)
    ts = np.arange(1, n_sweep + 1, dtype=float) * float(period_s)
    sweep_q = np.empty((n_sweep, 2))
    sweep_q[:, sweep.knob] = sweep.position_deg(ts)
    sweep_q[:, 1 - sweep.knob] = sweep.other_deg
    q = np.concatenate([move, sweep_q])
    t = np.arange(1, len(q) + 1, dtype=float) * float(period_s)
    return SweepRun(sweep, t, q, len(move))


def return_to_zero(start_deg: NDArray[np.float64], period_s: float,
                   speed_deg_s: float = 45.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(t, q) of a smooth move of both knobs back to 0 (end of a calibration or a cancel)."""
    q = move_trajectory(np.asarray(start_deg, dtype=float), np.zeros(2), period_s, speed_deg_s)
    if len(q) == 0:
        q = np.zeros((1, 2))
    return np.arange(1, len(q) + 1, dtype=float) * float(period_s), q
