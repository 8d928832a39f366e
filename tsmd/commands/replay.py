"""`tsmd replay`: run a trajectory file through the full stack and write the recording.

With ``--sim`` (lockstep on the in-process simulated rig) the output depends only on the
input, the config and the seed: the same command writes the same file byte for byte. Without
it the trajectory is played in real time on the drives of the configuration file.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
from typing import Any, cast

import numpy as np

from tsmd.compensation import METHODS
from tsmd.config import (
    DEFAULT_CONFIG_PATH,
    TsmdConfig,
    default_sim_config,
    load_config,
    resolve_data_path,
)
from tsmd.daemon import Daemon
from tsmd.errors import TsmdError
from tsmd.profile import ProfileStore, load_profile
from tsmd.recording import Recording, read_trajectory, write_recording
from tsmd.replay import LiveTrajectoryRunner, carry_conditions, run_trajectory


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--trajectory", required=True, metavar="CSV",
                        help="trajectory file with columns t,q1,q2 (s, deg); a 'segment' "
                             "column and the condition headers (segments, configuration, "
                             "catheter) are carried into the recording")
    parser.add_argument("--out", required=True, metavar="CSV", help="recording to write")
    comp = parser.add_mutually_exclusive_group()
    comp.add_argument("--no-compensation", action="store_true",
                      help="send the desired angles as they are")
    comp.add_argument("--profile", metavar="ID|FILE",
                      help="catheter profile: an id in profiles.dir or a YAML file "
                           "(default profiles.active)")
    parser.add_argument("--method", choices=[m for m in METHODS if m != "none"],
                        help="compensator (default compensation.method of the config)")
    parser.add_argument("--sim", action="store_true",
                        help="lockstep on the in-process simulated rig (deterministic)")
    parser.add_argument("--config", metavar="FILE",
                        help=f"configuration (default: packaged sim config with --sim, else "
                             f"{DEFAULT_CONFIG_PATH})")
    parser.add_argument("--seed", type=int, help="noise seed of the simulated rig "
                                                 "(default sim.seed)")


def _profile(args: argparse.Namespace, config: TsmdConfig) -> Any:
    if args.no_compensation:
        return None
    ident = args.profile or config.profiles.active
    if ident is None:
        return None
    if ident.endswith((".yaml", ".yml")) or "/" in ident:
        return load_profile(ident)
    return ProfileStore(resolve_data_path(config.profiles.dir)).load(ident)


def main(args: argparse.Namespace) -> int:
    if args.config is not None:
        config = load_config(args.config)
    elif args.sim:
        config = default_sim_config()
    else:
        config = load_config(DEFAULT_CONFIG_PATH)
    trajectory = read_trajectory(args.trajectory)
    profile = _profile(args, config)
    method = "none" if profile is None else (args.method or config.compensation.method)
    if args.no_compensation:
        method = "none"
    if profile is None and args.method is not None:
        raise TsmdError(f"--method {args.method} needs a profile (--profile or profiles.active)")
    t_s = trajectory["t"]
    q = trajectory.columns
    q_deg = np.column_stack([q["q1"], q["q2"]])
    if args.sim:
        seed = config.sim.seed if args.seed is None else args.seed
        recording = run_trajectory(t_s, q_deg, config=config, profile=profile, method=method,
                                   seed=seed)
    else:
        recording = _run_live(config, profile, method, t_s, q_deg)
    recording.metadata["trajectory"] = Path(args.trajectory).name
    carry_conditions(trajectory, recording)
    write_recording(args.out, recording)
    _print_summary(recording, args.out)
    return 0


def _run_live(config: TsmdConfig, profile: Any, method: str, t_s: Any, q_deg: Any) -> Recording:
    """Real time on the configured drives, without opening the socket API."""
    config = dataclasses.replace(config, compensation=dataclasses.replace(
        config.compensation, method=cast(Any, method if method != "none" else "ours"),
        enabled=method != "none"))
    daemon = Daemon(config, api=False)
    daemon.start()
    try:
        assert daemon.loop is not None
        daemon.loop.post("enable").result(timeout=10.0)
        return LiveTrajectoryRunner(daemon.loop).run(t_s, q_deg, compensate=method != "none")
    finally:
        daemon.stop()


def _print_summary(recording: Recording, out: str) -> None:
    line = f"tsmd replay: {len(recording)} ticks -> {out}"
    if recording.has_tip:
        err = np.column_stack([recording["tip1"] - recording["q1"],
                               recording["tip2"] - recording["q2"]])
        rmse = np.sqrt(np.nanmean(err ** 2, axis=0))
        line += f"; tip RMSE phi1 {rmse[0]:.2f} deg, phi2 {rmse[1]:.2f} deg"
    print(line)
