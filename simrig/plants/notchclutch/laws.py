"""The constitutive laws of the notchclutch plant, each a plain function of floats (fast enough
for the lockstep loop, no arrays).

* an aramid braid: slack, a quadratic toe while its crimp straightens, then linear;
* one lumped lumen contact per tendon on a hydrophilic liner: the contact sticks while the
  tensions on its two sides stay within the capstan ratio (plus a drag), else it slides until
  they sit on the ratio (Euler-Eytelwein over the contact's wrap);
* the liner's friction coefficient: boundary level after the coating has soaked, higher at
  insertion, with a Stribeck rise at low film speed (mixed lubrication);
* a notched steel tube: linear bending until the notches on the concave side touch, then
  progressively stiffer (notches close one after another), closure set by the total bend.
"""

from __future__ import annotations

import math


def toe_force_N(k_N_mm: float, toe_mm: float, stretch_mm: float) -> float:
    """Tension of a braid stretched by ``stretch_mm`` past its slack (C1 toe, then linear)."""
    if stretch_mm <= 0.0:
        return 0.0
    if stretch_mm < toe_mm:
        return k_N_mm * stretch_mm * stretch_mm / (2.0 * toe_mm)
    return k_N_mm * (stretch_mm - 0.5 * toe_mm)


def toe_stretch_mm(k_N_mm: float, toe_mm: float, force_N: float) -> float:
    """Inverse of :func:`toe_force_N` (0 for no tension)."""
    if force_N <= 0.0:
        return 0.0
    if force_N < 0.5 * k_N_mm * toe_mm:
        return math.sqrt(2.0 * toe_mm * force_N / k_N_mm)
    return force_N / k_N_mm + 0.5 * toe_mm


def _toe_root(k1: float, toe: float, g: float, k2: float, total: float, b: float) -> float:
    """Proximal stretch y >= 0 with k1 h(y) = g k2 (total - y) + b (the distal side taut)."""
    rhs0 = g * k2 * total + b
    if rhs0 <= 0.0:
        return 0.0
    y = (rhs0 + 0.5 * k1 * toe) / (k1 + g * k2)  # linear part of the braid
    if y >= toe:
        return y
    a2 = k1 / (2.0 * toe)  # in the toe: a2 y^2 + g k2 y - rhs0 = 0
    bb = g * k2
    return 2.0 * rhs0 / (bb + math.sqrt(bb * bb + 4.0 * a2 * rhs0))


def tendon_contact(pull_mm: float, slack_mm: float, contact_mm: float, path_mm: float,
                   k1: float, k2: float, toe_mm: float, ratio: float, drag_N: float
                   ) -> tuple[float, float, float]:
    """One tendon over its lumen contact: ``(contact_mm, proximal_N, distal_N)``.

    ``pull_mm`` is what the drum has drawn in, ``path_mm`` what the section's bend takes from the
    tendon beyond the contact, ``contact_mm`` where the contact was (it stays there while the
    capstan ratio ``ratio`` and the drag hold the two tensions). The proximal part carries the
    slack and the braid's toe; the short distal part is linear.
    """
    total = pull_mm - slack_mm - path_mm
    y = pull_mm - slack_mm - contact_mm
    e2 = contact_mm - path_mm
    t1 = toe_force_N(k1, toe_mm, y)
    t2 = k2 * e2 if e2 > 0.0 else 0.0
    if t1 > ratio * t2 + drag_N:  # the drum drags the tendon toward the handle
        y_drag = toe_stretch_mm(k1, toe_mm, drag_N)
        if total <= y_drag:
            y = y_drag
        else:
            y = max(_toe_root(k1, toe_mm, ratio, k2, total, drag_N), y_drag)
    elif t2 > ratio * (t1 + drag_N):  # the section pulls the tendon back into the shaft
        y = _toe_root(k1, toe_mm, 1.0 / ratio, k2, total, -drag_N)
        if y <= 0.0:
            y = min(total - ratio * drag_N / k2, 0.0)
    else:
        return contact_mm, t1, t2
    e2 = total - y
    return pull_mm - slack_mm - y, toe_force_N(k1, toe_mm, y), (k2 * e2 if e2 > 0.0 else 0.0)


def liner_friction(boundary: float, dry_ratio: float, soak_time_s: float, t_s: float,
                   rise: float, film_speed_mm_s: float, stribeck_speed_mm_s: float) -> float:
    """Friction coefficient of the braid on the liner ``t_s`` after insertion at film speed."""
    soak = 1.0 + (dry_ratio - 1.0) * math.exp(-t_s / soak_time_s)
    return boundary * soak * (1.0 + rise * math.exp(-film_speed_mm_s / stribeck_speed_mm_s))


def liner_drag_N(drag_N: float, dry_ratio: float, soak_time_s: float, t_s: float) -> float:
    """Tension-independent drag ``t_s`` after insertion: it grows as the coating swells."""
    return drag_N * (1.0 + (dry_ratio - 1.0) * math.exp(-t_s / soak_time_s))


def notch_moment_Nmm(stiffness: float, bend_rad: float, total_rad: float, close_rad: float,
                     width_rad: float, stiffening: float) -> float:
    """Elastic moment of the notched tube in one plane, with the closure set by the total bend."""
    moment = stiffness * bend_rad
    if stiffening > 0.0 and total_rad > 1e-9:
        z = (total_rad - close_rad) / width_rad
        closed = width_rad * (z + math.log1p(math.exp(-z)) if z > 0.0 else math.log1p(math.exp(z)))
        moment += stiffness * stiffening * closed * bend_rad / total_rad
    return moment
