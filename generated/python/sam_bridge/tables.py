# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The sam interface as data: devices, topics and their QoS, bridge mappings, parameters, frames and nodes.

Standard library only: the bridge runtime reads this module without importing ROS or the DSDL packages.
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


VEHICLE = 'sam'
ROS_PACKAGE = 'sam_msgs'
DSDL_ROOT_NAMESPACE = 'sam'
BRIDGE_NAME = 'uavcan_ros_bridge'
BRIDGE_NODE_ID = 100
NODES_PACKAGE = 'sam_nodes'
# Under the generated folder: every parameter's default in ROS 2's --params-file format.
PARAMS_FILE = 'params/sam.params.yaml'
# The generated ROS packages (generated/ros/<name>), each after those it depends on.
ROS_PACKAGES: tuple[str, ...] = ('sam_msgs', 'tf2_msgs')

# The devices with Cyphal firmware and their Cyphal ports (LAYOUTS say which run Cyphal).
DEVICES: tuple[DeviceInfo, ...] = (
    DeviceInfo(
        name='imu',
        node_id=11,
        description='Inertial measurement unit.',
        publishes=(
            PortInfo(1100, 'sam.sensor.RawIMU.0.1', 'sam.sensor', 'RawIMU_0_1', 100.0),
        ),
        subscribes=(),
        interface_hash=0xd637a59eaf89905f,
    ),
    DeviceInfo(
        name='magnetometer',
        node_id=12,
        description='Three-axis magnetometer.',
        publishes=(
            PortInfo(
                subject_id=1101,
                dsdl_type='sam.sensor.MagneticFieldStrength.0.1',
                dsdl_module='sam.sensor',
                dsdl_class='MagneticFieldStrength_0_1',
                rate_hz=50.0,
            ),
        ),
        subscribes=(),
        interface_hash=0x91845a90d6c01c77,
    ),
    DeviceInfo(
        name='gps',
        node_id=13,
        description='GPS receiver, usable at the surface.',
        publishes=(
            PortInfo(1102, 'sam.sensor.GNSSFix.0.1', 'sam.sensor', 'GNSSFix_0_1', 5.0),
        ),
        subscribes=(),
        interface_hash=0xe085da2eaaafb1f9,
    ),
    DeviceInfo(
        name='pressure',
        node_id=14,
        description='Water pressure sensor.',
        publishes=(
            PortInfo(1103, 'sam.sensor.StaticPressure.0.1', 'sam.sensor', 'StaticPressure_0_1', 20.0),
        ),
        subscribes=(),
        interface_hash=0x536d8a2339c45079,
    ),
    DeviceInfo(
        name='battery',
        node_id=15,
        description='Battery management system.',
        publishes=(
            PortInfo(1104, 'sam.power.BatteryInfo.0.1', 'sam.power', 'BatteryInfo_0_1', 1.0),
        ),
        subscribes=(),
        interface_hash=0xdd92abd4cbac74ed,
    ),
    DeviceInfo(
        name='altimeter',
        node_id=16,
        description='Altimeter looking down at the sea floor (an addition to the document).',
        publishes=(
            PortInfo(1106, 'sam.sensor.Altitude.0.1', 'sam.sensor', 'Altitude_0_1', 10.0),
        ),
        subscribes=(),
        interface_hash=0xe33abf430944c2b4,
    ),
    DeviceInfo(
        name='thruster_1',
        node_id=21,
        description='Thruster 1 motor controller.',
        publishes=(
            PortInfo(1300, 'sam.actuator.ThrusterFeedback.0.1', 'sam.actuator', 'ThrusterFeedback_0_1', 10.0),
        ),
        subscribes=(
            PortInfo(1200, 'sam.actuator.ThrusterRPM.0.1', 'sam.actuator', 'ThrusterRPM_0_1', 10.0),
        ),
        interface_hash=0xe8aa5843e87f68fc,
    ),
    DeviceInfo(
        name='thruster_2',
        node_id=22,
        description='Thruster 2 motor controller.',
        publishes=(
            PortInfo(1301, 'sam.actuator.ThrusterFeedback.0.1', 'sam.actuator', 'ThrusterFeedback_0_1', 10.0),
        ),
        subscribes=(
            PortInfo(1201, 'sam.actuator.ThrusterRPM.0.1', 'sam.actuator', 'ThrusterRPM_0_1', 10.0),
        ),
        interface_hash=0xb62a8c10aec1cb54,
    ),
    DeviceInfo(
        name='thrust_vector',
        node_id=23,
        description='Thrust vectoring nozzle servos.',
        publishes=(
            PortInfo(
                subject_id=1302,
                dsdl_type='sam.actuator.ThrustVectorFeedback.0.1',
                dsdl_module='sam.actuator',
                dsdl_class='ThrustVectorFeedback_0_1',
                rate_hz=10.0,
            ),
        ),
        subscribes=(
            PortInfo(1202, 'sam.actuator.ThrustVector.0.1', 'sam.actuator', 'ThrustVector_0_1', 10.0),
        ),
        interface_hash=0x4bd8faffe39569c2,
    ),
    DeviceInfo(
        name='ballast',
        node_id=24,
        description='The two ballast weights.',
        publishes=(),
        subscribes=(
            PortInfo(1203, 'sam.actuator.BallastAngles.0.1', 'sam.actuator', 'BallastAngles_0_1', 10.0),
        ),
        interface_hash=0x6f1b373e3940c462,
    ),
    DeviceInfo(
        name='longitudinal_weight',
        node_id=25,
        description='Longitudinal trim weight.',
        publishes=(
            PortInfo(1304, 'sam.actuator.PositionFeedback.0.1', 'sam.actuator', 'PositionFeedback_0_1', 10.0),
        ),
        subscribes=(
            PortInfo(1204, 'sam.actuator.PercentCommand.0.1', 'sam.actuator', 'PercentCommand_0_1', 10.0),
        ),
        interface_hash=0xe0f208d469bd0b99,
    ),
    DeviceInfo(
        name='buoyancy_piston',
        node_id=26,
        description='Variable buoyancy piston.',
        publishes=(
            PortInfo(1305, 'sam.actuator.PositionFeedback.0.1', 'sam.actuator', 'PositionFeedback_0_1', 10.0),
        ),
        subscribes=(
            PortInfo(1205, 'sam.actuator.PercentCommand.0.1', 'sam.actuator', 'PercentCommand_0_1', 10.0),
        ),
        interface_hash=0xaff974292348d87e,
    ),
)

