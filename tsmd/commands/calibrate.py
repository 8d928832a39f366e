"""`tsmd calibrate`: calibrate a catheter from motor current and save its profile.

Three ways to run it, one identification code path:

* through the running daemon (default): asks over the socket (API command ``calibrate``),
  shows the streamed progress; Ctrl-C asks the daemon to cancel (knobs back to 0, nothing saved);
* ``--sim``: in-process on the simulated rig in lockstep (full CAN stack, faster than real time);
* ``--from-recording FILE...``: offline from logged sweeps (one sweep per file; real TEE
  acquisitions are read directly, see docs/calibration.md).
"""

from __future__ import annotations

import argparse
import json
import signal
import socket
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tsmd.calibration import fast_protocol, paper_protocol, run_calibration
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.errors import CalibrationError, CalibrationRefusedError
from tsmd.calibration.identify import IdentifyOptions
from tsmd.calibration.offline import data_report, identification_table, read_sweep_file
from tsmd.calibration.report import grid_table, write_report
from tsmd.calibration.resweep import pool_repeats
from tsmd.calibration.run import calibration_from_points, identify_recording
from tsmd.config import default_sim_config, load_config, resolve_data_path
from tsmd.errors import TsmdError
from tsmd.profile import ProfileStore, load_device_model
from tsmd.recording import write_recording
from tsmd.replay import LockstepRunner


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--catheter", required=True, metavar="ID",
                        help="catheter id: the profile is saved as <profiles dir>/<ID>.yaml")
    parser.add_argument("--sim", action="store_true",
                        help="run in-process on the simulated rig (lockstep), not via the daemon")
    parser.add_argument("--config", metavar="FILE",
                        help="tsmd config (default: /etc/tsmd/tsmd.yaml, or the sim default "
                             "with --sim)")
    parser.add_argument("--fast", action="store_true",
                        help="the fast protocol (200 s: the other knob at -90/0/+90 only, sine at "
                             "0.06 Hz, re-sweeps up to 233 s in all) instead of the paper's "
                             "(700 s: 7 grid points, 0.04 Hz, re-sweeps up to 900 s); --sim "
                             "and recordings only")
    parser.add_argument("--report", metavar="DIR",
                        help="write a calibration report (Markdown + PNG plots) into DIR")
    parser.add_argument("--from-recording", nargs="+", metavar="FILE",
                        help="identify from logged sweeps (recording CSVs or TEE acquisitions)")
    parser.add_argument("--device", metavar="FILE",
                        help="device model YAML (default: profiles.device_model of the config)")
    parser.add_argument("--profiles", metavar="DIR",
                        help="where to save the profile (default: profiles.dir of the config)")
    parser.add_argument("--save-sweeps", metavar="DIR",
                        help="also write each sweep's recording (CSV) into DIR (--sim)")
    parser.add_argument("--steps-per-knob-deg", type=float, default=None,
                        help="TEE acquisitions: motor steps per knob degree (assumed; "
                             "default 16, see docs/calibration.md)")
    parser.add_argument("--no-save", action="store_true",
                        help="identify and check, print the result, do not save a profile")
    parser.add_argument("--socket", metavar="PATH",
                        help="daemon socket (default: api.socket_path of the config)")
    parser.add_argument("--seed", type=int, default=0, help="--sim: noise seed")
    parser.add_argument("--edge", choices=("fit", "knee", "rise"), default="fit",
                        help="dead-zone edge: 'fit' (default) = least-squares line intersection "
                             "of the dead-zone level with the loaded ramp (or the end of a steep "
                             "first rise); 'knee' = the same from change points; 'rise' = the "
                             "paper's, where the current starts to rise "
                             "(--sim and recordings; the daemon uses the default)")


def main(args: argparse.Namespace) -> int:
    if args.from_recording:
        return _from_recordings(args)
    if args.sim:
        return _sim(args)
    if args.fast:
        raise TsmdError("--fast needs --sim or --from-recording (the daemon runs its own "
                        "protocol)")
    return _via_daemon(args)


# --- shared helpers -----------------------------------------------------------------------


def _config(args: argparse.Namespace, sim: bool) -> Any:
    if args.config:
        return load_config(args.config)
    if sim:
        return default_sim_config()
    return load_config("/etc/tsmd/tsmd.yaml")


def _device(args: argparse.Namespace, config: Any) -> Any:
    path = args.device or (config.profiles.device_model if config is not None else None)
    if path is None:
        raise TsmdError("no device model: pass --device FILE or set profiles.device_model")

    return load_device_model(resolve_data_path(str(path)))


def _store(args: argparse.Namespace, config: Any) -> ProfileStore | None:
    """Where the profile will go, checked before anything moves: a calibration that runs for
    minutes must not end in "cannot save" (a bad id, no directory, a read-only directory)."""
    if args.no_save:
        return None
    directory = args.profiles or (config.profiles.dir if config is not None else None)
    if directory is None:
        raise TsmdError("no profiles directory: pass --profiles DIR or --config FILE")
    store = ProfileStore(directory)
    store.path(args.catheter)
    try:
        store.directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=store.directory):
            pass
    except OSError as exc:
        raise TsmdError(f"profiles directory {store.directory}: cannot write "
                        f"({exc.strerror or exc})") from None
    return store


def _save(args: argparse.Namespace, store: ProfileStore | None, cal: Any) -> None:
    _print_result(cal)
    if args.report:
        index = write_report(cal, Path(args.report))
        print(f"report: {index}")
    if store is None:
        print("not saved (--no-save)")
        return
    path = store.save(cal.profile)
    print(f"saved profile {cal.profile.catheter_id!r} to {path}")


