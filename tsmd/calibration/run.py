"""Running a calibration: the protocol over a trajectory runner, or logged sweeps offline.

Both paths go through :func:`identify_recording` (one recording = one sweep) and
:func:`finish`: the quality checks, H from the data sheet, our compensator's fit, the profile.
Nothing is saved here: the caller saves the returned profile (so a cancelled or refused
calibration never leaves a half-written profile).
"""

from __future__ import annotations

import contextlib
import math
import multiprocessing
import os
import threading
import time
from collections.abc import Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, field, replace

import numpy as np

from tsmd import __version__
from tsmd.calibration.assemble import (
    KNOB_LABELS,
    GridPoint,
    QualityLimits,
    QualityReport,
    build_profile,
    check_quality,
    cross_check_device,
)
from tsmd.calibration.dead_zone_loop import play_loops, wants_loop
from tsmd.calibration.errors import (
    CalibrationCancelledError,
    CalibrationError,
    CalibrationRefusedError,
)
from tsmd.calibration.estimate import EstimateOptions
from tsmd.calibration.identify import IdentifyOptions, identify_sweep
from tsmd.calibration.options import device_options
from tsmd.calibration.paper_frame import with_paper_frame
from tsmd.calibration.play_creep import check_play_creep
from tsmd.calibration.player import (
    Player,
    Progress,
    ProgressCallback,
)
from tsmd.calibration.protocol import Protocol as SweepProtocol
from tsmd.calibration.protocol import paper_protocol, sweep_run
from tsmd.calibration.reading_offset import REPORT_MIN_OFFSET_DEG, corrected, left_u95_deg
from tsmd.calibration.recovery import with_unseen
from tsmd.calibration.resweep import (
    budget_spent_note,
    choose_resweep,
    pool_repeats,
    pooled,
    uncertain_points,
)
from tsmd.calibration.sample_offset import with_sample_offset
from tsmd.calibration.tension_play_fit import PlateauGaps, with_prefit, with_tension_play
from tsmd.calibration.unit_part import with_unit_part
from tsmd.profile import CatheterProfile, DeviceModel
from tsmd.recording import Recording
from tsmd.trajectory import TrajectoryRunner


@dataclass
class Calibration:
    """A finished calibration: the profile and everything that went into it (for the report)."""

    profile: CatheterProfile
    points: list[GridPoint]
    quality: QualityReport
    protocol_name: str = ""
    sweep_time_s: float = 0.0
    """Simulated or real time spent sweeping (what the paper's 700 s counts)."""
    motion_time_s: float = 0.0
    """All knob motion including moves between sweeps."""
    wall_time_s: float = 0.0
    notes: list[str] = field(default_factory=list)


def _meta_float(rec: Recording, key: str) -> float | None:
    text = rec.metadata.get(key)
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise CalibrationError(f"metadata {key!r} is not a number: {text!r}") from None
    if not math.isfinite(value):
        raise CalibrationError(f"metadata {key!r} is not finite: {text!r}")
    return value


KnobOptions = IdentifyOptions | tuple[IdentifyOptions, IdentifyOptions] | None
"""One identification for both knobs, or one per knob (:func:`device_options`)."""


