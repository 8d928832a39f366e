"""Cutting one knob's samples into strokes at the reversals of its command."""

from __future__ import annotations

import numpy as np

from tsmd.online.features import Stroke


class StrokeSegmenter:
    """Collects one knob's moving samples and returns a :class:`Stroke` at each reversal.

    A reversal is the command turning back by more than ``reversal_deg`` from its extreme (so
    noise in a standing command is not one). Samples are kept only when the knob moved by at
    least ``min_step_deg`` since the last kept one; a stroke longer than ``max_samples`` keeps
    its last samples. Each sample carries the knob's travel since it last stood still (moved
    at most ``still_step_deg`` per sample for ``still_s``) or reversed (``Stroke.slip_deg``).
    """

    def __init__(self, knob: int, reversal_deg: float = 1.0, min_step_deg: float = 0.05,
                 max_samples: int = 20000, still_s: float = 0.05,
                 still_step_deg: float = 1e-3) -> None:
        self.knob = knob
        self.still_s = still_s
        self.still_step_deg = still_step_deg
        self._last_pos = float("nan")
        self._last_t = float("nan")
        self._still_s = 0.0
        self.reversal_deg = reversal_deg
        self.min_step_deg = min_step_deg
        self.max_samples = max_samples
        self._direction = 0
        self._extreme = float("nan")
        self._rows: list[tuple[float, float, float, float, float, float]] = []
        self._slip_deg = 0.0

    def _dt(self, t_s: float) -> float:
        dt = t_s - self._last_t
        return dt if dt == dt and dt > 0.0 else 0.0

    def discard(self) -> None:
        """Forget the stroke in progress (a fault, a gap in the samples)."""
        self._direction = 0
        self._extreme = float("nan")
        self._rows = []
        self._slip_deg = 0.0

    def push(self, t_s: float, cmd_deg: float, pos_deg: float, current_A: float,
             other_deg: float) -> Stroke | None:
        done = None
        if self._extreme != self._extreme:  # NaN: first sample
            self._extreme = cmd_deg
        d = self._direction
        if d == 0:
            if abs(cmd_deg - self._extreme) > self.reversal_deg:
                self._direction = 1 if cmd_deg > self._extreme else -1
                self._extreme = cmd_deg
        elif d * (cmd_deg - self._extreme) >= 0.0:
            self._extreme = cmd_deg
        elif d * (self._extreme - cmd_deg) > self.reversal_deg:
            if len(self._rows) >= 2:
                a = np.asarray(self._rows, dtype=float)
                done = Stroke(self.knob, d, a[:, 0], a[:, 1], a[:, 2], a[:, 3], a[:, 4],
                              a[:, 5])
            self._rows = []
            self._slip_deg = 0.0
            self._direction = -d
            self._extreme = cmd_deg
        step = abs(pos_deg - self._last_pos) if self._last_pos == self._last_pos else 0.0
        self._last_pos = pos_deg
        if step <= self.still_step_deg:
            self._still_s += self._dt(t_s)
        else:
            if self._still_s >= self.still_s:
                self._slip_deg = 0.0  # it stood still: the handle sticks again
            self._still_s = 0.0
            self._slip_deg += step
        self._last_t = t_s
        rows = self._rows
        if not rows:
            rows.append((t_s, cmd_deg, pos_deg, current_A, other_deg, 0.0))
        elif abs(pos_deg - rows[-1][2]) >= self.min_step_deg:
            rows.append((t_s, cmd_deg, pos_deg, current_A, other_deg, self._slip_deg))
            if len(rows) > self.max_samples:
                del rows[: len(rows) - self.max_samples]
        return done
