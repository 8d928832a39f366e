"""Calibration from motor current: protocol, identification, quality checks, profile, report.

``calibrate(runner, catheter_id, device, progress=..., cancel=...)`` runs the protocol over a
trajectory runner and returns the profile (the caller saves it); ``identify_sweep`` is the pure
identification of one sweep; ``calibrate_from_recordings`` identifies logged sweeps offline.
"""

from tsmd.calibration.assemble import GridPoint, QualityLimits, check_quality
from tsmd.calibration.errors import CalibrationCancelledError, CalibrationError
from tsmd.calibration.identify import IdentifyOptions, identify_sweep
from tsmd.calibration.protocol import Protocol, Sweep, fast_protocol, paper_protocol
from tsmd.calibration.run import (
    Calibration,
    calibrate,
    calibrate_from_recordings,
    identify_recording,
    run_calibration,
)
from tsmd.calibration.sweep_result import SweepResult

__all__ = [
    "Calibration", "CalibrationCancelledError", "CalibrationError", "GridPoint", "IdentifyOptions",
    "Protocol", "QualityLimits", "Sweep", "SweepResult", "calibrate",
    "calibrate_from_recordings", "check_quality", "fast_protocol", "identify_recording",
    "identify_sweep", "paper_protocol", "run_calibration",
]
