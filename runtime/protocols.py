"""The runtime's protocols, registered: one entry per protocol, beside the generator's description of it
(sam_codegen.model.protocols). The composition root, the layouts, replay, the simulator and the generated-package
loader ask an entry instead of comparing the protocol's name.

An entry names its parts by module path (``"module:attribute"``), imported on first use: the bridge's part (its
backend, converters, duties, service mappings, time-sync message: sam_runtime.bridge.backends.part.BridgePart) and
the simulated devices' adapter (sam_runtime.sim.ports.DeviceAdapter). So a vehicle without DroneCAN devices never
imports dronecan (it parses its whole DSDL set at import, ~0.4 s), and this registry sits below the parts it names.
Adding a protocol: its description and parts in their own modules, and one line in REGISTERED (tests/runtime/
test_protocols.py checks that every part resolves and the two registries agree).
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.description import ProtocolDescription
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.protocols.registry import UnknownProtocolError

__all__ = ["REGISTERED", "RuntimeProtocol", "default_protocol", "protocol_names", "registered", "runtime_protocol"]


@dataclass(frozen=True)
class RuntimeProtocol:
    """A protocol as the runtime uses it: the generated tables' records of it and where its parts are."""

    description: ProtocolDescription
    bridge_part: str  # "module:attribute" of its sam_runtime.bridge.backends.part.BridgePart
    sim_adapter: str  # "module:attribute" of its simulated devices' adapter class (sam_runtime.sim.ports)
    needs: str = ""  # what its parts need installed beyond the base runtime (said when one does not import)

    @property
    def name(self) -> str:
        return self.description.name

    @property
    def label(self) -> str:
        return self.description.label

    # The generated tables' records of this protocol (sam_codegen.contracts.tables_api names them all).
    def mappings(self, tables: Any) -> tuple[Any, ...]:
        """Its topic mappings (MappingInfo / DroneCanMappingInfo), in the tables' order."""
        return tuple(getattr(tables, self.description.mappings_table))

    def devices(self, tables: Any) -> tuple[Any, ...]:
        """The devices' firmware on it (DeviceInfo / DroneCanDeviceInfo)."""
        return tuple(getattr(tables, self.description.devices_table))

    def device_stamped(self, tables: Any) -> frozenset[str]:
        """Its UAVCAN -> ROS mappings whose header.stamp is the device's clock."""
        return frozenset(getattr(tables, self.description.device_stamped_table))

    def layout_mappings(self, layout: Any) -> Sequence[str]:
        """The names of a LayoutInfo's mappings on it."""
        names: Sequence[str] = getattr(layout, self.description.layout_mappings_field)
        return names

    def bridge(self) -> Any:
        """Its sam_runtime.bridge.backends.part.BridgePart."""
        return self.load(self.bridge_part)

    def sim(self) -> Any:
        """Its simulated devices' adapter class (called with the Simulator)."""
        return self.load(self.sim_adapter)

    def load(self, ref: str) -> Any:
        """One of its parts (an ImportError says what the protocol needs installed)."""
        module, _, attribute = ref.partition(":")
        try:
            return getattr(importlib.import_module(module), attribute)
        except ImportError as ex:
            if not self.needs:
                raise
            raise ImportError(f"{self.label} needs {self.needs}: {ex}") from ex


REGISTERED: tuple[RuntimeProtocol, ...] = (
    RuntimeProtocol(CYPHAL, "sam_runtime.bridge.backends.cyphal_part:PART", "sam_runtime.sim.cyphal:CyphalDevices"),
    RuntimeProtocol(DRONECAN, "sam_runtime.bridge.backends.dronecan_part:PART",
                    "sam_runtime.sim.dronecan:DroneCanDevices", needs="the dronecan package (pip extra 'runtime')"),
)


# Read at every call, never copied at import: what asks the registry sees a protocol registered later (a test's).
def registered() -> tuple[RuntimeProtocol, ...]:
    return REGISTERED


def protocol_names() -> tuple[str, ...]:
    return tuple(p.name for p in REGISTERED)


def default_protocol() -> RuntimeProtocol:
    """The spec's default (a device without `protocol`; tables without layouts run every device on it)."""
    return REGISTERED[0]


def runtime_protocol(name: str) -> RuntimeProtocol:
    """The registered protocol called ``name`` (UnknownProtocolError, a ValueError, names the known ones)."""
    for p in REGISTERED:
        if p.name == name:
            return p
    raise UnknownProtocolError(f"unknown protocol {name!r}: expected one of {', '.join(protocol_names())}")
