"""The spec model: what validation checks and every emitter and the runtime tables read.

Invariants: the frontend (sam_codegen.frontend.loader) builds it from YAML, each object whole and the Spec last; every
class is frozen, and nothing changes a model object after it is built, so the validators and the emitters may run in
any order and share it. What validation derives (the messages derived from DSDL types, the resolved mappings) lives
in validate.Resolved, never in the Spec. Positions point back into the YAML for errors.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Final, Literal

from sam_codegen.model.device_params import DeviceParameter
from sam_codegen.model.diagnostics import NOWHERE, Pos
from sam_codegen.model.expr import ExprSource, UavcanExpr
from sam_codegen.model.types import DsdlType, RosType, split_composite_name

Direction = Literal["uavcan_to_ros", "ros_to_uavcan"]
UAVCAN_TO_ROS: Final[Direction] = "uavcan_to_ros"  # the bridge publishes on ROS what a device sent
ROS_TO_UAVCAN: Final[Direction] = "ros_to_uavcan"  # the bridge sends to devices what it receives on ROS
DIRECTIONS: tuple[Direction, ...] = (UAVCAN_TO_ROS, ROS_TO_UAVCAN)
Reliability = Literal["reliable", "best_effort"]
Durability = Literal["volatile", "transient_local"]
OutOfRange = Literal["saturate", "reject"]
Scalar = bool | int | float | str


@dataclass(frozen=True)
class Field:
    name: str
    type: RosType | DsdlType
    comment: str = ""
    pos: Pos = NOWHERE
    default: Scalar | None = None


@dataclass(frozen=True)
class Constant:
    name: str
    type: RosType | DsdlType
    value: Scalar
    comment: str = ""
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class RosMessage:
    package: str
    name: str
    fields: list[Field]
    constants: list[Constant] = field(default_factory=list)
    description: str = ""
    derived_from: str | None = None
    external: bool = False
    pos: Pos = NOWHERE

    @property
    def full_name(self) -> str:
        return f"{self.package}/{self.name}"

    def field(self, name: str) -> Field | None:
        return next((f for f in self.fields if f.name == name), None)


@dataclass(frozen=True)
class DsdlStruct:
    """A DSDL composite type: one of the spec's own, or a standard one read from CYPHAL_PATH."""

    name: str  # full name with version: sam.sensor.RawIMU.0.1
    fields: list[Field]  # the data fields: void padding left out, as pydsdl's fields_except_padding
    constants: list[Constant] = field(default_factory=list)
    description: str = ""
    sealed: bool = True
    extent: int | None = None
    standard: bool = False
    union: bool = False
    pos: Pos = NOWHERE
    # Every field as declared, void padding (no name) included; empty when the type has no padding.
    layout: list[Field] = field(default_factory=list)

    @property
    def declared_fields(self) -> list[Field]:
        """The fields in declaration order with the padding between them: what the DSDL definition lists."""
        return self.layout or self.fields

    @property
    def full_name(self) -> str:
        return split_composite_name(self.name)[0]

    @property
    def version(self) -> tuple[int, int]:
        _, major, minor = split_composite_name(self.name)
        return major, minor

    @property
    def namespace(self) -> str:
        return self.full_name.rsplit(".", 1)[0]

    @property
    def short_name(self) -> str:
        return self.full_name.rsplit(".", 1)[1]

    def field(self, name: str) -> Field | None:
        return next((f for f in self.fields if f.name == name), None)


@dataclass(frozen=True)
class V0Struct(DsdlStruct):
    """A UAVCAN v0 (DroneCAN) composite type: one of the spec's `dronecan_types` or a standard one of dronecan's
    definitions. Its name has no version (`uavcan.equipment.ahrs.RawIMU`); fields hold v0 types (composites by
    full name)."""

    data_type_id: int | None = None  # None: only nested in other types (e.g. uavcan.Timestamp)
    signature: int = 0  # the data type signature (CRC-64-WE), which seeds a transfer's CRC
    service: bool = False
    source: str = ""  # the definition file of a standard type
    # A service type (service=True): `fields`/`layout` are its request, these its response (padding included in
    # response_layout, empty when it has none), as the part after `---` of its definition.
    response: list[Field] = field(default_factory=list)
    response_layout: list[Field] = field(default_factory=list)
    # the response's constants (`response_constants`, issue 27), emitted after `---`; `constants` are the request's
    response_constants: list[Constant] = field(default_factory=list)

    @property
    def declared_response(self) -> list[Field]:
        """The response fields in declaration order with their padding."""
        return self.response_layout or self.response

    @property
    def full_name(self) -> str:
        return self.name

    @property
    def version(self) -> tuple[int, int]:
        return 0, 0

    @property
    def file_name(self) -> str:
        """`<data type id>.<Name>.uavcan`, or `<Name>.uavcan` for a type without id."""
        prefix = f"{self.data_type_id}." if self.data_type_id is not None else ""
        return f"{prefix}{self.short_name}.uavcan"


