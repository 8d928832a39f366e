"""Errors the calibration reports to the user instead of saving a wrong profile."""

from __future__ import annotations

from tsmd.errors import TsmdError


class CalibrationError(TsmdError):
    """The data cannot give a trustworthy profile; the message says which sweep and why."""


class CalibrationCancelledError(CalibrationError):
    """The user cancelled; the knobs were sent back to 0 and nothing was saved."""
