"""What each API command does; runs in the API thread's asyncio loop.

Commands that change the drives go through the loop's command queue (executed between two
ticks by the loop thread); ``set`` replaces the atomic latest setpoint after checking it
against the knob limits. Slow work (reading a profile, calibrating) runs in worker threads.
"""

from __future__ import annotations

import asyncio
import math
import threading
from collections.abc import Callable
from typing import Any, Protocol

from drivers.drive import DriveError, DriveUnreachableError
from tsmd.api.protocol import ApiError, Request, ok
from tsmd.api.server import Connection
from tsmd.errors import TsmdError
from tsmd.loop import ControlLoop, LoopError, LoopState


class Services(Protocol):
    """What the daemon offers the API besides the loop (see tsmd.service.Service)."""

    loop: ControlLoop

    def status(self) -> dict[str, Any]: ...

    def sample(self) -> dict[str, Any] | None: ...

    def set_compensation(self, enabled: bool | None, method: str | None) -> dict[str, Any]: ...

    def load_profile(self, catheter: str | None) -> dict[str, Any]: ...

    def calibrate(self, catheter: str, progress: Callable[[dict[str, Any]], None],
                  cancel: threading.Event) -> dict[str, Any]: ...

    def cancel_calibration(self, reason: str) -> bool: ...

    def require_zero_reference(self, what: str) -> None: ...

    def home(self, drives: list[int] | None) -> dict[str, Any]: ...

    def set_online(self, enabled: bool | None) -> dict[str, Any]: ...

    def save_online(self) -> dict[str, Any]: ...


