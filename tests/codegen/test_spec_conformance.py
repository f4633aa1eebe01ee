"""The spec matches the design document (sections IV.A-IV.H). The expected tables live here, written from the
document, not read back from the spec."""

from __future__ import annotations

from pathlib import Path

import pytest

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.validate.mapping_rules import widen_int
from sam_codegen.validate.resolve import Resolved, validate

SPEC = Path(__file__).parents[2] / "spec" / "interfaces.yaml"

# (topic, type) from sections IV.C, IV.D, IV.E, IV.F, IV.G and IV.H; /ballast_angles replaces the document's
# second /thruster_angles (two types on one topic is an error).
DOCUMENT_TOPICS = {
    "/imu": "sensor_msgs/Imu",
    "/magnetic_field": "sensor_msgs/MagneticField",
    "/gps_fix": "sensor_msgs/NavSatFix",
    "/pressure": "sensor_msgs/FluidPressure",
    "/thruster_rpms": "sam_msgs/ThrusterRPMs",
    "/thruster_angles": "sam_msgs/ThrusterAngles",
    "/ballast_angles": "sam_msgs/BallastAngles",
    "/longitudinal_weight_position": "sam_msgs/PercentStamped",
    "/buoyancy_piston_position": "sam_msgs/PercentStamped",
    "/nav_heading": "sam_msgs/HeadingStamped",
    "/nav_goal": "geometry_msgs/PoseStamped",
    "/global_plan": "nav_msgs/Path",
    "/battery_state": "sensor_msgs/BatteryState",
    "/tf": "tf2_msgs/TFMessage",
}

# The custom messages of sam_msgs with the document's fields (the ROS 2 header has no seq).
DOCUMENT_MESSAGES = {
    "ThrusterRPMs": {"header": "std_msgs/Header", "thruster_1_rpm": "int32", "thruster_2_rpm": "int32"},
    "ThrusterAngles": {"header": "std_msgs/Header", "thruster_vertical_radians": "float32",
                       "thruster_horizontal_radians": "float32"},
    "BallastAngles": {"header": "std_msgs/Header", "weight_1_offset_radians": "float32",
                      "weight_2_offset_radians": "float32"},
    "PercentStamped": {"header": "std_msgs/Header", "percent": "float32"},
    "HeadingStamped": {"header": "std_msgs/Header", "heading": "float64", "z": "float64"},
}

DOCUMENT_PARAMETERS = {"/safe_altitude", "/safe_depth", "/critical_altitude", "/critical_depth"}

# The devices of section IV.A/IV.C/IV.D and whether the bridge reads them (sensor) or commands them (actuator).
DOCUMENT_DEVICES = {
    "imu": ("uavcan_to_ros", "/imu"),
    "magnetometer": ("uavcan_to_ros", "/magnetic_field"),
    "gps": ("uavcan_to_ros", "/gps_fix"),
    "pressure": ("uavcan_to_ros", "/pressure"),
    "battery": ("uavcan_to_ros", "/battery_state"),
    "thruster_1": ("ros_to_uavcan", "/thruster_rpms"),
    "thruster_2": ("ros_to_uavcan", "/thruster_rpms"),
    "thrust_vector": ("ros_to_uavcan", "/thruster_angles"),
    "ballast": ("ros_to_uavcan", "/ballast_angles"),
    "longitudinal_weight": ("ros_to_uavcan", "/longitudinal_weight_position"),
    "buoyancy_piston": ("ros_to_uavcan", "/buoyancy_piston_position"),
}

DOCUMENT_NODES = {"dead_reckoning", "slam", "motion_planner", "controller", "performance_monitor"}


@pytest.fixture(scope="module")
def resolved() -> Resolved:
    return validate(load_spec_file(SPEC))


def test_topics(resolved: Resolved) -> None:
    topics = {name: t.type for name, t in resolved.spec.topics.items()}
    for name, type_ in DOCUMENT_TOPICS.items():
        assert topics.get(name) == type_, name


def test_tf_frames(resolved: Resolved) -> None:
    s = resolved.spec
    assert {"world", "odom", "base_link"} <= set(s.frames)
    transforms = {(t.parent, t.child): t.publisher for t in s.transforms}
    assert transforms[("odom", "base_link")] == "dead_reckoning"
    assert transforms[("world", "odom")] == "slam"


