"""The helixbelt plant's constitutive laws: pure functions of the constants and the state.

- ``helix_wrap_rad``: total angle a helical tendon turns through in a curved shaft. The tendon's
  curvature is the sum of the helix's own (kappa_h = r / (r^2 + c^2), c = pitch / 2 pi, pointing
  at the shaft axis and turning with the helix phase) and the shaft's (kappa_s, fixed in space).
  Over many turns the wrap is L times the mean of |kappa_h n_h + kappa_s n_s| over the phase:
  it does not add the two linearly (a helix pays wrap in a straight shaft and gains little more
  when the shaft curves), and the tendon's length does not change with the shaft's curve (each
  turn passes the inside and the outside of the bend alike) - why catheters route tendons so.
- ``friction_centroid``: where the one lumped contact of a tendon sits: the mean position of
  its friction along the shaft when loaded.
- ``mesh_deflection_rad``: the belt's deflection at the drum for a torque: the tooth clearance,
  then a progressive tooth mesh (deflection ~ sqrt(torque): flank contact and the number of
  loaded teeth grow with the load).
- ``masing_moment_Nmm``: the braid's inter-wire friction moment by Masing's rule: a saturating
  backbone f(u) = M tanh(u / u0); after a reversal at (b_r, H_r) the branch is
  H_r + 2 f((b - b_r) / 2), clipped at the backbone's limit.
"""

from __future__ import annotations

import math


def helix_wrap_rad(length_mm: float, helix_radius_mm: float, helix_pitch_mm: float,
                   shaft_bend_rad: float, phases: int = 32) -> float:
    """Wrap (rad) of a helical tendon over ``length_mm`` of shaft bent by ``shaft_bend_rad``."""
    c = helix_pitch_mm / (2.0 * math.pi)
    kappa_h = helix_radius_mm / (helix_radius_mm ** 2 + c * c)
    kappa_s = abs(shaft_bend_rad) / length_mm
    total = 0.0
    for i in range(phases):
        phi = 2.0 * math.pi * (i + 0.5) / phases
        total += math.sqrt(kappa_h * kappa_h + kappa_s * kappa_s
                           + 2.0 * kappa_h * kappa_s * math.cos(phi))
    return length_mm * total / phases


def friction_centroid(friction_exponent: float) -> float:
    """Where along the shaft (fraction from the handle) the friction of a loaded tendon acts on
    average: the normal force follows the tension, which falls as exp(-x s / L) (x = mu Theta),
    so the friction crowds towards the handle; 1/2 when there is none."""
    x = friction_exponent
    if x < 1e-6:
        return 0.5
    return 1.0 / x - math.exp(-x) / (1.0 - math.exp(-x))


def helix_length_factor(helix_radius_mm: float, helix_pitch_mm: float) -> float:
    """Tendon length per unit of shaft length along the helix."""
    return math.hypot(1.0, 2.0 * math.pi * helix_radius_mm / helix_pitch_mm)


def mesh_deflection_rad(torque_Nmm: float, clearance_half_rad: float, ref_deflection_rad: float,
                        ref_torque_Nmm: float) -> float:
    """Belt deflection (knob minus drum, rad) carrying ``torque_Nmm`` (> 0 forward)."""
    if torque_Nmm == 0.0:
        return 0.0
    d = clearance_half_rad + ref_deflection_rad * math.sqrt(abs(torque_Nmm) / ref_torque_Nmm)
    return d if torque_Nmm > 0.0 else -d


def masing_moment_Nmm(bend_rad: float, reversal_rad: float, reversal_moment_Nmm: float,
                      limit_Nmm: float, slip_rad: float) -> float:
    """Braid friction moment on the branch that left ``(reversal_rad, reversal_moment_Nmm)``."""
    if limit_Nmm == 0.0:
        return 0.0
    h = reversal_moment_Nmm + 2.0 * limit_Nmm * math.tanh((bend_rad - reversal_rad)
                                                         / (2.0 * slip_rad))
    return min(limit_Nmm, max(-limit_Nmm, h))
