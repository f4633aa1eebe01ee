"""What the composition root (sam_runtime.bridge.composition) asks of one protocol: its backend, its converters, its
node duties and service mappings, its time-sync message, what replay needs first. One object per protocol
(cyphal_part.PART, dronecan_part.PART), named by its entry in sam_runtime.protocols."""

from __future__ import annotations

import collections
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Protocol

from sam_runtime.bridge.backend import Backend
from sam_runtime.bridge.backends.cyphal import DEFAULT_RX_QUEUE_SIZE, TransportConfig
from sam_runtime.bridge.backends.param_access import ParamAccess
from sam_runtime.bridge.backends.service_mappings import ServiceMappingsRos
from sam_runtime.bridge.backends.time_sync_messages import SyncMessage
from sam_runtime.bridge.interface_check import Ask
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.genpkg import GeneratedPackage

__all__ = ["BackendSettings", "BridgePart"]


@dataclass(frozen=True)
class BackendSettings:
    """The bridge's options a backend takes (each protocol reads its own)."""

    name: str  # the node's name on the bus, e.g. org.sam.uavcan_ros_bridge
    node_id: int
    rlog: RateLimitedLog
    errors: collections.Counter[str]
    transport: TransportConfig = field(default_factory=TransportConfig)  # Cyphal
    rx_queue_size: int = DEFAULT_RX_QUEUE_SIZE  # Cyphal
    dronecan_iface: str = "mcast-lo:"  # DroneCAN


class BridgePart(Protocol):
    """One protocol's part of a bridge."""

    def backend(self, settings: BackendSettings) -> Backend:
        """The protocol's backend (not open yet)."""

    def converters(self, gen: GeneratedPackage) -> ModuleType:
        """The generated object converters, with the protocol's types loaded first; inside the running loop."""

    def duties(self, lifetime: Lifetime, backend: Backend, ros: Any, devices: Mapping[int, str], tables: Any,
               options: Mapping[str, Any]) -> Any:
        """The protocol's built-in node duties (attached), or None when it has none."""

    def services(self, lifetime: Lifetime, backend: Backend, ros: Any, mappings: Sequence[Any], *,
                 diagnostics_period: float) -> ServiceMappingsRos:
        """The spec's service mappings of this protocol, served (not attached yet)."""

    def param_access(self, backend: Backend) -> ParamAccess:
        """Reads and writes of the boards' settings (the bridge's ROS parameters <device>.<setting>)."""

    def sync_message(self) -> SyncMessage:
        """The time-sync master's message."""

    def prepare_replay(self, gen: GeneratedPackage) -> None:
        """What replaying recorded transfers through the codecs needs loaded first."""

    def interface_ask(self, backend: Backend) -> Ask:
        """The request for a board's interface version (issue 28: sam_runtime.bridge.interface_check)."""
