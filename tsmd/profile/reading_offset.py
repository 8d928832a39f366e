"""A product's reading offset: what the motor current reads minus what the tip shows, per
parameter and other-knob angle, measured once on the data sheet's tracked unit.

Some products put a mechanism between the tendons and the tip that the current does not carry
(twistshaft: the shaft's twist moves the tip at a reversal when the other knob is bent;
screwrod: the self-locking collar flips the motor torque at once at a reversal). There B (and
D) read from the current sit off the tip's by the same amount in every half-cycle: a bias,
not scatter, that no re-sweep can reach. The sheet keeps the measurement (mean, 95 %
half-width, half-cycles); whether and how much of it a calibration applies is decided there
(:mod:`tsmd.calibration.reading_offset`), so the rule can change without re-measuring sheets.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

OFFSET_PARAMETERS = ("dead_zone_pos_deg", "dead_zone_neg_deg", "backlash_pos_deg",
                     "backlash_neg_deg")
"""The parameters an offset may be measured for (calibration's identified values)."""
MAX_OFFSET_DEG = 30.0
"""A larger offset between current and tip is a measurement gone wrong, not a product."""
MAX_U95_DEG = 90.0


@dataclass(frozen=True)
class OffsetGrid:
    """One parameter's offset over the sheet unit's other-knob angles."""

    mean_deg: tuple[float, ...]
    """Current's value minus the tip's (threshold truth), mean over the half-cycles."""
    u95_deg: tuple[float, ...]
    """95 % half-width of that mean."""
    half_cycles: tuple[int, ...]


@dataclass(frozen=True)
class ReadingOffset:
    """One knob's offsets, per parameter over the other knob's angle (sorted, distinct)."""

    other_knob_deg: tuple[float, ...]
    grids: tuple[tuple[str, OffsetGrid], ...]
    """(parameter, its grid) pairs: a tuple, so that a data sheet stays hashable."""

    def grid(self, name: str) -> OffsetGrid | None:
        return dict(self.grids).get(name)

    def __post_init__(self) -> None:
        grid = self.other_knob_deg
        if not grid or any(b <= a for a, b in itertools.pairwise(grid)):
            raise ValueError(f"other_knob_deg must be sorted strictly increasing, got "
                             f"{list(grid)}")
        for name, g in self.grids:
            if name not in OFFSET_PARAMETERS:
                raise ValueError(f"{name}: unknown parameter (expected one of "
                                 f"{', '.join(OFFSET_PARAMETERS)})")
            if not len(g.mean_deg) == len(g.u95_deg) == len(g.half_cycles) == len(grid):
                raise ValueError(f"{name}: needs one mean_deg, u95_deg and half_cycles per "
                                 f"other-knob angle ({len(grid)})")


def offset_from_mapping(m: Any, where: str) -> ReadingOffset:
    """A ``reading_offset`` block; ValueError naming the key that is wrong."""
    if not isinstance(m, Mapping):
        raise ValueError(f"{where}: must be a mapping with other_knob_deg and parameters")
    unknown = set(m) - {"other_knob_deg", *OFFSET_PARAMETERS}
    if unknown:
        raise ValueError(f"{where}.{sorted(unknown)[0]}: unknown key")
    grid = _numbers(m.get("other_knob_deg"), f"{where}.other_knob_deg", 360.0)
    grids = []
    for name in OFFSET_PARAMETERS:
        if name not in m:
            continue
        g = m[name]
        if not isinstance(g, Mapping) or set(g) != {"mean_deg", "u95_deg", "half_cycles"}:
            raise ValueError(f"{where}.{name}: must be a mapping of mean_deg, u95_deg and "
                             f"half_cycles")
        counts = g["half_cycles"]
        if (isinstance(counts, str) or not isinstance(counts, Sequence)
                or any(isinstance(c, bool) or not isinstance(c, int) or c < 1 for c in counts)):
            raise ValueError(f"{where}.{name}.half_cycles: must be a list of positive integers")
        grids.append((name, OffsetGrid(
            _numbers(g["mean_deg"], f"{where}.{name}.mean_deg", MAX_OFFSET_DEG),
            _numbers(g["u95_deg"], f"{where}.{name}.u95_deg", MAX_U95_DEG, lo=0.0),
            tuple(int(c) for c in counts))))
    try:
        return ReadingOffset(grid, tuple(grids))
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def offset_to_mapping(o: ReadingOffset) -> dict[str, Any]:
    out: dict[str, Any] = {"other_knob_deg": list(o.other_knob_deg)}
    for name, g in o.grids:
        out[name] = {"mean_deg": list(g.mean_deg), "u95_deg": list(g.u95_deg),
                     "half_cycles": list(g.half_cycles)}
    return out


def _numbers(v: Any, key: str, hi: float, lo: float | None = None) -> tuple[float, ...]:
    low = -hi if lo is None else lo
    if isinstance(v, str) or not isinstance(v, Sequence) or not v:
        raise ValueError(f"{key}: must be a non-empty list of numbers")
    out = []
    for x in v:
        if isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x):
            raise ValueError(f"{key}: must be a list of finite numbers, got {x!r}")
        if not low <= x <= hi:
            raise ValueError(f"{key}: {x} is outside the plausible range [{low:g}, {hi:g}]")
        out.append(float(x))
    return tuple(out)
