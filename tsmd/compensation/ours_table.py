"""One knob of method ``ours``: its tension-play parameters over the other knob's angle, with
the branches precomputed at every :data:`TABLE_STEP_DEG` of that angle (a tick only looks a row
up, :class:`tsmd.compensation.ours.OursCompensator`). Built in milliseconds, never in a tick:
online re-estimation builds shifted knobs on its own thread.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

from tsmd.compensation.fresh_play import fresh_branches
from tsmd.compensation.grid import ParameterField
from tsmd.compensation.knee_map import moved_grid, moved_knee
from tsmd.compensation.level_grid import LevelGrid
from tsmd.compensation.loaded_shape import LoadedShape, ShapeGrid, curved, steepest_slope
from tsmd.compensation.release_round import reference_backlash_deg, shifted_zero_load_deg
from tsmd.compensation.reversal_release import ReleaseEndShape
from tsmd.compensation.shaped_play import model_branches
from tsmd.compensation.tension_play import Branches, release_slope
from tsmd.compensation.tension_play_params import TensionPlayParams

OURS_COLUMNS: tuple[str, ...] = ("dead_zone_pos_deg", "dead_zone_neg_deg", "backlash_gain_pos",
                                 "backlash_gain_neg", "zero_load_pos_deg", "zero_load_neg_deg")
"""The columns of :attr:`OursKnob.field`, in the order :func:`branches` takes them. A slack
change moves a tendon's whole characteristic along the knob axis: its edge and its zero-load
point move together (:data:`MOVES_WITH_EDGE`)."""
MOVES_WITH_EDGE: dict[str, str] = {"dead_zone_pos_deg": "zero_load_pos_deg",
                                   "dead_zone_neg_deg": "zero_load_neg_deg"}
TABLE_STEP_DEG = 0.25
"""Resolution of the other knob's angle in the precomputed branches."""


