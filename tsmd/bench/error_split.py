"""Where ours' tracking error lives: a run's error split by the branch the model is on.

The profile's model (``tension_play``) is fed the knob command each knob played (delayed by the
drive lag the calibration measured, so it stands for the knob's actual angle); at every sample
the model is on one of four parts of its play, and the tracking error (tip minus desired angle,
the simulated tip: diagnosis only) is summed per part:

* ``loaded``: on a branch, beyond the plateau in the direction of motion (a tendon loading);
* ``release``: on a branch, on the near side of the plateau (a tendon giving its load back);
* ``plateau``: on a branch's flat (the dead zone);
* ``backlash``: the output held after a reversal, before the new branch is reached.

Per part: its share of the samples, its share of the mean-square error, and the mean error
*outward* (tip beyond the desired angle, away from the knob's zero: positive means overshoot).
Over the whole run: the model's own error (tip minus model) and the inverse's (model minus
desired). The split says which branch to fix; it never enters a compensator.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.model_parts import PARTS, model_parts
from tsmd.compensation.tension_play_params import TensionPlayParams

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class PartError:
    """One part of the play: share of the samples and of the mean-square error (0..1), and
    the mean outward error (deg)."""

    time_share: float
    mse_share: float
    outward_deg: float


@dataclass(frozen=True)
class ErrorSplit:
    """One knob's tracking error split by the model's part (:data:`PARTS`)."""

    knob: int
    rmse_deg: float
    model_rmse_deg: float
    inverse_rmse_deg: float
    parts: dict[str, PartError]

    def line(self) -> str:
        """One line for a report."""
        parts = "; ".join(f"{name} {100 * p.time_share:.0f} % of time, {100 * p.mse_share:.0f} % "
                          f"of MSE, outward {p.outward_deg:+.2f}"
                          for name, p in self.parts.items() if p.time_share > 0.0)
        return (f"knob {self.knob + 1}: RMSE {self.rmse_deg:.2f} deg (model "
                f"{self.model_rmse_deg:.2f}, inverse {self.inverse_rmse_deg:.2f}); {parts}")


def delayed(x: FloatArray, samples: int) -> FloatArray:
    """``x`` delayed by ``samples`` (the first value held before the start)."""
    if samples <= 0:
        return np.asarray(x, dtype=float)
    return np.concatenate([np.full(samples, float(x[0])), np.asarray(x[:-samples], dtype=float)])


def split_error(desired_deg: FloatArray, tip_deg: FloatArray, model_deg: FloatArray,
                parts: Sequence[str], knob: int) -> ErrorSplit:
    """The split of one knob's error (arrays of one run, same length)."""
    q, tip, y = (np.asarray(a, dtype=float) for a in (desired_deg, tip_deg, model_deg))
    if not len(q) == len(tip) == len(y) == len(parts) or len(q) == 0:
        raise ValueError(f"needs equally long non-empty series, got {len(q)}, {len(tip)}, "
                         f"{len(y)}, {len(parts)}")
    err = tip - q
    total = float(np.sum(err * err))
    labels = np.asarray(parts)
    out: dict[str, PartError] = {}
    for name in PARTS:
        m = labels == name
        if not m.any():
            out[name] = PartError(0.0, 0.0, 0.0)
            continue
        outward = np.where(y[m] >= 0.0, 1.0, -1.0) * err[m]
        out[name] = PartError(float(m.mean()), float(np.sum(err[m] ** 2) / total) if total else 0.0,
                              float(np.mean(outward)))
    return ErrorSplit(knob, float(np.sqrt(np.mean(err * err))),
                      float(np.sqrt(np.mean((tip - y) ** 2))),
                      float(np.sqrt(np.mean((y - q) ** 2))), out)


def split_run(desired_deg: FloatArray, cmd_deg: FloatArray, tip_deg: FloatArray,
              params: Sequence[TensionPlayParams], knobs: Sequence[int],
              period_s: float) -> list[ErrorSplit]:
    """Each scored knob's split for one run (columns: knob 1, knob 2), the model fed each
    knob's command delayed by its profile's drive lag."""
    q, cmd, tip = (np.asarray(a, dtype=float) for a in (desired_deg, cmd_deg, tip_deg))
    x = np.column_stack([delayed(cmd[:, k], round(params[k].lag_s / period_s))
                         for k in (0, 1)])
    out = []
    for k in knobs:
        p = params[k]
        y, parts = model_parts(x[:, k], x[:, 1 - k], p, float(tip[0, k]))
        y = y + p.other_tip_gain * q[:, 1 - k]  # the other plane's share (session 14)
        out.append(split_error(q[:, k], tip[:, k], y, parts, k))
    return out
