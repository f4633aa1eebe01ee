"""The time-sync master's message per protocol (for sam_runtime.bridge.time_sync): its port, type, how one is built
from the previous transmission's time, and the longest interval the protocol allows between two of them.

- Cyphal: ``uavcan.time.Synchronization.1.0`` on its fixed subject 7168, ``previous_transmission_timestamp_microsecond``
  (uint56), at most MAX_PUBLICATION_PERIOD (1 s) apart.
- DroneCAN: ``uavcan.protocol.GlobalTimeSync`` (data type id 4), ``previous_transmission_timestamp_usec`` (uint56),
  at most MAX_BROADCASTING_PERIOD_MS (1100 ms) apart. Sent on the wire path (``raw``: the port is advertised raw
  and ``make`` gives the payload bytes, the uint56 little endian as v0 serializes it): dronecan's object encoding of
  this one field cost more than the rest of the master's work, twice a second on an idle bridge.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sam_runtime.protocols import runtime_protocol

__all__ = ["SyncMessage", "cyphal_sync_message", "dronecan_sync_message", "sync_message"]

UINT56 = (1 << 56) - 1


@dataclass(frozen=True)
class SyncMessage:
    label: str
    port_id: int
    dtype: Any
    make: Callable[[int], Any]  # previous transmission time [us] -> message (raw: its payload bytes)
    max_interval_s: float
    raw: bool = False  # advertise the port raw (the backend sends ``make``'s bytes as they are)


def sync_message(protocol: str) -> SyncMessage:
    """The time-sync message of a registered protocol (its bridge part's)."""
    message: SyncMessage = runtime_protocol(protocol).bridge().sync_message()
    return message


def dronecan_sync_message() -> SyncMessage:
    import dronecan

    cls = dronecan.TYPENAMES["uavcan.protocol.GlobalTimeSync"]
    return SyncMessage("uavcan.protocol.GlobalTimeSync", int(cls.default_dtid), cls,
                       lambda us: (us & UINT56).to_bytes(7, "little"),
                       cls().MAX_BROADCASTING_PERIOD_MS / 1000.0, raw=True)


def cyphal_sync_message() -> SyncMessage:
    import uavcan.time

    sync = uavcan.time.Synchronization_1_0
    return SyncMessage("uavcan.time.Synchronization.1.0", int(sync._FIXED_PORT_ID_), sync,
                       lambda us: sync(previous_transmission_timestamp_microsecond=us & UINT56),
                       float(sync.MAX_PUBLICATION_PERIOD))