TOPICS: tuple[TopicInfo, ...] = (
    TopicInfo(
        name='/imu',
        ros_type='sensor_msgs/msg/Imu',
        ros_module='sensor_msgs.msg',
        ros_class='Imu',
        description='IMU samples.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/magnetic_field',
        ros_type='sensor_msgs/msg/MagneticField',
        ros_module='sensor_msgs.msg',
        ros_class='MagneticField',
        description='Magnetometer samples.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/gps_fix',
        ros_type='sensor_msgs/msg/NavSatFix',
        ros_module='sensor_msgs.msg',
        ros_class='NavSatFix',
        description='GPS fixes, at the surface.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/pressure',
        ros_type='sensor_msgs/msg/FluidPressure',
        ros_module='sensor_msgs.msg',
        ros_class='FluidPressure',
        description='Water pressure.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/thruster_rpms',
        ros_type='sam_msgs/msg/ThrusterRPMs',
        ros_module='sam_msgs.msg',
        ros_class='ThrusterRPMs',
        description='Thruster speed commands.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/thruster_angles',
        ros_type='sam_msgs/msg/ThrusterAngles',
        ros_module='sam_msgs.msg',
        ros_class='ThrusterAngles',
        description='Thrust vector commands.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/ballast_angles',
        ros_type='sam_msgs/msg/BallastAngles',
        ros_module='sam_msgs.msg',
        ros_class='BallastAngles',
        description='Ballast weight commands.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/longitudinal_weight_position',
        ros_type='sam_msgs/msg/PercentStamped',
        ros_module='sam_msgs.msg',
        ros_class='PercentStamped',
        description='Longitudinal weight position command.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/buoyancy_piston_position',
        ros_type='sam_msgs/msg/PercentStamped',
        ros_module='sam_msgs.msg',
        ros_class='PercentStamped',
        description='Buoyancy piston position command.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/tf',
        ros_type='tf2_msgs/msg/TFMessage',
        ros_module='tf2_msgs.msg',
        ros_class='TFMessage',
        description='Transforms odom->base_link (DR) and world->odom (SLAM).',
        qos=QosInfo('reliable', 'volatile', 100, 'tf'),
        subscriber_qos=QosInfo('reliable', 'volatile', 100, 'tf'),
    ),
    TopicInfo(
        name='/tf_static',
        ros_type='tf2_msgs/msg/TFMessage',
        ros_module='tf2_msgs.msg',
        ros_class='TFMessage',
        description='The static child frames (sensor mountings), published once.',
        qos=QosInfo('reliable', 'transient_local', 1, 'latched'),
        subscriber_qos=QosInfo('reliable', 'transient_local', 1, 'latched'),
    ),
    TopicInfo(
        name='/nav_heading',
        ros_type='sam_msgs/msg/HeadingStamped',
        ros_module='sam_msgs.msg',
        ros_class='HeadingStamped',
        description='Heading goal; z < 0 depth, z > 0 altitude.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/nav_goal',
        ros_type='geometry_msgs/msg/PoseStamped',
        ros_module='geometry_msgs.msg',
        ros_class='PoseStamped',
        description='Pose goal in /world; position.z < 0 depth, > 0 altitude.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/global_plan',
        ros_type='nav_msgs/msg/Path',
        ros_module='nav_msgs.msg',
        ros_class='Path',
        description='The planned path the controller follows.',
        qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
        subscriber_qos=QosInfo('reliable', 'volatile', 10, 'reliable'),
    ),
    TopicInfo(
        name='/battery_state',
        ros_type='sensor_msgs/msg/BatteryState',
        ros_module='sensor_msgs.msg',
        ros_class='BatteryState',
        description='Battery health and charge.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/altitude',
        ros_type='sensor_msgs/msg/Range',
        ros_module='sensor_msgs.msg',
        ros_class='Range',
        description='Altitude above the sea floor from the altimeter; NaN range = no bottom lock.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/abort',
        ros_type='sam_msgs/msg/Abort',
        ros_module='sam_msgs.msg',
        ros_class='Abort',
        description='Emergency ascent ordered (active) or cleared by the performance monitor.',
        qos=QosInfo('reliable', 'transient_local', 1, 'latched'),
        subscriber_qos=QosInfo('reliable', 'transient_local', 1, 'latched'),
    ),
    TopicInfo(
        name='/battery_info',
        ros_type='sam_msgs/msg/BatteryInfo',
        ros_module='sam_msgs.msg',
        ros_class='BatteryInfo',
        description="The battery's full UAVCAN report.",
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/thruster_1/feedback',
        ros_type='sam_msgs/msg/ThrusterFeedback',
        ros_module='sam_msgs.msg',
        ros_class='ThrusterFeedback',
        description='Thruster 1 feedback.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/thruster_2/feedback',
        ros_type='sam_msgs/msg/ThrusterFeedback',
        ros_module='sam_msgs.msg',
        ros_class='ThrusterFeedback',
        description='Thruster 2 feedback.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/thrust_vector/feedback',
        ros_type='sam_msgs/msg/ThrustVectorFeedback',
        ros_module='sam_msgs.msg',
        ros_class='ThrustVectorFeedback',
        description='Thrust vector feedback.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/longitudinal_weight/feedback',
        ros_type='sam_msgs/msg/PositionFeedback',
        ros_module='sam_msgs.msg',
        ros_class='PositionFeedback',
        description='Longitudinal weight position.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
    TopicInfo(
        name='/buoyancy_piston/feedback',
        ros_type='sam_msgs/msg/PositionFeedback',
        ros_module='sam_msgs.msg',
        ros_class='PositionFeedback',
        description='Buoyancy piston position.',
        qos=QosInfo('reliable', 'volatile', 5, ''),
        subscriber_qos=QosInfo('best_effort', 'volatile', 5, 'sensor_data'),
    ),
)

_TOPICS_BY_NAME = {topic.name: topic for topic in TOPICS}

MAPPINGS: tuple[MappingInfo, ...] = (
    MappingInfo(
        name='imu',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/imu'],
        port=PortInfo(1100, 'sam.sensor.RawIMU.0.1', 'sam.sensor', 'RawIMU_0_1', 100.0),
        source_node_ids=frozenset({11}),
        destination_node_id=None,
        frame_id='imu_link',
        rate_hz=100.0,
        on_out_of_range='saturate',
        to_ros='imu_to_ros',
        to_uavcan='imu_to_uavcan',
        exact_uavcan_fields=(
            'timestamp.microsecond',
            'rate_gyro_latest[0]',
            'rate_gyro_latest[1]',
            'rate_gyro_latest[2]',
            'accelerometer_latest[0]',
            'accelerometer_latest[1]',
            'accelerometer_latest[2]',
        ),
        linked_uavcan_fields=(
            'timestamp.microsecond',
            'rate_gyro_latest[0]',
            'rate_gyro_latest[1]',
            'rate_gyro_latest[2]',
            'accelerometer_latest[0]',
            'accelerometer_latest[1]',
            'accelerometer_latest[2]',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_imu',
    ),
    MappingInfo(
        name='magnetic_field',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/magnetic_field'],
        port=PortInfo(
            subject_id=1101,
            dsdl_type='sam.sensor.MagneticFieldStrength.0.1',
            dsdl_module='sam.sensor',
            dsdl_class='MagneticFieldStrength_0_1',
            rate_hz=50.0,
        ),
        source_node_ids=frozenset({12}),
        destination_node_id=None,
        frame_id='magnetometer_link',
        rate_hz=50.0,
        on_out_of_range='saturate',
        to_ros='magnetic_field_to_ros',
        to_uavcan='magnetic_field_to_uavcan',
        exact_uavcan_fields=('magnetic_field_ga[0]', 'magnetic_field_ga[1]', 'magnetic_field_ga[2]'),
        linked_uavcan_fields=(
            'magnetic_field_ga[0]',
            'magnetic_field_ga[1]',
            'magnetic_field_ga[2]',
            'magnetic_field_covariance',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_magnetic_field',
    ),
    MappingInfo(
        name='gps_fix',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/gps_fix'],
        port=PortInfo(1102, 'sam.sensor.GNSSFix.0.1', 'sam.sensor', 'GNSSFix_0_1', 5.0),
        source_node_ids=frozenset({13}),
        destination_node_id=None,
        frame_id='gps_link',
        rate_hz=5.0,
        on_out_of_range='saturate',
        to_ros='gps_fix_to_ros',
        to_uavcan='gps_fix_to_uavcan',
        exact_uavcan_fields=(
            'timestamp.microsecond',
            'latitude_deg_1e8',
            'longitude_deg_1e8',
            'height_ellipsoid_mm',
        ),
        linked_uavcan_fields=(
            'timestamp.microsecond',
            'latitude_deg_1e8',
            'longitude_deg_1e8',
            'height_ellipsoid_mm',
            'status',
            'position_covariance',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_gps_fix',
    ),
    MappingInfo(
        name='pressure',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/pressure'],
        port=PortInfo(1103, 'sam.sensor.StaticPressure.0.1', 'sam.sensor', 'StaticPressure_0_1', 20.0),
        source_node_ids=frozenset({14}),
        destination_node_id=None,
        frame_id='pressure_link',
        rate_hz=20.0,
        on_out_of_range='saturate',
        to_ros='pressure_to_ros',
        to_uavcan='pressure_to_uavcan',
        exact_uavcan_fields=('static_pressure', 'static_pressure_variance'),
        linked_uavcan_fields=('static_pressure', 'static_pressure_variance'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_pressure',
    ),
    MappingInfo(
        name='battery_state',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/battery_state'],
        port=PortInfo(1104, 'sam.power.BatteryInfo.0.1', 'sam.power', 'BatteryInfo_0_1', 1.0),
        source_node_ids=frozenset({15}),
        destination_node_id=None,
        frame_id='base_link',
        rate_hz=1.0,
        on_out_of_range='saturate',
        to_ros='battery_state_to_ros',
        to_uavcan='battery_state_to_uavcan',
        exact_uavcan_fields=('voltage', 'current', 'state_of_charge_pct'),
        linked_uavcan_fields=(
            'voltage',
            'current',
            'temperature',
            'state_of_charge_pct',
            'state_of_health_pct',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_battery_state',
    ),
    MappingInfo(
        name='altitude',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/altitude'],
        port=PortInfo(1106, 'sam.sensor.Altitude.0.1', 'sam.sensor', 'Altitude_0_1', 10.0),
        source_node_ids=frozenset({16}),
        destination_node_id=None,
        frame_id='altimeter_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='altitude_to_ros',
        to_uavcan='altitude_to_uavcan',
        exact_uavcan_fields=('timestamp.microsecond', 'altitude', 'altitude_variance'),
        linked_uavcan_fields=('timestamp.microsecond', 'altitude', 'altitude_variance'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_altitude',
    ),
    MappingInfo(
        name='battery_info',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/battery_info'],
        port=PortInfo(1104, 'sam.power.BatteryInfo.0.1', 'sam.power', 'BatteryInfo_0_1', 1.0),
        source_node_ids=frozenset({15}),
        destination_node_id=None,
        frame_id='base_link',
        rate_hz=1.0,
        on_out_of_range='saturate',
        to_ros='battery_info_to_ros',
        to_uavcan='battery_info_to_uavcan',
        exact_uavcan_fields=(
            'temperature',
            'voltage',
            'current',
            'average_power_10sec',
            'remaining_capacity_wh',
            'full_charge_capacity_wh',
            'hours_to_full_charge',
            'status_flags',
            'state_of_health_pct',
            'state_of_charge_pct',
            'state_of_charge_pct_stdev',
            'battery_id',
            'model_instance_id',
            'model_name',
        ),
        linked_uavcan_fields=(
            'temperature',
            'voltage',
            'current',
            'average_power_10sec',
            'remaining_capacity_wh',
            'full_charge_capacity_wh',
            'hours_to_full_charge',
            'status_flags',
            'state_of_health_pct',
            'state_of_charge_pct',
            'state_of_charge_pct_stdev',
            'battery_id',
            'model_instance_id',
            'model_name',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_battery_info',
    ),
    MappingInfo(
        name='thruster_1_rpm',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/thruster_rpms'],
        port=PortInfo(1200, 'sam.actuator.ThrusterRPM.0.1', 'sam.actuator', 'ThrusterRPM_0_1', 10.0),
        source_node_ids=frozenset(),
        destination_node_id=21,
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thruster_1_rpm_to_ros',
        to_uavcan='thruster_1_rpm_to_uavcan',
        exact_uavcan_fields=('rpm',),
        linked_uavcan_fields=('rpm',),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thruster_1_rpm',
    ),
    MappingInfo(
        name='thruster_2_rpm',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/thruster_rpms'],
        port=PortInfo(1201, 'sam.actuator.ThrusterRPM.0.1', 'sam.actuator', 'ThrusterRPM_0_1', 10.0),
        source_node_ids=frozenset(),
        destination_node_id=22,
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thruster_2_rpm_to_ros',
        to_uavcan='thruster_2_rpm_to_uavcan',
        exact_uavcan_fields=('rpm',),
        linked_uavcan_fields=('rpm',),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thruster_2_rpm',
    ),
    MappingInfo(
        name='thrust_vector',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/thruster_angles'],
        port=PortInfo(1202, 'sam.actuator.ThrustVector.0.1', 'sam.actuator', 'ThrustVector_0_1', 10.0),
        source_node_ids=frozenset(),
        destination_node_id=23,
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thrust_vector_to_ros',
        to_uavcan='thrust_vector_to_uavcan',
        exact_uavcan_fields=('vertical_radians', 'horizontal_radians'),
        linked_uavcan_fields=('vertical_radians', 'horizontal_radians'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thrust_vector',
    ),
    MappingInfo(
        name='ballast',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/ballast_angles'],
        port=PortInfo(1203, 'sam.actuator.BallastAngles.0.1', 'sam.actuator', 'BallastAngles_0_1', 10.0),
        source_node_ids=frozenset(),
        destination_node_id=24,
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='ballast_to_ros',
        to_uavcan='ballast_to_uavcan',
        exact_uavcan_fields=('weight_1_offset_radians', 'weight_2_offset_radians'),
        linked_uavcan_fields=('weight_1_offset_radians', 'weight_2_offset_radians'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_ballast',
    ),
    MappingInfo(
        name='longitudinal_weight',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/longitudinal_weight_position'],
        port=PortInfo(1204, 'sam.actuator.PercentCommand.0.1', 'sam.actuator', 'PercentCommand_0_1', 10.0),
        source_node_ids=frozenset(),
        destination_node_id=25,
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='longitudinal_weight_to_ros',
        to_uavcan='longitudinal_weight_to_uavcan',
        exact_uavcan_fields=('percent',),
        linked_uavcan_fields=('percent',),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_longitudinal_weight',
    ),
    MappingInfo(
        name='buoyancy_piston',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/buoyancy_piston_position'],
        port=PortInfo(1205, 'sam.actuator.PercentCommand.0.1', 'sam.actuator', 'PercentCommand_0_1', 10.0),
        source_node_ids=frozenset(),
        destination_node_id=26,
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='buoyancy_piston_to_ros',
        to_uavcan='buoyancy_piston_to_uavcan',
        exact_uavcan_fields=('percent',),
        linked_uavcan_fields=('percent',),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_buoyancy_piston',
    ),
    MappingInfo(
        name='thruster_1_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/thruster_1/feedback'],
        port=PortInfo(
            subject_id=1300,
            dsdl_type='sam.actuator.ThrusterFeedback.0.1',
            dsdl_module='sam.actuator',
            dsdl_class='ThrusterFeedback_0_1',
            rate_hz=10.0,
        ),
        source_node_ids=frozenset({21}),
        destination_node_id=None,
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thruster_1_feedback_to_ros',
        to_uavcan='thruster_1_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.microsecond', 'rpm', 'current', 'temperature_c'),
        linked_uavcan_fields=('timestamp.microsecond', 'rpm', 'current', 'temperature_c'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thruster_1_feedback',
    ),
    MappingInfo(
        name='thruster_2_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/thruster_2/feedback'],
        port=PortInfo(
            subject_id=1301,
            dsdl_type='sam.actuator.ThrusterFeedback.0.1',
            dsdl_module='sam.actuator',
            dsdl_class='ThrusterFeedback_0_1',
            rate_hz=10.0,
        ),
        source_node_ids=frozenset({22}),
        destination_node_id=None,
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thruster_2_feedback_to_ros',
        to_uavcan='thruster_2_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.microsecond', 'rpm', 'current', 'temperature_c'),
        linked_uavcan_fields=('timestamp.microsecond', 'rpm', 'current', 'temperature_c'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thruster_2_feedback',
    ),
    MappingInfo(
        name='thrust_vector_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/thrust_vector/feedback'],
        port=PortInfo(
            subject_id=1302,
            dsdl_type='sam.actuator.ThrustVectorFeedback.0.1',
            dsdl_module='sam.actuator',
            dsdl_class='ThrustVectorFeedback_0_1',
            rate_hz=10.0,
        ),
        source_node_ids=frozenset({23}),
        destination_node_id=None,
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thrust_vector_feedback_to_ros',
        to_uavcan='thrust_vector_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.microsecond', 'vertical_mrad', 'horizontal_mrad'),
        linked_uavcan_fields=('timestamp.microsecond', 'vertical_mrad', 'horizontal_mrad'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thrust_vector_feedback',
    ),
    MappingInfo(
        name='longitudinal_weight_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/longitudinal_weight/feedback'],
        port=PortInfo(
            subject_id=1304,
            dsdl_type='sam.actuator.PositionFeedback.0.1',
            dsdl_module='sam.actuator',
            dsdl_class='PositionFeedback_0_1',
            rate_hz=10.0,
        ),
        source_node_ids=frozenset({25}),
        destination_node_id=None,
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='longitudinal_weight_feedback_to_ros',
        to_uavcan='longitudinal_weight_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.microsecond', 'percent', 'encoder_count'),
        linked_uavcan_fields=('timestamp.microsecond', 'percent', 'encoder_count'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_longitudinal_weight_feedback',
    ),
    MappingInfo(
        name='buoyancy_piston_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/buoyancy_piston/feedback'],
        port=PortInfo(
            subject_id=1305,
            dsdl_type='sam.actuator.PositionFeedback.0.1',
            dsdl_module='sam.actuator',
            dsdl_class='PositionFeedback_0_1',
            rate_hz=10.0,
        ),
        source_node_ids=frozenset({26}),
        destination_node_id=None,
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='buoyancy_piston_feedback_to_ros',
        to_uavcan='buoyancy_piston_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.microsecond', 'percent', 'encoder_count'),
        linked_uavcan_fields=('timestamp.microsecond', 'percent', 'encoder_count'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_buoyancy_piston_feedback',
    ),
)

# Under the generated folder: the spec's own DroneCAN types, for dronecan.load_dsdl() (convert_v0.load_types).
DRONECAN_DSDL_DIRS: tuple[str, ...] = ('dsdl_v0/sam',)

# The namespaces of dronecan's own definitions the spec uses (uavcan always; None: every one dronecan
# loads): the data type ids of the others are free (sam_runtime.dronecan_io.types leaves their types out).
DRONECAN_NAMESPACES: tuple[str, ...] | None = None

# Who handles uavcan.protocol.Panic: "builtin" (the bridge's duty), "mappings" (the spec's) or "both".
DRONECAN_PANIC_DUTY: str = 'builtin'

# The DroneCAN message types of the devices and mappings, by name.
DRONECAN_TYPES: tuple[DroneCanTypeInfo, ...] = (
    DroneCanTypeInfo('sam.actuator.PositionFeedback', 20102, 0x4F9415770AF42BD6, True),
    DroneCanTypeInfo('sam.actuator.ThrustVectorFeedback', 20101, 0x05FD0D1CC24F4B59, True),
    DroneCanTypeInfo('sam.sensor.Altitude', 20103, 0x48A1C8047B5312FA, True),
    DroneCanTypeInfo('uavcan.equipment.actuator.ArrayCommand', 1010, 0xD8A7486238EC3AF3, False),
    DroneCanTypeInfo('uavcan.equipment.ahrs.MagneticFieldStrength', 1001, 0xE2A7D4A9460BC2F2, False),
    DroneCanTypeInfo('uavcan.equipment.ahrs.RawIMU', 1003, 0x8280632C40E574B5, False),
    DroneCanTypeInfo('uavcan.equipment.air_data.StaticPressure', 1028, 0xCDC7C43412BDC89A, False),
    DroneCanTypeInfo('uavcan.equipment.esc.RPMCommand', 1031, 0xCE0F9F621CF7E70B, False),
    DroneCanTypeInfo('uavcan.equipment.esc.Status', 1034, 0xA9AF28AEA2FBB254, False),
    DroneCanTypeInfo('uavcan.equipment.gnss.Fix2', 1063, 0xCA41E7000F37435F, False),
    DroneCanTypeInfo('uavcan.equipment.power.BatteryInfo', 1092, 0x249C26548A711966, False),
)

_DRONECAN_TYPE = {t.name: t for t in DRONECAN_TYPES}

# The devices with DroneCAN firmware and their DroneCAN ports.
DRONECAN_DEVICES: tuple[DroneCanDeviceInfo, ...] = (
    DroneCanDeviceInfo(
        name='imu',
        node_id=11,
        description='Inertial measurement unit.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.ahrs.RawIMU'], 100.0),
        ),
        subscribes=(),
        interface_hash=0xd637a59eaf89905f,
    ),
    DroneCanDeviceInfo(
        name='magnetometer',
        node_id=12,
        description='Three-axis magnetometer.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.ahrs.MagneticFieldStrength'], 50.0),
        ),
        subscribes=(),
        interface_hash=0x91845a90d6c01c77,
    ),
    DroneCanDeviceInfo(
        name='gps',
        node_id=13,
        description='GPS receiver, usable at the surface.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.gnss.Fix2'], 5.0),
        ),
        subscribes=(),
        interface_hash=0xe085da2eaaafb1f9,
    ),
    DroneCanDeviceInfo(
        name='pressure',
        node_id=14,
        description='Water pressure sensor.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.air_data.StaticPressure'], 20.0),
        ),
        subscribes=(),
        interface_hash=0x536d8a2339c45079,
    ),
    DroneCanDeviceInfo(
        name='battery',
        node_id=15,
        description='Battery management system.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.power.BatteryInfo'], 1.0),
        ),
        subscribes=(),
        interface_hash=0xdd92abd4cbac74ed,
    ),
    DroneCanDeviceInfo(
        name='altimeter',
        node_id=16,
        description='Altimeter looking down at the sea floor (an addition to the document).',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['sam.sensor.Altitude'], 10.0),
        ),
        subscribes=(),
        interface_hash=0xe33abf430944c2b4,
    ),
    DroneCanDeviceInfo(
        name='thruster_1',
        node_id=21,
        description='Thruster 1 motor controller.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.esc.Status'], 10.0),
        ),
        subscribes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.esc.RPMCommand'], 10.0),
        ),
        interface_hash=0xe8aa5843e87f68fc,
    ),
    DroneCanDeviceInfo(
        name='thruster_2',
        node_id=22,
        description='Thruster 2 motor controller.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.esc.Status'], 10.0),
        ),
        subscribes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.esc.RPMCommand'], 10.0),
        ),
        interface_hash=0xb62a8c10aec1cb54,
    ),
    DroneCanDeviceInfo(
        name='thrust_vector',
        node_id=23,
        description='Thrust vectoring nozzle servos.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['sam.actuator.ThrustVectorFeedback'], 10.0),
        ),
        subscribes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'], 10.0),
        ),
        interface_hash=0x4bd8faffe39569c2,
    ),
    DroneCanDeviceInfo(
        name='ballast',
        node_id=24,
        description='The two ballast weights.',
        publishes=(),
        subscribes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'], 10.0),
        ),
        interface_hash=0x6f1b373e3940c462,
    ),
    DroneCanDeviceInfo(
        name='longitudinal_weight',
        node_id=25,
        description='Longitudinal trim weight.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['sam.actuator.PositionFeedback'], 10.0),
        ),
        subscribes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'], 10.0),
        ),
        interface_hash=0xe0f208d469bd0b99,
    ),
    DroneCanDeviceInfo(
        name='buoyancy_piston',
        node_id=26,
        description='Variable buoyancy piston.',
        publishes=(
            DroneCanPortInfo(_DRONECAN_TYPE['sam.actuator.PositionFeedback'], 10.0),
        ),
        subscribes=(
            DroneCanPortInfo(_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'], 10.0),
        ),
        interface_hash=0xaff974292348d87e,
    ),
)

