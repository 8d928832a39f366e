"""A small CANopen SDO client that waits through a hook instead of blocking on a thread.

canopen's ``SdoClient`` waits on a queue its notifier thread fills, so a lockstep simulation
would depend on thread timing. This client sends a request and calls ``wait`` (the simulated
rig's ``exchange`` in lockstep, a short sleep plus receive in real time) until the master's
receive path hands it the answer through :meth:`SdoClient.on_response`. It speaks expedited
download, expedited and segmented upload: all the master's configuration needs.
"""

from __future__ import annotations

import struct
from collections.abc import Callable

from drivers.clock import Clock
from drivers.drive import DriveError
from drivers.od import abort_meaning


class SdoClient:
    """SDO client of one node (requests on 0x600 + node, answers on 0x580 + node)."""

    def __init__(self, node_id: int, name: str, send: Callable[[int, bytes], None],
                 wait: Callable[[], None], clock: Clock, timeout_s: float) -> None:
        self.node_id = node_id
        self.name = name
        self._send = send
        self._wait = wait
        self._clock = clock
        self.timeout_s = timeout_s
        self._response: bytes | None = None

    def on_response(self, data: bytes | bytearray) -> None:
        """The master's receive path calls this for each frame on 0x580 + node."""
        self._response = bytes(data)

    def upload(self, index: int, subindex: int = 0) -> bytes:
        what = f"upload 0x{index:04X}:{subindex:02X}"
        resp = self._transfer(struct.pack("<BHB4x", 0x40, index, subindex), what)
        cs = resp[0]
        if cs & 0xE0 != 0x40:
            raise DriveError(f"{self.name}: SDO {what}: unexpected response 0x{cs:02X}")
        self._check_mux(resp, index, subindex, what)
        if cs & 0x02:  # expedited
            size = 4 - ((cs >> 2) & 0x3) if cs & 0x01 else 4
            return resp[4:4 + size]
        total = struct.unpack_from("<I", resp, 4)[0] if cs & 0x01 else None
        data = bytearray()
        toggle = 0
        while True:
            seg = self._transfer(bytes((0x60 | toggle,)) + bytes(7), what)
            if seg[0] & 0xE0 != 0x00 or seg[0] & 0x10 != toggle:
                raise DriveError(f"{self.name}: SDO {what}: bad segment 0x{seg[0]:02X}")
            unused = (seg[0] >> 1) & 0x7
            data += seg[1:8 - unused]
            if seg[0] & 0x01:
                break
            toggle ^= 0x10
        if total is not None and len(data) != total:
            raise DriveError(f"{self.name}: SDO {what}: got {len(data)} bytes, "
                             f"announced {total}")
        return bytes(data)

    def download(self, index: int, subindex: int, data: bytes) -> None:
        what = f"download 0x{index:04X}:{subindex:02X}"
        if not 1 <= len(data) <= 4:
            raise DriveError(f"{self.name}: SDO {what}: only 1..4 byte values are supported")
        cs = 0x23 | ((4 - len(data)) << 2)
        request = struct.pack("<BHB", cs, index, subindex) + bytes(data).ljust(4, b"\x00")
        resp = self._transfer(request, what)
        if resp[0] != 0x60:
            raise DriveError(f"{self.name}: SDO {what}: unexpected response 0x{resp[0]:02X}")
        self._check_mux(resp, index, subindex, what)

    def _transfer(self, request: bytes, what: str) -> bytes:
        self._response = None
        self._send(0x600 + self.node_id, request)
        deadline = self._clock.now_s() + self.timeout_s
        while self._response is None:
            if self._clock.now_s() > deadline:
                raise DriveError(f"{self.name}: SDO {what} timed out after {self.timeout_s} s "
                                 f"(no answer from node {self.node_id})")
            self._wait()
        resp = self._response
        if len(resp) != 8:
            raise DriveError(f"{self.name}: SDO {what}: malformed response of {len(resp)} "
                             f"bytes")
        if resp[0] == 0x80:
            code = struct.unpack_from("<I", resp, 4)[0]
            raise DriveError(f"{self.name}: SDO {what} aborted with 0x{code:08X}: "
                             f"{abort_meaning(code)}")
        return resp

    def _check_mux(self, resp: bytes, index: int, subindex: int, what: str) -> None:
        got = struct.unpack_from("<HB", resp, 1)
        if got != (index, subindex):
            raise DriveError(f"{self.name}: SDO {what}: answer is for "
                             f"0x{got[0]:04X}:{got[1]:02X}")
