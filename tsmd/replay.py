"""Running a trajectory through the full stack (drives + loop) and recording every tick.

Two :class:`tsmd.trajectory.TrajectoryRunner` implementations, used by replay, the accuracy
benchmark and the calibration: :class:`LockstepRunner` builds the in-process simulated rig and
ticks the loop in lockstep with the rig's SimClock (deterministic, much faster than real time);
:class:`LiveTrajectoryRunner` hands the trajectory to the running daemon's loop, which plays
it one sample per tick in real time. Both return a :class:`tsmd.recording.Recording`.
"""

from __future__ import annotations

import math
import threading

import numpy as np
from numpy.typing import ArrayLike, NDArray

from simrig.plant import Plant
from tsmd import __version__
from tsmd.compensation import METHODS
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.errors import TsmdError
from tsmd.loop import ROW_COLUMNS, ControlLoop, LoopError, Playback
from tsmd.profile import CatheterProfile
from tsmd.recording import Recording
from tsmd.stack import build_loop, make_compensator, open_sim
from tsmd.trajectory import ProgressFn


class ReplayError(TsmdError):
    """A trajectory could not be run (bad input, a fault on the way, cancelled)."""


def resample(t_s: ArrayLike, q_deg: ArrayLike, period_s: float
             ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The trajectory at the loop's tick times ``t0 + k * period`` (linear interpolation)."""
    t = np.asarray(t_s, dtype=float)
    q = np.asarray(q_deg, dtype=float)
    if t.ndim != 1 or t.size < 1:
        raise ReplayError("trajectory: t_s must be a non-empty 1-D array")
    if q.shape != (t.size, 2):
        raise ReplayError(f"trajectory: q_deg must have shape ({t.size}, 2), got {q.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q))):
        raise ReplayError("trajectory: t_s and q_deg must be finite")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        raise ReplayError("trajectory: t_s must be strictly increasing")
    n = math.floor((t[-1] - t[0]) / period_s + 1e-9) + 1
    ticks = t[0] + np.arange(n) * period_s
    if t.size == 1:
        return ticks, q.copy()
    out = np.column_stack([np.interp(ticks, t, q[:, j]) for j in range(2)])
    return ticks, out


def rows_to_recording(rows: NDArray[np.float64], t_ticks: NDArray[np.float64],
                      metadata: dict[str, str]) -> Recording:
    """A playback's table (:meth:`Playback.table`) as a recording whose ``t`` is the
    trajectory's own time; one copy, column by column contiguous."""
    table = np.asarray(rows, dtype=float).reshape(-1, len(ROW_COLUMNS))
    data = table[:, 1:].T.copy()  # the loop's own time (column 0) is replaced by the ticks'
    columns = {name: data[j] for j, name in enumerate(ROW_COLUMNS[1:])}
    return Recording({"t": t_ticks[: len(table)].copy(), **columns}, metadata)


CONDITION_KEYS: tuple[str, ...] = ("segments", "configuration", "sheath_shape", "catheter")
"""Trajectory header keys describing the conditions of the run; a replay copies them into its
recording (``tsmd gap`` reads them)."""


def carry_conditions(trajectory: Recording, recording: Recording) -> None:
    """Copy the trajectory's condition headers and, when it has one, its ``segment`` column
    onto the recording's rows (the label of the last trajectory sample at or before each
    row's time): a protocol played on the rig comes back labelled (in place)."""
    for key in CONDITION_KEYS:
        if trajectory.metadata.get(key, "").strip():
            recording.metadata[key] = trajectory.metadata[key]
    if "segment" not in trajectory.columns:
        return
    t_traj = trajectory["t"]
    idx = np.searchsorted(t_traj, recording["t"] + 1e-9, side="right") - 1
    label = trajectory["segment"][np.clip(idx, 0, len(t_traj) - 1)]
    recording.columns["segment"] = np.where(idx >= 0, label, -1.0)


class LockstepRunner:
    """The full stack on the in-process simulated rig, ticked in lockstep (deterministic).

    The rig and the loop live as long as the runner: consecutive runs continue from where the
    knobs are, as on the device (calibration runs many sweeps back to back).
    """

    def __init__(self, config: TsmdConfig | None = None, profile: CatheterProfile | None = None,
                 method: str = "none", seed: int = 0, plant: Plant | None = None) -> None:
        self.config = config if config is not None else default_sim_config()
        cfg = self.config
        if method not in METHODS:
            raise ReplayError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        if method != "none" and profile is None:
            raise ReplayError(f"method {method!r} needs a catheter profile")
        self.method = method
        self.profile = profile
        self.seed = seed
        self.drives, self.rig = open_sim(cfg, seed, lockstep=True, plant=plant)
        self.loop = build_loop(cfg, self.drives, make_compensator(profile, method, cfg),
                               self.rig.clock, compensation_label=method,
                               tip_source=self.rig.tip_pair, after_sync=self.rig.exchange)
        try:
            self.drives.boot()
            self.loop.tick()
            self.loop.execute("enable")
        except (LoopError, TsmdError) as exc:
            self.close()
            raise ReplayError(f"the simulated rig did not start: {exc}") from None

    @property
    def period_s(self) -> float:
        return self.loop.period_s

    def run(self, t_s: ArrayLike, q_deg: ArrayLike, compensate: bool,
            cancel: threading.Event | None = None,
            progress: ProgressFn | None = None) -> Recording:
        loop = self.loop
        ticks, q = resample(t_s, q_deg, loop.period_s)
        if loop.state.value != "ENABLED":
            raise ReplayError(f"the loop is {loop.state.value} ({loop.fault_reason})")
        playback = Playback(q, compensate and self.method != "none", cancel)
        loop.execute("play", playback=playback)
        every = max(len(q) // 100, 1)
        while not playback.done.is_set():
            loop.step()
            if progress is not None and playback.index % every == 0:
                progress(playback.progress)
        return self._finish(playback, ticks)

    def _finish(self, playback: Playback, ticks: NDArray[np.float64]) -> Recording:
        if playback.error is not None and playback.error != "cancelled":
            raise ReplayError(f"trajectory stopped after {playback.index} of "
                              f"{len(playback.q_deg)} ticks: {playback.error}")
        meta = {"source": "tsmd replay (lockstep sim)", "version": __version__,
                "rate_hz": f"{1.0 / self.loop.period_s:g}",
                "compensation": self.method if playback.compensate else "none",
                "profile": str(getattr(self.profile, "catheter_id", "none")),
                "seed": str(self.seed), "plant": self.config.sim.plant}
        if playback.error == "cancelled":
            meta["cancelled"] = "true"
        return rows_to_recording(playback.table(), ticks, meta)

    def close(self) -> None:
        for obj in (self.drives, self.rig):
            close = getattr(obj, "close", None)
            if close is not None:
                close()

    def __enter__(self) -> LockstepRunner:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def run_trajectory(t_s: ArrayLike, q_deg: ArrayLike, *, config: TsmdConfig | None = None,
                   profile: CatheterProfile | None = None, method: str = "none", seed: int = 0,
                   plant: Plant | None = None) -> Recording:
    """Run one trajectory in lockstep on a fresh simulated rig and return its recording."""
    with LockstepRunner(config, profile, method, seed, plant) as runner:
        return runner.run(t_s, q_deg, compensate=method != "none")


class LiveTrajectoryRunner:
    """Plays trajectories on the daemon's running loop (real time), for calibration."""

    def __init__(self, loop: ControlLoop, poll_s: float = 0.05) -> None:
        self.loop = loop
        self.poll_s = poll_s

    @property
    def period_s(self) -> float:
        return self.loop.period_s

    def run(self, t_s: ArrayLike, q_deg: ArrayLike, compensate: bool,
            cancel: threading.Event | None = None,
            progress: ProgressFn | None = None) -> Recording:
        loop = self.loop
        ticks, q = resample(t_s, q_deg, loop.period_s)
        playback = Playback(q, compensate, cancel)
        try:
            loop.post("play", playback=playback).result(timeout=5.0)
        except LoopError as exc:
            raise ReplayError(str(exc)) from None
        while not playback.done.wait(self.poll_s):
            if progress is not None:
                progress(playback.progress)
        if playback.error is not None and playback.error != "cancelled":
            raise ReplayError(f"trajectory stopped after {playback.index} of {len(q)} ticks: "
                              f"{playback.error}")
        meta = {"source": "tsmd daemon (live)", "version": __version__,
                "rate_hz": f"{1.0 / loop.period_s:g}",
                "compensation": loop.compensation_label if compensate else "none"}
        if playback.error == "cancelled":
            meta["cancelled"] = "true"
        return rows_to_recording(playback.table(), ticks, meta)
