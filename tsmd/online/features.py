"""What the motor current shows during ordinary motion: pure functions on arrays.

A *stroke* is one knob's motion between two reversals of its command. When a stroke goes out of
the dead zone, the tendon of that side engages and the direction-signed current climbs the
loaded ramp: current against knob angle is close to a line whose foot is the dead-zone edge. A
slack change moves that line along the knob axis by the change of the edge, a curvature change
also tilts it (more wrap, more friction), so the feature is the line itself, fitted robustly on
a window a few degrees beyond the edge, and the edge is where it crosses a fixed current level
(the level the ramp had at the calibrated edge, learned by the estimator).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Stroke:
    """One knob's samples between two reversals; ``direction`` +1 rising, -1 falling.

    Only samples where the knob moved are kept (standing still shows static friction, not the
    ramp). ``other_deg`` is the other knob's actual angle (the calibration grid's coordinate).
    """

    knob: int
    direction: int
    t_s: Array
    cmd_deg: Array
    pos_deg: Array
    current_A: Array
    other_deg: Array


@dataclass(frozen=True)
class RampOptions:
    """Where and how the loaded ramp is fitted; angles in knob degrees."""

    margin_deg: float = 4.0
    """The window starts this far beyond the expected edge (past the steep engagement)."""
    width_deg: float = 12.0
    """Knob travel the window spans; a stroke that turns back earlier gives no ramp."""
    min_samples: int = 20
    max_lag_deg: float = 3.0
    """|command - position| above this inside the window: the motor does not follow (stall)."""
    spike_sigma: float = 5.0
    """Samples further than this many robust sigmas from the first fit are dropped (spikes)."""


@dataclass(frozen=True)
class LoadedRamp:
    """The direction-signed current over a window of the loaded ramp, as a line.

    ``side`` +1 is the tendon pulled by positive rotation (edge D_pos), -1 the other (D_neg).
    ``u`` is the knob angle signed by ``side`` (distance outward), so the ramp always rises.
    """

    knob: int
    side: int
    u0_deg: float
    current_at_u0_A: float
    slope_A_per_deg: float
    other_deg: float
    t_s: float
    n_samples: int
    noise_A: float

    def current_at(self, knob_deg: float) -> float:
        """The line's current at a knob angle."""
        return self.current_at_u0_A + self.slope_A_per_deg * (self.side * knob_deg - self.u0_deg)

    def crossing_deg(self, level_A: float) -> float:
        """Knob angle where the line crosses ``level_A`` (the edge for that level)."""
        return self.side * (self.u0_deg + (level_A - self.current_at_u0_A) / self.slope_A_per_deg)


@dataclass(frozen=True)
class Rejected:
    """A stroke that gave no feature, and why (one line)."""

    knob: int
    reason: str
    stall: bool = False


def _line(x: Array, y: Array) -> tuple[float, float, Array]:
    """(value at mean x, slope, residuals) of the least-squares line."""
    xm = float(x.mean())
    dx = x - xm
    sxx = float(dx @ dx)
    b = float(dx @ (y - y.mean())) / sxx if sxx > 0 else 0.0
    a = float(y.mean())
    return a, b, y - (a + b * dx)


def loaded_ramp(stroke: Stroke, expected_edge_deg: float,
                options: RampOptions | None = None) -> LoadedRamp | Rejected:
    """The loaded ramp of a stroke that leaves the dead zone beyond ``expected_edge_deg``.

    ``expected_edge_deg`` is the edge of the stroke's side (D_pos for a rising stroke, D_neg
    for a falling one) as the compensation currently has it.
    """
    o = options or RampOptions()
    side = stroke.direction
    u = side * stroke.pos_deg
    start = side * expected_edge_deg + o.margin_deg
    sel = (u >= start) & (u <= start + o.width_deg)
    n = int(np.count_nonzero(sel))
    if n < o.min_samples:
        return Rejected(stroke.knob, f"{n} samples in the loaded window "
                                     f"({start:.1f}..{start + o.width_deg:.1f} deg outward)")
    x = u[sel]
    if float(x.max() - x.min()) < 0.7 * o.width_deg:
        return Rejected(stroke.knob, "the stroke turns back inside the loaded window")
    lag = np.abs(stroke.cmd_deg[sel] - stroke.pos_deg[sel])
    if float(lag.max()) > o.max_lag_deg:
        return Rejected(stroke.knob, f"the motor lags its command by {float(lag.max()):.1f} deg "
                                     "(stalled or blocked)", stall=True)
    y = side * stroke.current_A[sel]
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(x))):
        return Rejected(stroke.knob, "non-finite samples in the loaded window")
    a, b, r = _line(x, y)
    sigma = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    if sigma > 0:
        keep = np.abs(r) <= o.spike_sigma * sigma
        if np.count_nonzero(keep) >= o.min_samples and not keep.all():
            x, y = x[keep], y[keep]
            a, b, r = _line(x, y)
    if not b > 0:
        return Rejected(stroke.knob, "the current does not rise in the loaded window")
    noise = float(np.sqrt(np.mean(r * r))) if r.size else math.nan
    return LoadedRamp(stroke.knob, side, float(x.mean()), a, b,
                      float(np.median(stroke.other_deg[sel])), float(stroke.t_s[sel][-1]),
                      int(x.size), noise)