def _print_result(cal: Any) -> None:
    print(grid_table(cal))
    for warning in cal.quality.warnings:
        print(f"warning: {warning}")
    if cal.sweep_time_s:
        print(f"protocol {cal.protocol_name}: {cal.sweep_time_s:.0f} s sweeping, "
              f"{cal.motion_time_s:.0f} s of motion, {cal.wall_time_s:.1f} s wall")


class _Bar:
    """A one-line progress bar on a terminal; a line per sweep and per 10 % otherwise."""

    def __init__(self) -> None:
        self.tty = sys.stderr.isatty()
        self.last = ""
        self.last_key: tuple[str, int] = ("", -1)

    def __call__(self, fraction: float, text: str) -> None:
        width = 30
        filled = round(fraction * width)
        line = f"[{'#' * filled}{'.' * (width - filled)}] {fraction * 100:5.1f}% {text}"
        if self.tty:
            sys.stderr.write("\r" + line[:150].ljust(len(self.last)))
            sys.stderr.flush()
        else:
            key = (text.split(":")[0], int(fraction * 10))
            if key != self.last_key:
                sys.stderr.write(line + "\n")
                sys.stderr.flush()
            self.last_key = key
        self.last = line

    def done(self) -> None:
        if self.tty and self.last:
            sys.stderr.write("\n")


# --- the three paths ----------------------------------------------------------------------


def _sim(args: argparse.Namespace) -> int:
    config = _config(args, sim=True)
    device = _device(args, config)
    store = _store(args, config)
    protocol = fast_protocol() if args.fast else paper_protocol()
    cancel = threading.Event()
    bar = _Bar()
    previous = signal.signal(signal.SIGINT, lambda *_: cancel.set())
    try:
        with LockstepRunner(config, seed=args.seed) as runner:
            # isolate: each sweep is identified in a worker process (the other core) while the
            # next one runs; no live loop to protect here (not waited for, not niced)
            cal = run_calibration(runner, args.catheter, device, protocol=protocol,
                                  progress=bar, cancel=cancel,
                                  options=IdentifyOptions(edge=args.edge), isolate=True,
                                  live_loop=False)
    except CalibrationRefusedError as exc:
        # A refused calibration's sweeps are what its user needs to see why.
        if args.save_sweeps:
            _write_sweeps(Path(args.save_sweeps), exc.points)
        raise
    finally:
        signal.signal(signal.SIGINT, previous)
        bar.done()
    if args.save_sweeps:
        _write_sweeps(Path(args.save_sweeps), cal.points)
    _save(args, store, cal)
    return 0


def _write_sweeps(out: Path, points: Sequence[GridPoint]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for i, point in enumerate(points):
        if point.recording is not None:
            write_recording(out / f"sweep{i + 1:02d}.csv", point.recording)
    print(f"sweeps written to {out}")


def _from_recordings(args: argparse.Namespace) -> int:
    config = _config(args, sim=False) if args.config else None
    device = _device(args, config)
    store = _store(args, config)
    options = IdentifyOptions(edge=args.edge)
    points = []
    failures = []
    for f in args.from_recording:
        try:
            points.append(identify_recording(read_sweep_file(f, args.steps_per_knob_deg),
                                             options, source=str(f)))
        except CalibrationError as exc:
            # Every file is looked at: the report then says what each gave or lacked.
            failures.append((str(f), str(exc).removeprefix(f"{f} ")))
    if points:
        print(identification_table(points))
    unusable = "; ".join(f"{Path(f).name}: {why}" for f, why in failures)
    try:
        if not points:
            raise CalibrationError(f"no recording could be used: {unusable}")
        cal = calibration_from_points(points, args.catheter, device)
        if failures:
            raise CalibrationError(f"{len(failures)} recording(s) could not be used: {unusable}")
    except CalibrationError as exc:
        # Repeated acquisitions of one grid point are pooled, as a re-sweep would be.
        print("\n" + data_report(pool_repeats(points), failures, str(exc)))
        raise
    _save(args, store, cal)
    return 0


def _via_daemon(args: argparse.Namespace) -> int:
    path = args.socket or _config(args, sim=False).api.socket_path
    bar = _Bar()
    try:
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.connect(path)
    except OSError as exc:
        raise TsmdError(f"cannot reach the daemon at {path}: {exc.strerror or exc} "
                        "(is 'tsmd run' running? use --sim for the simulator)") from None
    request = {"id": "calibrate", "cmd": "calibrate", "catheter": args.catheter}
    sock.sendall((json.dumps(request) + "\n").encode())
    stream = sock.makefile("rb")
    cancelled = False
    try:
        while True:
            try:
                line = stream.readline()
            except KeyboardInterrupt:
                if not cancelled:
                    cancelled = True
                    sys.stderr.write("\ncancelling: the knobs return to 0...\n")
                    _send_cancel(path)
                continue
            if not line:
                raise TsmdError("the daemon closed the connection during calibration")
            message = json.loads(line)
            if message.get("event") == "progress":
                info = message.get("info") or [""]
                bar(float(message.get("progress", 0.0)), str(message.get("status", info[0])))
                continue
            if message.get("id") != "calibrate":
                continue
            bar.done()
            if message.get("ok"):
                print(f"saved profile {message.get('profile')!r} to {message.get('path')}")
                return 0
            error = message.get("error", {})
            raise TsmdError(f"{error.get('code', 'error')}: {error.get('message', message)}")
    finally:
        sock.close()


def _send_cancel(path: str) -> None:
    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
            s.settimeout(5.0)
            s.connect(path)
            s.sendall(b'{"id": "cancel", "cmd": "cancel"}\n')
            s.recv(4096)
    except OSError:
        time.sleep(0.1)