@dataclass(frozen=True)
class Qos:
    """The QoS of a topic's endpoints: reliability, durability and keep-last history depth."""

    reliability: Reliability
    durability: Durability
    depth: int
    profile: str = ""  # the named profile it came from; "" for a spelled-out mapping

    def describe(self) -> str:
        """
        >>> QOS_PROFILES["latched"].describe()
        'latched (reliable, transient_local, keep last 1)'
        >>> Qos("best_effort", "volatile", 3).describe()
        'best_effort, volatile, keep last 3'
        """
        text = f"{self.reliability}, {self.durability}, keep last {self.depth}"
        return f"{self.profile} ({text})" if self.profile else text


# The named profiles a spec may give as `qos: <name>`. sensor_data is rclpy's qos_profile_sensor_data.
QOS_PROFILES: dict[str, Qos] = {
    "sensor_data": Qos("best_effort", "volatile", 5, "sensor_data"),
    "reliable": Qos("reliable", "volatile", 10, "reliable"),
    "latched": Qos("reliable", "transient_local", 1, "latched"),
    "tf": Qos("reliable", "volatile", 100, "tf"),
}
# A topic's `qos:` names both sides of it. `sensor_data` there follows REP 2003: sensor drivers (the bridge)
# publish reliably, consumers subscribe best effort (rclpy's qos_profile_sensor_data), so a subscriber with default
# (reliable) settings, a best-effort one and a reliable one all match. Every other profile is the same on both sides.
SENSOR_PUBLISHERS = Qos("reliable", "volatile", 5)
QOS_SIDES = ("publishers", "subscribers")


def topic_profile(name: str) -> tuple[Qos, Qos] | None:
    """(publishers, subscribers) of a topic's `qos: <name>`; None for an unknown name.

    >>> [q.reliability for q in topic_profile("sensor_data")]
    ['reliable', 'best_effort']
    >>> topic_profile("latched")[0] == topic_profile("latched")[1] == QOS_PROFILES["latched"]
    True
    """
    profile = QOS_PROFILES.get(name)
    if profile is None:
        return None
    return (SENSOR_PUBLISHERS, profile) if name == "sensor_data" else (profile, profile)


def describe_sides(publishers: Qos, subscribers: Qos) -> str:
    """The QoS of a topic's two sides, once when they are the same.

    >>> describe_sides(*topic_profile("reliable"))
    'publishers and subscribers reliable (reliable, volatile, keep last 10)'
    >>> describe_sides(*topic_profile("sensor_data"))
    'publishers reliable, volatile, keep last 5; subscribers sensor_data (best_effort, volatile, keep last 5)'
    """
    if publishers == subscribers:
        return f"publishers and subscribers {publishers.describe()}"
    return f"publishers {publishers.describe()}; subscribers {subscribers.describe()}"
RELIABILITIES: tuple[Reliability, ...] = ("reliable", "best_effort")
DURABILITIES: tuple[Durability, ...] = ("volatile", "transient_local")
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"
TF_MESSAGE = "tf2_msgs/TFMessage"


@dataclass(frozen=True)
class Topic:
    name: str
    type: str  # pkg/Name
    description: str = ""
    section: str = ""
    pos: Pos = NOWHERE
    # The spec's `qos:` per side (publishers, subscribers), if it gives that side
    declared_qos: Qos | None = None
    qos_pos: Pos = NOWHERE
    # The QoS its publishers use (the bridge's and external ones too): the declared one or the default for the
    # topic (default_qos), chosen by the frontend, which knows the bridge's mappings when it builds the topic.
    # None only for a hand-built Topic.
    qos: Qos | None = None
    qos_origin: str = ""  # why: "declared", or the default rule that chose it (either side)
    # The QoS its subscriptions use (the bridge's command subscriptions too) unless a node's subscription gives its
    # own; chosen as `qos` is. REP 2003: best effort for sensor data, which a reliable publisher serves.
    declared_subscriber_qos: Qos | None = None
    subscriber_qos: Qos | None = None
    # `published_by: external`: published (also) from outside the spec (an operator GUI, a mission executive);
    # the text says who ("" when the spec does not say). None: only the spec's nodes and bridge publish it.
    external_publisher: str | None = None
    external_pos: Pos = NOWHERE
    implied: bool = False  # not declared: /tf or /tf_static, which the nodes' transforms imply (frontend.tf_topics)


