"""What a generated tables.py offers, as a Protocol the runtime can annotate against.

The runtime loads a generated ``<vehicle>_bridge.tables`` at run time, where mypy cannot see it; annotated as
``tables = cast(TablesModule, module)`` its members get their real types. Invariant: the members and their types are
those templates/python/tables.py.j2 writes, and the classes are table_types.py's, which every generated tables.py
defines verbatim (same fields, same behaviour; but they are that module's own classes, so compare fields, never
isinstance against table_types). Standard library only, like the tables.
"""

from __future__ import annotations

from typing import Protocol

from sam_codegen.contracts.table_types import (
    DeviceInfo,
    DeviceParameterInfo,
    DroneCanDeviceInfo,
    DroneCanMappingInfo,
    DroneCanTypeInfo,
    LayoutInfo,
    MappingInfo,
    NodeInfo,
    ParameterInfo,
    ParameterRuleInfo,
    StaticTransformInfo,
    TopicInfo,
    TransformInfo,
)

__all__ = ["TablesModule"]


class TablesModule(Protocol):
    """The module-level names of a generated tables.py."""

    VEHICLE: str
    ROS_PACKAGE: str
    DSDL_ROOT_NAMESPACE: str
    BRIDGE_NAME: str | None
    BRIDGE_NODE_ID: int | None
    NODES_PACKAGE: str
    PARAMS_FILE: str  # under the generated folder
    ROS_PACKAGES: tuple[str, ...]  # each after those it depends on
    DEVICES: tuple[DeviceInfo, ...]
    TOPICS: tuple[TopicInfo, ...]
    MAPPINGS: tuple[MappingInfo, ...]
    DRONECAN_DSDL_DIRS: tuple[str, ...]
    DRONECAN_TYPES: tuple[DroneCanTypeInfo, ...]
    DRONECAN_DEVICES: tuple[DroneCanDeviceInfo, ...]
    DRONECAN_MAPPINGS: tuple[DroneCanMappingInfo, ...]
    LAYOUTS: tuple[LayoutInfo, ...]
    DEFAULT_LAYOUT: str
    PARAMETERS: tuple[ParameterInfo, ...]
    PARAMETER_RULES: tuple[ParameterRuleInfo, ...]
    FRAMES: tuple[tuple[str, str | None], ...]  # (frame, parent)
    STATIC_TRANSFORMS: tuple[StaticTransformInfo, ...]
    TRANSFORMS: tuple[TransformInfo, ...]
    NODES: tuple[NodeInfo, ...]
    DRONECAN_NAMESPACES: tuple[str, ...] | None  # None: every namespace dronecan loads
    DRONECAN_PANIC_DUTY: str  # "builtin" | "mappings" | "both"
    TIME_SYNC_PERIOD_S: float | None  # the bridge's time-sync master; None: off
    DEVICE_STAMPED_MAPPINGS: frozenset[str]  # Cyphal UAVCAN -> ROS mappings whose header.stamp is the device's
    DRONECAN_DEVICE_STAMPED_MAPPINGS: frozenset[str]  # the same of the DroneCAN mappings
    INTERFACE_HASH: int  # the whole spec's interface version (every board's)
    INTERFACE_ON_MISMATCH: str  # "warn" | "stop": bridge.interface_check.on_mismatch
    DEVICE_PARAMETERS: tuple[DeviceParameterInfo, ...]  # every board's settings, device by device
