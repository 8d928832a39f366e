"""Parameters of one knob as continuous functions of the other knob's angle.

Calibration measures them on a grid of the other knob's angle (-90..90 deg, 30 deg steps); the
compensators evaluate them every tick at the other knob's current angle. Outside the grid the
end values are held (no extrapolation): the grid already spans the knob's range.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline, PchipInterpolator

INTERPOLATION_METHODS: tuple[str, ...] = ("pchip", "linear", "cubic")
"""pchip: shape-preserving cubic (no overshoot between grid points, the default);
linear: piecewise linear; cubic: natural cubic spline (smoothest, may overshoot)."""

CALIBRATION_GRID_DEG: tuple[float, ...] = (-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0)


class ParameterField:
    """Several named parameters sampled on one grid, evaluated together at any angle."""

    def __init__(self, grid_deg: Sequence[float], values: NDArray[np.float64],
                 method: str = "pchip", columns: Sequence[str] = ()) -> None:
        grid = np.asarray(grid_deg, dtype=float)
        vals = np.asarray(values, dtype=float)
        if method not in INTERPOLATION_METHODS:
            raise ValueError(f"interpolation {method!r} is not one of {INTERPOLATION_METHODS}")
        if grid.ndim != 1 or grid.size < 2 or np.any(np.diff(grid) <= 0):
            raise ValueError("grid must be strictly increasing with at least two points")
        if vals.ndim != 2 or vals.shape[0] != grid.size:
            raise ValueError(f"values must have shape ({grid.size}, n), got {vals.shape}")
        if columns and len(columns) != vals.shape[1]:
            raise ValueError(f"{len(columns)} column names for {vals.shape[1]} columns")
        self.grid_deg = grid
        self.values = vals
        self.method = method
        self.columns = tuple(columns)
        """The parameters' names, in column order (empty for an unnamed field)."""
        self._lo = float(grid[0])
        self._hi = float(grid[-1])
        if method == "pchip":
            self._f = PchipInterpolator(grid, vals, axis=0, extrapolate=False)
        elif method == "cubic":
            self._f = CubicSpline(grid, vals, axis=0, bc_type="natural", extrapolate=False)

    def at(self, other_deg: float) -> NDArray[np.float64]:
        """All parameters at the other knob's angle (clamped into the grid)."""
        a = min(max(float(other_deg), self._lo), self._hi)
        if self.method == "linear":
            i = int(np.searchsorted(self.grid_deg, a, side="right")) - 1
            i = min(max(i, 0), self.grid_deg.size - 2)
            g0, g1 = self.grid_deg[i], self.grid_deg[i + 1]
            w = (a - g0) / (g1 - g0)
            out: NDArray[np.float64] = (1.0 - w) * self.values[i] + w * self.values[i + 1]
            return out
        return np.asarray(self._f(a), dtype=float)

    @classmethod
    def from_columns(cls, grid_deg: Sequence[float], columns: Mapping[str, Sequence[float]],
                     method: str = "pchip") -> ParameterField:
        """A named field: one grid row of values per name, columns in the mapping's order."""
        names = tuple(columns)
        values = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
        return cls(grid_deg, values, method, names)

    def column(self, name: str) -> int:
        """The column index of the parameter ``name``."""
        try:
            return self.columns.index(name)
        except ValueError:
            raise KeyError(f"no parameter {name!r} in this field {self.columns}") from None

    def shifted(self, offsets_deg: Mapping[str, float]) -> ParameterField:
        """A copy with ``offsets_deg[name]`` added to each named parameter at every grid point."""
        values = self.values.copy()
        for name, offset in offsets_deg.items():
            values[:, self.column(name)] += offset
        return ParameterField(self.grid_deg.tolist(), values, self.method, self.columns)

    def scaled(self, factors: Mapping[str, float],
               bounds: tuple[float, float] = (-math.inf, math.inf)) -> ParameterField:
        """A copy with each named parameter multiplied by ``factors[name]`` at every grid
        point, the scaled values kept within ``bounds`` (the parameter's physical range)."""
        values = self.values.copy()
        for name, factor in factors.items():
            col = self.column(name)
            values[:, col] = np.clip(values[:, col] * factor, *bounds)
        return ParameterField(self.grid_deg.tolist(), values, self.method, self.columns)