def default_qos(topic: Topic, bridged: set[str]) -> tuple[Qos, Qos, str]:
    """The QoS of a topic without `qos:` (publishers, subscribers), by ROS convention, and why; `bridged`: the
    topics the bridge publishes from UAVCAN (its uavcan_to_ros mappings).

    >>> default_qos(Topic("/tf_static", "tf2_msgs/TFMessage"), set())[0].profile
    'latched'
    >>> pub, sub, why = default_qos(Topic("/imu", "sensor_msgs/Imu"), {"/imu"})
    >>> pub.reliability, sub.reliability, why
    ('reliable', 'best_effort', 'a UAVCAN sensor stream (REP 2003)')
    >>> default_qos(Topic("/goal", "geometry_msgs/PoseStamped"), set())[2]
    'a command, goal or plan'
    """
    if topic.name == TF_STATIC_TOPIC:
        profile, why = "latched", "static transforms (tf2's convention)"
    elif topic.type == TF_MESSAGE:
        profile, why = "tf", "transforms (tf2's convention)"
    elif topic.name in bridged:
        profile, why = "sensor_data", "a UAVCAN sensor stream (REP 2003)"
    else:
        profile, why = "reliable", "a command, goal or plan"
    sides = topic_profile(profile)
    assert sides is not None, "a known profile"
    return sides[0], sides[1], why


@dataclass(frozen=True)
class Parameter:
    name: str
    type: str
    default: Scalar
    unit: str = ""
    minimum: float | None = None
    maximum: float | None = None
    description: str = ""
    section: str = ""
    pos: Pos = NOWHERE
    allow_nan: bool = False  # NaN is a meaningful value (`allow_nan: true`); else a NaN default is refused


@dataclass(frozen=True)
class ParameterRule:
    left: str
    op: str
    right: str
    description: str = ""
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class Frame:
    name: str
    parent: str | None = None
    description: str = ""
    pos: Pos = NOWHERE
    # A static child frame's mounting offset in its parent (URDF's origin): metres, and roll, pitch, yaw in
    # radians (fixed axes x, y, z).
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Transform:
    parent: str
    child: str
    publisher: str
    description: str = ""
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class Port:
    subject_id: int
    type: str  # DSDL full name with version
    rate_hz: float
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class V0Port:
    """A UAVCAN v0 (DroneCAN) message a device broadcasts or receives: no subject id, the data type says it all."""

    type: str  # full name, e.g. uavcan.equipment.ahrs.RawIMU
    rate_hz: float
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class Device:
    name: str
    node_id: int
    description: str = ""
    publishes: list[Port] = field(default_factory=list)  # its Cyphal ports
    subscribes: list[Port] = field(default_factory=list)
    pos: Pos = NOWHERE
    protocol: str = "cyphal"  # what it speaks in the default layout
    protocols: tuple[str, ...] = ("cyphal",)  # every protocol it has ports for (firmware it can run)
    dronecan_publishes: list[V0Port] = field(default_factory=list)  # its DroneCAN ports
    dronecan_subscribes: list[V0Port] = field(default_factory=list)
    protocol_pos: dict[str, Pos] = field(default_factory=dict)  # where each protocol's ports are declared
    parameters: tuple[DeviceParameter, ...] = ()  # the settings its board holds


@dataclass(frozen=True)
class CanBus:
    """The CAN bus of the vehicle or of one layout (`bus:`), which the build's bus budget judges (validate.bus_budget).

    `bus: none` (present=False): a vehicle without CAN (Cyphal/UDP only), no budget."""

    bitrate: int = 1_000_000  # bit/s: classic CAN, or CAN FD's arbitration phase
    fd_data_bitrate: int | None = None  # CAN FD's data phase (Cyphal at MTU 64); None: classic CAN
    load_warning_percent: float = 70.0
    present: bool = True
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class Layout:
    """Which protocol each device speaks: the vehicle as one firmware set (a bus may carry both protocols)."""

    name: str
    description: str = ""
    protocol: str | None = None  # every device that has ports for it; None: each device's own `protocol`
    devices: dict[str, str] = field(default_factory=dict)  # per-device overrides
    device_pos: dict[str, Pos] = field(default_factory=dict)
    pos: Pos = NOWHERE
    bus: CanBus | None = None  # its own bus; None: the spec's


