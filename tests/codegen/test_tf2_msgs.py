"""The generated tf2_msgs package is ROS 2's: TFMessage.msg byte for byte, and the same type hash (RIHS01).

Three hashes must agree: the one rosidl's own code (rosidl_adapter + rosidl_generator_type_description, from the
wheels) computes from ROS 2's published definition of tf2_msgs/TFMessage, the one a Jazzy system reports
(`ros2 topic info -v /tf`: PUBLISHED_HASH below), and the one rclpy reports for our built type.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from helpers.ros_packages import built_prefix, missing_tools, run_child
from helpers.runtime_support import domain_id

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets import ros as emit_ros
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "spec" / "interfaces.yaml"
GENERATED = ROOT / "generated"

# ros2/geometry2, tf2_msgs/msg/TFMessage.msg (the whole file).
UPSTREAM_TFMESSAGE = "geometry_msgs/TransformStamped[] transforms\n"
# The type hash a ROS 2 Jazzy system reports for tf2_msgs/msg/TFMessage (`ros2 topic info -v /tf`).
PUBLISHED_HASH = "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"


def rosidl_hash(package: str, name: str, definition: str, tmp: Path) -> str:
    """RIHS01 of a message definition, computed by rosidl's own code against the installed dependencies."""
    msg = pytest.importorskip("rosidl_adapter.msg")
    type_description = pytest.importorskip("rosidl_generator_type_description")
    source = tmp / package / "msg" / f"{name}.msg"
    source.parent.mkdir(parents=True, exist_ok=True)
    source.write_text(definition, encoding="utf-8")
    idl = tmp / "idl"
    msg.convert_msg_to_idl(tmp / package, package, Path("msg") / f"{name}.msg", idl / "msg")
    share = Path(sys.prefix) / "share"
    args = tmp / "args.json"
    args.write_text(json.dumps({
        "package_name": package, "output_dir": str(tmp / "out"), "idl_tuples": [f"{idl}:msg/{name}.idl"],
        "include_paths": [f"{dep}:{share / dep}" for dep in ("geometry_msgs", "std_msgs", "builtin_interfaces")],
    }), encoding="utf-8")
    [out] = type_description.generate_type_hash(str(args))
    hashes = {h["type_name"]: h["hash_string"] for h in json.loads(Path(out).read_text())["type_hashes"]}
    return hashes[f"{package}/msg/{name}"]


@pytest.fixture(scope="module")
def files() -> dict[str, str]:
    return emit_ros.emit(validate(load_spec_file(SPEC)))


def test_message_file_is_upstream_byte_for_byte(files: dict[str, str]) -> None:
    assert files["ros/tf2_msgs/msg/TFMessage.msg"] == UPSTREAM_TFMESSAGE
    assert (GENERATED / "ros" / "tf2_msgs" / "msg" / "TFMessage.msg").read_bytes() == UPSTREAM_TFMESSAGE.encode()
    assert sorted(p for p in files if p.startswith("ros/tf2_msgs/")) == [
        "ros/tf2_msgs/CMakeLists.txt", "ros/tf2_msgs/msg/TFMessage.msg", "ros/tf2_msgs/package.xml"]


def test_package_is_an_interface_package_like_upstreams(files: dict[str, str]) -> None:
    import xml.etree.ElementTree as ET

    root = ET.fromstring(files["ros/tf2_msgs/package.xml"])
    assert root.findtext("name") == "tf2_msgs"
    assert [e.text for e in root.findall("buildtool_depend")] == ["ament_cmake", "rosidl_default_generators"]
    assert [e.text for e in root.findall("depend")] == ["geometry_msgs"]
    assert [e.text for e in root.findall("exec_depend")] == ["rosidl_default_runtime"]
    assert root.findtext("member_of_group") == "rosidl_interface_packages"
    cmake = files["ros/tf2_msgs/CMakeLists.txt"]
    assert "project(tf2_msgs)" in cmake and '"msg/TFMessage.msg"' in cmake and "DEPENDENCIES geometry_msgs" in cmake


def test_hash_of_the_upstream_definition(files: dict[str, str], tmp_path: Path) -> None:
    """rosidl's hash of ROS 2's definition is the published one, and so is the hash of the file we generate."""
    assert rosidl_hash("tf2_msgs", "TFMessage", UPSTREAM_TFMESSAGE, tmp_path / "upstream") == PUBLISHED_HASH
    assert rosidl_hash("tf2_msgs", "TFMessage", files["ros/tf2_msgs/msg/TFMessage.msg"],
                       tmp_path / "ours") == PUBLISHED_HASH


def test_a_changed_definition_changes_the_hash(tmp_path: Path) -> None:
    """The comparison can fail: one field more gives another hash."""
    changed = UPSTREAM_TFMESSAGE + "uint8 extra\n"
    assert rosidl_hash("tf2_msgs", "TFMessage", changed, tmp_path) != PUBLISHED_HASH


_REPORT = r"""
import json, os, sys, time
import rclpy
from rclpy.node import Node
from tf2_msgs.msg import TFMessage
rclpy.init()
node = Node("tf2_msgs_hash_probe")
node.create_publisher(TFMessage, "/hash_probe_tf", 1)
deadline = time.monotonic() + 10
infos = []
while not infos and time.monotonic() < deadline:
    infos = node.get_publishers_info_by_topic("/hash_probe_tf")
    rclpy.spin_once(node, timeout_sec=0.05)
print(json.dumps({"hash": str(infos[0].topic_type_hash), "type": infos[0].topic_type,
                  "module": TFMessage.__module__, "file": sys.modules["tf2_msgs"].__file__}))
node.destroy_node()
rclpy.shutdown()
"""


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.skipif(missing_tools() is not None, reason=str(missing_tools()))
def test_built_type_has_the_upstream_hash() -> None:
    """Built with CMake from generated/ros/tf2_msgs: rosidl's installed description and what rclpy reports for
    the type both carry the published hash."""
    prefix = built_prefix([GENERATED / "ros" / "tf2_msgs"])
    installed = json.loads((prefix / "share" / "tf2_msgs" / "msg" / "TFMessage.json").read_text())
    assert installed["type_hashes"][0] == {"type_name": "tf2_msgs/msg/TFMessage", "hash_string": PUBLISHED_HASH}
    proc = run_child(["-c", _REPORT], prefix, domain_id(40), timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["hash"] == PUBLISHED_HASH and report["type"] == "tf2_msgs/msg/TFMessage"
    assert report["file"].startswith(str(prefix)), report  # our build, not another copy