@dataclass(frozen=True)
class OursKnob:
    """One knob's parameters over the other knob's angle, with its branches precomputed.

    ``field`` holds :data:`OURS_COLUMNS`; the table is built here (milliseconds), never in a
    tick: online re-estimation builds shifted knobs on its own thread (``dataclasses.replace``).
    """

    field: ParameterField
    omega: float
    height_pos_deg: float
    height_neg_deg: float
    lag_s: float = 0.0
    fresh_hold_deg: float = 0.0
    fresh_edge_delay_deg: float | None = None
    shape_pos: LoadedShape | None = None
    """The product's loaded-branch template per side (None: straight); a fresh knob's first
    loading and release (``fresh_branches``) stay straight."""
    shape_neg: LoadedShape | None = None
    other_tip_gain: float = 0.0
    """Tip degrees in this plane per tip degree of the other (the product's, data sheet)."""
    shape_grid: tuple[ShapeGrid, ShapeGrid] | None = None
    """The product's templates over the other knob's angle (positive, negative side); where
    given, each table row takes the templates at its angle instead of ``shape_pos/neg``."""
    release_round: float = 0.0
    """The product's rounded release (:mod:`tsmd.compensation.release_round`): half-width in
    backlashes at a 90 deg reversal; 0: the sharp corner (fresh tables stay sharp)."""
    release_shift: float = 0.0
    """How much later the release lines lie, in the same backlashes."""
    level_grid: LevelGrid | None = None
    """The product's shift of each side's plateau height over the other knob's angle
    (:mod:`tsmd.compensation.level_grid`); None: the heights at every angle (fresh tables
    keep them)."""
    release_end: ReleaseEndShape | None = None
    """The product's release end per reversal (:mod:`tsmd.compensation.reversal_release`);
    None: the static release lines (fresh tables keep them)."""
    hold_at_home: bool = False
    """The product's choice that this knob keeps its command at rest inside its plateau band
    while the other knob moves its branches (:func:`tsmd.compensation.ours._keep_at_home`)."""
    _table: tuple[Branches, ...] = dataclasses.field(init=False, repr=False, compare=False)
    _fresh: tuple[tuple[Branches, ...], ...] = dataclasses.field(init=False, repr=False,
                                                                 compare=False)
    _lo: float = dataclasses.field(init=False, repr=False, compare=False)
    _step: float = dataclasses.field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.field.columns != OURS_COLUMNS:
            raise ValueError(f"the field must hold {OURS_COLUMNS}, got {self.field.columns}")
        grid = self.field.grid_deg
        lo, hi = float(grid[0]), float(grid[-1])
        n = max(2, round((hi - lo) / TABLE_STEP_DEG) + 1)
        step = (hi - lo) / (n - 1)
        rows = [[float(v) for v in self.field.at(lo + i * step)] for i in range(n)]
        w, h_pos, h_neg = self.omega, self.height_pos_deg, self.height_neg_deg
        table = tuple(self._row_branches(r, lo + i * step) for i, r in enumerate(rows))
        # a fresh knob's tables by the side it loaded first: -1, none yet, +1
        fresh = tuple(tuple(fresh_branches(b, w, r[0], r[1], h_pos, h_neg, self.fresh_hold_deg,
                                           self.fresh_edge_delay_deg, side)
                            for b, r in zip(table, rows, strict=True))
                      for side in (-1, 0, 1)) if self.is_fresh_known else (table,) * 3
        object.__setattr__(self, "_table", table)
        object.__setattr__(self, "_fresh", fresh)
        object.__setattr__(self, "_lo", lo)
        object.__setattr__(self, "_step", step)

    def _row_branches(self, r: list[float], other_deg: float) -> Branches:
        """One table row's branches, the release rounded and shifted where the product says."""
        w, h_pos, h_neg = self.omega, self.height_pos_deg, self.height_neg_deg
        if self.level_grid is not None:
            shift_pos, shift_neg = self.level_grid.at(other_deg)
            h_pos, h_neg = h_pos + shift_pos, h_neg + shift_neg
        x0_pos, x0_neg = r[4], r[5]
        if self.release_shift != 0.0:
            x0_pos = shifted_zero_load_deg(r[2], r[4], self.release_shift, 1)
            x0_neg = shifted_zero_load_deg(r[3], r[5], self.release_shift, -1)
        b = model_branches(w, h_pos, h_neg, r[0], r[1], r[2], r[3], x0_pos, x0_neg,
                           *self.shapes_at(other_deg))
        if self.release_end is not None:
            b = dataclasses.replace(b, release_end=self.release_end)
        if self.release_round == 0.0:
            return b
        k_pos, k_neg = (self.release_round * reference_backlash_deg(beta, x0, side)
                        * release_slope(w, beta)
                        for beta, x0, side in ((r[2], r[4], 1), (r[3], r[5], -1)))
        return dataclasses.replace(b, round_pos_deg=k_pos, round_neg_deg=k_neg)

    @classmethod
    def from_params(cls, p: TensionPlayParams, interpolation: str = "pchip") -> OursKnob:
        shape_pos, shape_neg, grid = p.shape_pos, p.shape_neg, p.shape_grid
        if p.loaded_knee_deg is not None and p.sheet_loaded_knee_deg is not None:
            # the templates' knee where this unit's current puts it (sheet and unit read alike)
            (ks_pos, ks_neg), (ku_pos, ku_neg) = p.sheet_loaded_knee_deg, p.loaded_knee_deg
            shape_pos = None if shape_pos is None else moved_knee(shape_pos, ks_pos, ku_pos)
            shape_neg = None if shape_neg is None else moved_knee(shape_neg, ks_neg, ku_neg)
            grid = None if grid is None else (moved_grid(grid[0], ks_pos, ku_pos),
                                              moved_grid(grid[1], ks_neg, ku_neg))
        return cls(ParameterField(p.other_knob_deg, p.columns(), interpolation, OURS_COLUMNS),
                   p.omega, p.height_pos_deg, p.height_neg_deg, p.lag_s, p.fresh_hold_deg,
                   # the profile's fresh numbers come together from one first sweep
                   p.fresh_edge_delay_deg if p.fresh_hold_deg > 0.0 else None,
                   curved(shape_pos), curved(shape_neg), p.other_tip_gain, grid,
                   p.release_round, p.release_shift, p.level_grid, p.release_end,
                   p.hold_at_home)

    def shapes_at(self, other_deg: float) -> tuple[LoadedShape | None, LoadedShape | None]:
        """The templates (positive, negative side) at the other knob's angle."""
        if self.shape_grid is None:
            return self.shape_pos, self.shape_neg
        return curved(self.shape_grid[0].at(other_deg)), curved(self.shape_grid[1].at(other_deg))

    @property
    def steepest_shape_slope(self) -> float:
        """The templates' steepest piece at any angle (1 when straight)."""
        grid = () if self.shape_grid is None else (*self.shape_grid[0].shapes,
                                                   *self.shape_grid[1].shapes)
        return steepest_slope(self.shape_pos, self.shape_neg, *grid)

    @property
    def is_fresh_known(self) -> bool:
        """The profile says how a fresh catheter differs (else it is taken as conditioned)."""
        return self.fresh_hold_deg > 0.0 or self.fresh_edge_delay_deg is not None

    def at(self, other_deg: float, fresh: bool = False, side: int = 0) -> Branches:
        """The branches at the other knob's angle (nearest table row, clamped to the grid);
        ``fresh``: those of a fresh catheter before its first release has ended, loaded first
        on ``side`` (0: not yet)."""
        table = self._fresh[side + 1] if fresh else self._table
        if other_deg != other_deg:  # NaN
            return table[0]
        i = int((other_deg - self._lo) / self._step + 0.5)
        return table[0 if i < 0 else (i if i < len(table) else len(table) - 1)]



def ours_knobs(params: Sequence[TensionPlayParams], interpolation: str = "pchip"
               ) -> tuple[OursKnob, OursKnob]:
    """Both knobs from a profile's per-knob tension-play parameters."""
    return (OursKnob.from_params(params[0], interpolation),
            OursKnob.from_params(params[1], interpolation))
