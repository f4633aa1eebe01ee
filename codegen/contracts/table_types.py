"""The types of the generated tables.py (devices, topics, QoS, mappings, layouts, parameters, frames, nodes):
frozen dataclasses, standard library only.

Invariant: everything below this docstring is copied verbatim into every generated tables.py (targets/python/
tables.py reads this file), so the generated package stays self-contained and these classes are exactly the ones
it defines. Hence: no imports beyond the standard library, nothing here that must not be in the output, and any
change here changes generated/ (rebuild it and the golden files). The runtime may import these classes (under
TYPE_CHECKING) to annotate what it reads from a generated tables module.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PortInfo:
    """A UAVCAN subject a device publishes or subscribes to."""

    subject_id: int
    dsdl_type: str  # full name with version, e.g. "sam.sensor.RawIMU.0.1"
    dsdl_module: str  # the pycyphal module, e.g. "sam.sensor"
    dsdl_class: str  # the pycyphal class in it, e.g. "RawIMU_0_1"
    rate_hz: float


@dataclass(frozen=True)
class DeviceInfo:
    """A UAVCAN node of the vehicle."""

    name: str
    node_id: int
    description: str
    publishes: tuple[PortInfo, ...]
    subscribes: tuple[PortInfo, ...]
    # The board's interface version (sam_codegen.validate.interface_version), what its firmware reports.
    interface_hash: int = 0


@dataclass(frozen=True)
class QosInfo:
    """The QoS of a topic's endpoints (keep-last history); the rclpy profile:
    sam_runtime.node_support.qos_profile(q.reliability, q.durability, q.depth)."""

    reliability: str  # "reliable" | "best_effort"
    durability: str  # "volatile" | "transient_local"
    depth: int
    profile: str  # the spec's profile name ("sensor_data", "reliable", "latched", "tf"), "" if spelled out


@dataclass(frozen=True)
class TopicInfo:
    """A ROS topic; its publishers (the bridge's too) use its ``qos``, its subscriptions (the bridge's command
    subscriptions too) its ``subscriber_qos`` unless a node's own differs (NodeInfo). Sensor data: publishers
    reliable, subscribers best effort (REP 2003), so any subscriber matches."""

    name: str
    ros_type: str  # e.g. "sensor_msgs/msg/Imu"
    ros_module: str  # e.g. "sensor_msgs.msg"
    ros_class: str  # e.g. "Imu"
    description: str
    qos: QosInfo
    subscriber_qos: QosInfo


@dataclass(frozen=True)
class MappingInfo:
    """One mapping of the bridge between a UAVCAN subject and a ROS topic."""

    name: str
    direction: str  # "uavcan_to_ros" | "ros_to_uavcan"
    topic: TopicInfo
    port: PortInfo
    source_node_ids: frozenset[int]  # UAVCAN->ROS: the nodes whose messages are accepted
    destination_node_id: int | None  # ROS->UAVCAN: the node the commands are meant for
    frame_id: str | None
    rate_hz: float
    on_out_of_range: str  # "saturate" | "reject"
    to_ros: str  # name of the converter function in convert.py
    to_uavcan: str
    # UAVCAN paths whose value survives UAVCAN->ROS->UAVCAN exactly (but a timestamp of 0, "unknown", comes
    # back as the receive time; and text only when it is UTF-8 without NUL characters)
    exact_uavcan_fields: tuple[str, ...]
    linked_uavcan_fields: tuple[str, ...]  # every UAVCAN path the converters read or write
    # `source_node_ids: any`: UAVCAN->ROS accepts every node (no source filter, so no spoofing protection)
    any_node: bool = False
    # run-time traffic control (sam_runtime.bridge.rate_limit, .switches): the latest message at most
    # max_rate_hz a second (None: every one); ROS->UAVCAN: a command older than deadline_s since the
    # bridge received it is not sent; the mapping's initial state and its std_srvs/SetBool service
    # (a ROS name the bridge's node resolves)
    max_rate_hz: float | None = None
    deadline_s: float | None = None
    enabled: bool = True
    enable_service: str = ""


@dataclass(frozen=True)
class DroneCanTypeInfo:
    """A UAVCAN v0 (DroneCAN) message type: its name in dronecan, and what its transfers are checked with."""

    name: str  # full name, e.g. "uavcan.equipment.ahrs.RawIMU"
    data_type_id: int
    signature: int  # the data type signature (CRC-64-WE); it seeds the CRC of a multi-frame transfer
    custom: bool  # one of the spec's dronecan_types: dronecan knows it after load_dsdl(DRONECAN_DSDL_DIRS)


@dataclass(frozen=True)
class DroneCanPortInfo:
    """A DroneCAN message a device broadcasts or receives (no subject id: the data type is the key)."""

    data_type: DroneCanTypeInfo
    rate_hz: float


@dataclass(frozen=True)
class DroneCanDeviceInfo:
    """A device's DroneCAN firmware: its node and the messages it broadcasts and receives."""

    name: str
    node_id: int
    description: str
    publishes: tuple[DroneCanPortInfo, ...]
    subscribes: tuple[DroneCanPortInfo, ...]
    interface_hash: int = 0  # as DeviceInfo's


