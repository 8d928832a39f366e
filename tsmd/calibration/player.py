"""Playing sweeps over a trajectory runner: the runner contract, progress with a time-left
estimate, and a player that tracks where the knobs are and brings them back to 0."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.assemble import KNOB_LABELS
from tsmd.calibration.errors import CalibrationCancelledError, CalibrationError
from tsmd.calibration.protocol import Protocol as SweepProtocol
from tsmd.calibration.protocol import Sweep, SweepRun, return_to_zero, sweep_run
from tsmd.errors import TsmdError
from tsmd.recording import Recording
from tsmd.trajectory import TrajectoryRunner

ProgressCallback = Callable[[float, str], None]
"""Called with the overall fraction done (0..1) and a line such as
``"sweep 3/14: phi1 sweep, phi2 at -30 deg; 412 s left"``."""


def sweep_metadata(sweep: Sweep, sweep_start_s: float) -> dict[str, str]:
    """The keys a sweep recording carries so that it can be identified offline."""
    return {
        "calibration_knob": KNOB_LABELS[sweep.knob],
        "calibration_other_deg": repr(float(sweep.other_deg)),
        "calibration_sweep_start_s": repr(float(sweep_start_s)),
        "calibration_amplitude_deg": repr(float(sweep.amplitude_deg)),
        "calibration_waveform": sweep.waveform,
        "calibration_frequency_hz": repr(float(sweep.frequency_hz)),
        "calibration_cycles": repr(float(sweep.cycles)),
    }


class Progress:
    """Turns per-run fractions into overall progress with a time-left estimate; re-sweeps are
    added as they are decided (the total grows)."""

    def __init__(self, callback: ProgressCallback | None, durations_s: Sequence[float]) -> None:
        self.callback = callback
        self.durations = list(durations_s)
        self.planned = len(self.durations)
        self.started = time.monotonic()
        self.index = 0
        self.label = ""
        self.fraction = 0.0

    def begin(self, index: int, label: str) -> None:
        self.index = index
        self.label = label
        self.report(0.0)

    def add(self, duration_s: float) -> int:
        """A re-sweep joins the plan; returns its index."""
        self.durations.append(duration_s)
        return len(self.durations) - 1

    def overall(self, fraction: float) -> float:
        total = float(sum(self.durations)) or 1.0
        done = sum(self.durations[:self.index]) + fraction * self.durations[self.index]
        return min(1.0, done / total)

    def report(self, fraction: float, phase: str = "") -> None:
        self.fraction = fraction
        if self.callback is None:
            return
        overall = self.overall(fraction)
        elapsed = time.monotonic() - self.started
        if self.index < self.planned:
            text = f"sweep {self.index + 1}/{self.planned}: {self.label}"
        else:
            text = f"re-sweep {self.index + 1 - self.planned}: {self.label}"
        if phase:
            text += f" ({phase})"
        if overall > 1e-3:
            text += f"; {elapsed * (1.0 - overall) / overall:.0f} s left"
        self.callback(overall, text)


class Player:
    """Plays sweeps one after the other over the runner and tracks where the knobs are."""

    def __init__(self, runner: TrajectoryRunner, proto: SweepProtocol, period_s: float,
                 cancel: threading.Event | None) -> None:
        self.runner = runner
        self.proto = proto
        self.period_s = period_s
        self.cancel = cancel
        self.q_last = np.zeros(2)
        self.motion_s = 0.0
        self.at_zero = True

    def play(self, sweep: Sweep, what: str, tracker: Progress,
             run: SweepRun | None = None) -> Recording:
        """Run one sweep from where the knobs are (re-planned unless ``run`` is given); the
        recording carries the sweep's metadata."""
        cancel = self.cancel
        if cancel is not None and cancel.is_set():
            raise CalibrationCancelledError(f"cancelled before {what}")
        run = run or sweep_run(sweep, self.q_last, self.period_s, self.proto)
        self.at_zero = False
        try:
            rec = self.runner.run(run.t_s, run.q_deg, False, cancel, tracker.report)
        except TsmdError as exc:
            self.q_last = _where_now(self.runner, run.q_deg, tracker.fraction)
            if cancel is not None and cancel.is_set():
                raise CalibrationCancelledError(
                    f"cancelled during {what} ({sweep.label})") from None
            raise CalibrationError(f"{sweep.label}: {exc}") from None
        self.motion_s += len(rec) * self.period_s
        self.q_last = _last_command(rec, run.q_deg)
        if cancel is not None and cancel.is_set():
            raise CalibrationCancelledError(f"cancelled during {what} ({sweep.label})")
        if len(rec) < len(run.q_deg):
            raise CalibrationError(f"{sweep.label}: the runner stopped after "
                                   f"{len(rec)} of {len(run.q_deg)} ticks")
        t0 = float(rec["t"][0]) - float(run.t_s[0])
        rec.metadata.update(sweep_metadata(sweep, t0 + float(run.t_s[run.sweep_start])))
        tracker.report(1.0, "identifying")
        return rec

    def return_to_zero(self) -> None:
        """Bring the knobs back to 0 once (never cancelled: this is the safe end)."""
        if not self.at_zero:
            self.motion_s += _return_to_zero(self.runner, self.q_last, self.period_s)
            self.at_zero = True


def _last_command(rec: Recording, planned: NDArray[np.float64]) -> NDArray[np.float64]:
    """Where the knobs were last sent (from the recording; the plan's start if it is empty)."""
    if len(rec) == 0:
        return np.asarray(planned[0], dtype=float).copy()
    last = np.array([rec["cmd1"][-1], rec["cmd2"][-1]], dtype=float)
    if not np.all(np.isfinite(last)):
        last = np.array([rec["pos1"][-1], rec["pos2"][-1]], dtype=float)
    return last


def _where_now(runner: TrajectoryRunner, planned: NDArray[np.float64],
               fraction: float) -> NDArray[np.float64]:
    """Where the knobs were last commanded when a run ended without a recording: the loop's
    latest sample when the runner exposes its loop, else the plan at the last progress."""
    sample = getattr(getattr(runner, "loop", None), "latest_sample", None)
    cmd = getattr(sample, "cmd_deg", None)
    if cmd is not None and np.all(np.isfinite(np.asarray(cmd, dtype=float))):
        return np.asarray(cmd, dtype=float).copy()
    k = min(len(planned) - 1, max(0, round(fraction * len(planned))))
    return np.asarray(planned[k], dtype=float).copy()


def _return_to_zero(runner: TrajectoryRunner, q_deg: NDArray[np.float64],
                    period_s: float) -> float:
    """Smoothly bring both knobs back to 0 (never cancelled: this is the safe end)."""
    t, q = return_to_zero(q_deg, period_s)
    runner.run(t, q, False, None, None)
    return len(q) * period_s