@dataclass(frozen=True)
class FieldLink:
    """One `ros_path: uavcan_source` line of a mapping."""

    ros_path: str
    uavcan_path: str | None = None
    scale: float | None = None
    offset: float | None = None
    table: dict[int, int] | None = None
    table_default: int | None = None  # the ROS value of every UAVCAN value the table does not list
    value: Scalar | None = None
    limits: tuple[float, float] | None = None
    pos: Pos = NOWHERE
    round: bool = False  # a UAVCAN float into a ROS integer: rounded half to even
    # `on_out_of_range: wrap` on this line (issue 27): an integer beyond the target stored modulo 2**bits, as C
    # stores it; the mapping's saturate / reject stays for every other line
    wrap: bool = False
    expr: ExprSource | None = None  # `{expr: "..."}`: the ROS field computed from UAVCAN fields (model.expr)
    # An element mapping (`ros_array: {each: uavcan_array, fields: {...}}`): arrays of composites converted element
    # by element, `element_links` relative to the elements (validate.element_mappings); `each` the UAVCAN array.
    each: str | None = None
    element_links: tuple[FieldLink, ...] = ()
    element_ignore: tuple[str, ...] = ()
    element_values: tuple[tuple[str, Scalar], ...] = ()  # the element's uavcan_values (ROS -> UAVCAN constants)


@dataclass(frozen=True)
class Mapping:
    name: str
    direction: Direction
    topic: str
    subject_id: int
    source_node_ids: list[int] = field(default_factory=list)
    destination_node_id: int | None = None
    frame_id: str | None = None
    links: list[FieldLink] = field(default_factory=list)
    ignore: list[str] = field(default_factory=list)
    uavcan_values: dict[str, Scalar] = field(default_factory=dict)
    auto: bool = False
    on_out_of_range: OutOfRange = "saturate"
    pos: Pos = NOWHERE
    protocol: str = "cyphal"
    # DroneCAN only: messages carry no subject id (the data type is the key) and no destination (they are
    # broadcast); `select` keeps the messages whose fields have these values (UAVCAN->ROS) and sets them (ROS->UAVCAN).
    data_type: str = ""
    destination_node_ids: list[int] = field(default_factory=list)
    select: dict[str, Scalar] = field(default_factory=dict)
    select_pos: Pos = NOWHERE
    # Routing (codegen/validate/routing.py): `source_node_ids: any` (or DroneCAN's `destination_node_ids: any`)
    # accepts every node instead of the static ids; `shares_data_type` lets several ROS->UAVCAN mappings broadcast
    # the same DroneCAN data type (each sends its own messages).
    any_node: bool = False
    any_node_pos: Pos = NOWHERE
    shares_data_type: bool = False
    # Run-time traffic control (sam_codegen.frontend.traffic): the latest message at most max_rate_hz times a second
    # (None: every one); ROS->UAVCAN only, a command older than deadline_s seconds since the bridge received it is
    # not sent (None: never too old); the initial state of the mapping's std_srvs/SetBool switch and its name.
    max_rate_hz: float | None = None
    deadline_s: float | None = None
    enabled: bool = True
    enable_service: str = ""  # "": ENABLE_SERVICE_DEFAULT
    # ROS -> UAVCAN: UAVCAN fields computed from ROS fields (model.expr); UAVCAN -> ROS: the ROS fields that keep
    # their type's default (0, false, empty) on purpose (every other ROS field must be written).
    uavcan_exprs: list[UavcanExpr] = field(default_factory=list)
    ros_defaults: list[str] = field(default_factory=list)
    # ROS -> UAVCAN: a float NaN command is rejected (counted as `not_a_number`) unless the mapping says
    # `pass_nan: true`, for a device that reads NaN as a command of its own ("hold", "no setpoint").
    pass_nan: bool = False
    pass_nan_pos: Pos | None = None  # where `pass_nan` is written (its errors point there)

    @property
    def enable_service_name(self) -> str:
        """The SetBool service that enables and disables the mapping at run time (a ROS name, resolved by the
        bridge's node: `~/` is under the node's own name)."""
        return self.enable_service or ENABLE_SERVICE_DEFAULT.format(name=self.name)


