"""The matched-condition protocol: the same knob motion under different conditions.

A real catheter's base physics differ from any simulator's by more than most unmodelled
effects move the tip, so an effect is looked for as a *difference inside the data*: the same
motion at two speeds (rate), the same sweep with the other knob held at different angles
(coupling), dwells with the tendon loaded and unloaded (creep). Whatever the base physics, it
is the same in matched segments and cancels. The recording carries the design: a per-row
column ``segment`` (index into the table, -1 outside the matched windows) and a header line
``segments`` listing ``test:level:rep:knob`` per segment (:func:`encode_table`).

Segments of one test are played in palindromic order (A B B A, or 0 +B -B -B +B 0), so a
linear drift over the test cancels in the level means and shows in the repeats instead.
Ramps move at constant speed on a lattice of knob angles shared by every speed, so matched
segments are sampled at the same knob angles and compared sample by sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.errors import GapError
from tsmd.recording import Recording

FloatArray = NDArray[np.float64]

TESTS: tuple[str, ...] = ("rate", "coupling", "creep")
"""Tests of the protocol; each names the signature it decides (creep decides ``drift``)."""


@dataclass(frozen=True)
class Segment:
    """One matched window: the test, the condition level, its repeat, the knob it is about."""

    test: str
    level: str
    rep: int
    knob: int
    """0 or 1: the knob whose loop or dwell is compared (-1: both knobs, e.g. the rate test)."""


@dataclass(frozen=True)
class ProtocolDesign:
    """Amplitudes, speeds and dwell lengths of the protocol (knob deg, deg/s, s)."""

    amp_deg: float = 40.0
    slow_deg_s: float = 20.0
    fast_deg_s: float = 80.0
    coupling_deg_s: float = 40.0
    other_deg: float = 50.0
    """Where the other knob is held in the coupling test (0, +, -)."""
    dwell_amp_deg: float = 60.0
    heavy_amp_deg: float = 0.0
    """When above 0, the protocol ends with two cycles of both knobs at this amplitude: slow
    reversals at a third, heavier load, for a compliance figure from loads further apart while
    the usual pair keeps testing its premise; appended, so every earlier sample is as without
    them (in the warm-up they changed the 60 deg reversals' history and warmgear's release
    spread; docs/gap.md "Session 26"). 0: no such cycles."""
    dwell_s: float = 20.0
    rest_s: float = 10.0
    settle_s: float = 1.0
    """A dwell's first second is not compared (the catheter comes to rest)."""


class _Builder:
    """Appends constant-speed ramps and dwells on the sample lattice, labelling windows."""

    def __init__(self, rate_hz: float) -> None:
        self.dt = 1.0 / rate_hz
        self.q: list[FloatArray] = [np.zeros((1, 2))]
        self.label: list[FloatArray] = [np.full(1, -1.0)]
        self.table: list[Segment] = []

    @property
    def pos(self) -> FloatArray:
        return self.q[-1][-1]

    def ramp(self, target: tuple[float, float], speed_deg_s: float,
             label: int = -1) -> None:
        start = self.pos.copy()
        dist = float(np.max(np.abs(np.asarray(target) - start)))
        n = max(round(dist / (speed_deg_s * self.dt)), 1)
        frac = np.arange(1, n + 1)[:, None] / n
        self.q.append(start + frac * (np.asarray(target) - start))
        self.label.append(np.full(n, float(label)))

    def dwell(self, duration_s: float, label: int = -1, settle_s: float = 0.0) -> None:
        n = max(round(duration_s / self.dt), 1)
        lab = np.full(n, float(label))
        lab[: round(settle_s / self.dt)] = -1.0
        self.q.append(np.repeat(self.pos[None, :], n, axis=0))
        self.label.append(lab)

    def segment(self, seg: Segment) -> int:
        self.table.append(seg)
        return len(self.table) - 1

    def loop(self, knob: int, amp: float, speed: float, other: float | None,
             seg: Segment, warm: int = 0) -> None:
        """0 -> +A -> -A -> +A -> 0 on ``knob`` (both when ``other`` is None); the closed loop
        from the last but one arrival at +A to the last is the matched window. ``warm`` loops
        at the same speed go first: a rate-dependent catheter keeps the previous speed's
        friction state in its loop, one loop at the new speed wipes it."""
        def at(x: float) -> tuple[float, float]:
            if other is None:
                return (x, x)
            return (x, other) if knob == 0 else (other, x)
        label = self.segment(seg)
        self.ramp(at(amp), speed)
        for _ in range(warm):
            self.ramp(at(-amp), speed)
            self.ramp(at(amp), speed)
        self.ramp(at(-amp), speed, label)
        self.ramp(at(amp), speed, label)
        self.ramp(at(0.0), speed)


