"""The catalogue of candidate unmodelled effects, each a transform around the base simulator.

These are written here, independently of any plant's own effect switches: a user's real catheter
shares no code with our plant, so the diagnosis must recognise an effect from its signature, not
from the same function. Every candidate is neutral (the base simulator) at its neutral parameters.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.model import Candidate, View
from tsmd.gap.simulate import lowpass


def play(x: NDArray[np.float64], half_width: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Backlash (play) operator: the output moves only once the input is ``half_width`` away.

    ``half_width`` may vary per row (a friction band that widens and narrows).
    """
    if np.all(np.asarray(half_width) <= 0):
        return x.copy()
    y = np.empty_like(x)
    y[0] = x[0]
    lo, hi = x - half_width, x + half_width
    for k in range(1, len(x)):
        y[k] = np.minimum(np.maximum(y[k - 1], lo[k]), hi[k])
    return y


class KnobCoupling(Candidate):
    """The other knob's bend lengthens or shortens this knob's tendon path."""

    name = "coupling"
    title = "coupling between the knobs"
    physics = ("bending one plane changes the tendon path length of the other: its dead zone "
               "widens by w*(phi_other/90)^2 and shifts by s*(phi_other/90)")
    param_names = ("widen_deg", "shift_deg")
    lower = (-20.0, -15.0)
    upper = (20.0, 15.0)
    neutral = (0.0, 0.0)
    changes_input = True

    def knob(self, theta: NDArray[np.float64], view: View,
             knob_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        other = view.knob_deg[:, ::-1] / 90.0
        widen = theta[0] * other**2
        out = np.sign(knob_deg) * np.maximum(np.abs(knob_deg) - widen, 0.0)
        return out - theta[1] * other


class RateDependence(Candidate):
    """Sheath friction that grows with speed: wider backlash and more pull force when fast."""

    name = "rate"
    title = "rate dependence"
    physics = ("velocity-strengthened sheath friction: an extra play of half-width "
               "b*s/v90 between knob and tendon, s = the knob's sweep speed (|v| low-passed over "
               "1 s, so the loop of a fast sweep stays wide through its reversal; v90 = 90th "
               "percentile of |v|), and a pull torque growing with s")
    param_names = ("play_at_v90_deg",)
    lower = (0.0,)
    upper = (15.0,)
    neutral = (0.0,)
    changes_input = True
    sweep_tau_s = 1.0

    def sweep_speed(self, view: View) -> NDArray[np.float64]:
        """Per knob the sweep speed relative to its 90th percentile (about 1 when fast)."""
        speed = np.abs(view.vel_deg_s)
        v90 = np.maximum(np.percentile(speed, 90, axis=0), 1e-6)
        return lowpass(view.t_s, speed, self.sweep_tau_s) / v90

    def knob(self, theta: NDArray[np.float64], view: View,
             knob_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        width = theta[0] * self.sweep_speed(view)
        return np.column_stack([play(knob_deg[:, j], width[:, j]) for j in range(2)])

    def current_extra(self, theta: NDArray[np.float64], view: View,
                      knob: int) -> list[NDArray[np.float64]]:
        assert view.base_torque is not None
        return [view.base_torque[:, knob] * self.sweep_speed(view)[:, knob]]


class TendonCompliance(Candidate):
    """Tendon stretch under load: lost motion proportional to the knob torque."""

    name = "compliance"
    title = "tendon compliance"
    physics = ("elastic tendon: the pulley turns c degrees (at the reference torque) before the "
               "load reaches the tip; knob seen by the tip = knob - c*torque/torque_ref")
    param_names = ("stretch_deg",)
    lower = (-30.0,)
    upper = (30.0,)
    neutral = (0.0,)
    changes_input = True

    def __init__(self, torque_ref_Nm: NDArray[np.float64] | None = None) -> None:
        self.torque_ref_Nm = (np.ones(2) if torque_ref_Nm is None
                              else np.maximum(np.asarray(torque_ref_Nm, dtype=float), 1e-9))

    def knob(self, theta: NDArray[np.float64], view: View,
             knob_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        assert view.base_torque is not None
        return knob_deg - theta[0] * view.base_torque / self.torque_ref_Nm


class SheathCurvature(Candidate):
    """A curved sheath adds capstan friction: extra backlash and direction-dependent load."""

    name = "curvature"
    title = "sheath curvature / shape"
    physics = ("capstan friction of a curved sheath: extra play of half-width b between knob and "
               "tendon, and a torque gain that differs between pulling and releasing")
    param_names = ("extra_play_deg",)
    lower = (0.0,)
    upper = (15.0,)
    neutral = (0.0,)
    changes_input = True

    def knob(self, theta: NDArray[np.float64], view: View,
             knob_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        b = float(theta[0])
        return np.column_stack([play(knob_deg[:, j], b) for j in range(2)])

    def current_extra(self, theta: NDArray[np.float64], view: View,
                      knob: int) -> list[NDArray[np.float64]]:
        assert view.base_torque is not None
        v = view.vel_deg_s[:, knob]
        scale = max(float(np.percentile(np.abs(v), 90)), 1e-6) * 0.1
        return [view.base_torque[:, knob] * np.tanh(v / scale)]


class CurrentSensorDynamics(Candidate):
    """The current measurement chain low-pass filters the true motor current."""

    name = "sensor"
    title = "current-sensor dynamics"
    physics = "measured current = first-order lag (tau) of the motor current (filter, ADC chain)"
    param_names = ("tau_s",)
    lower = (0.0,)
    upper = (0.5,)
    neutral = (0.0,)

    def current_filter(self, theta: NDArray[np.float64], view: View,
                       regs: NDArray[np.float64]) -> NDArray[np.float64]:
        return lowpass(view.t_s, regs, float(theta[0]))


class DriftCreep(Candidate):
    """Slow changes over the run: tracker/sensor drift and viscoelastic creep of the section."""

    name = "drift"
    title = "drift / creep"
    physics = ("a linear drift in time of tip and current; creep of the section: the tip "
               "relaxes towards its slow (30 s) average, tip += k*(lowpass(tip) - tip); creep of "
               "the tendons: the bent tip loses angle in proportion to the load its tendon has "
               "carried so far (time integral of the bend on that side; creep strain grows with "
               "stress x time), at its own rate on each side")
    creep_tau_s = 30.0
    bent_deg = 5.0

    def tip_extra(self, theta: NDArray[np.float64], view: View,
                  knob: int) -> list[NDArray[np.float64]]:
        assert view.base_tip is not None
        t_run = view.t_s - view.series.t_s[0]
        tip = view.base_tip[:, knob]
        bent = np.tanh(tip / self.bent_deg)
        out = [t_run, lowpass(view.t_s, tip, self.creep_tau_s) - tip]
        for side in (np.maximum, np.minimum):
            load = side(tip, 0.0)
            carried = np.concatenate([[0.0], np.cumsum(0.5 * (load[1:] + load[:-1])
                                                       * np.diff(view.t_s))])
            scale = max(float(np.max(np.abs(carried))), 1e-9)
            out.append(carried / scale * side(bent, 0.0))
        return out

    def current_extra(self, theta: NDArray[np.float64], view: View,
                      knob: int) -> list[NDArray[np.float64]]:
        return [view.t_s - view.series.t_s[0]]


def catalogue(torque_ref_Nm: NDArray[np.float64] | None = None) -> list[Candidate]:
    """All candidates, in the order they are tried."""
    return [KnobCoupling(), RateDependence(), TendonCompliance(torque_ref_Nm),
            SheathCurvature(), CurrentSensorDynamics(), DriftCreep()]