ENABLE_SERVICE_DEFAULT = "~/enable_{name}"


@dataclass(frozen=True)
class DsdlService:
    """A Cyphal service type of the spec (`dsdl_types` with `request` and `response`): its two halves as structs
    of its name, each emitted with the same `sealed`/`extent`, `---` between them."""

    name: str  # full name with version: lolo.power.SetLimits.1.0
    request: DsdlStruct
    response: DsdlStruct
    description: str = ""
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class RosService:
    """A ROS 2 service type of the spec's package (`services:`), or of another package (`external_services:`,
    `external`): a .srv with a request and a response, and constants."""

    package: str
    name: str
    request: list[Field]
    response: list[Field]
    description: str = ""
    pos: Pos = NOWHERE
    constants: list[Constant] = field(default_factory=list)  # emitted at the top of the request (issue 27)
    external: bool = False  # `external_services`: a srv of another package, generated as that package (issue 27)

    @property
    def full_name(self) -> str:
        return f"{self.package}/{self.name}"


@dataclass(frozen=True)
class ServiceMapping:
    """A ROS service the bridge serves by a UAVCAN request to one device (`bridge.service_mappings`). Both link
    lists are `ros_field: uavcan_field` lines as in a mapping: `request` goes ROS->UAVCAN (with `uavcan_values` for
    request fields set to constants), `response` UAVCAN->ROS."""

    name: str
    service: str  # the ROS service name
    type: str  # the srv type, pkg/Name
    data_type: str  # the UAVCAN service type (v0 full name)
    destination_node_id: int
    timeout_s: float = 1.0
    request: list[FieldLink] = field(default_factory=list)
    response: list[FieldLink] = field(default_factory=list)
    uavcan_values: dict[str, Scalar] = field(default_factory=dict)  # request fields set to constants
    protocol: str = "dronecan"
    pos: Pos = NOWHERE
    # The ROS request field that names the node to ask (`destination_node_id: node_id`, e.g. GetNodeInfo of any
    # node); None: always destination_node_id.
    destination_field: str | None = None
    # Cyphal: the service id (`service_id`); None: the standard type's fixed port id
    service_id: int | None = None
    # a device duty of `bridge.node_services` (get_node_info...): any device of the bridge's protocol, by node id
    duty: str | None = None
    # ROS response fields (or what nothing writes under one) meant to keep the srv's defaults (issue 27: any other
    # field no line writes is an error, never a silent zero)
    response_defaults: tuple[str, ...] = ()


@dataclass(frozen=True)
class NodeService:
    """One device duty of `bridge.node_services` (frontend.node_services): `duty` is get_node_info, restart_node or
    get_transport_stats; off (`false`) when not `enabled`; `service` the ROS name as written; `type` the srv
    (pkg/Name): the spec's own by `type:`, else the default the tool generates (`<package>/UavcanGetNodeInfo`...)."""

    duty: str
    enabled: bool
    service: str
    type: str
    timeout_s: float = 1.0
    pos: Pos = NOWHERE
    type_pos: Pos = NOWHERE
    type_given: bool = False  # `type:` written (else the default name, which the spec may declare itself)
    response_defaults: tuple[str, ...] = ()  # the srv's response fields the duty leaves at their defaults


@dataclass(frozen=True)
class TimeSync:
    """`bridge.time_sync`: the bridge as the bus's time-sync master on both protocols (frontend.time_sync)."""

    enabled: bool = True
    period_s: float = 0.5
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class Bridge:
    name: str
    node_id: int
    mappings: list[Mapping] = field(default_factory=list)  # Cyphal
    pos: Pos = NOWHERE
    dronecan_mappings: list[Mapping] = field(default_factory=list)
    # Who handles uavcan.protocol.Panic: "builtin" (the bridge's duty), "mappings" (only dronecan_mappings of
    # Panic) or "both"; None: not said (the built-in duty, and no mapping of Panic allowed)
    panic_duty: str | None = None
    panic_duty_pos: Pos = NOWHERE
    service_mappings: list[ServiceMapping] = field(default_factory=list)
    time_sync: TimeSync = field(default_factory=TimeSync)
    node_services: list[NodeService] = field(default_factory=list)  # the device duties (all three by default)
    # `interface_check: {on_mismatch: warn | stop}`: what the bridge does with a board whose firmware reports another
    # interface version than the spec's (issue 28): warn, or also stop bridging its mappings
    interface_on_mismatch: str = "warn"

    @property
    def all_mappings(self) -> list[Mapping]:
        return [*self.mappings, *self.dronecan_mappings]


