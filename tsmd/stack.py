"""Config (+ drives, profile, clock) -> a ready :class:`ControlLoop`: the one place that does it.

The daemon, replay, calibration and the benchmarks all build their loop here, so the knob
limits, the compensator and the limiter are derived from a configuration in one way only:
limits once from ``limits.*`` (already checked against the drive config by
:func:`tsmd.config.load_config`, and against the device's data sheet here when one is given),
the compensator for the profile and method, the limiter last in the loop.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from drivers.clock import Clock
from drivers.drive import KnobDrives
from simrig.plant import Plant, load_plant
from simrig.rig import SimRig, open_sim_rig
from tsmd.compensation import METHODS, Compensator, build_compensator
from tsmd.compensation.safety import KnobLimiter, KnobLimits
from tsmd.config import TsmdConfig, drive_configs
from tsmd.errors import TsmdError
from tsmd.loop import ControlLoop, TickRecorder
from tsmd.profile import CatheterProfile, DeviceModel


class StackError(TsmdError):
    """The loop cannot be built from this configuration; ``code`` names the part for the API."""

    def __init__(self, message: str, code: str = "stack") -> None:
        super().__init__(message)
        self.code = code


def knob_limits(config: TsmdConfig, device: DeviceModel | None = None
                ) -> tuple[KnobLimits, KnobLimits]:
    """The knobs' motion limits from ``limits.*``, refused when wider than the data sheet's."""
    limits = tuple(KnobLimits(k.min_deg, k.max_deg, k.max_velocity_deg_s, k.max_accel_deg_s2)
                   for k in config.limits.knobs())
    if device is not None:
        for name, lim, sheet in zip(("phi1", "phi2"), limits, device.limits, strict=True):
            if (lim.min_deg < sheet.min_deg or lim.max_deg > sheet.max_deg
                    or lim.max_velocity_deg_s > sheet.max_velocity_deg_s
                    or lim.max_accel_deg_s2 > sheet.max_accel_deg_s2):
                raise StackError(f"limits.{name} {lim} exceeds the data sheet of "
                                 f"{device.device_model}: {sheet}", "limits")
    return limits[0], limits[1]


def make_compensator(profile: CatheterProfile | None, method: str,
                     config: TsmdConfig) -> Compensator:
    """The compensator for ``profile`` (None: no compensation), pure and cheap to build.

    It knows the configured motor limits (when a jump across a dead zone must start) but does
    not apply them: the loop applies the limiter itself, last.
    """
    if profile is None:
        method = "none"
    try:
        return build_compensator(profile, method, config.loop.period_s, knob_limits(config),
                                 apply_limits=False,
                                 fresh_catheter=config.compensation.fresh_catheter)
    except (ValueError, TsmdError) as exc:
        raise StackError(f"cannot build the {method!r} compensator for "
                         f"{getattr(profile, 'catheter_id', '?')}: {exc}",
                         "compensation") from None


def make_standby(profile: CatheterProfile | None, method: str, active_method: str,
                 config: TsmdConfig) -> dict[str, Compensator]:
    """The configured ``method``'s compensator while another (none) is active: the loop keeps
    it following the motor, so switching it on mid-motion starts on the right branch.

    Only that one: a compensator standing by costs its model every tick (paper's: ~45 us of
    CPU per tick beside ours on the shared VM), and the operator switches compensation on and
    off, rarely the method (a switch of method starts the new one at rest).
    """
    if profile is None or method in ("none", active_method):
        return {}
    try:
        return {method: make_compensator(profile, method, config)}
    except StackError:
        return {}  # e.g. an older profile without the parameters of 'ours'


def build_loop(config: TsmdConfig, drives: KnobDrives, compensator: Compensator, clock: Clock,
               *, compensation_label: str,
               tip_source: Callable[[], Any] | None = None,
               after_sync: Callable[[], None] | None = None,
               recorder: TickRecorder | None = None,
               on_event: Callable[..., None] | None = None,
               standby: Mapping[str, Compensator] | None = None) -> ControlLoop:
    """The control loop of ``config`` on ``drives``, ticking on ``clock``; ``standby``
    compensators (:func:`make_standby`) follow the motor while not active."""
    if compensation_label not in METHODS:
        raise StackError(f"compensation label {compensation_label!r} is not one of "
                         f"{list(METHODS)}", "compensation")
    period_s = config.loop.period_s
    return ControlLoop(
        drives, compensator, KnobLimiter(knob_limits(config), period_s), period_s, clock,
        stale_feedback_syncs=config.loop.stale_feedback_syncs,
        overrun_fault_streak=config.loop.overrun_fault_streak,
        compensation_label=compensation_label, tip_source=tip_source, after_sync=after_sync,
        recorder=recorder, on_event=on_event, standby=standby)


def open_sim(config: TsmdConfig, seed: int, *, lockstep: bool, plant: Plant | None = None,
             **master_kwargs: Any) -> tuple[KnobDrives, SimRig]:
    """The simulated rig of ``config.sim`` (plant, drives, EM tracker noise) and its drives.

    ``master_kwargs`` go to the CANopen master (``receive="poll"`` for the daemon's loop).
    """
    if plant is None:
        plant = load_plant(config.sim.plant, config.sim.params)
    return open_sim_rig(plant, drive_configs(config), config.loop.period_s, seed,
                        lockstep=lockstep,
                        rig_kwargs={"tracker_noise_deg": config.sim.tracker_noise_deg},
                        **master_kwargs)
