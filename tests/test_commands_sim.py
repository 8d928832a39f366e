"""`tsmd sim` serves a bus the master boots against (virtual here, vcan0 on a HIL set-up)."""

from __future__ import annotations

import argparse
import itertools
import threading

import can
import pytest

from drivers.canopen_master import CanOpenDrives
from drivers.drive import DriveState
from drivers.units import DriveConfig
from tsmd.commands import sim as sim_command
from tsmd.errors import TsmdError


def main(argv: list[str]) -> int:
    """``tsmd sim ARGS`` without the rest of the CLI (other commands' modules stay out)."""
    parser = argparse.ArgumentParser(prog="tsmd sim")
    sim_command.add_arguments(parser)
    return sim_command.main(parser.parse_args(argv[1:]))

_CHANNEL = itertools.count()


def test_tsmd_sim_serves_drives_a_master_can_enable(capsys):
    channel = f"tsmd-sim-cmd-{next(_CHANNEL)}"
    master_bus = can.Bus(interface="virtual", channel=channel)
    result: dict[str, int] = {}
    sim = threading.Thread(target=lambda: result.setdefault("rc", main(
        ["sim", "--interface", "virtual", "--channel", channel, "--duration", "1.5",
         "--status-every", "0"])))
    sim.start()
    drives = CanOpenDrives(master_bus, [DriveConfig(node_id=1), DriveConfig(node_id=2)], 0.004,
                           receive="notifier")
    try:
        drives.boot()
        drives.enable()
        assert [f.state for f in drives.feedback()] == [DriveState.OPERATION_ENABLED] * 2
    finally:
        drives.close()
        sim.join(5.0)
        master_bus.shutdown()
    assert result["rc"] == 0
    assert "drives (node 1, 2) on virtual:" in capsys.readouterr().out


def test_tsmd_sim_reports_an_unknown_interface_as_a_user_error():
    # a TsmdError: the CLI prints it as one line and exits 2
    with pytest.raises(TsmdError, match="cannot open CAN interface 'no-such-interface' "
                                        "channel 'x'"):
        main(["sim", "--interface", "no-such-interface", "--channel", "x", "--duration", "0"])
