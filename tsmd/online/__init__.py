"""Online re-estimation of the dead-zone edges from motor current during ordinary use.

``OnlineWorker(compensator, period_s, ROW_COLUMNS)`` is the loop's ``observer``; see
docs/online.md for what it estimates from which feature, its bounds and its failure modes.
"""

from tsmd.online.apply import (
    ZERO_OFFSETS,
    Offsets,
    OnlineError,
    profile_with_offsets,
    save_online_version,
    shifted_knob,
)
from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp, RampOptions, Rejected, Stroke, loaded_ramp
from tsmd.online.segment import StrokeSegmenter
from tsmd.online.worker import RECORDING_COLUMNS, OnlineWorker

__all__ = [
    "RECORDING_COLUMNS", "ZERO_OFFSETS", "EdgeTracker", "EstimatorOptions", "LoadedRamp",
    "Offsets", "OnlineError", "OnlineWorker", "RampOptions", "Rejected", "Stroke",
    "StrokeSegmenter", "loaded_ramp", "profile_with_offsets", "save_online_version",
    "shifted_knob",
]
