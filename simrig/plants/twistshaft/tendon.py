"""One tendon in its lumen: a toe-then-linear fibre, pressed on the lumen with a Hertzian contact.

The tendon is two elastic stretches (drum to the contact, contact to the tip) meeting at one
friction contact that stands for its lumen. The contact's friction coefficient is constant at low
normal force and falls as its power ``n - 1`` (n = 2/3: Hertzian polymer asperities) above
``contact_load_N``, so friction grows less than in proportion to the load: a
backlash that grows less than in proportion to the load, which a fixed dead-zone/backlash
model does not have. The solve is a return mapping: the contact sticks where it was unless the
tension difference exceeds its capacity, then slides to where it equals it (bracketed Newton).
All lengths in mm, forces in N.
"""

from __future__ import annotations

import math


class LumenTendon:
    """Quasi-static state of one tendon: where its contact is (``x_mm``, drawn towards the drum)."""

    __slots__ = (
        "_x_trial",
        "drag_N",
        "kd_N_mm",
        "kp_N_mm",
        "load_N",
        "mu",
        "n",
        "slack_mm",
        "td_N",
        "toe_mm",
        "tp_N",
        "wrap_rad",
        "x_mm",
    )

    def __init__(self, *, kp_N_mm: float, kd_N_mm: float, toe_mm: float, slack_mm: float,
                 wrap_rad: float, mu: float, n: float, load_N: float, drag_N: float) -> None:
        self.kp_N_mm = kp_N_mm
        self.kd_N_mm = kd_N_mm
        self.toe_mm = toe_mm
        self.slack_mm = slack_mm
        self.wrap_rad = wrap_rad
        self.mu = mu
        self.n = n
        self.load_N = load_N
        self.drag_N = drag_N
        self.x_mm = 0.0
        self._x_trial = 0.0
        self.tp_N = 0.0
        self.td_N = 0.0

    def reset(self) -> None:
        self.x_mm = self._x_trial = self.tp_N = self.td_N = 0.0

    def _proximal(self, e_mm: float) -> tuple[float, float]:
        """Drum-side tension and its slope: zero while slack, quadratic toe, then linear."""
        if e_mm <= 0.0:
            return 0.0, 0.0
        k, t = self.kp_N_mm, self.toe_mm
        if e_mm < t:
            return 0.5 * k * e_mm * e_mm / t, k * e_mm / t
        return k * (e_mm - 0.5 * t), k

    def _capacity(self, tp: float, td: float, mu: float) -> tuple[float, float]:
        """Friction capacity of the contact (N) and its slope in the sum of both tensions.

        ``(Tp + Td) tanh(mu w / 2)`` is the capstan's own ratio ``Tp / Td = exp(mu w)`` written
        for one contact (it never locks the tendon); ``mu`` falls with the normal force
        ``w (Tp + Td) / 2`` as ``(1 + N / N_c)^(n - 1)``: linear at low load, Hertzian above.
        """
        w = self.wrap_rad
        total = tp + td
        ratio = 0.5 * w * total / self.load_N
        f = (1.0 + ratio) ** (self.n - 1.0)
        z = 0.5 * w * mu * f
        th = math.tanh(z)
        dz_dtotal = z * (self.n - 1.0) / (1.0 + ratio) * 0.5 * w / self.load_N
        return self.drag_N + total * th, th + total * (1.0 - th * th) * dz_dtotal

    def trial(self, u_mm: float, g_mm: float, mu_factor: float) -> tuple[float, float]:
        """Distal tension (N) with the drum drawn ``u_mm`` and the tip taking ``g_mm``, and its
        slope in ``g_mm``; the contact's new place is kept as the trial (see :meth:`commit`)."""
        mu = self.mu * mu_factor
        kd = self.kd_N_mm
        x = self.x_mm
        base = u_mm - self.slack_mm
        tp, dtp = self._proximal(base - x)
        ed = x - g_mm
        td, dtd = (kd * ed, kd) if ed > 0.0 else (0.0, 0.0)
        cap, dcap = self._capacity(tp, td, mu)
        diff = tp - td
        if -cap <= diff <= cap:  # sticks
            self._x_trial = x
            return td, -dtd
        sigma = 1.0 if diff > cap else -1.0
        if sigma > 0.0:
            lo, hi = x, max(x, base)
        else:
            lo, hi = min(x, g_mm), x
        for _ in range(60):
            tp, dtp = self._proximal(base - x)
            ed = x - g_mm
            td, dtd = (kd * ed, kd) if ed > 0.0 else (0.0, 0.0)
            cap, dcap = self._capacity(tp, td, mu)
            h = tp - td - sigma * cap
            if h > 0.0:
                lo = x
            else:
                hi = x
            if abs(h) < 1e-10 or hi - lo < 1e-12:
                break
            dh = -dtp - dtd - sigma * dcap * (dtd - dtp)
            step_ok = dh < 0.0
            xn = x - h / dh if step_ok else 0.5 * (lo + hi)
            x = xn if lo < xn < hi else 0.5 * (lo + hi)
        self._x_trial = x
        dh_dx = -dtp - dtd - sigma * dcap * (dtd - dtp)
        dh_dg = dtd * (1.0 + sigma * dcap)
        dx_dg = -dh_dg / dh_dx if dh_dx < 0.0 else 0.0
        return td, dtd * (dx_dg - 1.0)

    def commit(self, u_mm: float, g_mm: float) -> None:
        """Accept the last trial: the contact stays there; both tensions are kept for output."""
        x = self._x_trial
        self.x_mm = x
        self.tp_N = self._proximal(u_mm - self.slack_mm - x)[0]
        ed = x - g_mm
        self.td_N = self.kd_N_mm * ed if ed > 0.0 else 0.0


def wrap_rad(sheath_wrap_deg: float, curvature_deg: float) -> float:
    return math.radians(sheath_wrap_deg + curvature_deg)
