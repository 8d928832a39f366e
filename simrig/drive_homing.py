"""Homing Mode (0x6060 = 6) of the simulated drive: the methods the master configures.

A relative encoder reads 0 wherever the motor was at power-up; homing finds a physical
reference and moves the encoder's zero so that the position reads ``-0x607C`` there:

- 37 (and its older number 35): the current position is home;
- -3 / -4: move in the positive / negative direction at 0x6099:01 until the motor current
  exceeds 0x2080 (the mechanism's hard stop, :attr:`Motor.travel_deg`); home is where it stopped;
- 34 / 33: move in the positive / negative direction at 0x6099:02 to the next encoder index
  pulse (one per motor revolution); home is the pulse.

Statusword bits 10/12/13 follow the CiA 402 homing table (not started, in progress, attained,
error).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from drivers import cia402
from drivers import od as o

if TYPE_CHECKING:  # the node owns this object; importing it here would be circular
    from simrig.drive_node import SimDriveNode

NOT_STARTED = cia402.SW_TARGET_REACHED
"""Homing interrupted or not started."""
IN_PROGRESS = 0
ATTAINED = cia402.SW_HOMING_ATTAINED | cia402.SW_TARGET_REACHED
ERROR = cia402.SW_HOMING_ERROR | cia402.SW_TARGET_REACHED
"""Homing error, velocity 0."""
HOMING_BITS = cia402.SW_TARGET_REACHED | cia402.SW_HOMING_ATTAINED | cia402.SW_HOMING_ERROR


class SimHoming:
    """Homing state of one simulated drive."""

    def __init__(self, node: SimDriveNode) -> None:
        self.node = node
        self.clear()

    def clear(self) -> None:
        """Power-on or reset: not started, nothing referenced."""
        self.bits = NOT_STARTED
        self.active = False
        self.method = 0
        self._direction = 0.0
        self._speed_deg_s = 0.0
        self._accel_deg_s2 = 0.0
        self._velocity_deg_s = 0.0
        self._target_deg = 0.0
        self._last_deg = 0.0

    def on_controlword(self, previous: int, cw: int) -> None:
        """Bit 4 rising: start; falling while active: interrupt."""
        start = cw & cia402.CW_HOMING_START
        if start and not previous & cia402.CW_HOMING_START:
            self._start()
        elif not start and self.active:
            self.interrupt()
            self.node.hold_position()

    def interrupt(self) -> None:
        """Stop searching without a reference (bit 4 cleared, drive left OPERATION ENABLED)."""
        self.active = False
        self.bits = NOT_STARTED

    def _start(self) -> None:
        node = self.node
        cpd = node.counts_per_deg
        self.method = int(node.value(o.HOMING_METHOD, 0))
        self.bits = IN_PROGRESS
        position = node.motor.position_deg
        if self.method in (35, 37):
            self._finish(position)
            return
        if self.method not in (-3, -4, 33, 34):
            self.bits = ERROR
            return
        self._direction = 1.0 if self.method in (-3, 34) else -1.0
        speed_sub = 1 if self.method in (-3, -4) else 2
        self._speed_deg_s = node.value(o.HOMING_SPEEDS, speed_sub) / cpd
        self._accel_deg_s2 = node.value(o.HOMING_ACCELERATION, 0) / cpd
        if self._speed_deg_s <= 0 or self._accel_deg_s2 <= 0:
            self.bits = ERROR  # a search needs a speed and an acceleration
            return
        self._velocity_deg_s = 0.0
        self._target_deg = position
        self._last_deg = position
        self.active = True

    def target_deg(self, dt_s: float) -> float:
        """Where the search moves this period (motor frame, knob degrees)."""
        if not self.active:
            return self.node.internal_target_deg
        goal = self._direction * self._speed_deg_s
        dv = self._accel_deg_s2 * dt_s
        v = self._velocity_deg_s
        v = goal if abs(goal - v) <= dv else v + math.copysign(dv, goal - v)
        self._velocity_deg_s = v
        self._target_deg += v * dt_s
        return self._target_deg

    def after_step(self, measured_current_A: float) -> None:
        """After the physics step: has the search found its reference?"""
        if not self.active:
            return
        node = self.node
        position = node.motor.position_deg
        if self.method in (-3, -4):
            threshold_A = node.value(o.HOMING_CURRENT_THRESHOLD, 0) * 1e-3
            if measured_current_A * self._direction >= threshold_A:
                self._finish(position)
        else:
            pitch = 360.0 / node.motor.gear_ratio
            before = math.floor((self._last_deg - node.index_phase_deg) / pitch)
            now = math.floor((position - node.index_phase_deg) / pitch)
            if now != before:
                self._finish(node.index_phase_deg + pitch * max(before, now))
        self._last_deg = position

    def _finish(self, home_deg: float) -> None:
        node = self.node
        offset_deg = node.value(o.HOME_OFFSET, 0) / node.counts_per_deg
        node.encoder_zero_deg = home_deg + offset_deg
        self.active = False
        self.bits = ATTAINED
        node.hold_position()
