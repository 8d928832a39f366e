"""The simulated rig: drive nodes + motors + catheter plant + EM tracker on a python-can bus.

Lockstep (default): nothing runs by itself. Each :meth:`SimRig.exchange` reads every pending
frame, advances the motors and the plant by one period on the rig's :class:`SimClock`, and sends
the TPDOs due on the SYNC it saw, so a run is bit-for-bit repeatable for a given seed.
Real time (``lockstep=False``): a thread serves the bus and keeps the physics on the wall clock,
in whole periods: a SYNC steps one period with the targets it latches, and the periods no SYNC
came for are stepped with the targets last latched (the drive holds them), so a late or missing
SYNC does not slow the catheter down.
"""

from __future__ import annotations

import itertools
import logging
import os
import threading
from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import can
import numpy as np
from numpy.typing import NDArray

from drivers.can_errors import error_frame
from drivers.canopen_master import CanOpenDrives
from drivers.clock import Clock, MonotonicClock, SimClock
from drivers.units import DriveConfig
from simrig.current_sensor import CurrentSensor
from simrig.drive_node import SimDriveNode
from simrig.lockstep_bus import Frame, LockstepBus, as_frame, make_message
from simrig.motor import Motor, MotorParams
from simrig.plant import Plant, as_plant_step, load_plant
from simrig.tracker import EmTracker

DEFAULT_PLANT = "simrig.plants.capstan:make_tendon_sheath_plant"
MAX_CATCH_UP_S = 0.25
"""Longest gap the real-time rig steps through at once; the rest of a longer gap (the process
stalled) is skipped and counted, not simulated in a CPU-burning burst."""
_CHANNELS = itertools.count()
_log = logging.getLogger(__name__)


class CurrentMeasurement(Protocol):
    """Turns the true motor current into what the drive's current sensor reports."""

    def measure(self, dt_s: float, current_A: float) -> float: ...


class IdealCurrentSensor:
    """No lag, offset or noise (used when the plant package provides no sensor model)."""

    def measure(self, dt_s: float, current_A: float) -> float:
        return current_A


def default_drive_configs() -> list[DriveConfig]:
    """Two knob drives, node ids 1 (phi1 anterior-posterior) and 2 (phi2 right-left)."""
    return [DriveConfig(node_id=1), DriveConfig(node_id=2)]


