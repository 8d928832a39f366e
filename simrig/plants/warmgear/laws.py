"""The warmgear plant's physical laws as pure functions (no state)."""

from __future__ import annotations

import math
from collections.abc import Callable

KELVIN = 273.15
WATER_VISCOSITY_B_K = 1800.0
"""Andrade's law for water and saline, mu ~ exp(B/T): 0.95 mPa s at 22 C, 0.69 at 37 C."""


def shaft_temperature_C(t_s: float, room_C: float, body_C: float, warm_time_s: float) -> float:
    """Temperature of the inserted shaft ``t_s`` after insertion (first-order warm-up)."""
    return body_C - (body_C - room_C) * math.exp(-t_s / warm_time_s)


def viscosity_factor(temp_C: float, room_C: float) -> float:
    """The film's viscosity at ``temp_C`` over its viscosity at ``room_C`` (Andrade)."""
    return math.exp(WATER_VISCOSITY_B_K * (1.0 / (temp_C + KELVIN) - 1.0 / (room_C + KELVIN)))


def mesh_phase(knob_deg: float, pinion_teeth: float) -> float:
    """Where the mesh is in its tooth period, in [-0.5, 0.5): 0 at the pitch point."""
    x = knob_deg * pinion_teeth / 360.0
    return x - math.floor(x) - 0.5


def mesh_stiffness(phase: float, mean: float, ripple: float) -> float:
    """Mesh stiffness: highest with two tooth pairs in contact (the ends of the period),
    lowest with one (around the pitch point)."""
    return mean * (1.0 - ripple * math.cos(2.0 * math.pi * phase))


def mesh_loss(phase: float, friction: float, pinion_teeth: float, drum_teeth: float) -> float:
    """Share of the transmitted torque lost to flank sliding: zero at the pitch point, twice its
    period mean (pi mu (1/z1 + 1/z2), Buckingham's estimate) at the ends of contact."""
    return 4.0 * abs(phase) * math.pi * friction * (1.0 / pinion_teeth + 1.0 / drum_teeth)


def play_deflection(x: float, half_play: float) -> float:
    """Deflection of a mesh with play ``2 * half_play``: zero inside the play."""
    if x > half_play:
        return x - half_play
    if x < -half_play:
        return x + half_play
    return 0.0


def film_after(film: float, normal_N: float, speed_mm_s: float, dt_s: float,
               squeeze_time_s: float, entrain_length_mm: float, rewet_time_s: float) -> float:
    """Film thickness (share of full) after ``dt_s``.

    Squeeze (Reynolds, constant load): d(film)/dt = -film^3 (N / 10 N) / tau, solved exactly;
    then the film is rebuilt by sliding (entrainment over ``entrain_length_mm`` of travel) and
    by capillary flow (``rewet_time_s``).
    """
    rate = normal_N / 10.0 / squeeze_time_s
    if rate > 0.0:
        film = film / math.sqrt(1.0 + 2.0 * rate * film * film * dt_s)
    rebuild = speed_mm_s / entrain_length_mm + 1.0 / rewet_time_s
    return 1.0 - (1.0 - film) * math.exp(-rebuild * dt_s)


def root_decreasing(fun: Callable[[float], tuple[float, float]], x0: float, f0: float,
                    d0: float, tol: float, first_step: float, ftol: float) -> float:
    """Root of a decreasing function from ``x0``, where it is ``f0 != 0`` with slope ``d0``:
    a Newton step from ``x0`` (doubled until the sign turns), then Newton kept inside the
    bracket (bisection when it would leave); done within ``tol`` of x or ``ftol`` of 0."""
    s = 1.0 if f0 > 0.0 else -1.0
    step = max(abs(f0 / d0), tol) if d0 < 0.0 else first_step
    lo = x0
    hi = x0 + s * step
    fhi, dhi = fun(hi)
    if abs(fhi) < ftol:
        return hi
    while fhi * s > 0.0:
        lo = hi
        step *= 2.0
        hi = x0 + s * step
        fhi, dhi = fun(hi)
    # the root lies between lo (sign s) and hi (sign -s)
    x, fx, dx = hi, fhi, dhi
    for _ in range(60):
        if abs(fx) < ftol:
            return x
        nxt = x - fx / dx if dx < 0.0 else 0.5 * (lo + hi)
        if not (min(lo, hi) < nxt < max(lo, hi)):
            nxt = 0.5 * (lo + hi)
        moved = abs(nxt - x)
        fx, dx = fun(nxt)
        x = nxt
        if fx * s > 0.0:
            lo = x
        else:
            hi = x
        if moved < tol or abs(hi - lo) < tol:
            return x
    return x