DRONECAN_MAPPINGS: tuple[DroneCanMappingInfo, ...] = (
    DroneCanMappingInfo(
        name='imu',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/imu'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.ahrs.RawIMU'],
        select=(),
        elements=(),
        source_node_ids=frozenset({11}),
        destination_node_ids=frozenset(),
        frame_id='imu_link',
        rate_hz=100.0,
        on_out_of_range='saturate',
        to_ros='imu_to_ros',
        to_uavcan='imu_to_uavcan',
        exact_uavcan_fields=(
            'timestamp.usec',
            'rate_gyro_latest[0]',
            'rate_gyro_latest[1]',
            'rate_gyro_latest[2]',
            'accelerometer_latest[0]',
            'accelerometer_latest[1]',
            'accelerometer_latest[2]',
        ),
        linked_uavcan_fields=(
            'timestamp.usec',
            'rate_gyro_latest[0]',
            'rate_gyro_latest[1]',
            'rate_gyro_latest[2]',
            'accelerometer_latest[0]',
            'accelerometer_latest[1]',
            'accelerometer_latest[2]',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_imu',
    ),
    DroneCanMappingInfo(
        name='magnetic_field',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/magnetic_field'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.ahrs.MagneticFieldStrength'],
        select=(),
        elements=(),
        source_node_ids=frozenset({12}),
        destination_node_ids=frozenset(),
        frame_id='magnetometer_link',
        rate_hz=50.0,
        on_out_of_range='saturate',
        to_ros='magnetic_field_to_ros',
        to_uavcan='magnetic_field_to_uavcan',
        exact_uavcan_fields=('magnetic_field_ga[0]', 'magnetic_field_ga[1]', 'magnetic_field_ga[2]'),
        linked_uavcan_fields=(
            'magnetic_field_ga[0]',
            'magnetic_field_ga[1]',
            'magnetic_field_ga[2]',
            'magnetic_field_covariance',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_magnetic_field',
    ),
    DroneCanMappingInfo(
        name='gps_fix',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/gps_fix'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.gnss.Fix2'],
        select=(),
        elements=(),
        source_node_ids=frozenset({13}),
        destination_node_ids=frozenset(),
        frame_id='gps_link',
        rate_hz=5.0,
        on_out_of_range='saturate',
        to_ros='gps_fix_to_ros',
        to_uavcan='gps_fix_to_uavcan',
        exact_uavcan_fields=(
            'timestamp.usec',
            'latitude_deg_1e8',
            'longitude_deg_1e8',
            'height_ellipsoid_mm',
        ),
        linked_uavcan_fields=(
            'timestamp.usec',
            'latitude_deg_1e8',
            'longitude_deg_1e8',
            'height_ellipsoid_mm',
            'status',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_gps_fix',
    ),
    DroneCanMappingInfo(
        name='pressure',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/pressure'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.air_data.StaticPressure'],
        select=(),
        elements=(),
        source_node_ids=frozenset({14}),
        destination_node_ids=frozenset(),
        frame_id='pressure_link',
        rate_hz=20.0,
        on_out_of_range='saturate',
        to_ros='pressure_to_ros',
        to_uavcan='pressure_to_uavcan',
        exact_uavcan_fields=('static_pressure', 'static_pressure_variance'),
        linked_uavcan_fields=('static_pressure', 'static_pressure_variance'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_pressure',
    ),
    DroneCanMappingInfo(
        name='battery_state',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/battery_state'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.power.BatteryInfo'],
        select=(),
        elements=(),
        source_node_ids=frozenset({15}),
        destination_node_ids=frozenset(),
        frame_id='base_link',
        rate_hz=1.0,
        on_out_of_range='saturate',
        to_ros='battery_state_to_ros',
        to_uavcan='battery_state_to_uavcan',
        exact_uavcan_fields=('voltage', 'current', 'state_of_charge_pct'),
        linked_uavcan_fields=('voltage', 'current', 'temperature', 'state_of_charge_pct'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_battery_state',
    ),
    DroneCanMappingInfo(
        name='battery_info',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/battery_info'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.power.BatteryInfo'],
        select=(),
        elements=(),
        source_node_ids=frozenset({15}),
        destination_node_ids=frozenset(),
        frame_id='base_link',
        rate_hz=1.0,
        on_out_of_range='saturate',
        to_ros='battery_info_to_ros',
        to_uavcan='battery_info_to_uavcan',
        exact_uavcan_fields=(
            'temperature',
            'voltage',
            'current',
            'average_power_10sec',
            'remaining_capacity_wh',
            'full_charge_capacity_wh',
            'hours_to_full_charge',
            'status_flags',
            'state_of_health_pct',
            'state_of_charge_pct',
            'state_of_charge_pct_stdev',
            'battery_id',
            'model_instance_id',
            'model_name',
        ),
        linked_uavcan_fields=(
            'temperature',
            'voltage',
            'current',
            'average_power_10sec',
            'remaining_capacity_wh',
            'full_charge_capacity_wh',
            'hours_to_full_charge',
            'status_flags',
            'state_of_health_pct',
            'state_of_charge_pct',
            'state_of_charge_pct_stdev',
            'battery_id',
            'model_instance_id',
            'model_name',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_battery_info',
    ),
    DroneCanMappingInfo(
        name='altitude',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/altitude'],
        data_type=_DRONECAN_TYPE['sam.sensor.Altitude'],
        select=(),
        elements=(),
        source_node_ids=frozenset({16}),
        destination_node_ids=frozenset(),
        frame_id='altimeter_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='altitude_to_ros',
        to_uavcan='altitude_to_uavcan',
        exact_uavcan_fields=('timestamp.usec', 'altitude', 'altitude_variance'),
        linked_uavcan_fields=('timestamp.usec', 'altitude', 'altitude_variance'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_altitude',
    ),
    DroneCanMappingInfo(
        name='thruster_rpms',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/thruster_rpms'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.esc.RPMCommand'],
        select=(),
        elements=('rpm[0]', 'rpm[1]'),
        source_node_ids=frozenset(),
        destination_node_ids=frozenset({21, 22}),
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thruster_rpms_to_ros',
        to_uavcan='thruster_rpms_to_uavcan',
        exact_uavcan_fields=('rpm[0]', 'rpm[1]'),
        linked_uavcan_fields=('rpm[0]', 'rpm[1]'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thruster_rpms',
    ),
    DroneCanMappingInfo(
        name='thrust_vector',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/thruster_angles'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'],
        select=(),
        elements=('commands[actuator_id=0]', 'commands[actuator_id=1]'),
        source_node_ids=frozenset(),
        destination_node_ids=frozenset({23}),
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thrust_vector_to_ros',
        to_uavcan='thrust_vector_to_uavcan',
        exact_uavcan_fields=(
            'commands[actuator_id=0].command_value',
            'commands[actuator_id=1].command_value',
        ),
        linked_uavcan_fields=(
            'commands[actuator_id=0].command_value',
            'commands[actuator_id=1].command_value',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thrust_vector',
    ),
    DroneCanMappingInfo(
        name='ballast',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/ballast_angles'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'],
        select=(),
        elements=('commands[actuator_id=2]', 'commands[actuator_id=3]'),
        source_node_ids=frozenset(),
        destination_node_ids=frozenset({24}),
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='ballast_to_ros',
        to_uavcan='ballast_to_uavcan',
        exact_uavcan_fields=(
            'commands[actuator_id=2].command_value',
            'commands[actuator_id=3].command_value',
        ),
        linked_uavcan_fields=(
            'commands[actuator_id=2].command_value',
            'commands[actuator_id=3].command_value',
        ),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_ballast',
    ),
    DroneCanMappingInfo(
        name='longitudinal_weight',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/longitudinal_weight_position'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'],
        select=(),
        elements=('commands[actuator_id=4]',),
        source_node_ids=frozenset(),
        destination_node_ids=frozenset({25}),
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='longitudinal_weight_to_ros',
        to_uavcan='longitudinal_weight_to_uavcan',
        exact_uavcan_fields=('commands[actuator_id=4].command_value',),
        linked_uavcan_fields=('commands[actuator_id=4].command_value',),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_longitudinal_weight',
    ),
    DroneCanMappingInfo(
        name='buoyancy_piston',
        direction='ros_to_uavcan',
        topic=_TOPICS_BY_NAME['/buoyancy_piston_position'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.actuator.ArrayCommand'],
        select=(),
        elements=('commands[actuator_id=5]',),
        source_node_ids=frozenset(),
        destination_node_ids=frozenset({26}),
        frame_id=None,
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='buoyancy_piston_to_ros',
        to_uavcan='buoyancy_piston_to_uavcan',
        exact_uavcan_fields=('commands[actuator_id=5].command_value',),
        linked_uavcan_fields=('commands[actuator_id=5].command_value',),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_buoyancy_piston',
    ),
    DroneCanMappingInfo(
        name='thruster_1_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/thruster_1/feedback'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.esc.Status'],
        select=(('esc_index', 0),),
        elements=(),
        source_node_ids=frozenset({21}),
        destination_node_ids=frozenset(),
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thruster_1_feedback_to_ros',
        to_uavcan='thruster_1_feedback_to_uavcan',
        exact_uavcan_fields=('rpm', 'current'),
        linked_uavcan_fields=('rpm', 'current', 'temperature'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thruster_1_feedback',
    ),
    DroneCanMappingInfo(
        name='thruster_2_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/thruster_2/feedback'],
        data_type=_DRONECAN_TYPE['uavcan.equipment.esc.Status'],
        select=(('esc_index', 1),),
        elements=(),
        source_node_ids=frozenset({22}),
        destination_node_ids=frozenset(),
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thruster_2_feedback_to_ros',
        to_uavcan='thruster_2_feedback_to_uavcan',
        exact_uavcan_fields=('rpm', 'current'),
        linked_uavcan_fields=('rpm', 'current', 'temperature'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thruster_2_feedback',
    ),
    DroneCanMappingInfo(
        name='thrust_vector_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/thrust_vector/feedback'],
        data_type=_DRONECAN_TYPE['sam.actuator.ThrustVectorFeedback'],
        select=(),
        elements=(),
        source_node_ids=frozenset({23}),
        destination_node_ids=frozenset(),
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='thrust_vector_feedback_to_ros',
        to_uavcan='thrust_vector_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.usec', 'vertical_mrad', 'horizontal_mrad'),
        linked_uavcan_fields=('timestamp.usec', 'vertical_mrad', 'horizontal_mrad'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_thrust_vector_feedback',
    ),
    DroneCanMappingInfo(
        name='longitudinal_weight_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/longitudinal_weight/feedback'],
        data_type=_DRONECAN_TYPE['sam.actuator.PositionFeedback'],
        select=(),
        elements=(),
        source_node_ids=frozenset({25}),
        destination_node_ids=frozenset(),
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='longitudinal_weight_feedback_to_ros',
        to_uavcan='longitudinal_weight_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.usec', 'percent', 'encoder_count'),
        linked_uavcan_fields=('timestamp.usec', 'percent', 'encoder_count'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_longitudinal_weight_feedback',
    ),
    DroneCanMappingInfo(
        name='buoyancy_piston_feedback',
        direction='uavcan_to_ros',
        topic=_TOPICS_BY_NAME['/buoyancy_piston/feedback'],
        data_type=_DRONECAN_TYPE['sam.actuator.PositionFeedback'],
        select=(),
        elements=(),
        source_node_ids=frozenset({26}),
        destination_node_ids=frozenset(),
        frame_id='base_link',
        rate_hz=10.0,
        on_out_of_range='saturate',
        to_ros='buoyancy_piston_feedback_to_ros',
        to_uavcan='buoyancy_piston_feedback_to_uavcan',
        exact_uavcan_fields=('timestamp.usec', 'percent', 'encoder_count'),
        linked_uavcan_fields=('timestamp.usec', 'percent', 'encoder_count'),
        max_rate_hz=None,
        deadline_s=None,
        enabled=True,
        enable_service='~/enable_buoyancy_piston_feedback',
    ),
)

