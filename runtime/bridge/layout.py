"""What one bridge runs: the spec's layout (which firmware each device runs: ``layouts`` of the spec, ``default`` =
every device on its own ``protocol``) and the protocol of the bridge's backend.

A bridge has one protocol backend. A layout whose devices all run one protocol needs one bridge; a mixed layout
(Cyphal v1 and DroneCAN devices on one bus) runs one bridge per protocol (``protocol=``), each with the mappings of
its devices, under its own ROS node name (``uavcan_ros_bridge_cyphal`` / ``uavcan_ros_bridge_dronecan``) so that
their /diagnostics do not collide.

The two kinds of mapping records of the generated tables are read through :func:`port_id_of` (the Cyphal subject id
or the DroneCAN data type id) and :func:`destinations_of`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from sam_runtime.bridge.backend import BridgeConfigError
from sam_runtime.protocols import default_protocol, protocol_names, registered, runtime_protocol

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule

__all__ = ["Selection", "destinations_of", "port_id_of", "protocols_in_use", "select"]


@dataclass(frozen=True)
class Selection:
    """The mappings and devices of one bridge."""

    layout: str
    protocol: str  # "cyphal" | "dronecan"
    mappings: tuple[Any, ...]  # MappingInfo (Cyphal) or DroneCanMappingInfo, in the tables' order
    devices: dict[int, str]  # node id -> device name, the layout's devices on this protocol
    device_infos: tuple[Any, ...]  # their DeviceInfo / DroneCanDeviceInfo
    shared: bool  # the layout also has devices on the other protocol (another bridge serves them)


def port_id_of(m: Any) -> int:
    """The Cyphal subject id or the DroneCAN data type id of a mapping."""
    return int(m.data_type.data_type_id) if hasattr(m, "data_type") else int(m.port.subject_id)


def destinations_of(m: Any) -> tuple[int, ...]:
    """The destination node ids of a ROS -> UAVCAN mapping (Cyphal: one or none; DroneCAN: a set)."""
    if hasattr(m, "destination_node_ids"):
        return tuple(sorted(m.destination_node_ids))
    return () if m.destination_node_id is None else (int(m.destination_node_id),)


def _layouts(tables: TablesModule) -> dict[str, Any]:
    return {lay.name: lay for lay in tables.LAYOUTS}


def protocols_in_use(tables: TablesModule, layout: str) -> list[str]:
    """The protocols whose mappings the layout runs, in the registry's order (sam_runtime.protocols)."""
    lay = _layouts(tables).get(layout)
    if lay is None:
        return [default_protocol().name] if layout == "default" else []
    return [p.name for p in registered() if p.layout_mappings(lay)]


def select(tables: TablesModule, layout: str | None = None, protocol: str | None = None) -> Selection:
    """The mappings and devices of a bridge for ``layout`` (default: the tables' DEFAULT_LAYOUT) on ``protocol``
    (default: the layout's only protocol)."""
    layouts = _layouts(tables)
    name = layout or tables.DEFAULT_LAYOUT
    lay = layouts.get(name)
    if lay is None and not (name == "default" and not layouts):
        raise BridgeConfigError(f"the spec has no layout {name!r}; its layouts: {', '.join(sorted(layouts))}")
    used = protocols_in_use(tables, name)
    if protocol is not None and protocol not in protocol_names():
        raise BridgeConfigError(f"unknown protocol {protocol!r}: expected one of {', '.join(protocol_names())}")
    if protocol is None:
        if len(used) > 1:
            raise BridgeConfigError(
                f"layout {name!r} has devices on {' and '.join(used)}: run one bridge per protocol "
                f"(--protocol {' / --protocol '.join(used)})")
        protocol = used[0] if used else default_protocol().name
    elif used and protocol not in used:
        raise BridgeConfigError(f"layout {name!r} has no mapping on {protocol} (it uses {', '.join(used)})")
    entry = runtime_protocol(protocol)
    if lay is None:  # generated tables without layouts: every mapping on the default protocol (Cyphal)
        infos: Sequence[Any] = entry.devices(tables)
        mappings: tuple[Any, ...] = entry.mappings(tables)
    else:
        names = set(lay.devices(protocol))
        infos = [d for d in entry.devices(tables) if d.name in names]
        wanted = set(entry.layout_mappings(lay))
        mappings = tuple(m for m in entry.mappings(tables) if m.name in wanted)
    return Selection(name, protocol, mappings, {d.node_id: d.name for d in infos}, tuple(infos), len(used) > 1)