class SimRig:
    """Simulated drives, plant and tracker serving one python-can bus."""

    def __init__(self, bus: can.BusABC, plant: Plant, drive_configs: Sequence[DriveConfig],
                 period_s: float, seed: int = 0, *, lockstep: bool = True,
                 motor: MotorParams | None = None,
                 sensors: Sequence[CurrentMeasurement] | None = None,
                 current_sensor: Mapping[str, float] | None = None,
                 tracker: Any | None = None, tracker_noise_deg: float = 0.1,
                 own_bus: bool = True, clock: Clock | None = None,
                 max_catch_up_s: float = MAX_CATCH_UP_S) -> None:
        if len(drive_configs) != 2:
            raise ValueError(f"the rig drives two knobs, got {len(drive_configs)} drive configs")
        if lockstep and clock is not None:
            raise ValueError("a lockstep rig keeps its own simulated clock; clock is for real time")
        self.bus = bus
        self.plant = plant
        self.period_s = period_s
        self.seed = seed
        self.lockstep = lockstep
        self.clock: Clock = SimClock() if lockstep else clock or MonotonicClock()
        self._sim_clock = (self.clock if lockstep and isinstance(self.clock, SimClock)
                           else None)
        """The clock each lockstep step advances (a real-time rig only reads its clock)."""
        self._own_bus = own_bus
        self._send_owned = bus.send_owned if isinstance(bus, LockstepBus) else None
        self._take_frames = (bus.take_frames if isinstance(bus, LockstepBus) and bus.reads_frames
                             else None)
        params = motor or MotorParams()
        self.motors = [Motor(params, c.gear_ratio, period_s) for c in drive_configs]
        self.nodes = [
            SimDriveNode(c.node_id, m, c.counts_per_deg, self._send, vendor_id=c.vendor_id,
                         product_code=c.product_code or 0x402,
                         rated_current_mA=c.rated_current_mA)
            for c, m in zip(drive_configs, self.motors, strict=True)]
        self.sensors = (list(sensors) if sensors is not None
                        else _default_sensors(seed, current_sensor))
        self.tracker = (tracker if tracker is not None
                        else _default_tracker(seed, tracker_noise_deg))
        self.plant.reset()
        self._knob = np.zeros(2)
        self._tip = np.zeros(2)
        self._torque = [0.0, 0.0]
        self.ticks = 0
        self.max_catch_up_s = max_catch_up_s
        self.physics_s: float | None = None
        """Real time: the clock time the physics has been stepped to (None before serving)."""
        self.stalls = 0
        """Real time: gaps longer than ``max_catch_up_s``; ``stalled_s`` is the time skipped."""
        self.stalled_s = 0.0
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.error: BaseException | None = None

    # -- lockstep --------------------------------------------------------------------------
    def exchange(self) -> None:
        """Process all pending frames, advance one period, send the TPDOs due."""
        nodes = self.nodes
        now = self.clock.now_s()
        sync = False
        for cid, data, flags in self._pending_frames():
            if cid == 0x080:
                sync = True
                for n in nodes:
                    n.on_sync(now)
            elif not flags:  # a plain data frame
                for n in nodes:
                    n.on_frame(cid, data, now)
        self._advance(sync)

    def _pending_frames(self) -> list[Frame]:
        """Every frame received since the last tick: the lockstep bus's own tuples (no
        ``Message`` objects), or those of any other python-can bus, read until empty."""
        if self._take_frames is not None:
            return self._take_frames()
        frames = []
        recv = self.bus.recv
        while (msg := recv(0)) is not None:
            frames.append(as_frame(msg))
        return frames

    def _advance(self, sync: bool) -> None:
        dt = self.period_s
        nodes = self.nodes
        knob = self._knob
        for i, n in enumerate(nodes):
            knob[i] = n.motor.step(n.motion_target_deg(), n.powered)
        step = as_plant_step(self.plant.step(dt, knob))
        self._tip = step.tip_deg
        torque = step.knob_torque_Nm.tolist()
        if self._sim_clock is not None:
            self._sim_clock.advance(dt)
        now = self.clock.now_s()
        sensors = self.sensors
        for i, n in enumerate(nodes):
            tau = torque[i]
            current = n.motor.set_load(tau, n.powered)
            n.end_of_period(tau, sensors[i].measure(dt, current), now)
            n.transmit(sync, now)
        self.ticks += 1

    def _send(self, can_id: int, data: bytes) -> None:
        if self._send_owned is not None:
            self._send_owned(make_message(can_id, data))
        else:
            self.bus.send(can.Message(arbitration_id=can_id, data=data, is_extended_id=False))

    # -- evaluation ------------------------------------------------------------------------
    def tip_deg(self) -> NDArray[np.float64]:
        """EM tracker reading of the tip angle (ground truth for evaluation, with its noise)."""
        return np.asarray(self.tracker.measure(np.array(self._tip, dtype=float)), dtype=float)

    def tip_pair(self) -> tuple[float, float]:
        """:meth:`tip_deg` as two floats (the same values and noise draws; the loop's hot path)."""
        tip = self._tip
        pair = getattr(self.tracker, "measure_pair", None)
        if pair is None or not (type(tip) is np.ndarray and tip.dtype == np.float64
                                and tip.shape == (2,)):
            a, b = self.tip_deg().tolist()
            return a, b
        t0, t1 = tip.tolist()
        return pair(t0, t1)

    def true_tip_deg(self) -> NDArray[np.float64]:
        """Noise-free tip angle."""
        return np.array(self._tip, dtype=float)

    def knob_deg(self) -> NDArray[np.float64]:
        """True knob angles (motor positions)."""
        return self._knob.copy()

    # -- fault injection -------------------------------------------------------------------
    def inject_fault(self, kind: str, drive: int = 0, **kwargs: Any) -> None:
        """Make drive ``drive`` misbehave.

        ``emcy`` (``code``, default 0x2310 over-current): drive faults and sends the EMCY;
        ``following_error``: the motor jams until ``clear_fault``, the drive detects it;
        ``heartbeat_stop``: heartbeats stop, PDOs go on; ``silent``: the node sends nothing;
        ``corrupt``: the next TPDO is sent truncated; ``frame``: send a raw frame
        (``can_id``, ``data``) on the rig's side of the bus; ``reboot``: the drive power-cycles
        (boot-up message, parameters and PDO mapping lost, its relative encoder restarts at 0).
        Bus-wide (``drive`` ignored): ``error_frame`` (``classes``, ``data``: a SocketCAN error
        frame as linux/can/error.h defines it); ``bus_off`` / ``bus_restart``: the master's
        controller goes bus-off / is restarted (lockstep bus only: python-can's ``virtual``
        has no controller to switch off).
        """
        node = self.nodes[drive]
        if kind == "emcy":
            node.fault(int(kwargs.get("code", 0x2310)))
        elif kind == "following_error":
            node.motor.jammed = True
        elif kind == "heartbeat_stop":
            node.heartbeat_stopped = True
        elif kind == "silent":
            node.silent = True
        elif kind == "corrupt":
            node.corrupt_next_tpdo = True
        elif kind == "frame":
            self._send(int(kwargs["can_id"]), bytes(kwargs.get("data", b"")))
        elif kind == "reboot":
            node.reboot(self.clock.now_s())
        elif kind == "error_frame":
            self.bus.send(error_frame(int(kwargs["classes"]), bytes(kwargs.get("data", b""))))
        elif kind in ("bus_off", "bus_restart"):
            if not isinstance(self.bus, LockstepBus):
                raise ValueError(f"{kind} needs the lockstep bus (interface='lockstep')")
            for master_bus in self.bus.others():
                master_bus.set_bus_off(kind == "bus_off")
        else:
            raise ValueError(f"unknown fault kind {kind!r}; one of emcy, following_error, "
                             f"heartbeat_stop, silent, corrupt, frame, reboot, error_frame, "
                             f"bus_off, bus_restart")

    def clear_fault(self, drive: int = 0) -> None:
        """Undo every injected fault on ``drive`` (the drive's own FAULT state stays)."""
        node = self.nodes[drive]
        node.motor.jammed = False
        node.heartbeat_stopped = False
        node.silent = False
        node.corrupt_next_tpdo = False

    # -- real time -------------------------------------------------------------------------
    def start(self) -> None:
        """Serve the bus from a thread (real-time mode), the physics on the rig's clock."""
        if self.lockstep:
            raise RuntimeError("a lockstep rig is driven by exchange(), not a thread")
        self._stop.clear()
        self._thread = threading.Thread(target=self._serve, name="sim-rig", daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        try:
            wait_s = self.period_s / 4
            while not self._stop.is_set():
                self.serve(self.bus.recv(wait_s))
        except BaseException as exc:  # surfaced by stop()
            self.error = exc

    def serve(self, msg: can.Message | None) -> None:
        """One pass of the real-time server: handle ``msg`` (None: none came), then step the
        physics through the whole periods the clock has gone past.

        A SYNC first steps the periods before it under the old targets, then latches the new
        RPDOs and steps its own period at once (the TPDO answers it, as in lockstep). A SYNC
        always steps one period, even an early one, but the count of where the physics is never
        runs more than one period ahead of the clock, so early SYNCs do not eat later gaps.
        """
        now = self.clock.now_s()
        if self.physics_s is None:
            self.physics_s = now
        if msg is not None:
            cid = msg.arbitration_id
            if cid == 0x080:
                self._catch_up(now)
                for n in self.nodes:
                    n.on_sync(now)
                self._advance(True)
                self.physics_s = min(self.physics_s + self.period_s, now + self.period_s)
                return
            if not (msg.is_error_frame or msg.is_remote_frame or msg.is_extended_id):
                for n in self.nodes:
                    n.on_frame(cid, msg.data, now)
        self._catch_up(now)

    def _catch_up(self, now_s: float) -> None:
        """Step the periods between the physics and ``now_s`` that no SYNC stepped: each drive
        keeps the target it latched last (CSP with no new target holds it)."""
        period = self.period_s
        physics_s = self.physics_s if self.physics_s is not None else now_s
        steps = int((now_s - physics_s) / period)
        if steps <= 0:
            return
        max_steps = max(1, int(self.max_catch_up_s / period))
        if steps > max_steps:
            skipped_s = (steps - max_steps) * period
            self.stalls += 1
            self.stalled_s += skipped_s
            _log.warning("simulated rig stalled: %.3f s behind the clock, %.3f s of physics "
                         "skipped", steps * period, skipped_s)
            physics_s += skipped_s
            steps = max_steps
        for _ in range(steps):
            self._advance(False)
        self.physics_s = physics_s + steps * period

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        if self.error is not None:
            raise RuntimeError(f"simulated rig thread failed: {self.error}") from self.error

    def close(self) -> None:
        if self._thread is not None:
            self.stop()
        if self._own_bus:
            self.bus.shutdown()


DEFAULT_CURRENT_SENSOR: dict[str, float] = {
    "lag_s": 0.001, "offset_A": 0.002, "noise_A": 0.003, "spike_rate_hz": 0.2, "spike_A": 0.05}
"""Drive current measurement: 1 ms lag, 2 mA offset, 3 mA noise, rare 50 mA spikes."""


def _default_sensors(seed: int, params: Mapping[str, float] | None) -> list[CurrentMeasurement]:
    """The drive's current-sensor model, one per drive with its own seed."""
    kwargs = dict(DEFAULT_CURRENT_SENSOR if params is None else params)
    return [CurrentSensor(seed=seed + 1000 * (i + 1), **kwargs) for i in range(2)]


def _default_tracker(seed: int, noise_deg: float) -> EmTracker:
    return EmTracker(noise_deg=noise_deg, seed=seed + 7)


def open_sim_rig(plant: Plant | None, drive_configs: Sequence[DriveConfig] | None,
                 period_s: float, seed: int = 0, lockstep: bool = True,
                 channel: str | None = None, interface: str | None = None,
                 rig_kwargs: Mapping[str, Any] | None = None,
                 **master_kwargs: Any) -> tuple[CanOpenDrives, SimRig]:
    """A master and a simulated rig on a fresh in-process bus channel.

    Neither is booted: call ``drives.boot(); drives.enable()``. In lockstep the master's clock
    is ``rig.clock`` and its idle hook is ``rig.exchange``; per tick run
    ``drives.write_targets(cmd); drives.sync(); rig.exchange(); drives.pump()``.
    ``interface`` is ``"lockstep"`` (default in lockstep: :class:`LockstepBus`, no copies, no
    threads) or ``"virtual"`` (python-can's, default in real time). ``rig_kwargs`` go to
    :class:`SimRig` (``motor``, ``current_sensor``, ``tracker_noise_deg``...), the rest to
    :class:`CanOpenDrives`.
    """
    configs = list(drive_configs) if drive_configs is not None else default_drive_configs()
    if plant is None:
        plant = load_plant(DEFAULT_PLANT)
    if channel is None:
        channel = f"tsmd-sim-{os.getpid()}-{next(_CHANNELS)}"
    if interface is None:
        interface = "lockstep" if lockstep else "virtual"
    if interface == "lockstep":
        if not lockstep:
            raise ValueError("the lockstep bus is single-threaded; use interface='virtual'")
        rig_bus: can.BusABC = LockstepBus(channel, frames=True)
        master_bus: can.BusABC = LockstepBus(channel)
    elif interface == "virtual":
        rig_bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
        master_bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
    else:
        raise ValueError(f"sim rig interface must be 'lockstep' or 'virtual', not {interface!r}")
    rig = SimRig(rig_bus, plant, configs, period_s, seed, lockstep=lockstep,
                 **dict(rig_kwargs or {}))
    if lockstep:
        drives = CanOpenDrives(master_bus, configs, period_s, clock=rig.clock, idle=rig.exchange,
                               own_bus=True, **master_kwargs)
    else:
        master_kwargs.setdefault("receive", "notifier")
        drives = CanOpenDrives(master_bus, configs, period_s, own_bus=True, **master_kwargs)
        rig.start()
    return drives, rig
