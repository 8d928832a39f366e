"""The two constitutive laws of the nitinol plant, in closed form so a step stays cheap.

- :func:`slide_contact`: one tendon's lumped lumen contact, backward Euler: it sticks while the
  tension difference across it stays within boundary friction (normal force from the local
  tension and wrap) plus drag, and slides otherwise against that plus the lubricant film's shear
  (proportional to the sliding speed).
- :func:`transform`: the NiTi tube's martensite fraction, a rate-independent return map with two
  thresholds (upper and lower plateau): a flag-shaped loop with no residual bend.
"""

from __future__ import annotations

from simrig.plants.nitinol.params import Backbone


def slide_contact(draw_mm: float, tip_mm: float, u0_mm: float, kp_N_mm: float,
                  kd_N_mm: float, mu_half: float, drag_N: float, film_N_mm: float
                  ) -> tuple[float, float, float]:
    """Where a tendon's contact node ends the step: ``(u_mm, handle_T_N, tip_T_N)``.

    ``draw_mm`` is the handle-side draw minus the slack (the proximal part is taut beyond
    ``u = draw``), ``tip_mm`` the tip-side draw (the distal part is taut beyond ``u = tip``),
    ``u0_mm`` the node at the step's start, ``mu_half`` friction x wrap / 2 (the normal force of
    a wrapped contact is the mean tension x wrap), ``film_N_mm`` film damping / dt.
    The balance f(u) = T_p - T_d - d (mu_half (T_p + T_d) + drag) - film (u - u0) falls
    strictly with u and is linear between the two kinks, so the root is exact.
    """
    tp = kp_N_mm * (draw_mm - u0_mm) if u0_mm < draw_mm else 0.0
    td = kd_N_mm * (u0_mm - tip_mm) if u0_mm > tip_mm else 0.0
    g = tp - td
    if abs(g) <= mu_half * (tp + td) + drag_N:
        return u0_mm, tp, td
    d = 1.0 if g > 0.0 else -1.0

    def f(u: float) -> float:
        p = kp_N_mm * (draw_mm - u) if u < draw_mm else 0.0
        q = kd_N_mm * (u - tip_mm) if u > tip_mm else 0.0
        return p - q - d * (mu_half * (p + q) + drag_N) - film_N_mm * (u - u0_mm)

    kinks = sorted((draw_mm, tip_mm), reverse=d < 0.0)
    u_lo, f_lo = u0_mm, g - d * (mu_half * (tp + td) + drag_N)
    for k in kinks:
        if (k - u0_mm) * d <= 0.0:
            continue
        f_k = f(k)
        if f_k * d <= 0.0:
            u = u_lo + f_lo * (k - u_lo) / (f_lo - f_k)
            break
        u_lo, f_lo = k, f_k
    else:  # beyond both kinks: one part taut, the other slack
        slope = (-kd_N_mm * (1.0 + mu_half) if d > 0.0 else -kp_N_mm * (1.0 + mu_half))
        u = u_lo - f_lo / (slope - film_N_mm)
    tp = kp_N_mm * (draw_mm - u) if u < draw_mm else 0.0
    td = kd_N_mm * (u - tip_mm) if u > tip_mm else 0.0
    return u, tp, td


def transform(bb: Backbone, bend_rad: float, fraction0: float) -> float:
    """The martensite fraction after the tube reaches the resultant bend ``bend_rad`` (>= 0)
    from ``fraction0``: forward on the upper plateau, back on the lower, frozen between."""
    k, span = bb.stiffness_Nm_per_rad, bb.stiffness_Nm_per_rad * bb.transformation_rad
    moment = k * (bend_rad - bb.transformation_rad * fraction0)
    if moment > bb.forward_Nm + bb.hardening_Nm * fraction0 and fraction0 < 1.0:
        return min(1.0, max(fraction0, (k * bend_rad - bb.forward_Nm) / (span + bb.hardening_Nm)))
    if moment < bb.reverse_Nm + bb.hardening_Nm * fraction0 and fraction0 > 0.0:
        return max(0.0, min(fraction0, (k * bend_rad - bb.reverse_Nm) / (span + bb.hardening_Nm)))
    return fraction0


def tube_moment(bb: Backbone, bend_rad: float, other_rad: float, fraction0: float
                ) -> tuple[float, float]:
    """The tube's moment in this plane at bend ``bend_rad`` with the other plane at
    ``other_rad``, and the fraction it implies: the transformation follows the resultant bend
    (one tube: the planes share it) and its strain lies along the bend's direction."""
    resultant = (bend_rad * bend_rad + other_rad * other_rad) ** 0.5
    if resultant < 1e-12:
        return bb.stiffness_Nm_per_rad * bend_rad, fraction0
    frac = transform(bb, resultant, fraction0)
    magnitude = bb.stiffness_Nm_per_rad * (resultant - bb.transformation_rad * frac)
    return magnitude * bend_rad / resultant, frac
