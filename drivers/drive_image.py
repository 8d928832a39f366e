"""The master's process image of one CiA 402 drive: what its PDOs carry, as plain attributes.

RPDO1 (controlword, target position) is packed into one reused frame; TPDO1 (statusword,
position actual, current actual) is decoded into the image by the receive path. The layouts are
:data:`drivers.od.RPDO1_FORMAT` / :data:`drivers.od.TPDO1_FORMAT`, the mapping the master writes
at boot.
"""

from __future__ import annotations

import struct

import can

from drivers import od as o
from drivers.drive import DriveFeedback, DriveState
from drivers.sdo import SdoClient
from drivers.units import DriveConfig

RPDO = struct.Struct(o.RPDO1_FORMAT)
TPDO = struct.Struct(o.TPDO1_FORMAT)


class DriveImage:
    """Master-side image of one drive (plain attributes: this is the hot path)."""

    def __init__(self, index: int, config: DriveConfig) -> None:
        self.index = index
        self.config = config
        self.node_id = config.node_id
        self.name = f"drive {index} (node {config.node_id})"
        self.cpd = config.counts_per_deg
        self.scale_A = config.current_scale_A
        self.min_counts = config.deg_to_counts(config.min_deg)
        self.max_counts = config.deg_to_counts(config.max_deg)
        self.controlword = 0
        self.target_counts = 0
        self.statusword = 0
        self.position_counts = 0
        self.current_raw = 0
        self.state = DriveState.UNKNOWN
        self.age_syncs = 0
        self.has_feedback = False
        self.stale_reported = False
        self.last_heartbeat_s: float | None = None
        self.nmt_state: int | None = None
        self.heartbeat_lost = False
        self.supervised = False
        self.last_emcy: int | None = None
        self.rebooted = False
        """Sent a boot-up while running: parameters lost, waits for fault_reset to re-configure."""
        self.homed = False
        self.sdo: SdoClient
        self.rpdo = can.Message(arbitration_id=0x200 + self.node_id, is_extended_id=False,
                                data=bytearray(RPDO.size))
        self.feedback_key: tuple[int, int, int, DriveState, int] | None = None
        self.feedback: DriveFeedback | None = None
        """The last DriveFeedback built, reused while ``feedback_key`` is unchanged."""

    def snapshot(self) -> DriveFeedback:
        """Feedback as a DriveFeedback; one object per change, not per call (hot path)."""
        key = (self.position_counts, self.current_raw, self.statusword, self.state,
               self.age_syncs)
        fb = self.feedback
        if fb is None or key != self.feedback_key:
            fb = self.feedback = DriveFeedback(  # position_deg, current_A, statusword, ...
                self.position_counts / self.cpd, self.current_raw * self.scale_A,
                self.statusword, self.state, self.age_syncs)
            self.feedback_key = key
        return fb

    def pack_rpdo(self) -> can.Message:
        RPDO.pack_into(self.rpdo.data, 0, self.controlword, self.target_counts)
        return self.rpdo