# The layouts: "default" (every device on its own `protocol`) first, then the spec's; the bridge runs one.
LAYOUTS: tuple[LayoutInfo, ...] = (
    LayoutInfo(
        name='default',
        description='Every device on its own `protocol`.',
        protocols=(
            ('imu', 'cyphal'),
            ('magnetometer', 'cyphal'),
            ('gps', 'cyphal'),
            ('pressure', 'cyphal'),
            ('battery', 'cyphal'),
            ('altimeter', 'cyphal'),
            ('thruster_1', 'cyphal'),
            ('thruster_2', 'cyphal'),
            ('thrust_vector', 'cyphal'),
            ('ballast', 'cyphal'),
            ('longitudinal_weight', 'cyphal'),
            ('buoyancy_piston', 'cyphal'),
        ),
        cyphal_mappings=(
            'imu',
            'magnetic_field',
            'gps_fix',
            'pressure',
            'battery_state',
            'altitude',
            'battery_info',
            'thruster_1_rpm',
            'thruster_2_rpm',
            'thrust_vector',
            'ballast',
            'longitudinal_weight',
            'buoyancy_piston',
            'thruster_1_feedback',
            'thruster_2_feedback',
            'thrust_vector_feedback',
            'longitudinal_weight_feedback',
            'buoyancy_piston_feedback',
        ),
        dronecan_mappings=(),
    ),
    LayoutInfo(
        name='dronecan',
        description='SAM as it runs today, every Teensy on DroneCAN (UAVCAN v0).',
        protocols=(
            ('imu', 'dronecan'),
            ('magnetometer', 'dronecan'),
            ('gps', 'dronecan'),
            ('pressure', 'dronecan'),
            ('battery', 'dronecan'),
            ('altimeter', 'dronecan'),
            ('thruster_1', 'dronecan'),
            ('thruster_2', 'dronecan'),
            ('thrust_vector', 'dronecan'),
            ('ballast', 'dronecan'),
            ('longitudinal_weight', 'dronecan'),
            ('buoyancy_piston', 'dronecan'),
        ),
        cyphal_mappings=(),
        dronecan_mappings=(
            'imu',
            'magnetic_field',
            'gps_fix',
            'pressure',
            'battery_state',
            'battery_info',
            'altitude',
            'thruster_rpms',
            'thrust_vector',
            'ballast',
            'longitudinal_weight',
            'buoyancy_piston',
            'thruster_1_feedback',
            'thruster_2_feedback',
            'thrust_vector_feedback',
            'longitudinal_weight_feedback',
            'buoyancy_piston_feedback',
        ),
    ),
    LayoutInfo(
        name='mixed',
        description=(
            'Half way, on one CAN bus - the navigation sensors on Cyphal v1, the battery and actuators on '
            'DroneCAN.'
        ),
        protocols=(
            ('imu', 'cyphal'),
            ('magnetometer', 'cyphal'),
            ('gps', 'cyphal'),
            ('pressure', 'cyphal'),
            ('battery', 'dronecan'),
            ('altimeter', 'cyphal'),
            ('thruster_1', 'dronecan'),
            ('thruster_2', 'dronecan'),
            ('thrust_vector', 'dronecan'),
            ('ballast', 'dronecan'),
            ('longitudinal_weight', 'dronecan'),
            ('buoyancy_piston', 'dronecan'),
        ),
        cyphal_mappings=('imu', 'magnetic_field', 'gps_fix', 'pressure', 'altitude'),
        dronecan_mappings=(
            'battery_state',
            'battery_info',
            'thruster_rpms',
            'thrust_vector',
            'ballast',
            'longitudinal_weight',
            'buoyancy_piston',
            'thruster_1_feedback',
            'thruster_2_feedback',
            'thrust_vector_feedback',
            'longitudinal_weight_feedback',
            'buoyancy_piston_feedback',
        ),
    ),
)
DEFAULT_LAYOUT = "default"

