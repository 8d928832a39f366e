"""The profile types: what calibration identified for one catheter (the data sheet it starts from
is :mod:`tsmd.profile.device`)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from tsmd.compensation.grid import CALIBRATION_GRID_DEG
from tsmd.compensation.paper import at_other_knob_zero, plateau_heights
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.errors import TsmdError
from tsmd.profile.device import DeviceKnob, ReferencePoint

PROFILE_SCHEMA_VERSION = 1
KNOB_NAMES: tuple[str, str] = ("phi1", "phi2")
ANGLE_RANGE_DEG = 360.0
"""Every angle in a profile (knob or tip) must lie within +-ANGLE_RANGE_DEG: a larger value is
almost certainly in the wrong unit (radians are caught by the omega and range checks instead)."""
OMEGA_RANGE: tuple[float, float] = (0.2, 5.0)
"""Plausible tip-per-knob slopes; outside this the value is a unit or sign mistake."""
ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")
class ProfileError(TsmdError, ValueError):
    """A profile or device model is missing, malformed or implausible; the message says why."""


@dataclass(frozen=True)
class KnobProfile:
    """What calibration identified for one knob, over the other knob's angle."""

    omega: float
    reference_pos: ReferencePoint
    reference_neg: ReferencePoint
    height_pos_deg: float
    height_neg_deg: float
    other_knob_deg: tuple[float, ...]
    dead_zone_pos_deg: tuple[float, ...]
    dead_zone_neg_deg: tuple[float, ...]
    backlash_pos_deg: tuple[float, ...]
    backlash_neg_deg: tuple[float, ...]
    tension_play: TensionPlayParams | None = None
    """The parameters of method ``ours`` (None: calibrated by an older tsmd)."""
    paper: KnobProfile | None = None
    """The same knob as the paper's compensator is fed, where that differs from the reported
    values (session 27): D and B read in our fit's frame (reading offsets of
    ``MODEL_MIN_OFFSET_DEG`` and more), H drawn through that D(0). The reported values take
    every sure offset, however small: right for the tip's 1 deg threshold, but on a rounded knee
    and a gradual release they carry the paper's straight lines away from the tip (warmgear
    development 1-2: 19 of 22 rows worse). None: the reported values."""

    def for_paper(self) -> KnobProfile:
        """The knob as the paper's compensator takes it (:attr:`paper`, else this one)."""
        return self.paper if self.paper is not None else self

    def grid_array(self) -> np.ndarray:
        """(n, 4) array: D_pos, D_neg, B_pos, B_neg per grid point."""
        return np.column_stack([self.dead_zone_pos_deg, self.dead_zone_neg_deg,
                                self.backlash_pos_deg, self.backlash_neg_deg]).astype(float)


@dataclass(frozen=True)
class CatheterProfile:
    """One catheter's calibration: everything the compensators need."""

    catheter_id: str
    device_model: str
    calibrated_at: str
    software_version: str
    interpolation: str
    knobs: tuple[KnobProfile, KnobProfile]
    source: str = "calibration"
    quality: dict[str, float] = field(default_factory=dict)
    schema_version: int = PROFILE_SCHEMA_VERSION


def standard_grid() -> tuple[float, ...]:
    """The paper's calibration grid of the other knob's angle."""
    return CALIBRATION_GRID_DEG


def make_knob_profile(device_knob: DeviceKnob, other_knob_deg: Sequence[float],
                      dead_zone_pos_deg: Sequence[float], dead_zone_neg_deg: Sequence[float],
                      backlash_pos_deg: Sequence[float], backlash_neg_deg: Sequence[float],
                      tension_play: TensionPlayParams | None = None) -> KnobProfile:
    """A knob's profile from identified grids and the data sheet.

    H_pos/H_neg follow design assumptions 1-3: the line of slope omega through the reference point
    (other knob at 0 deg) meets the dead-zone edge D(0) at height H; H is then constant.
    """
    k = device_knob
    h_pos, h_neg = plateau_heights(k, at_other_knob_zero(other_knob_deg, dead_zone_pos_deg),
                                   at_other_knob_zero(other_knob_deg, dead_zone_neg_deg))

    def floats(values: Sequence[float]) -> tuple[float, ...]:
        return tuple(float(v) for v in values)

    return KnobProfile(k.omega, k.reference_pos, k.reference_neg, float(h_pos), float(h_neg),
                       floats(other_knob_deg), floats(dead_zone_pos_deg),
                       floats(dead_zone_neg_deg), floats(backlash_pos_deg),
                       floats(backlash_neg_deg), tension_play)
