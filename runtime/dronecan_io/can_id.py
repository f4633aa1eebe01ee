"""UAVCAN v0 (DroneCAN) CAN identifiers and tail bytes, read without the dronecan package.

The receive path needs these before a frame reaches dronecan: to count a drop under the source node and data type
that sent it, and to tell a Cyphal v1 frame (whose first frame has the toggle bit set) from a v0 one (whose first
frame has it clear).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["TAIL_EOT", "TAIL_SOT", "TAIL_TID", "TAIL_TOGGLE", "Tail", "V0Id"]

TAIL_SOT = 0x80
TAIL_EOT = 0x40
TAIL_TOGGLE = 0x20
TAIL_TID = 0x1F


@dataclass(frozen=True)
class Tail:
    """The last byte of a v0 or v1 CAN frame.

    >>> Tail.of(bytes([1, 2, 0xC5]))
    Tail(start=True, end=True, toggle=False, transfer_id=5)
    >>> Tail.of(bytes([0xE0])).is_cyphal_v1_start
    True
    >>> Tail.of(b"") is None
    True
    """

    start: bool
    end: bool
    toggle: bool
    transfer_id: int

    @classmethod
    def of(cls, data: bytes | bytearray) -> Tail | None:
        if not data:
            return None
        b = data[-1]
        return cls(bool(b & TAIL_SOT), bool(b & TAIL_EOT), bool(b & TAIL_TOGGLE), b & TAIL_TID)

    @property
    def is_cyphal_v1_start(self) -> bool:
        """A first frame with the toggle bit set: Cyphal v1 starts at toggle 1, UAVCAN v0 at toggle 0."""
        return self.start and self.toggle


@dataclass(frozen=True)
class V0Id:
    """The fields of a 29-bit UAVCAN v0 CAN id.

    For an anonymous message (source node 0) only the two low bits of the data type id are on the wire; the
    discriminator is left out here.

    >>> V0Id.parse(0x1403EB0A)  # RawIMU (1003) from node 10, priority 20
    V0Id(priority=20, service=False, data_type_id=1003, source_node_id=10, dest_node_id=None, request=None)
    >>> V0Id.parse(0x1401A48B)  # GetNodeInfo (1) request from node 11 to node 36
    V0Id(priority=20, service=True, data_type_id=1, source_node_id=11, dest_node_id=36, request=True)
    """

    priority: int
    service: bool
    data_type_id: int
    source_node_id: int
    dest_node_id: int | None
    request: bool | None

    @classmethod
    def parse(cls, can_id: int) -> V0Id:
        priority = (can_id >> 24) & 0x1F
        source = can_id & 0x7F
        if can_id & 0x80:
            return cls(priority, True, (can_id >> 16) & 0xFF, source, (can_id >> 8) & 0x7F, bool(can_id & 0x8000))
        if source == 0:
            return cls(priority, False, (can_id >> 8) & 0x3, 0, None, None)
        return cls(priority, False, (can_id >> 8) & 0xFFFF, source, None, None)
