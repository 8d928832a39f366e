"""The unit's backlash gain read as the data sheet read its own (session 23, round 2).

The sheet's ``reference_rule_backlash_gain`` (and ``reference_backlash_gain``) are read on its
unit *before* the product's reading offset exists (``tsmd datasheet`` measures the offset last):
with the backlash as the current showed it. Every unit's B is then corrected by that offset
(:mod:`tsmd.calibration.reading_offset`), which is right for the play's own backlash, but a gain
read with the corrected B and set against the sheet's uncorrected one compares two estimators.
Where the offset is large the comparison says the unit stretches far more than the sheet's unit
did: planetwist (current reads B ~10.5 deg short of the tip, its tooth play) gave dev unit 1 a
gain 0.19-0.22 against the sheet's 0.057, omega 1.18 / 1.21 against the sheet's 1.29 / 1.37,
and a release line steeper than the tracked one; ours overshot on loading and on release.

Here the offset the calibration subtracted is added back for those comparisons only (where the
current did not show the backlash, the B is the sheet's and nothing was subtracted).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from tsmd.calibration.load_ramp import SideFit
from tsmd.calibration.reading_offset import offset_at

BACKLASH_NAMES = ("backlash_pos_deg", "backlash_neg_deg")


def subtracted_backlash_deg(device_knob: Any, unseen: tuple[bool, bool]
                            ) -> tuple[float, float]:
    """(+, -) offset the calibration subtracts from B with the other knob at 0, where the
    sheet read its gains (0 where none is applied or the backlash was unseen). Taken at 0 for
    every grid angle: the sheet's gains never saw what the offset does at the other knob's
    ends (nitinol's -2 deg at +-90 only), and the unit's own trend over the grid is kept."""
    offset = getattr(device_knob, "reading_offset", None)
    if offset is None:
        return 0.0, 0.0
    shift = [0.0 if hidden else offset_at(offset, name, 0.0)[0]
             for name, hidden in zip(BACKLASH_NAMES, unseen, strict=True)]
    return shift[0], shift[1]


def read_gain(fit: SideFit, subtracted_deg: float) -> float:
    """The side's gain with B as the current read it: ``(B + offset) / |A - x0|`` (B is a
    magnitude on both sides, the offset current minus tip; the play's gain where that B is not
    positive)."""
    run = abs(fit.amplitude_deg - fit.zero_load_deg)
    b = fit.backlash_deg + subtracted_deg
    return fit.backlash_gain if not (run > 0 and b > 0) else b / run


def read_gains(device_knob: Any, unseen: Sequence[tuple[bool, bool]],
               pos_fits: Sequence[SideFit], neg_fits: Sequence[SideFit],
               own: Sequence[tuple[float | None, float | None]] | None = None
               ) -> tuple[list[float], list[float]]:
    """Per side and sweep, the play's gain with its B as read (before the reading offset);
    where the unit read its own offset (``own``, the play's end its current showed:
    :mod:`tsmd.calibration.play_engage`), that one is added back instead of the sheet's."""
    pos, neg = [], []
    owns = own if own is not None else [(None, None)] * len(pos_fits)
    for hidden, fp, fn, mine in zip(unseen, pos_fits, neg_fits, owns, strict=True):
        s_pos, s_neg = subtracted_backlash_deg(device_knob, hidden)
        pos.append(read_gain(fp, s_pos if mine[0] is None else mine[0]))
        neg.append(read_gain(fn, s_neg if mine[1] is None else mine[1]))
    return pos, neg


def read_side_ratio(ratio: float, gain: float, read: float) -> float:
    """The ratio handed to :func:`tsmd.calibration.release_path.release_through_amplitude` so
    that the release line's slope is ``ratio`` times the locus the *read* gain gives (the
    sheet's ratio is against its read gain) while it still passes through the corrected
    backlash end: ``ratio (1 - gain) / (1 - read)``; the ratio unchanged where they agree."""
    if gain == read or ratio == 1.0:
        return ratio
    return ratio * (1.0 - gain) / (1.0 - read)


__all__ = ["read_gain", "read_gains", "read_side_ratio", "subtracted_backlash_deg"]
