"""A loaded window whose current falls gives no ramp (RampOptions.load_drop_fraction).

A knob moving outward on a loaded tendon only adds load; a fall inside the window is the load
path changing during the stroke (a slack arriving while the tendon is loaded), and the line
through such a window crosses the level far outward of either edge.
"""

from __future__ import annotations

import numpy as np
from support.online import SLOPE_A_PER_DEG, knob_current

from tsmd.online.features import LoadedRamp, RampOptions, Rejected, Stroke, loaded_ramp

EDGE_DEG = 20.0
WITH_RULE = RampOptions(load_drop_fraction=0.5)


def stroke_with_slack_at(change_deg: float | None, moved_edge_deg: float = 30.0, *,
                         seed: int = 0, noise_A: float = 0.003) -> Stroke:
    """A rising stroke over the edge at ``EDGE_DEG``; from ``change_deg`` on the edge lies at
    ``moved_edge_deg`` (the tendon's load collapses there and builds up again)."""
    rng = np.random.default_rng(seed)
    pos = np.arange(-20.0, 60.0, 0.1)
    edges = [EDGE_DEG if change_deg is None or p < change_deg else moved_edge_deg for p in pos]
    cur = np.array([knob_current(p, 10.0, e, -e) for p, e in zip(pos, edges, strict=True)])
    cur += noise_A * rng.standard_normal(pos.size)
    return Stroke(0, 1, np.arange(pos.size) * 0.01, pos, pos, cur, np.zeros(pos.size),
                  pos + 20.0)


def test_a_load_that_collapses_inside_the_window_gives_no_ramp() -> None:
    ramp = loaded_ramp(stroke_with_slack_at(40.0), EDGE_DEG, WITH_RULE)
    assert isinstance(ramp, Rejected)
    assert "falls" in ramp.reason


def test_without_the_rule_the_collapsed_window_is_fitted_as_a_ramp() -> None:
    # off by default: the line through the fall is a ramp of half the tendon's slope
    ramp = loaded_ramp(stroke_with_slack_at(40.0), EDGE_DEG, RampOptions())
    assert isinstance(ramp, LoadedRamp)
    assert ramp.slope_A_per_deg < 0.5 * SLOPE_A_PER_DEG


def test_ordinary_noisy_ramps_are_kept() -> None:
    for seed in range(8):
        ramp = loaded_ramp(stroke_with_slack_at(None, seed=seed, noise_A=0.006), EDGE_DEG,
                           WITH_RULE)
        assert isinstance(ramp, LoadedRamp), seed


def test_single_samples_falling_are_spikes_not_a_collapse() -> None:
    stroke = stroke_with_slack_at(None, seed=3)
    dipped = stroke.current_A.copy()
    dipped[::37] -= 0.3
    ramp = loaded_ramp(Stroke(0, 1, stroke.t_s, stroke.cmd_deg, stroke.pos_deg, dipped,
                              stroke.other_deg, stroke.slip_deg), EDGE_DEG, WITH_RULE)
    assert isinstance(ramp, LoadedRamp)


def test_a_change_before_the_window_is_an_ordinary_ramp() -> None:
    # the slack arrived while the tendon was still slack: the window sees the moved edge only
    ramp = loaded_ramp(stroke_with_slack_at(5.0, moved_edge_deg=24.0), 24.0, WITH_RULE)
    assert isinstance(ramp, LoadedRamp)