def identify_recording(rec: Recording, options: KnobOptions = None,
                       source: str = "recording") -> GridPoint:
    """One recording holding one sweep -> a grid point (swept knob and other angle inferred
    from the metadata when present, else from which knob moved)."""
    for col in ("t", "cmd1", "cmd2", "pos1", "pos2", "cur1", "cur2"):
        if col not in rec.columns:
            raise CalibrationError(f"{source}: no column {col!r}")
    knob_name = rec.metadata.get("calibration_knob")
    if knob_name is not None:
        if knob_name not in KNOB_LABELS:
            raise CalibrationError(f"{source}: calibration_knob {knob_name!r} not in "
                                   f"{KNOB_LABELS}")
        knob = KNOB_LABELS.index(knob_name)
    else:
        spans = [float(np.nanmax(rec[f"cmd{k}"]) - np.nanmin(rec[f"cmd{k}"])) for k in (1, 2)]
        knob = int(np.argmax(spans))
    start_s = _meta_float(rec, "calibration_sweep_start_s")
    other_cmd = rec[f"cmd{2 - knob}"]
    t = rec["t"]
    in_sweep = t >= start_s if start_s is not None else np.ones(len(t), dtype=bool)
    other = _meta_float(rec, "calibration_other_deg")
    held = other_cmd[in_sweep & np.isfinite(other_cmd)]
    if held.size == 0:
        raise CalibrationError(f"{source}: no valid sample of the other knob")
    if float(np.ptp(held)) > 1.0:
        raise CalibrationError(
            f"{source}: both knobs move (the other knob spans {np.ptp(held):.1f} deg); "
            "a calibration sweep holds the other knob still")
    if other is None:
        other = float(np.round(np.median(held), 1))
    k = knob + 1
    try:
        opts = options[knob] if isinstance(options, tuple) else options
        result = identify_sweep(t, rec[f"cmd{k}"], rec[f"pos{k}"], rec[f"cur{k}"], opts,
                                sweep_start_s=start_s)
    except CalibrationError as exc:
        raise CalibrationError(f"{source} ({KNOB_LABELS[knob]} sweep): {exc}") from None
    seen = with_unseen(result, opts, other)
    offset = opts.reading_offset if opts else None
    slope = opts.release_slope if opts else None
    part = opts.unit_part if opts else None
    # reported values: every sure offset; our compensator's fit: its own frame (session 26)
    left = {name: left_u95_deg(offset, name, other, REPORT_MIN_OFFSET_DEG)
            for name in seen.values}
    # The play's end is searched past the line rule's end; a stick end's offset is no play
    # (pronyring's -5 deg: no step in 12 of 12 half-cycles, a creep warning on every unit).
    play = not (opts is not None and opts.backlash_stick_end)
    # the sample's one-sided miss: reported values only (session 28)
    report = with_sample_offset(corrected(seen, offset, other, slope, REPORT_MIN_OFFSET_DEG, play),
                                dict(part.offsets_deg) if part is not None else {})
    found = with_unit_part(report, part, left)
    model = with_unit_part(corrected(seen, offset, other, slope, read_play=play), part, left)
    same = model.values == found.values
    return GridPoint(knob, other, found, rec, model_result=None if same else model)


def finish(catheter_id: str, device: DeviceModel, points: list[GridPoint], *,
           limits: QualityLimits | None = None, amplitude_deg: float = 90.0,
           source: str = "calibration from motor current",
           plateau_gaps: PlateauGaps = None) -> tuple[CatheterProfile, QualityReport]:
    """Quality checks, our compensator's fit and the profile (CalibrationError if refused);
    ``plateau_gaps``: each knob's dead-zone loop gap where one was played."""
    report = check_quality(points, limits, amplitude_deg,
                           omegas=tuple(k.omega for k in device.knobs))
    # Before refusing: a backlash far below the data sheet's often explains cycles that disagree.
    cross_check_device(points, device, report,
                       (limits or QualityLimits()).estimate.max_tip_error_deg)
    # A play whose end moves over the grid: the tip crept while it opened (B widened in points).
    check_play_creep(points, report)
    try:
        report.raise_if_bad()
    except CalibrationError as exc:
        raise CalibrationRefusedError(str(exc), points) from None
    profile = build_profile(catheter_id, device, points, quality=report,
                            software_version=__version__, source=source)
    model = [p.in_model_frame() for p in points]
    if any(p.model_result is not None for p in points):  # the paper's frame is ours' (s27)
        profile = with_paper_frame(profile, build_profile(
            catheter_id, device, model, quality=report, software_version=__version__,
            source=source))
    try:
        profile = with_tension_play(profile, model, device, plateau_gaps)
    except (ValueError, ArithmeticError) as exc:
        raise CalibrationError(f"our compensator's fit (tension play) failed: {exc}") from None
    return profile, report


@dataclass
class SweepRuns:
    """Every sweep of a protocol, run and identified, re-sweeps pooled (no quality check yet)."""

    points: list[GridPoint]
    motion_time_s: float
    wall_time_s: float
    resweep_time_s: float = 0.0
    """Extra sweeping spent on re-sweeps (within the protocol's budget)."""
    resweeps: list[str] = field(default_factory=list)
    """One line per re-sweep: which grid point and why."""
    budget_note: str = ""
    """Which grid points were still over the gate when the budget ran out (empty: none)."""


