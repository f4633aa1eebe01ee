"""Whole v0 transfers as payload bytes, below dronecan's decoding: the wire path of the bridge.

dronecan decodes every transfer bit by bit in pure Python (hundreds of microseconds a message) and encodes every
message the same way; a generated codec does both straight from and to the bytes. :class:`TransferTaps` takes, for
the data types it is given, the completed message transfers that :class:`~.frame_gate.FrameGate` assembled, checks
them as dronecan's ``Transfer.from_frames`` does (toggle bits, transfer ids, and the CRC of a multi-frame transfer,
seeded with the data type's signature) and hands the payload to a handler instead of to the node. What fails a check
is counted under the same :class:`~.drops.DropReason` the NodeLoop gives dronecan's own errors. A data type marked
:meth:`TransferTaps.share` goes to the node as well once its handler had it (a part that handles it with dronecan's
own handlers beside a tapped mapping: the bridge's built-in Panic duty beside a mapping of Panic).
:func:`broadcast_payload` sends payload bytes as dronecan's ``Node.broadcast`` sends a message: same framing (tail
bytes, CRC, transfer ids from the node's own counter, classic CAN with tail array optimisation), no encoding.
"""

from __future__ import annotations

import binascii
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from dronecan.driver.common import CANFrame

from sam_runtime.dronecan_io.can_id import TAIL_TOGGLE
from sam_runtime.dronecan_io.drops import DropCounter, DropReason

__all__ = ["TransferTaps", "broadcast_payload", "crc16"]

PayloadHandler = Callable[[bytes, int, int, float], None]  # (payload, source node id, transfer id, monotonic s)
DEFAULT_PRIORITY = 20  # what dronecan's node.broadcast uses when given none (dronecan.node.DEFAULT_TRANSFER_PRIORITY)


def crc16(data: bytes | bytearray, initial: int) -> int:
    """CRC-16-CCITT as UAVCAN v0 computes a multi-frame transfer's CRC (dronecan.dsdl.common.crc16_from_bytes):
    binascii's crc_hqx is that CRC (polynomial 0x1021, not reflected, any seed), in C instead of dronecan's eight
    shifts a byte (tests/runtime/dronecan_io/test_wire_path.py compares them).

    >>> hex(crc16(b"123456789", 0xFFFF))
    '0x29b1'
    """
    return binascii.crc_hqx(data, initial)


@dataclass(frozen=True)
class _Tap:
    crc_base: int  # the data type's CRC seed (from its signature)
    handler: PayloadHandler


class TransferTaps:
    """Message transfers of chosen data types, taken before dronecan sees them (see the module docstring)."""

    def __init__(self, drops: DropCounter) -> None:
        self.drops = drops
        self._taps: dict[int, _Tap] = {}
        self._shared: set[int] = set()  # data type ids the node gets too

    def share(self, data_type_id: int) -> None:
        """Transfers of this data type that pass the checks go to the node too, after the tap's handler."""
        self._shared.add(data_type_id)

    def add(self, data_type_id: int, crc_base: int, handler: PayloadHandler) -> None:
        self._taps[data_type_id] = _Tap(crc_base, handler)

    def take(self, frames: list[CANFrame]) -> bool:
        """A completed transfer (its frames, in order): True when it was tapped (handled or counted), False when
        it is the node's."""
        ident = frames[0].id
        if ident & 0x80 or not ident & 0x7F:  # a service, or an anonymous message: dronecan's
            return False
        dtid = (ident >> 8) & 0xFFFF
        tap = self._taps.get(dtid)
        if tap is None:
            return False
        src = ident & 0x7F
        payload = self._payload(frames, tap.crc_base, dtid, src)
        if payload is not None:
            tap.handler(payload, src, frames[0].data[-1] & 0x1F, frames[0].ts_monotonic)
            return dtid not in self._shared  # a failed check is counted once, here: the node never sees it
        return True

    def _payload(self, frames: list[CANFrame], crc_base: int, dtid: int, src: int) -> bytes | None:
        if len(frames) == 1:
            return bytes(frames[0].data[:-1])
        toggle = 0
        for i, f in enumerate(frames):
            if f.data[-1] & TAIL_TOGGLE != toggle:
                self._drop(DropReason.TOGGLE_ERROR, dtid, src, f"toggle bit wrong on frame {i}")
                return None
            toggle ^= TAIL_TOGGLE
        data = b"".join([f.data[:-1] for f in frames])
        payload = data[2:]
        expected = data[0] | data[1] << 8
        crc = binascii.crc_hqx(payload, crc_base)
        if crc != expected:
            self._drop(DropReason.CRC_MISMATCH, dtid, src, f"CRC mismatch: expected {crc:x}, got {expected:x}")
            return None
        return payload

    def _drop(self, reason: DropReason, dtid: int, src: int, detail: str) -> None:
        self.drops.add(reason, data_type_id=dtid, source_node_id=src, detail=detail)


def broadcast_payload(node: Any, data_type_id: int, crc_base: int, payload: bytes,
                      priority: int = DEFAULT_PRIORITY) -> None:
    """Broadcast a message's payload bytes from ``node`` (a dronecan Node with a node id) as ``node.broadcast``
    would broadcast the message they encode."""
    from dronecan import transport

    transfer = transport.Transfer(source_node_id=node.node_id,
                                  transfer_id=node._next_transfer_id(data_type_id),  # the node's own counter
                                  transfer_priority=priority, service_not_message=False)
    transfer.payload = bytearray(payload)
    transfer.data_type_id = data_type_id
    transfer.data_type_crc = crc_base
    driver = node.can_driver
    for frame in transfer.to_frames():
        driver.send(frame.message_id, frame.bytes, extended=True, canfd=False)