@dataclass(frozen=True)
class DroneCanMappingInfo:
    """A DroneCAN mapping of the bridge between a v0 data type and a ROS topic (converters: convert_v0.py)."""

    name: str
    direction: str  # "uavcan_to_ros" | "ros_to_uavcan"
    topic: TopicInfo
    data_type: DroneCanTypeInfo
    # (field path, value): UAVCAN->ROS takes only the messages with these values (convert_v0.MATCHES checks
    # them and the elements); ROS->UAVCAN sets them
    select: tuple[tuple[str, int | bool], ...]
    elements: tuple[str, ...]  # broadcast-array elements read or written: "rpm[1]", "commands[actuator_id=4]"
    source_node_ids: frozenset[int]  # UAVCAN->ROS: the nodes whose messages are accepted
    destination_node_ids: frozenset[int]  # ROS->UAVCAN: the nodes its broadcast commands are meant for
    frame_id: str | None
    rate_hz: float
    on_out_of_range: str  # "saturate" | "reject"
    to_ros: str  # name of the converter function in convert_v0.py
    to_uavcan: str
    exact_uavcan_fields: tuple[str, ...]  # as MappingInfo's
    linked_uavcan_fields: tuple[str, ...]
    # `source_node_ids: any` / `destination_node_ids: any`: every node (the node id sets are empty);
    # UAVCAN->ROS then routes only on `select` and the items read
    any_node: bool = False
    max_rate_hz: float | None = None  # these four as MappingInfo's
    deadline_s: float | None = None
    enabled: bool = True
    enable_service: str = ""


@dataclass(frozen=True)
class LayoutInfo:
    """A firmware set of the vehicle: the protocol of each device, and the mappings the bridge runs then."""

    name: str
    description: str
    protocols: tuple[tuple[str, str], ...]  # (device, "cyphal" | "dronecan"), in spec order
    cyphal_mappings: tuple[str, ...]  # names in MAPPINGS
    dronecan_mappings: tuple[str, ...]  # names in DRONECAN_MAPPINGS

    def devices(self, protocol: str) -> tuple[str, ...]:
        return tuple(device for device, p in self.protocols if p == protocol)


@dataclass(frozen=True)
class ParameterInfo:
    """A ROS parameter of the vehicle's nodes."""

    name: str
    type: str  # "double" | "integer" | "bool" | "string"
    default: float | int | bool | str
    minimum: float | None
    maximum: float | None
    unit: str
    description: str


@dataclass(frozen=True)
class StaticTransformInfo:
    """A static child frame: the pose of `child` in `parent` (its mounting), published once on /tf_static."""

    parent: str
    child: str
    translation: tuple[float, float, float]  # m
    rotation: tuple[float, float, float, float]  # unit quaternion x, y, z, w


@dataclass(frozen=True)
class TransformInfo:
    """A transform a node publishes on /tf."""

    parent: str
    child: str
    publisher: str  # the node


@dataclass(frozen=True)
class EndpointInfo:
    """A node's publication or subscription and the QoS it uses."""

    topic: str
    qos: QosInfo


@dataclass(frozen=True)
class NodeInfo:
    """A node of the spec and its generated base class."""

    name: str
    description: str
    module: str  # e.g. "sam_nodes.motion_planner"
    base_class: str  # e.g. "MotionPlannerBase"
    publishes: tuple[EndpointInfo, ...]
    subscribes: tuple[EndpointInfo, ...]
    parameters: tuple[str, ...]  # spec names, e.g. "/safe_depth"
    transforms: tuple[tuple[str, str], ...]  # (parent, child) it publishes
    reads_transforms: tuple[tuple[str, str], ...]  # (parent, child) it looks up


@dataclass(frozen=True)
class ParameterRuleInfo:
    """A relation two parameters must keep: `left op right`."""

    left: str
    op: str
    right: str
    description: str


@dataclass(frozen=True)
class DeviceParameterInfo:
    """A setting a board holds (a device's `parameters:`): a register on Cyphal, a param on DroneCAN.

    `default` is the spec's value (an enum's name); `values` map an enum's names to the integers the board
    stores; `minimum`/`maximum` bound an integer or a real; `max_length` a string's UTF-8 bytes; `names` give
    its name on each protocol the board speaks. The bridge exposes it as the ROS parameter `<device>.<name>`.
    """

    device: str
    name: str
    type: str  # "bool" | "integer" | "real" | "string" | "enum"
    default: bool | int | float | str
    description: str
    minimum: int | float | None
    maximum: int | float | None
    unit: str
    values: tuple[tuple[str, int], ...]
    max_length: int | None
    restart: bool
    names: tuple[tuple[str, str], ...]  # (protocol, its name there)

    def name_on(self, protocol: str) -> str:
        """Its name on `protocol` (one the board speaks)."""
        return dict(self.names)[protocol]
