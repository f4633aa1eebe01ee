"""The generated sam_msgs package, built with CMake and installed into this environment (the nox session runs
`sam-codegen ros-install` first): every type imports, serialises, and goes through rclpy publish/subscribe."""

from __future__ import annotations

import importlib
import sys
import time
from pathlib import Path

import pytest

from sam_codegen.project.ros_install import is_installed

ROOT = Path(__file__).parents[2]
PACKAGE_DIR = ROOT / "generated" / "ros" / "sam_msgs"
MESSAGES = sorted(p.stem for p in (PACKAGE_DIR / "msg").glob("*.msg"))

pytestmark = pytest.mark.ros


@pytest.fixture(scope="module")
def msg_module():  # type: ignore[no-untyped-def]
    rclpy = pytest.importorskip("rclpy")
    assert is_installed("sam_msgs", Path(sys.prefix)), (
        "sam_msgs is not installed in this environment: run `sam-codegen ros-install` (nox -s tests does)")
    installed = Path(sys.prefix) / "share" / "sam_msgs" / "msg"
    for name in MESSAGES:
        assert (installed / f"{name}.msg").read_text() == (PACKAGE_DIR / "msg" / f"{name}.msg").read_text(), (
            f"the installed sam_msgs is older than generated/: run `sam-codegen ros-install` ({name})")
    rclpy.init()
    yield importlib.import_module("sam_msgs.msg")
    rclpy.shutdown()


def _sample(cls):  # type: ignore[no-untyped-def]
    """A message with every numeric scalar set to a distinct non-default value."""
    msg = cls()
    for i, (name, type_name) in enumerate(cls.get_fields_and_field_types().items(), 1):
        if type_name in ("float", "double"):
            setattr(msg, name, i + 0.5)
        elif type_name.startswith(("int", "uint")) and not type_name.endswith(">"):
            setattr(msg, name, i)
        elif type_name == "boolean":
            setattr(msg, name, True)
        elif type_name.startswith("sequence<uint8"):
            setattr(msg, name, [1, 2, 3])
    if hasattr(msg, "header"):  # (not the constants-only Topics)
        msg.header.frame_id = "base_link"
        msg.header.stamp.sec = 12
    return msg


def test_every_message_round_trips_through_rclpy(msg_module) -> None:  # type: ignore[no-untyped-def]
    import rclpy
    from rclpy.serialization import deserialize_message, serialize_message

    node = rclpy.create_node("sam_msgs_check")
    try:
        for name in MESSAGES:
            cls = getattr(msg_module, name)
            sent = _sample(cls)
            assert deserialize_message(serialize_message(sent), cls) == sent, name
            received: list[object] = []
            pub = node.create_publisher(cls, f"/test/{name.lower()}", 10)
            sub = node.create_subscription(cls, f"/test/{name.lower()}", received.append, 10)
            deadline = time.monotonic() + 10
            while pub.get_subscription_count() < 1 and time.monotonic() < deadline:
                rclpy.spin_once(node, timeout_sec=0.05)
            pub.publish(sent)
            while not received and time.monotonic() < deadline:
                rclpy.spin_once(node, timeout_sec=0.05)
            assert received == [sent], name
            node.destroy_subscription(sub)
            node.destroy_publisher(pub)
    finally:
        node.destroy_node()


def test_constants_and_bounds(msg_module) -> None:  # type: ignore[no-untyped-def]
    info = msg_module.BatteryInfo.get_fields_and_field_types()
    assert info["model_name"] == "sequence<uint8, 31>"
    assert info["state_of_health_pct"] == "uint8" and info["status_flags"] == "uint16"
    assert msg_module.ThrusterFeedback.get_fields_and_field_types()["rpm"] == "int32"
    assert msg_module.ThrustVectorFeedback.get_fields_and_field_types()["vertical_mrad"] == "int16"
    assert msg_module.PositionFeedback.get_fields_and_field_types()["encoder_count"] == "uint32"


def test_rosbags_reads_the_same_bytes(msg_module) -> None:  # type: ignore[no-untyped-def]
    """An independent CDR decoder (rosbags, from the generated .msg text alone) reads what rclpy wrote."""
    typesys = pytest.importorskip("rosbags.typesys")
    from rclpy.serialization import serialize_message

    store = typesys.get_typestore(typesys.Stores.ROS2_JAZZY)
    types: dict = {}
    for name in MESSAGES:
        text = (PACKAGE_DIR / "msg" / f"{name}.msg").read_text(encoding="utf-8")
        types.update(typesys.get_types_from_msg(text, f"sam_msgs/msg/{name}"))
    store.register(types)
    for name in MESSAGES:
        sent = _sample(getattr(msg_module, name))
        decoded = store.deserialize_cdr(serialize_message(sent), f"sam_msgs/msg/{name}")
        for field in getattr(msg_module, name).get_fields_and_field_types():
            if field == "header":
                assert decoded.header.frame_id == sent.header.frame_id
                assert decoded.header.stamp.sec == sent.header.stamp.sec
                continue
            ours, theirs = getattr(sent, field), getattr(decoded, field)
            assert list(ours) == list(theirs) if hasattr(ours, "__len__") else ours == theirs, (name, field)
