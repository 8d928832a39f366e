"""A loaded window the change cut in two gives no suspect, while its slope still counts
(EstimatorOptions.cut_window_drop): wormeyelet 4's phi2 stroke across a +0.5 mm slack read
+5.73 deg where the edge's later ramps read +4.8, and that follow stayed; refusing the whole
ramp (RampOptions.load_drop_fraction) moved coilpipe 1's later phi2 readings through the
knob's slopes (docs/online.md, sessions 27-28)."""

from __future__ import annotations

import pytest
from test_online_load_drop import EDGE_DEG as STROKE_EDGE_DEG
from test_online_load_drop import stroke_with_slack_at

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp, RampOptions, loaded_ramp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
WINDOW_OUT_DEG = 15.0
CUT = 0.9
"""A window whose current fell by 0.9 of its line's rise (the change cut the load path)."""


def ramp(crossing_deg: float, *, slope: float = SLOPE, load_drop: float = 0.0,
         side: int = 1) -> LoadedRamp:
    return LoadedRamp(0, side, crossing_deg + WINDOW_OUT_DEG, LEVEL_A + slope * WINDOW_OUT_DEG,
                      slope, 0.0, 0.0, 200, 0.003, load_drop=load_drop)


def learned(options: EstimatorOptions) -> tuple[EdgeTracker, EdgeTracker]:
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp(EDGE_DEG, side=-1), EDGE_DEG, pos)
    return pos, neg


def test_a_cut_window_beyond_the_gate_gives_no_suspect() -> None:
    pos, neg = learned(EstimatorOptions(cut_window_drop=0.5))
    pos.update(ramp(EDGE_DEG + 5.7, load_drop=CUT), EDGE_DEG, neg)
    assert pos.suspects == []
    assert pos.status()["cut_window_ramps"] == 1


def test_without_the_rule_the_cut_window_is_a_suspect() -> None:
    pos, neg = learned(EstimatorOptions(cut_window_drop=0.0))
    pos.update(ramp(EDGE_DEG + 5.7, load_drop=CUT), EDGE_DEG, neg)
    assert pos.suspects == [pytest.approx(5.7, abs=0.01)]


def test_an_ordinary_window_beyond_the_gate_stays_a_suspect() -> None:
    pos, neg = learned(EstimatorOptions(cut_window_drop=0.5))
    pos.update(ramp(EDGE_DEG + 5.7, load_drop=0.3), EDGE_DEG, neg)
    assert pos.suspects == [pytest.approx(5.7, abs=0.01)]


def test_a_cut_window_still_counts_among_the_knobs_slopes() -> None:
    pos, neg = learned(EstimatorOptions(cut_window_drop=0.5))
    pos.update(ramp(EDGE_DEG + 5.7, slope=1.1 * SLOPE, load_drop=CUT), EDGE_DEG, neg)
    assert pos.recent_slopes[-1] == pytest.approx(1.1 * SLOPE)


def test_a_cut_window_within_the_gate_reads_as_any_ramp() -> None:
    pos, neg = learned(EstimatorOptions(cut_window_drop=0.5))
    pos.update(ramp(EDGE_DEG + 0.5, load_drop=CUT), EDGE_DEG, neg)
    assert pos.last_measurement_deg == pytest.approx(0.5, abs=0.01)


def test_the_ramp_carries_how_far_its_current_fell() -> None:
    cut = loaded_ramp(stroke_with_slack_at(40.0), STROKE_EDGE_DEG, RampOptions())
    ordinary = loaded_ramp(stroke_with_slack_at(None), STROKE_EDGE_DEG, RampOptions())
    assert isinstance(cut, LoadedRamp) and isinstance(ordinary, LoadedRamp)
    assert cut.load_drop > 0.5 > ordinary.load_drop