def run_calibration(runner: TrajectoryRunner, catheter_id: str, device: DeviceModel, *,
                    protocol: SweepProtocol | None = None,
                    progress: ProgressCallback | None = None,
                    cancel: threading.Event | None = None,
                    options: IdentifyOptions | None = None,
                    limits: QualityLimits | None = None, isolate: bool = False,
                    live_loop: bool = True) -> Calibration:
    """Run every sweep, identify each as it ends, sweep uncertain grid points again, return the
    knobs to 0, build the profile.

    Any failure or a cancel sends the knobs back to 0 first; then CalibrationError (or
    CalibrationCancelledError) is raised and nothing is returned to be saved.
    """
    proto = protocol or paper_protocol()
    proto.validate(tuple((k.limits.min_deg, k.limits.max_deg)  # type: ignore[arg-type]
                         for k in device.knobs))
    omegas = tuple(k.omega for k in device.knobs)
    per_knob = device_options(options, device)
    runs = run_sweeps(runner, proto, progress=progress, cancel=cancel,
                      options=per_knob, isolate=isolate,
                      live_loop=live_loop, omegas=omegas,
                      estimate=(limits or QualityLimits()).estimate,
                      refuse_tip_error_deg=(limits or QualityLimits()).refuse_tip_error_deg)
    # the dead-zone loop after the sweeps, on a product whose sheet opts in (session 25)
    loops = play_loops(runner, device, per_knob, cancel, progress) if wants_loop(device) else None
    profile, report = finish(catheter_id, device, runs.points, limits=limits,
                             amplitude_deg=max(s.amplitude_deg for s in proto.sweeps),
                             plateau_gaps=None if loops is None else loops.gaps_deg)
    calibration = Calibration(profile, runs.points, report, proto.name,
                              proto.sweep_time_s + runs.resweep_time_s,
                              runs.motion_time_s + (0.0 if loops is None else loops.motion_s),
                              runs.wall_time_s)
    calibration.notes.extend(runs.resweeps)
    if loops is not None:
        calibration.notes.extend(loops.notes)
    if runs.budget_note:
        calibration.notes.append(runs.budget_note)
    return calibration


def run_sweeps(runner: TrajectoryRunner, proto: SweepProtocol, *,
               progress: ProgressCallback | None = None, cancel: threading.Event | None = None,
               options: KnobOptions = None, isolate: bool = False,
               live_loop: bool = True,
               omegas: Sequence[float] | None = None,
               estimate: EstimateOptions | None = None,
               refuse_tip_error_deg: float = math.inf) -> SweepRuns:
    """Run and identify each sweep in turn, then re-sweep uncertain grid points within the
    protocol's budget (``omegas`` given: the data sheet's slopes for the tip-error gate), then
    those that would cost more than ``refuse_tip_error_deg`` on the tip (a refusal) within the
    protocol's rescue budget; the knobs end at 0 whatever happens.

    ``isolate``: identify in a separate process, overlapped with the next sweep. The
    change-point search is pure Python and holds the GIL; in the daemon's process it delays a
    4 ms control loop by up to 11 ms (measured), so the live daemon must isolate it.
    ``live_loop`` (the runner's loop runs in real time in this process): the worker's start
    (imports: a burst of CPU) is waited for before the first sweep and the worker runs niced,
    so that it never competes with the loop. In lockstep (False) neither: its start overlaps
    the first sweep and it runs at the caller's priority.
    """
    period_s = runner.period_s  # sweeps are planned at the loop's own tick
    wall0 = time.monotonic()
    identifier = _Identifier(options, isolate, live_loop)
    player = Player(runner, proto, period_s, cancel)
    plan = []
    q_now = np.zeros(2)
    for sweep in proto.sweeps:
        run = sweep_run(sweep, q_now, period_s, proto)
        plan.append(run)
        q_now = run.q_deg[-1].copy()
    tracker = Progress(progress, [len(r.q_deg) * period_s for r in plan])
    resweep_s = 0.0
    notes: list[str] = []
    budget_note = ""
    try:
        for i, planned in enumerate(plan):
            tracker.begin(i, planned.sweep.label)
            rec = player.play(planned.sweep, f"sweep {i + 1} of {len(plan)}", tracker,
                              planned if i == 0 else None)
            identifier.submit(rec, planned.sweep.label)
            identifier.check()  # a sweep that cannot be identified stops the protocol early
        points = identifier.results()
        while omegas is not None:
            todo = uncertain_points(points, omegas, estimate,
                                    max(1, math.floor(proto.resweep_cycles)))
            if not todo:
                break
            choice = choose_resweep(
                todo, resweep_s, lambda i: proto.resweep(plan[i].sweep).duration_s,
                proto.resweep_budget_s, proto.rescue_budget_s, refuse_tip_error_deg)
            if choice.point is None:
                budget_note = budget_spent_note(points, todo, choice.budget_s)
                break
            i = choice.point.index
            again = proto.resweep(plan[i].sweep)
            rescue = " (beyond the re-sweep budget: it would refuse the calibration)"
            why = choice.point.describe(points)
            notes.append(f"re-sweep {len(notes) + 1}: {why}; {again.cycles:g} more cycles"
                         f"{rescue if choice.rescue else ''}")
            run = sweep_run(again, player.q_last, period_s, proto)
            tracker.begin(tracker.add(len(run.q_deg) * period_s), f"{again.label} ({why})")
            rec = player.play(again, f"re-sweep {len(notes)}", tracker, run)
            points[i] = pooled(points[i], identifier.identify(rec, again.label))
            resweep_s += again.duration_s
        player.return_to_zero()
    except BaseException as exc:
        identifier.close()
        player.return_to_zero()
        if isinstance(exc, CalibrationCancelledError):
            raise CalibrationCancelledError(f"{exc}; knobs returned to 0, nothing saved") from None
        raise
    identifier.close()
    return SweepRuns(points, player.motion_s, time.monotonic() - wall0, resweep_s, notes,
                     budget_note)


