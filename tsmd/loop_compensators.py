"""The loop's compensators: the active one, and the ones standing by that follow the motor.

Switching compensation on mid-motion (the demo, an operator who first moves the knobs without
it) must start on the branch of the hysteresis the catheter is on. A compensator built at the
switch knows nothing of the motor's history, and a reset puts it at rest, which is wrong after
any motion. So the compensator standing by (``tsmd.stack.make_standby``: the configured
method's, while compensation is off) is fed, each enabled tick, what the motor was actually
sent (:meth:`tsmd.compensation.FollowsMotor.follow`), and one switched in takes the state of
the compensator of its own method that stood by (or was active) before. ``enable`` puts them all
at rest, the end of a trajectory the active one (its held angle may be a knob angle).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from tsmd.compensation import Compensator, FollowsMotor


class LoopCompensators:
    """The active compensator (``label``) and the others standing by, keyed by method."""

    def __init__(self, active: Compensator, label: str,
                 standby: Mapping[str, Compensator] | None = None) -> None:
        self.active = active
        self.label = label
        self.standby: dict[str, Compensator] = {}
        self._followers: tuple[FollowsMotor, ...] = ()
        self._set_standby(standby or {})

    def _set_standby(self, standby: Mapping[str, Compensator]) -> None:
        self.standby = {k: c for k, c in standby.items() if k != self.label}
        self._followers = tuple(c for c in self.standby.values() if isinstance(c, FollowsMotor))

    def reset(self, q_deg: np.ndarray) -> None:
        """All at rest at ``q_deg`` (enable, a trajectory's start): the loop's defined start."""
        self.active.reset(q_deg)
        for c in self.standby.values():
            c.reset(q_deg)

    def follow(self, q0: float, q1: float, cmd0: float, cmd1: float, dt_s: float) -> None:
        """The motor was sent (cmd0, cmd1) for the desired (q0, q1), ``dt_s`` after the last
        tick: those standing by follow."""
        followers = self._followers
        if not followers:
            return
        q, cmd = np.array((q0, q1)), np.array((cmd0, cmd1))
        for c in followers:
            c.follow(q, cmd, dt_s)

    def switch(self, active: Compensator, label: str, standby: Mapping[str, Compensator],
               q_deg: np.ndarray, *, keep_state: bool) -> None:
        """New compensators in; each takes the state of the outgoing one of its own method (same
        catheter, ``keep_state``), or starts at rest at ``q_deg``."""
        outgoing = {**self.standby, self.label: self.active}
        for name, c in ((label, active), *standby.items()):
            source = outgoing.get(name) if keep_state else None
            if (source is not None and type(source) is type(c)
                    and isinstance(c, FollowsMotor)):
                c.continue_from(source)
            else:
                c.reset(q_deg)
        self.active = active
        self.label = label
        self._set_standby(standby)
