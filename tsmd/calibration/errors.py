"""Errors the calibration reports to the user instead of saving a wrong profile."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from tsmd.errors import TsmdError

if TYPE_CHECKING:
    from tsmd.calibration.assemble import GridPoint


class CalibrationError(TsmdError):
    """The data cannot give a trustworthy profile; the message says which sweep and why."""


class CalibrationCancelledError(CalibrationError):
    """The user cancelled; the knobs were sent back to 0 and nothing was saved."""


class CalibrationRefusedError(CalibrationError):
    """The sweeps ran but the quality checks refused them; ``points`` keeps what was measured
    (with each sweep's recording) so that the refusal can be examined or re-identified."""

    def __init__(self, message: str, points: Sequence[GridPoint]) -> None:
        super().__init__(message)
        self.points = tuple(points)