def lattice_amp(amp_deg: float, speeds: tuple[float, ...], rate_hz: float) -> float:
    """The amplitude nearest ``amp_deg`` that every speed reaches in a whole number of samples
    (so all speeds sample the same knob angles)."""
    step = max(speeds) / rate_hz
    return max(round(amp_deg / step), 1) * step


def protocol(rate_hz: float, design: ProtocolDesign | None = None) -> tuple[
        FloatArray, FloatArray, FloatArray, list[Segment]]:
    """The protocol's time (s), knob angles (n x 2, deg), segment column and segment table."""
    p = design or ProtocolDesign()
    if p.fast_deg_s % p.slow_deg_s:
        raise GapError("protocol: the fast speed must be a whole multiple of the slow one")
    b = _Builder(rate_hz)
    amp = lattice_amp(p.amp_deg, (p.fast_deg_s,), rate_hz)
    # warm-up: the start from a straight catheter is a state no later motion returns to
    for _ in range(2):
        b.ramp((p.dwell_amp_deg, p.dwell_amp_deg), p.coupling_deg_s)
        b.ramp((-p.dwell_amp_deg, -p.dwell_amp_deg), p.coupling_deg_s)
    b.ramp((0.0, 0.0), p.coupling_deg_s)
    for rep, name in enumerate(("slow", "fast", "fast", "slow")):
        speed = p.slow_deg_s if name == "slow" else p.fast_deg_s
        b.loop(0, amp, speed, None, Segment("rate", name, rep // 2, -1), warm=1)
    c_amp = lattice_amp(p.amp_deg, (p.coupling_deg_s,), rate_hz)
    for knob in (0, 1):
        for rep, level in enumerate((0.0, 1.0, -1.0, -1.0, 1.0, 0.0)):
            other = level * p.other_deg
            hold = (0.0, other) if knob == 0 else (other, 0.0)
            b.ramp(hold, p.coupling_deg_s)
            b.loop(knob, c_amp, p.coupling_deg_s, other,
                   Segment("coupling", f"{level:+.0f}", int(rep >= 3), knob))
        b.ramp((0.0, 0.0), p.coupling_deg_s)
    for rep, side in enumerate((1.0, -1.0)):
        a = side * p.dwell_amp_deg
        b.ramp((a, a), p.coupling_deg_s)
        b.dwell(p.dwell_s, b.segment(Segment("creep", "loaded", rep, -1)), p.settle_s)
        b.ramp((0.0, 0.0), p.coupling_deg_s)
        b.dwell(p.rest_s, b.segment(Segment("creep", "unloaded", rep, -1)), p.settle_s)
    if p.heavy_amp_deg > 0.0:  # appended: every earlier sample stays as it was
        for _ in range(2):
            b.ramp((p.heavy_amp_deg, p.heavy_amp_deg), p.coupling_deg_s)
            b.ramp((-p.heavy_amp_deg, -p.heavy_amp_deg), p.coupling_deg_s)
        b.ramp((0.0, 0.0), p.coupling_deg_s)
    q = np.vstack(b.q)
    t = np.arange(len(q), dtype=float) * b.dt
    return t, q, np.concatenate(b.label), b.table


def protocol_trajectory(rate_hz: float, configuration: str = "") -> Recording:
    """The protocol as a trajectory file for ``tsmd replay``: ``t,q1,q2`` plus the ``segment``
    column and the ``segments`` header, which the replay carries into its recording. Made at
    the loop's rate, each tick plays one sample (the matched loops stay on one knob lattice)."""
    t, q, seg, table = protocol(rate_hz)
    meta = {"source": f"tsmd gap protocol ({rate_hz:g} Hz)", "segments": encode_table(table)}
    if configuration:
        meta["configuration"] = configuration
    return Recording({"t": t, "q1": q[:, 0], "q2": q[:, 1], "segment": seg}, meta)


def encode_table(table: list[Segment]) -> str:
    """The header value listing the segments: ``test:level:rep:knob`` separated by ``;``."""
    return ";".join(f"{s.test}:{s.level}:{s.rep}:{s.knob}" for s in table)


def decode_table(text: str, source: str) -> list[Segment]:
    """Parse :func:`encode_table`'s format; one clear error for a malformed entry."""
    out = []
    for i, item in enumerate(t for t in text.split(";") if t.strip()):
        parts = item.strip().split(":")
        try:
            test, level, rep, knob = parts
            seg = Segment(test, level, int(rep), int(knob))
        except ValueError:
            raise GapError(f"{source}: header 'segments' entry {i} {item!r}: expected "
                           "test:level:rep:knob") from None
        if seg.test not in TESTS or seg.knob not in (-1, 0, 1):
            raise GapError(f"{source}: header 'segments' entry {i} {item!r}: test must be one "
                           f"of {', '.join(TESTS)} and knob -1, 0 or 1")
        out.append(seg)
    return out