def _identify_detached(rec: Recording, options: KnobOptions, label: str,
                       prefit: bool = True) -> GridPoint:
    """:func:`identify_recording` in the worker, answered without the recording (the caller
    has it: sending it back would be a second copy of every sweep). ``prefit``: the tension-play
    fit's per-sweep analysis too (a protocol sweep's; a re-sweep's is never used), so that
    :func:`finish` is left with the cheap combination."""
    point = identify_recording(rec, options, label)
    if prefit:
        with contextlib.suppress(ValueError, ArithmeticError):
            # left empty: finish analyses it again and refuses with its own clear line
            point = with_prefit(point)
    return replace(point, recording=None)


def _lower_priority() -> None:
    """Worker initializer: run identification at a lower CPU priority than the daemon."""
    with contextlib.suppress(OSError):
        os.nice(10)


class _Identifier:
    """Identifies sweeps in this process, or in a worker process overlapped with the run."""

    def __init__(self, options: KnobOptions, isolate: bool, live_loop: bool = True) -> None:
        self.options = options
        self.pool: ProcessPoolExecutor | None = None
        if isolate:
            # Live: started now, while the knobs are still at rest (spawning imports numpy, scipy
            # and ruptures: a burst of CPU), and niced so that it yields to the control loop.
            self.pool = ProcessPoolExecutor(max_workers=1,
                                            mp_context=multiprocessing.get_context("spawn"),
                                            initializer=_lower_priority if live_loop else None)
            started = self.pool.submit(os.getpid)
            if live_loop:
                started.result()
        self.pending: list[tuple[Future[GridPoint], Recording]] = []
        self.points: list[GridPoint] = []

    def submit(self, rec: Recording, label: str) -> None:
        if self.pool is None:
            self.points.append(identify_recording(rec, self.options, label))
        else:
            self.pending.append((self.pool.submit(_identify_detached, rec, self.options, label),
                                 rec))

    def identify(self, rec: Recording, label: str) -> GridPoint:
        """One sweep now (a re-sweep), in the worker process when isolating."""
        if self.pool is None:
            return identify_recording(rec, self.options, label)
        point = self.pool.submit(_identify_detached, rec, self.options, label, False).result()
        return replace(point, recording=rec)

    def check(self) -> None:
        for future, _ in self.pending:
            if future.done() and future.exception() is not None:
                raise future.exception()  # type: ignore[misc]

    def results(self) -> list[GridPoint]:
        """Every sweep's grid point, holding the recording this process already has."""
        return self.points + [replace(f.result(), recording=rec) for f, rec in self.pending]

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(wait=False, cancel_futures=True)
            self.pool = None


def calibrate(runner: TrajectoryRunner, catheter_id: str, device: DeviceModel, *,
              protocol: SweepProtocol | None = None,
              progress: ProgressCallback | None = None,
              cancel: threading.Event | None = None) -> CatheterProfile:
    """Contract 5: calibrate one catheter over a trajectory runner; the caller saves it.

    Identification runs in a worker process (``isolate``), so that a live control loop in this
    process is never held up by it.
    """
    return run_calibration(runner, catheter_id, device, protocol=protocol,
                           progress=progress, cancel=cancel, isolate=True).profile


def calibrate_from_recordings(recordings: Sequence[tuple[str, Recording]], catheter_id: str,
                              device: DeviceModel, *,
                              options: IdentifyOptions | None = None,
                              limits: QualityLimits | None = None) -> Calibration:
    """Offline: the same identification and checks on logged sweeps (one sweep per recording)."""
    per_knob = device_options(options, device)
    points = [identify_recording(rec, per_knob, name) for name, rec in recordings]
    return calibration_from_points(points, catheter_id, device, limits=limits)


def calibration_from_points(points: list[GridPoint], catheter_id: str, device: DeviceModel, *,
                            limits: QualityLimits | None = None) -> Calibration:
    """Quality checks and profile from sweeps already identified (logged or just run)."""
    if not points:
        raise CalibrationError("no sweeps given")
    points = pool_repeats(points)
    amplitude = max(float(np.nanmax(np.abs(p.result.data.cmd_deg))) for p in points)
    profile, report = finish(catheter_id, device, points, limits=limits, amplitude_deg=amplitude,
                             source="calibration from logged motor current")
    return Calibration(profile, points, report, "recordings")


