"""The time-sync master's message per protocol (for sam_runtime.bridge.time_sync): its port, type, how one is built
from the previous transmission's time, and the longest interval the protocol allows between two of them.

- Cyphal: ``uavcan.time.Synchronization.1.0`` on its fixed subject 7168, ``previous_transmission_timestamp_microsecond``
  (uint56), at most MAX_PUBLICATION_PERIOD (1 s) apart.
- DroneCAN: ``uavcan.protocol.GlobalTimeSync`` (data type id 4), ``previous_transmission_timestamp_usec`` (uint56),
  at most MAX_BROADCASTING_PERIOD_MS (1100 ms) apart.
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
    make: Callable[[int], Any]  # previous transmission time [us] -> message
    max_interval_s: float


def sync_message(protocol: str) -> SyncMessage:
    """The time-sync message of a registered protocol (its bridge part's)."""
    message: SyncMessage = runtime_protocol(protocol).bridge().sync_message()
    return message


def dronecan_sync_message() -> SyncMessage:
    import dronecan

    cls = dronecan.TYPENAMES["uavcan.protocol.GlobalTimeSync"]
    return SyncMessage("uavcan.protocol.GlobalTimeSync", int(cls.default_dtid), cls,
                       lambda us: cls(previous_transmission_timestamp_usec=us & UINT56),
                       cls().MAX_BROADCASTING_PERIOD_MS / 1000.0)


def cyphal_sync_message() -> SyncMessage:
    import uavcan.time

    sync = uavcan.time.Synchronization_1_0
    return SyncMessage("uavcan.time.Synchronization.1.0", int(sync._FIXED_PORT_ID_), sync,
                       lambda us: sync(previous_transmission_timestamp_microsecond=us & UINT56),
                       float(sync.MAX_PUBLICATION_PERIOD))
