"""`tsmd sim`: the simulated rig as its own process on a CAN interface, in real time.

For hardware-in-the-loop set-ups: the daemon (or any CANopen master) on one side of a SocketCAN
or vcan interface, two simulated CiA 402 drives plus the catheter plant on the other.
The drives and the plant come from the same configuration file the daemon reads.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import time
from types import FrameType

import can

from simrig.plant import load_plant
from simrig.rig import SimRig
from tsmd.config import default_sim_config, drive_configs, load_config
from tsmd.errors import TsmdError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--interface", default="socketcan",
                        help="python-can interface (socketcan, virtual, ...); default socketcan")
    parser.add_argument("--channel", default="vcan0", help="CAN channel; default vcan0")
    parser.add_argument("--bitrate", type=int, default=1_000_000)
    parser.add_argument("--config", default=None,
                        help="tsmd YAML config (drives, loop rate, sim plant); default: the "
                             "packaged simulation config")
    parser.add_argument("--seed", type=int, default=None, help="override sim.seed")
    parser.add_argument("--duration", type=float, default=None,
                        help="stop after this many seconds (default: until Ctrl-C)")
    parser.add_argument("--status-every", type=float, default=1.0,
                        help="print knob, current and tip every N seconds (0: never)")


def main(args: argparse.Namespace) -> int:
    config = load_config(args.config) if args.config else default_sim_config()
    seed = config.sim.seed if args.seed is None else args.seed
    plant = load_plant(config.sim.plant, config.sim.params)
    configs = drive_configs(config)
    try:
        bus = can.Bus(interface=args.interface, channel=args.channel, bitrate=args.bitrate)
    except (can.CanError, OSError, ValueError, ImportError) as exc:
        raise TsmdError(f"cannot open CAN interface {args.interface!r} channel "
                        f"{args.channel!r}: {exc}") from None
    rig = SimRig(bus, plant, configs, config.loop.period_s, seed, lockstep=False,
                 tracker_noise_deg=config.sim.tracker_noise_deg)
    stop = {"now": False}

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop["now"] = True

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, on_signal)
    ids = ", ".join(str(c.node_id) for c in configs)
    print(f"tsmd sim: drives (node {ids}) on {args.interface}:{args.channel}, "
          f"period {config.loop.period_s * 1e3:g} ms, plant {config.sim.plant}", flush=True)
    rig.start()
    start = time.monotonic()
    next_status = start + args.status_every
    try:
        while not stop["now"]:
            time.sleep(0.05)
            now = time.monotonic()
            if rig.error is not None:
                break
            if args.duration is not None and now - start >= args.duration:
                break
            if args.status_every > 0 and now >= next_status:
                next_status += args.status_every
                knob = rig.knob_deg()
                tip = rig.true_tip_deg()
                states = ",".join(n.state.value for n in rig.nodes)
                print(f"t={now - start:7.1f}s ticks={rig.ticks} knob=[{knob[0]:7.2f} "
                      f"{knob[1]:7.2f}] deg tip=[{tip[0]:7.2f} {tip[1]:7.2f}] deg "
                      f"states={states}", flush=True)
    except KeyboardInterrupt:
        pass
    finally:
        try:
            rig.close()
        except RuntimeError as exc:
            print(f"tsmd sim: error: {exc}", file=sys.stderr)
            return 2
    return 0