PARAMETERS: tuple[ParameterInfo, ...] = (
    ParameterInfo(
        name='/safe_altitude',
        type='double',
        default=5.0,
        minimum=0.0,
        maximum=100.0,
        unit='m',
        description='The motion planner always tries to stay above this height over the sea floor.',
    ),
    ParameterInfo(
        name='/safe_depth',
        type='double',
        default=50.0,
        minimum=0.0,
        maximum=200.0,
        unit='m',
        description='The motion planner always tries to stay above this water depth.',
    ),
    ParameterInfo(
        name='/critical_altitude',
        type='double',
        default=2.0,
        minimum=0.0,
        maximum=100.0,
        unit='m',
        description='The monitor triggers an emergency ascent when below this altitude.',
    ),
    ParameterInfo(
        name='/critical_depth',
        type='double',
        default=60.0,
        minimum=0.0,
        maximum=200.0,
        unit='m',
        description='The monitor triggers an emergency ascent when below this water depth.',
    ),
    ParameterInfo(
        name='/min_battery_percent',
        type='double',
        default=20.0,
        minimum=0.0,
        maximum=100.0,
        unit='%',
        description='The monitor triggers an emergency ascent when the charge falls below this.',
    ),
)

PARAMETER_RULES: tuple[ParameterRuleInfo, ...] = (
    ParameterRuleInfo(
        left='/critical_altitude',
        op='<',
        right='/safe_altitude',
        description='The critical altitude lies below the safe altitude (closer to the sea floor).',
    ),
    ParameterRuleInfo(
        left='/critical_depth',
        op='>',
        right='/safe_depth',
        description='The critical depth lies below the safe depth (deeper).',
    ),
)