class ApiHandlers:
    """Turns a validated :class:`Request` into a response dict (or raises ApiError)."""

    def __init__(self, services: Services, *, max_subscribe_hz: float = 250.0,
                 command_timeout_s: float = 15.0) -> None:
        self.services = services
        self.max_subscribe_hz = max_subscribe_hz
        self.command_timeout_s = command_timeout_s

    @property
    def loop(self) -> ControlLoop:
        return self.services.loop

    async def __call__(self, request: Request, conn: Connection) -> dict[str, Any]:
        handler = getattr(self, f"_{request.cmd}")
        result: dict[str, Any] = await handler(request, conn)
        return ok(request.id, **result)

    async def _loop_command(self, name: str, **args: Any) -> Any:
        try:
            future = self.loop.post(name, **args)
        except LoopError as exc:
            raise ApiError(exc.code, str(exc)) from None
        try:
            return await asyncio.wait_for(asyncio.wrap_future(future), self.command_timeout_s)
        except TimeoutError:
            raise ApiError("timeout", f"{name}: the loop did not answer within "
                                      f"{self.command_timeout_s:g} s") from None
        except LoopError as exc:
            raise ApiError(exc.code, str(exc)) from None
        except DriveError as exc:  # unreachable (silent drive, bus-off) is a fault, not a refusal
            code = "fault" if isinstance(exc, DriveUnreachableError) else "drive"
            raise ApiError(code, f"{name}: {exc}") from None

    async def _status(self, request: Request, conn: Connection) -> dict[str, Any]:
        return self.services.status()

    def _zero_referenced(self, what: str) -> None:
        try:
            self.services.require_zero_reference(what)
        except TsmdError as exc:
            raise ApiError(getattr(exc, "code", "not_homed"), str(exc)) from None

    async def _enable(self, request: Request, conn: Connection) -> dict[str, Any]:
        self._zero_referenced("enable")
        return {"state": await self._loop_command("enable")}

    async def _home(self, request: Request, conn: Connection) -> dict[str, Any]:
        try:
            return await asyncio.to_thread(self.services.home, request.params.get("drives"))
        except TsmdError as exc:
            raise ApiError(getattr(exc, "code", "homing"), str(exc)) from None

    async def _disable(self, request: Request, conn: Connection) -> dict[str, Any]:
        self.services.cancel_calibration("disable")
        return {"state": await self._loop_command("disable")}

    async def _stop(self, request: Request, conn: Connection) -> dict[str, Any]:
        self.services.cancel_calibration("stop")  # it must end, not fail on the stopped loop
        return {"state": await self._loop_command("stop")}

    async def _reset(self, request: Request, conn: Connection) -> dict[str, Any]:
        return {"state": await self._loop_command("reset")}

    async def _set(self, request: Request, conn: Connection) -> dict[str, Any]:
        q = [float(v) for v in request.params["q"]]
        for i, (value, r) in enumerate(zip(q, self.loop.ranges(), strict=True)):
            if not (math.isfinite(value) and r.min_deg <= value <= r.max_deg):
                raise ApiError("out_of_range", f"set: q[{i}] = {value:g} deg is outside "
                                               f"[{r.min_deg:g}, {r.max_deg:g}]")
        state = self.loop.state
        if state is not LoopState.ENABLED:
            raise ApiError("not_enabled", f"set: the loop is {state.value}; send enable first")
        if self.loop.playing:
            raise ApiError("busy", "set: a calibration trajectory owns the knobs; cancel it first")
        self._zero_referenced("set")
        self.loop.setpoint.set((q[0], q[1]))
        return {"q": q}

    async def _get(self, request: Request, conn: Connection) -> dict[str, Any]:
        sample = self.services.sample()
        if sample is None:
            raise ApiError("no_sample", "get: the loop has not ticked yet")
        return {"sample": sample}

    async def _subscribe(self, request: Request, conn: Connection) -> dict[str, Any]:
        rate_hz = float(request.params.get("rate_hz", 50.0))
        if not 0 < rate_hz <= self.max_subscribe_hz:
            raise ApiError("out_of_range", f"subscribe: rate_hz {rate_hz:g} must be in "
                                           f"(0, {self.max_subscribe_hz:g}]")
        conn.start_task("subscribe", self._stream(conn, request.id, rate_hz))
        return {"rate_hz": rate_hz}

    async def _stream(self, conn: Connection, req_id: str | int | None, rate_hz: float) -> None:
        period = 1.0 / rate_hz
        last_tick = -1
        loop = asyncio.get_running_loop()
        next_t = loop.time()
        while not conn.closed and not conn.writer.transport.is_closing():
            latest = self.loop.latest_sample
            if latest is not None and latest.tick != last_tick:
                sample = self.services.sample()
                if sample is not None:
                    last_tick = int(sample["tick"])
                    conn.send_event({"id": req_id, "event": "sample", "sample": sample})
            next_t += period
            await asyncio.sleep(max(0.0, next_t - loop.time()))

    async def _unsubscribe(self, request: Request, conn: Connection) -> dict[str, Any]:
        return {"unsubscribed": conn.cancel_task("subscribe"), "dropped": conn.dropped}

    async def _compensation(self, request: Request, conn: Connection) -> dict[str, Any]:
        enabled = request.params.get("enabled")
        method = request.params.get("method")
        if enabled is None and method is None:
            return dict(self.services.status()["compensation"])
        try:
            return await asyncio.to_thread(self.services.set_compensation, enabled, method)
        except TsmdError as exc:
            raise ApiError(getattr(exc, "code", "compensation"), str(exc)) from None

    async def _profile(self, request: Request, conn: Connection) -> dict[str, Any]:
        try:
            return await asyncio.to_thread(self.services.load_profile,
                                           request.params.get("catheter"))
        except TsmdError as exc:
            raise ApiError(getattr(exc, "code", "profile"), str(exc)) from None

    async def _calibrate(self, request: Request, conn: Connection) -> dict[str, Any]:
        cancel = threading.Event()
        aio = asyncio.get_running_loop()

        def progress(info: dict[str, Any]) -> None:
            message = {"id": request.id, "event": "progress", **info}
            aio.call_soon_threadsafe(conn.send_event, message)

        watcher = asyncio.ensure_future(self._cancel_on_disconnect(conn, cancel))
        try:
            return await asyncio.to_thread(self.services.calibrate,
                                           request.params["catheter"], progress, cancel)
        except asyncio.CancelledError:
            # The connection closed (its tasks are cancelled): the worker thread would run on
            # with nobody to answer, so the calibration ends with its client.
            cancel.set()
            raise
        except TsmdError as exc:
            raise ApiError(getattr(exc, "code", "calibration"), str(exc)) from None
        finally:
            watcher.cancel()

    async def _cancel_on_disconnect(self, conn: Connection, cancel: threading.Event) -> None:
        while not conn.closed and not conn.writer.transport.is_closing():
            await asyncio.sleep(0.1)
        cancel.set()

    async def _cancel(self, request: Request, conn: Connection) -> dict[str, Any]:
        return {"cancelled": self.services.cancel_calibration("cancel command")}

    async def _online(self, request: Request, conn: Connection) -> dict[str, Any]:
        try:
            return await asyncio.to_thread(self.services.set_online,
                                           request.params.get("enabled"))
        except TsmdError as exc:
            raise ApiError(getattr(exc, "code", "online"), str(exc)) from None

    async def _online_save(self, request: Request, conn: Connection) -> dict[str, Any]:
        try:
            return await asyncio.to_thread(self.services.save_online)
        except TsmdError as exc:
            raise ApiError(getattr(exc, "code", "online"), str(exc)) from None
