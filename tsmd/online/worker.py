"""Online re-estimation beside the control loop: per-tick samples in, compensator updates out.

The loop calls :meth:`OnlineWorker.observe` once per tick (its ``observer`` hook): it appends
the tick's row to a bounded deque (atomic, no lock) and, if the worker published new knobs
since the last tick, hands them to the compensator, so an update always takes effect between
two ticks. Everything else (cutting strokes, fitting ramps, estimating, building the shifted
knobs) runs in :meth:`drain`, on the worker's own thread (:meth:`start`) or, for lockstep
simulation and tests, called synchronously every ``drain_every`` ticks.
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial
from typing import Any

from tsmd.online.apply import (
    GAIN_STEP,
    ONE_GAINS,
    ZERO_OFFSETS,
    Offsets,
    OnlineError,
    apply_knobs,
    edges_at,
    shifted_knob,
    towards,
)
from tsmd.online.bend import BendRelation, bend_targets
from tsmd.online.cross_knob import knob_shows
from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp, RampOptions, Rejected, Stroke
from tsmd.online.partner import holds_agreeing_suspect
from tsmd.online.segment import StrokeSegmenter
from tsmd.online.stroke_ramp import referred_stroke, stroke_ramp

RECORDING_COLUMNS: tuple[str, ...] = ("dz_off_pos1", "dz_off_neg1", "dz_off_pos2", "dz_off_neg2")
"""Recording columns for the applied offsets (deg, outward), one value per tick."""

EventSink = Callable[..., None]


class OnlineWorker:
    """Re-estimates each knob's dead-zone edge offsets and updates the compensator.

    ``columns``: the loop's row layout (``tsmd.loop.ROW_COLUMNS``); the worker reads ``t``,
    ``cmd1/2``, ``pos1/2``, ``cur1/2``. ``on_event(level, event, **fields)`` as the loop's.
    ``handle_slip_deg``: each knob's handle slip from the data sheet
    (:attr:`tsmd.profile.DeviceKnob.handle_slip_deg`); None keeps ``ramp``'s.
    ``ripple_period_deg``: each knob's handle torque ripple period from the data sheet
    (:attr:`tsmd.profile.DeviceKnob.torque_ripple_period_deg`, None for a knob without one):
    the loaded ramps are fitted to the current averaged over it; None keeps ``ramp``'s.
    ``fault_reason``: the loop's fault (``lambda: loop.fault_reason``); when the loop leaves
    ENABLED with a fault the freeze is a warning, otherwise (stop, disable, not yet enabled)
    the estimate pauses silently. ``bend``: the product's bend relation (data sheet's unit);
    with it each tendon's release line (not x0) moves with its edge as the relation says, in
    the share its slopes call a bend (:attr:`EdgeTracker.bend_weight`); None: x0 moves with
    the edge (a slack change's parametrisation).
    """

    def __init__(self, compensator: Any, period_s: float, columns: Sequence[str], *,
                 estimator: EstimatorOptions | None = None, ramp: RampOptions | None = None,
                 handle_slip_deg: tuple[float, float] | None = None,
                 ripple_period_deg: tuple[float | None, float | None] | None = None,
                 rate_deg_s: float = 4.0, gain_rate_per_s: float = 0.5,
                 queue_len: int = 8192, drain_every: int = 0,
                 on_event: EventSink | None = None,
                 fault_reason: Callable[[], str | None] | None = None,
                 bend: BendRelation | None = None) -> None:
        compensator = getattr(compensator, "inner", compensator)  # under a LimitedCompensator
        knobs = getattr(compensator, "knobs", None)
        if knobs is None or len(knobs) != 2:
            raise OnlineError("online re-estimation needs the 'ours' or 'paper' compensator, "
                              f"got {type(compensator).__name__}")
        self.compensator = compensator
        self.base_knobs: tuple[Any, Any] = (knobs[0], knobs[1])
        for k in self.base_knobs:
            shifted_knob(k, (0.0, 0.0))  # refuses a compensator it cannot shift, now
        self.period_s = period_s
        self.ramp_options = ramp or RampOptions()
        slip = handle_slip_deg or (self.ramp_options.handle_slip_deg,) * 2
        if not all(x > 0.0 for x in slip):  # also refuses NaN
            raise OnlineError(f"handle_slip_deg must be > 0 deg, got {slip}")
        ripple = ripple_period_deg or (self.ramp_options.torque_ripple_period_deg,) * 2
        if not all(p is None or p > 0.0 for p in ripple):
            raise OnlineError(f"ripple_period_deg must be > 0 deg or None, got {ripple}")
        self._knob_ramp = tuple(replace(self.ramp_options, handle_slip_deg=float(x),
                                        torque_ripple_period_deg=p)
                                for x, p in zip(slip, ripple, strict=True))
        self.fault_reason = fault_reason
        self.bend = bend
        options = estimator or EstimatorOptions()
        if bend is not None and bend.gain_per_slope > 0.0:  # its bends move no edge
            options = replace(options, knee_places_edge=False)
        self.trackers = {(knob, side): EdgeTracker(knob, side, options)
                         for knob in (0, 1) for side in (1, -1)}
        for (knob, side), tr in self.trackers.items():
            tr.partner = self.trackers[(knob, -side)]
        if options.other_knob_confirms:
            for (knob, _), tr in self.trackers.items():
                tr.other_knob_shows = partial(self._knob_shows, 1 - knob)
        self.rate_deg_s = rate_deg_s
        self.gain_rate_per_s = gain_rate_per_s
        self.gains: Offsets = ONE_GAINS
        self._gains_moving: Offsets = ONE_GAINS
        """The backlash gain ratios published with the knobs (pos, neg per knob)."""
        self.zero_loads: Offsets = ZERO_OFFSETS
        """The zero-load points' outward moves published with the knobs (pos, neg per knob)."""
        self.queue: collections.deque[tuple[tuple[float, ...], bool]] = collections.deque(
            maxlen=queue_len)
        self.drain_every = drain_every
        self.on_event = on_event
        self.events: collections.deque[dict[str, Any]] = collections.deque(maxlen=256)
        idx = {name: i for i, name in enumerate(columns)}
        self._i = [idx[c] for c in ("t", "cmd1", "cmd2", "pos1", "pos2", "cur1", "cur2")]
        self._segmenters = [StrokeSegmenter(0), StrokeSegmenter(1)]
        self.enabled = True
        self.published: tuple[int, Offsets, tuple[Any, Any]] = (0, ZERO_OFFSETS, self.base_knobs)
        """(version, offsets, knobs): replaced whole by the worker, read by the loop thread."""
        self._applied_version = 0
        self._ticks = 0
        self._t_last = None  # type: float | None
        self._t_publish = 0.0
        self._was_enabled = False
        self._stalled = [False, False]
        self._publish_lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # --- loop thread -----------------------------------------------------------------------

    def observe(self, row: tuple[float, ...], enabled: bool) -> None:
        """The loop's per-tick hook: queue the row, pick up a published update."""
        self.queue.append((row, enabled))
        published = self.published
        if published[0] != self._applied_version:
            apply_knobs(self.compensator, published[2])
            self._applied_version = published[0]
        if self.drain_every:
            self._ticks += 1
            if self._ticks % self.drain_every == 0:
                self.drain()

    # --- worker thread ---------------------------------------------------------------------

    def start(self, interval_s: float = 0.05) -> None:
        """Run :meth:`drain` every ``interval_s`` on a thread of its own."""
        if self._thread is not None:
            return

        def run() -> None:
            while not self._stop.wait(interval_s):
                self.drain()

        self._thread = threading.Thread(target=run, name="tsmd-online", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def drain(self) -> int:
        """Process every queued row; returns how many."""
        n = 0
        queue = self.queue
        t_now = self._t_last
        while queue:
            row, enabled = queue.popleft()
            n += 1
            t_now = self._sample(row, enabled)
        if t_now is not None:
            with self._publish_lock:
                self._publish(t_now)
        return n

    def _sample(self, row: tuple[float, ...], enabled: bool) -> float:
        t, c1, c2, p1, p2, i1, i2 = (row[j] for j in self._i)
        gap = self._t_last is not None and t - self._t_last > 2.5 * self.period_s
        self._t_last = t
        if not enabled or gap:
            for seg in self._segmenters:
                seg.discard()
            if not enabled and self._was_enabled:
                self._left_enabled()
            self._was_enabled = enabled
            return t
        self._was_enabled = True
        max_lag = self.ramp_options.max_lag_deg
        for knob, (cmd, pos, cur, other) in enumerate(((c1, p1, i1, p2), (c2, p2, i2, p1))):
            if abs(cmd - pos) > max_lag:  # the motor does not follow: stalled or blocked
                self._segmenters[knob].discard()
                if not self._stalled[knob]:
                    self._stalled[knob] = True
                    reason = f"the motor lags its command by more than {max_lag:g} deg"
                    for side in (1, -1):
                        self.trackers[(knob, side)].freeze(reason)
                    self._emit("warning", "online estimate frozen", knob=knob, reason=reason)
                continue
            self._stalled[knob] = False
            stroke = self._segmenters[knob].push(t, cmd, pos, cur, other)
            if stroke is not None:
                self._stroke(stroke)
        return t

    def _left_enabled(self) -> None:
        """The loop left ENABLED: the stroke under way is dropped and the edges freeze for
        two ramps (the knobs may have been moved by hand meanwhile). Only a fault warns; a
        stop or disable is ordinary use."""
        fault = self.fault_reason() if self.fault_reason is not None else None
        reason = f"the loop faulted ({fault})" if fault else "the loop was stopped or disabled"
        for tr in self.trackers.values():
            tr.freeze(reason)
        if fault:
            self._emit("warning", "online estimate frozen", reason=reason)

    def _stroke(self, stroke: Stroke) -> None:
        knob, side = stroke.knob, stroke.direction
        tracker = self.trackers[(knob, side)]
        stroke, edge = referred_stroke(stroke, self.base_knobs[knob])
        ramp = stroke_ramp(stroke, edge, tracker, self._knob_ramp[knob])
        if isinstance(ramp, Rejected):
            if ramp.stall:
                tracker.freeze(ramp.reason)
                self._emit("warning", "online estimate frozen", knob=knob, reason=ramp.reason)
            return
        self._ramp(tracker, ramp)

    def _ramp(self, tracker: EdgeTracker, ramp: LoadedRamp) -> None:
        d_pos, d_neg = edges_at(self.base_knobs[ramp.knob], ramp.other_deg)
        before, level_before = tracker.applied_deg, tracker.level_deg
        other = self.trackers[(ramp.knob, -ramp.side)]
        events = tracker.update(ramp, d_pos if ramp.side > 0 else d_neg, other)
        if tracker.level_deg != level_before and holds_agreeing_suspect(
                other, tracker.level_deg, tracker.options.confirm_spread_deg):
            events += self._follow_other(other, other.suspects[-1],
                                         "both edges of the knob agree", "")
        bend = (tracker.bend_suspect and tracker.options.follow_bend_at_once
                and other.frozen_for == 0)
        if bend or self._knob_agrees(tracker, other):
            value = tracker.suspects[-1]
            why = ("a bend on both tendons of the knob" if bend
                   else "both edges of the knob agree")
            events += tracker.follow(value, why)
            events += self._follow_other(other, value if bend else other.suspects[-1], why,
                                         "knee" if bend else "")
        for level, event, fields in events:
            self._emit(level, event, **fields)
        if tracker.applied_deg != before:
            self._emit_offset(tracker)
        if tracker.other_knob_shows is not None and tracker.applied_deg != before:
            # this knob's change may be what the other knob's held suspects waited for
            held, held_other = self.trackers[(1 - ramp.knob, 1)], self.trackers[(1 - ramp.knob, -1)]
            if self._knob_agrees(held, held_other):
                why = "both edges of the knob agree"
                events = self._follow_other(held, held.suspects[-1], why, "")
                events += self._follow_other(held_other, held_other.suspects[-1], why, "")
                for level, event, fields in events:
                    self._emit(level, event, **fields)

    @staticmethod
    def _knob_agrees(tracker: EdgeTracker, other: EdgeTracker) -> bool:
        """Both edges of a knob hold agreeing suspects, and the other knob shows the change
        too when that is asked (:attr:`EdgeTracker.other_knob_shows`)."""
        return tracker.agrees_with(other) and tracker.confirmed_elsewhere(tracker.suspects[-1])

    def _follow_other(self, other: EdgeTracker, value: float, why: str, feature: str
                      ) -> list[tuple[str, str, dict[str, Any]]]:
        before = other.applied_deg
        events = other.follow(value, why, feature)
        if other.applied_deg != before:
            self._emit_offset(other)
        return events

    def _emit_offset(self, tracker: EdgeTracker) -> None:
        self._emit("info", "online offset", knob=tracker.knob,
                   side="pos" if tracker.side > 0 else "neg",
                   offset_deg=round(tracker.applied_deg, 3),
                   confidence=round(tracker.confidence, 2))

    def _knob_shows(self, knob: int, direction: int) -> bool:
        """Whether ``knob``'s edges show a change ``direction`` (:func:`knob_shows`)."""
        return knob_shows((self.trackers[(knob, 1)], self.trackers[(knob, -1)]), direction)

    def _targets(self) -> Offsets:
        return self._per_edge("applied_deg") if self.enabled else ZERO_OFFSETS

    def _zero_load_targets(self) -> Offsets:
        if not self.enabled:
            return ZERO_OFFSETS
        return self._per_edge("zero_load_deg") if self.bend is None else self._bend_targets()[0]

    def _gain_targets(self) -> Offsets:
        if not self.enabled:
            return ONE_GAINS
        if self.bend is None or not self.trackers[(0, 1)].options.gain_from_bend:
            return self._per_edge("gain_ratio")
        return self._bend_targets()[1]

    def _bend_targets(self) -> tuple[Offsets, Offsets]:
        assert self.bend is not None
        return bend_targets(self.bend, self.trackers, self.base_knobs)

    def _per_edge(self, name: str) -> Offsets:
        """One tracker value per (knob, side), in the published offsets' layout."""
        def value(knob: int, side: int) -> float:
            return float(getattr(self.trackers[(knob, side)], name))
        return ((value(0, 1), value(0, -1)), (value(1, 1), value(1, -1)))

    def _publish(self, t_s: float) -> None:
        """Move the published offsets towards the targets at ``rate_deg_s`` and the backlash
        gain ratios at ``gain_rate_per_s`` (smoothly)."""
        version, current, _ = self.published
        dt = max(t_s - self._t_publish, 0.0)
        self._t_publish = t_s
        new = towards(current, self._targets(), self.rate_deg_s * dt)
        zero_loads = towards(self.zero_loads, self._zero_load_targets(), self.rate_deg_s * dt)
        targets = self._gain_targets()
        self._gains_moving = towards(self._gains_moving, targets, self.gain_rate_per_s * dt)
        gains = self._gains_moving
        if (max(abs(a - b) for g, h in zip(gains, self.gains, strict=True)
                for a, b in zip(g, h, strict=True)) < GAIN_STEP and gains != targets):
            gains = self.gains  # rebuilding the knobs costs ~0.1 s: in steps of GAIN_STEP
        if new == current and gains == self.gains and zero_loads == self.zero_loads:
            return
        old_knobs = self.published[2]
        knobs = tuple(  # a knob whose values did not move is kept (a rebuild costs ~65 ms)
            old_knobs[k] if (new[k], gains[k], zero_loads[k]) == (
                current[k], self.gains[k], self.zero_loads[k])
            else shifted_knob(self.base_knobs[k], new[k], gains[k], zero_loads[k],
                              self.omega_per_gain)
            for k in (0, 1))
        self.gains = gains
        self.zero_loads = zero_loads
        self.published = (version + 1, new, (knobs[0], knobs[1]))

    # --- control and reporting (any thread) --------------------------------------------------

    def set_enabled(self, enabled: bool) -> None:
        """Switch re-estimation off (the profile's values come back at once) or on again."""
        with self._publish_lock:  # not the loop's lock: the loop only reads ``published``
            self.enabled = enabled
            if not enabled:
                version = self.published[0]
                self.gains = self._gains_moving = ONE_GAINS
                self.zero_loads = ZERO_OFFSETS
                self.published = (version + 1, ZERO_OFFSETS, self.base_knobs)
        self._emit("info", "online re-estimation", enabled=enabled)

    @property
    def omega_per_gain(self) -> float | None:
        """How the published knobs' omega moves with beta: the bend relation's
        (:attr:`BendRelation.omega_per_gain`), None: the release-slope relation."""
        return None if self.bend is None else self.bend.omega_per_gain

    def offsets(self) -> Offsets:
        """The offsets in force (published to the loop)."""
        return self.published[1]

    def status(self) -> dict[str, Any]:
        """For the API's ``status``: the offsets in force and each edge's estimator."""
        off = self.published[1]
        return {"enabled": self.enabled, "version": self.published[0],
                "offsets_deg": [list(off[0]), list(off[1])],
                "backlash_gain_ratios": [list(self.gains[0]), list(self.gains[1])],
                "zero_load_offsets_deg": [list(self.zero_loads[0]), list(self.zero_loads[1])],
                "bend_relation": None if self.bend is None else {
                    "release_per_edge": self.bend.release_per_edge,
                    "gain_per_release_deg": self.bend.gain_per_release_deg,
                    "gain_per_slope": self.bend.gain_per_slope,
                    "omega_per_gain": self.bend.omega_per_gain},
                "edges": {f"phi{k + 1}_{'pos' if s > 0 else 'neg'}": tr.status()
                          for (k, s), tr in self.trackers.items()},
                "events": list(self.events)[-5:]}

    def recording_values(self) -> tuple[float, float, float, float]:
        """The row for :data:`RECORDING_COLUMNS`."""
        off = self.published[1]
        return (off[0][0], off[0][1], off[1][0], off[1][1])

    def _emit(self, level: str, event: str, **fields: Any) -> None:
        self.events.append({"level": level, "event": event, "t": self._t_last, **fields})
        if self.on_event is not None:
            self.on_event(level, event, **fields)