# (frame, parent); a frame with a parent is a static child frame of it.
FRAMES: tuple[tuple[str, str | None], ...] = (
    ('world', None),
    ('odom', None),
    ('base_link', None),
    ('imu_link', 'base_link'),
    ('magnetometer_link', 'base_link'),
    ('gps_link', 'base_link'),
    ('pressure_link', 'base_link'),
    ('altimeter_link', 'base_link'),
)

# The static child frames (a frame with a parent), published once on /tf_static.
STATIC_TRANSFORMS: tuple[StaticTransformInfo, ...] = (
    StaticTransformInfo(
        'base_link', 'imu_link',
        translation=(0.1, 0.0, 0.0),
        rotation=(0.0, 0.0, 0.0, 1.0),
    ),
    StaticTransformInfo(
        'base_link', 'magnetometer_link',
        translation=(0.3, 0.0, 0.04),
        rotation=(0.0, 0.0, 0.0, 1.0),
    ),
    StaticTransformInfo(
        'base_link', 'gps_link',
        translation=(-0.2, 0.0, 0.12),
        rotation=(0.0, 0.0, 0.0, 1.0),
    ),
    StaticTransformInfo(
        'base_link', 'pressure_link',
        translation=(-0.55, 0.0, 0.0),
        rotation=(0.0, 0.0, 0.0, 1.0),
    ),
    StaticTransformInfo(
        'base_link', 'altimeter_link',
        translation=(0.35, 0.0, -0.08),
        rotation=(0.0, 0.7071067811865475, 0.0, 0.7071067811865476),
    ),
)