@dataclass(frozen=True)
class NodeTopic:
    """One entry of a node's `publishes` or `subscribes`."""

    topic: str
    qos: Qos | None = None  # a subscription's own QoS; None: the topic's
    pos: Pos = NOWHERE
    type: str | None = None  # the type the node expects, checked against the topic's


@dataclass(frozen=True)
class NodeTransform:
    """One `parent->child` entry of a node's `transforms` (it publishes) or `reads_transforms` (it looks up)."""

    parent: str
    child: str
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class NodeParameter:
    name: str
    pos: Pos = NOWHERE


@dataclass(frozen=True)
class Node:
    name: str
    description: str = ""
    publish_items: list[NodeTopic] = field(default_factory=list)
    subscribe_items: list[NodeTopic] = field(default_factory=list)
    parameter_items: list[NodeParameter] = field(default_factory=list)
    transform_items: list[NodeTransform] = field(default_factory=list)  # published on /tf
    read_transform_items: list[NodeTransform] = field(default_factory=list)  # looked up from /tf, /tf_static
    pos: Pos = NOWHERE

    @property
    def publishes(self) -> list[str]:
        return [item.topic for item in self.publish_items]

    @property
    def subscribes(self) -> list[str]:
        return [item.topic for item in self.subscribe_items]

    @property
    def parameters(self) -> list[str]:
        return [item.name for item in self.parameter_items]

    @property
    def transforms(self) -> list[tuple[str, str]]:
        return [(item.parent, item.child) for item in self.transform_items]

    @property
    def reads_transforms(self) -> list[tuple[str, str]]:
        return [(item.parent, item.child) for item in self.read_transform_items]


@dataclass(frozen=True)
class RosPackageInfo:
    name: str
    version: str = "0.1.0"
    description: str = ""
    maintainer: str = "maintainer"
    maintainer_email: str = "maintainer@example.org"
    license: str = "MIT"
    topics_message: str | None = None  # `ros.topics_message`: a generated message of topic-name constants
    topics_message_pos: Pos = NOWHERE


@dataclass(frozen=True)
class Spec:
    file: str
    vehicle: str
    description: str
    ros: RosPackageInfo
    dsdl_root: str
    external_messages: dict[str, RosMessage] = field(default_factory=dict)
    messages: dict[str, RosMessage] = field(default_factory=dict)  # by full name pkg/Name
    dsdl_types: dict[str, DsdlStruct] = field(default_factory=dict)  # by full name with version
    frames: dict[str, Frame] = field(default_factory=dict)
    transforms: list[Transform] = field(default_factory=list)
    topics: dict[str, Topic] = field(default_factory=dict)
    parameters: dict[str, Parameter] = field(default_factory=dict)
    parameter_rules: list[ParameterRule] = field(default_factory=list)
    devices: dict[str, Device] = field(default_factory=dict)
    bridge: Bridge | None = None
    nodes: dict[str, Node] = field(default_factory=dict)
    dronecan_types: dict[str, V0Struct] = field(default_factory=dict)  # the spec's own v0 types, by full name
    layouts: dict[str, Layout] = field(default_factory=dict)  # the named layouts beside the implicit default
    bus: CanBus | None = None  # the vehicle's CAN bus; None: classic CAN at 1 Mbit/s
    # The namespaces of the standard v0 definitions the spec uses (uavcan always); None: every one (the default)
    dronecan_namespaces: tuple[str, ...] | None = None
    dronecan_namespaces_pos: tuple[Pos, ...] = ()  # each entry's position
    services: dict[str, RosService] = field(default_factory=dict)  # the package's own .srv types, by pkg/Name
    dsdl_services: dict[str, DsdlService] = field(default_factory=dict)  # the spec's Cyphal service types

    def devices_by_node_id(self) -> dict[int, Device]:
        return {d.node_id: d for d in self.devices.values()}

    def subject_types(self) -> dict[int, str]:
        """Subject id -> DSDL type, from every device port."""
        result: dict[int, str] = {}
        for device in self.devices.values():
            for port in device.publishes + device.subscribes:
                result.setdefault(port.subject_id, port.type)
        return result