def test_parameters(resolved: Resolved) -> None:
    params = resolved.spec.parameters
    assert DOCUMENT_PARAMETERS <= set(params)
    for name in DOCUMENT_PARAMETERS:
        p = params[name]
        assert p.type == "double" and p.unit == "m" and p.description
        assert p.minimum is not None and p.maximum is not None and p.minimum <= p.default <= p.maximum
    # A critical limit is beyond its safe limit: closer to the sea floor, deeper.
    assert params["/critical_altitude"].default < params["/safe_altitude"].default
    assert params["/critical_depth"].default > params["/safe_depth"].default
    rules = {(r.left, r.op, r.right) for r in resolved.spec.parameter_rules}
    assert ("/critical_altitude", "<", "/safe_altitude") in rules
    assert ("/critical_depth", ">", "/safe_depth") in rules


def test_custom_messages(resolved: Resolved) -> None:
    for name, fields in DOCUMENT_MESSAGES.items():
        message = resolved.ros.get(f"sam_msgs/{name}")
        assert message is not None, name
        assert {f.name: str(f.type) for f in message.fields} == fields, name
    heading = resolved.spec.messages["sam_msgs/HeadingStamped"].field("z")
    assert heading is not None and "negative" in heading.comment.lower() and "altitude" in heading.comment.lower()
    assert "depth" in resolved.spec.topics["/nav_goal"].description


def test_every_device_is_bridged(resolved: Resolved) -> None:
    by_node = {d.node_id: name for name, d in resolved.spec.devices.items()}
    assert set(DOCUMENT_DEVICES) <= set(resolved.spec.devices)
    for device, (direction, topic) in DOCUMENT_DEVICES.items():
        d = resolved.spec.devices[device]
        assert 0 <= d.node_id <= 127
        ports = d.publishes if direction == "uavcan_to_ros" else d.subscribes
        assert ports and all(0 <= p.subject_id <= 8191 and p.rate_hz > 0 for p in ports), device
        matching = [
            r for r in resolved.mappings
            if r.mapping.direction == direction and r.mapping.topic == topic
            and r.mapping.subject_id in {p.subject_id for p in ports}
        ]
        assert matching, device
        for r in matching:
            if direction == "uavcan_to_ros":
                assert [by_node[n] for n in r.mapping.source_node_ids] == [device]
            else:
                assert by_node[r.mapping.destination_node_id] == device


def test_v0_types_keep_their_widths(resolved: Resolved) -> None:
    raw_imu = resolved.spec.dsdl_types["sam.sensor.RawIMU.0.1"]
    types = {f.name: str(f.type) for f in raw_imu.fields}
    assert types["rate_gyro_latest"] == "float16[3]" and types["accelerometer_latest"] == "float16[3]"
    assert types["timestamp"] == "uavcan.time.SynchronizedTimestamp.1.0"
    rpm = resolved.spec.dsdl_types["sam.actuator.ThrusterRPM.0.1"].field("rpm")
    assert rpm is not None and str(rpm.type) == "int18"


def test_widening_rule_is_exercised(resolved: Resolved) -> None:
    """The document's examples: uint7->uint8, int13->int16, int18->int32, uint24->uint32, float16->float32."""
    assert [widen_int(k, b) for k, b in (("uint", 7), ("int", 13), ("int", 18), ("uint", 24))] == [
        "uint8", "int16", "int32", "uint32"]
    seen: set[tuple[str, str]] = set()
    for r in resolved.mappings:
        for step in r.steps:
            if step.kind == "number" and isinstance(step.uavcan_type, DsdlType):
                seen.add((step.uavcan_type.base_name, str(step.ros_type)))
    assert {("uint7", "uint8"), ("int13", "int16"), ("int18", "int32"), ("uint24", "uint32"),
            ("float16", "float32")} <= seen


def test_derived_bounded_array_keeps_bound(resolved: Resolved) -> None:
    info = resolved.ros.get("sam_msgs/BatteryInfo")  # derived: validation gives it, the spec does not
    assert info is not None
    model_name = info.field("model_name")
    assert model_name is not None and model_name.type == RosType("uint8", "bounded", 31)


def test_nodes(resolved: Resolved) -> None:
    nodes = resolved.spec.nodes
    assert DOCUMENT_NODES <= set(nodes)
    assert "/global_plan" in nodes["motion_planner"].publishes
    assert {"/nav_heading", "/nav_goal"} <= set(nodes["motion_planner"].subscribes)
    assert {"/safe_altitude", "/safe_depth"} <= set(nodes["motion_planner"].parameters)
    assert "/global_plan" in nodes["controller"].subscribes
    assert {"/critical_altitude", "/critical_depth"} <= set(nodes["performance_monitor"].parameters)
    assert "/battery_state" in nodes["performance_monitor"].subscribes
    assert resolved.spec.bridge is not None and resolved.spec.bridge.name == "uavcan_ros_bridge"