TRANSFORMS: tuple[TransformInfo, ...] = (
    TransformInfo('odom', 'base_link', 'dead_reckoning'),
    TransformInfo('world', 'odom', 'slam'),
)

NODES: tuple[NodeInfo, ...] = (
    NodeInfo(
        name='dead_reckoning',
        description=(
            'Dead reckoning; high-rate pose of base_link in odom from the IMU, compass, depth and '
            'thrusters (IV.E.1).'
        ),
        module='sam_nodes.dead_reckoning',
        base_class='DeadReckoningBase',
        publishes=(),
        subscribes=(
            EndpointInfo('/imu', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
            EndpointInfo('/magnetic_field', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
            EndpointInfo('/pressure', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
            EndpointInfo('/gps_fix', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
            EndpointInfo('/thruster_1/feedback', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
            EndpointInfo('/thruster_2/feedback', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
        ),
        parameters=(),
        transforms=(
            ('odom', 'base_link'),
        ),
        reads_transforms=(),
    ),
    NodeInfo(
        name='slam',
        description='SLAM; low-rate correction of odom in world from GPS fixes at the surface (IV.E.2).',
        module='sam_nodes.slam',
        base_class='SlamBase',
        publishes=(),
        subscribes=(
            EndpointInfo('/gps_fix', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
        ),
        parameters=(),
        transforms=(
            ('world', 'odom'),
        ),
        reads_transforms=(
            ('odom', 'base_link'),
        ),
    ),
    NodeInfo(
        name='motion_planner',
        description='Plans a path to a heading or pose goal at a target depth or altitude (IV.F).',
        module='sam_nodes.motion_planner',
        base_class='MotionPlannerBase',
        publishes=(
            EndpointInfo('/global_plan', QosInfo('reliable', 'volatile', 10, 'reliable')),
        ),
        subscribes=(
            EndpointInfo('/nav_goal', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/nav_heading', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/altitude', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
        ),
        parameters=(
            '/safe_altitude',
            '/safe_depth',
        ),
        transforms=(),
        reads_transforms=(
            ('world', 'base_link'),
        ),
    ),
    NodeInfo(
        name='controller',
        description='Follows the planned path by commanding the actuators; obeys an abort (IV.G).',
        module='sam_nodes.controller',
        base_class='ControllerBase',
        publishes=(
            EndpointInfo('/thruster_rpms', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/thruster_angles', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/ballast_angles', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/longitudinal_weight_position', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/buoyancy_piston_position', QosInfo('reliable', 'volatile', 10, 'reliable')),
        ),
        subscribes=(
            EndpointInfo('/global_plan', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/abort', QosInfo('reliable', 'transient_local', 1, 'latched')),
        ),
        parameters=(),
        transforms=(),
        reads_transforms=(
            ('world', 'base_link'),
        ),
    ),
    NodeInfo(
        name='performance_monitor',
        description='Watches depth, altitude and the battery; orders an emergency ascent (IV.H).',
        module='sam_nodes.performance_monitor',
        base_class='PerformanceMonitorBase',
        publishes=(
            EndpointInfo('/abort', QosInfo('reliable', 'transient_local', 1, 'latched')),
            EndpointInfo('/thruster_rpms', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/buoyancy_piston_position', QosInfo('reliable', 'volatile', 10, 'reliable')),
        ),
        subscribes=(
            EndpointInfo('/pressure', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
            EndpointInfo('/altitude', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
            EndpointInfo('/battery_state', QosInfo('best_effort', 'volatile', 5, 'sensor_data')),
        ),
        parameters=(
            '/critical_altitude',
            '/critical_depth',
            '/min_battery_percent',
        ),
        transforms=(),
        reads_transforms=(),
    ),
    NodeInfo(
        name='mission',
        description=(
            'Gives the motion planner its goals, a pose or a heading at a depth or altitude (an addition).'
        ),
        module='sam_nodes.mission',
        base_class='MissionBase',
        publishes=(
            EndpointInfo('/nav_goal', QosInfo('reliable', 'volatile', 10, 'reliable')),
            EndpointInfo('/nav_heading', QosInfo('reliable', 'volatile', 10, 'reliable')),
        ),
        subscribes=(),
        parameters=(),
        transforms=(),
        reads_transforms=(
            ('world', 'base_link'),
        ),
    ),
)

# The bridge's time-sync master on both protocols (bridge.time_sync): its period in seconds; None: off.
TIME_SYNC_PERIOD_S: float | None = 0.5
# The UAVCAN -> ROS mappings (Cyphal, DroneCAN) whose header.stamp is the device's own timestamp (0 = unknown:
# the receive time, counted).
DEVICE_STAMPED_MAPPINGS: frozenset[str] = frozenset({
    'altitude',
    'buoyancy_piston_feedback',
    'gps_fix',
    'imu',
    'longitudinal_weight_feedback',
    'thrust_vector_feedback',
    'thruster_1_feedback',
    'thruster_2_feedback',
})
DRONECAN_DEVICE_STAMPED_MAPPINGS: frozenset[str] = frozenset({
    'altitude',
    'buoyancy_piston_feedback',
    'gps_fix',
    'imu',
    'longitudinal_weight_feedback',
    'thrust_vector_feedback',
})

# The whole spec's interface version (every board's; each board's is its DeviceInfo's interface_hash): the
# hash rule is sam_codegen.validate.interface_version's.
INTERFACE_HASH: int = 0x23669fe96266cb3c
# A board that reports another one: "warn" (/diagnostics, counted) or "stop" (also its mappings' traffic).
INTERFACE_ON_MISMATCH: str = 'warn'

# Every board's settings (a device's `parameters:`), device by device; the bridge's ROS parameters
# `<device>.<name>` (sam_runtime.bridge.device_params).
DEVICE_PARAMETERS: tuple[DeviceParameterInfo, ...] = (
    DeviceParameterInfo(
        device='imu',
        name='imu.rate_hz',
        type='integer',
        default=100,
        description='Output rate.',
        minimum=10,
        maximum=400,
        unit='Hz',
        values=(),
        max_length=None,
        restart=False,
        names=(('cyphal', 'imu.rate_hz'), ('dronecan', 'IMU_RATE_HZ')),
    ),
    DeviceParameterInfo(
        device='imu',
        name='imu.gyro_range',
        type='enum',
        default='dps500',
        description='Gyroscope full scale in degrees per second.',
        minimum=None,
        maximum=None,
        unit='',
        values=(('dps250', 250), ('dps500', 500), ('dps1000', 1000), ('dps2000', 2000)),
        max_length=None,
        restart=True,
        names=(('cyphal', 'imu.gyro_range'), ('dronecan', 'IMU_GYRO_RANGE')),
    ),
    DeviceParameterInfo(
        device='thruster_1',
        name='motor.pole_count',
        type='integer',
        default=14,
        description='Magnet poles of the motor.',
        minimum=2,
        maximum=48,
        unit='',
        values=(),
        max_length=None,
        restart=True,
        names=(('cyphal', 'motor.pole_count'), ('dronecan', 'MOTOR_POLE_COUNT')),
    ),
    DeviceParameterInfo(
        device='thruster_1',
        name='motor.direction',
        type='enum',
        default='forward',
        description='Propeller sense (the two thrusters counter-rotate).',
        minimum=None,
        maximum=None,
        unit='',
        values=(('forward', 1), ('reverse', -1)),
        max_length=None,
        restart=False,
        names=(('cyphal', 'motor.direction'), ('dronecan', 'MOTOR_DIRECTION')),
    ),
    DeviceParameterInfo(
        device='thruster_1',
        name='esc.index',
        type='integer',
        default=0,
        description='Its index in uavcan.equipment.esc.RPMCommand.',
        minimum=0,
        maximum=19,
        unit='',
        values=(),
        max_length=None,
        restart=True,
        names=(('cyphal', 'esc.index'), ('dronecan', 'ESC_INDEX')),
    ),
    DeviceParameterInfo(
        device='thruster_2',
        name='motor.pole_count',
        type='integer',
        default=14,
        description='Magnet poles of the motor.',
        minimum=2,
        maximum=48,
        unit='',
        values=(),
        max_length=None,
        restart=True,
        names=(('cyphal', 'motor.pole_count'), ('dronecan', 'MOTOR_POLE_COUNT')),
    ),
    DeviceParameterInfo(
        device='thruster_2',
        name='motor.direction',
        type='enum',
        default='reverse',
        description='Propeller sense (the two thrusters counter-rotate).',
        minimum=None,
        maximum=None,
        unit='',
        values=(('forward', 1), ('reverse', -1)),
        max_length=None,
        restart=False,
        names=(('cyphal', 'motor.direction'), ('dronecan', 'MOTOR_DIRECTION')),
    ),
    DeviceParameterInfo(
        device='thruster_2',
        name='esc.index',
        type='integer',
        default=1,
        description='Its index in uavcan.equipment.esc.RPMCommand.',
        minimum=0,
        maximum=19,
        unit='',
        values=(),
        max_length=None,
        restart=True,
        names=(('cyphal', 'esc.index'), ('dronecan', 'ESC_INDEX')),
    ),
    DeviceParameterInfo(
        device='thrust_vector',
        name='servo.vertical.trim',
        type='real',
        default=0.0,
        description="Added to every vertical command (the nozzle's mechanical zero).",
        minimum=-0.1,
        maximum=0.1,
        unit='rad',
        values=(),
        max_length=None,
        restart=False,
        names=(('cyphal', 'servo.vertical.trim'), ('dronecan', 'SERVO_VERTICAL_TRIM')),
    ),
    DeviceParameterInfo(
        device='thrust_vector',
        name='servo.horizontal.trim',
        type='real',
        default=0.0,
        description='Added to every horizontal command.',
        minimum=-0.1,
        maximum=0.1,
        unit='rad',
        values=(),
        max_length=None,
        restart=False,
        names=(('cyphal', 'servo.horizontal.trim'), ('dronecan', 'SERVO_HORIZONTAL_TRIM')),
    ),
    DeviceParameterInfo(
        device='thrust_vector',
        name='servo.limit',
        type='real',
        default=0.12,
        description='The largest deflection either servo is driven to.',
        minimum=0.02,
        maximum=0.2,
        unit='rad',
        values=(),
        max_length=None,
        restart=False,
        names=(('cyphal', 'servo.limit'), ('dronecan', 'SERVO_LIMIT')),
    ),
    DeviceParameterInfo(
        device='buoyancy_piston',
        name='pid.kp',
        type='real',
        default=4.0,
        description=(
                        "Proportional gain of the piston's position loop (motor duty per unit of position "
                        'error).'
                    ),
        minimum=0.0,
        maximum=50.0,
        unit='1',
        values=(),
        max_length=None,
        restart=False,
        names=(('cyphal', 'pid.kp'), ('dronecan', 'PID_KP')),
    ),
    DeviceParameterInfo(
        device='buoyancy_piston',
        name='pid.ki',
        type='real',
        default=0.5,
        description='Integral gain.',
        minimum=0.0,
        maximum=10.0,
        unit='1/s',
        values=(),
        max_length=None,
        restart=False,
        names=(('cyphal', 'pid.ki'), ('dronecan', 'PID_KI')),
    ),
    DeviceParameterInfo(
        device='buoyancy_piston',
        name='pid.kd',
        type='real',
        default=0.05,
        description='Derivative gain.',
        minimum=0.0,
        maximum=5.0,
        unit='s',
        values=(),
        max_length=None,
        restart=False,
        names=(('cyphal', 'pid.kd'), ('dronecan', 'PID_KD')),
    ),
)
