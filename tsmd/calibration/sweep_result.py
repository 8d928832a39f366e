"""What one sweep's identification gives: its half-cycles and the values per parameter.

The result of :mod:`tsmd.calibration.identify`, read by the estimates, the gate, the re-sweeps
and the fits; its own module so that they need not import the identification.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tsmd.calibration.signal import Conditioned, walsh_median

PARAMETERS: tuple[str, ...] = (
    "dead_zone_pos_deg", "dead_zone_neg_deg", "backlash_pos_deg", "backlash_neg_deg")
SHORT = {"dead_zone_pos_deg": "D_pos", "dead_zone_neg_deg": "D_neg",
         "backlash_pos_deg": "B_pos", "backlash_neg_deg": "B_neg"}


@dataclass(frozen=True)
class HalfCycle:
    """One monotonic stretch between reversals and what was found in it (indices into arrays)."""

    direction: int
    start: int
    stop: int
    after_reversal: bool
    peak_index: int | None = None
    backlash_end_index: int | None = None
    edge_index: int | None = None
    backlash_deg: float = math.nan
    edge_deg: float = math.nan
    plateau_A: float = math.nan
    rise_A: float = math.nan
    snr: float = math.nan
    problems: tuple[str, ...] = ()
    slip: str | None = None
    """Where the loaded current dropped while the knob moved on, if it did."""
    release_swing_A: float = math.nan
    """After a reversal: the current's swing to its release level
    (:func:`tsmd.calibration.release.release_swing`)."""
    backlash_visibility: float = math.nan
    """Rule "recovery": how clearly the current shows where the backlash ends
    (:class:`tsmd.calibration.recovery.Recovery`); NaN under the other rules."""
    share_u95_deg: float = math.nan
    """Rule "line" moved by the unit's slope ratio: the 95 % half-width of ``backlash_deg`` that
    the share's unit part the ratio cannot know gives (knob travel per unit of share at the end
    times :data:`tsmd.calibration.options.LINE_SHARE_UNIT_U95`); NaN under the other rules."""

    @property
    def backlash_name(self) -> str:
        return "backlash_neg_deg" if self.direction > 0 else "backlash_pos_deg"

    @property
    def edge_name(self) -> str:
        return "dead_zone_pos_deg" if self.direction > 0 else "dead_zone_neg_deg"


@dataclass(frozen=True)
class SweepResult:
    """Everything one sweep gave: conditioned signals, half-cycles, values per parameter."""

    data: Conditioned
    half_cycles: tuple[HalfCycle, ...]
    values: dict[str, tuple[float, ...]] = field(default_factory=dict)
    """Each parameter's value from every half-cycle that gave one, in time order."""
    resweeps: int = 0
    """How many re-sweeps were pooled into this result."""
    own_half_cycles: int | None = None
    """How many of ``half_cycles`` (the first) index ``data``; the re-sweeps' index their own
    recordings (None: all of them)."""
    offset_u95_deg: dict[str, float] = field(default_factory=dict)
    """Per parameter the 95 % half-width of the product's reading offset subtracted from its
    values (:mod:`tsmd.calibration.reading_offset`); none subtracted: absent."""
    unseen: dict[str, float] = field(default_factory=dict)
    """Backlashes the current does not show at this grid point: their values are the data
    sheet's reference scaled by the unit's swing (:mod:`tsmd.calibration.recovery`), with this
    95 % half-width; no reading offset applies to them and no re-sweep narrows them."""
    product_u95_deg: dict[str, float] = field(default_factory=dict)
    """Per parameter, the 95 % half-width of what the product's sample measured that no sweep
    narrows (:mod:`tsmd.calibration.unit_part`); absent: the share's part, if any."""
    own_offset_deg: dict[str, float] = field(default_factory=dict)
    """Per backlash read at the end of the handle's play its current showed
    (:mod:`tsmd.calibration.play_engage`), the unit's own reading offset that replaced the
    sheet's (line end minus the play's end, mean over the half-cycles); absent: the sheet's."""
    play_ends_deg: dict[str, tuple[float, ...]] = field(default_factory=dict)
    """Per backlash read where the data sheet announces a handle's play, each half-cycle's
    play end (NaN where its current showed no step); re-sweeps' appended
    (:mod:`tsmd.calibration.play_creep` judges whether the play is rigid)."""

    @property
    def data_half_cycles(self) -> tuple[HalfCycle, ...]:
        """The half-cycles whose indices point into ``data`` (the first sweep's)."""
        return self.half_cycles[:self.own_half_cycles]

    def estimate(self, name: str) -> float:
        """The half-cycles' robust mean (:func:`walsh_median`; NaN when none gave a value)."""
        return walsh_median(np.asarray(self.values.get(name, ()), dtype=float))

    def share_u95_deg(self, name: str) -> float:
        """The 95 % half-width of a backlash that no sweep narrows (its half-cycles' median of
        :attr:`HalfCycle.share_u95_deg`); 0 where the rule has none."""
        v = [h.share_u95_deg for h in self.half_cycles
             if h.backlash_name == name and math.isfinite(h.share_u95_deg)]
        return float(np.median(v)) if v else 0.0

    def unit_u95_deg(self, name: str) -> float:
        """The half-width reported beyond the gate's: the product's sample's where the data
        sheet measured it, else :meth:`share_u95_deg`."""
        return self.product_u95_deg.get(name, self.share_u95_deg(name))

    def spread(self, name: str) -> float:
        """Largest minus smallest value over the half-cycles (0 with one value)."""
        v = self.values.get(name, ())
        return float(np.ptp(v)) if v else math.nan

    def merged(self, other: SweepResult) -> SweepResult:
        """This sweep's half-cycles pooled with a re-sweep's (the first sweep's signals kept)."""
        values = {name: self.values.get(name, ()) + other.values.get(name, ())
                  for name in PARAMETERS}
        ends = {name: self.play_ends_deg.get(name, ()) + other.play_ends_deg.get(name, ())
                for name in {*self.play_ends_deg, *other.play_ends_deg}}
        return SweepResult(self.data, self.half_cycles + other.half_cycles, values,
                           self.resweeps + 1, len(self.data_half_cycles), self.offset_u95_deg,
                           {**self.unseen, **other.unseen}, self.product_u95_deg,
                           self.own_offset_deg, ends)

    @property
    def snr(self) -> float:
        values = [h.snr for h in self.half_cycles if math.isfinite(h.snr)]
        return float(min(values)) if values else math.nan

    @property
    def median_snr(self) -> float:
        """The typical half-cycle's signal (one weak half-cycle gives no value, not a verdict)."""
        values = [h.snr for h in self.half_cycles if math.isfinite(h.snr)]
        return float(np.median(values)) if values else math.nan

    @property
    def problems(self) -> tuple[str, ...]:
        return tuple(p for h in self.half_cycles for p in h.problems)
