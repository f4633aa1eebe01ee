"""The runtime's namespace and frame prefix: from --namespace and ROS's __ns remap, exact errors, and what each
gives (node namespace, frame ids, status names, child arguments)."""

from __future__ import annotations

import pytest

from sam_runtime.common.ros_namespace import RosNamespace, namespace_from_ros_args, ros_namespace


def test_default_is_the_root_and_changes_nothing() -> None:
    ns = ros_namespace()
    assert ns == RosNamespace("/", "")
    assert ns.node_namespace is None and ns.frame("base_link") == "base_link"
    assert ns.status_name("controller") == "controller" and ns.argv() == []
    assert ns.resolve("core/imu") == "/core/imu"


def test_a_namespace_gives_the_tf2_frame_prefix_and_status_names() -> None:
    ns = ros_namespace("/sam1")
    assert ns == RosNamespace("/sam1", "sam1/")
    assert ns.frame("base_link") == "sam1/base_link" and ns.frame("") == ""
    assert ns.status_name("uavcan_ros_bridge/mapping/imu") == "sam1/uavcan_ros_bridge/mapping/imu"
    assert ns.resolve("core/imu") == "/sam1/core/imu" and ns.resolve("/tf") == "/tf"
    assert ns.argv() == ["--namespace", "/sam1", "--frame-prefix", "sam1/"]
    assert ros_namespace("/fleet/sam1").frame_prefix == "fleet/sam1/"
    assert ros_namespace("sam1").namespace == "/sam1"  # as rcl makes a node's namespace absolute


def test_frame_prefix_given() -> None:
    assert ros_namespace("/sam1", (), "").frame_prefix == ""
    assert ros_namespace("/sam1", (), "auv").frame_prefix == "auv/"
    assert ros_namespace(None, (), "auv/").frame("odom") == "auv/odom"
    with pytest.raises(ValueError, match=r"^frame prefix '1x/' is not valid"):
        ros_namespace("/sam1", (), "1x")


@pytest.mark.parametrize(("args", "ns"), [
    (["--ros-args", "-r", "__ns:=/sam2"], "/sam2"),
    (["--ros-args", "--remap", "__ns:=/sam2"], "/sam2"),
    (["--ros-args", "--remap=__ns:=/sam2"], "/sam2"),
    (["-r", "__ns:=/a", "-r", "__ns:=/b"], "/b"),  # the last wins, as in rcl
    (["--ros-args", "-r", "imu:=/other"], None),
    (["--ros-args", "-r", "bridge:__ns:=/x"], None),  # node-specific: rcl's business
])
def test_ns_remap(args: list[str], ns: str | None) -> None:
    assert namespace_from_ros_args(args) == ns


def test_remap_and_option() -> None:
    assert ros_namespace(None, ["--ros-args", "-r", "__ns:=/sam2"]) == RosNamespace("/sam2", "sam2/")
    assert ros_namespace("/sam2", ["-r", "__ns:=/sam2/"]).namespace == "/sam2"
    with pytest.raises(ValueError, match=r"^--namespace /sam1 and the ROS argument __ns:=/sam2 disagree$"):
        ros_namespace("/sam1", ["--ros-args", "-r", "__ns:=/sam2"])
    with pytest.raises(ValueError, match=r"^namespace '/sam-1' is not a valid ROS namespace: segment 'sam-1' has"):
        ros_namespace("/sam-1")


def test_the_cli_refuses_a_bad_namespace_before_starting(capsys: pytest.CaptureFixture[str]) -> None:
    from sam_runtime.cli import bridge_main, nodes_main

    assert bridge_main(["--namespace", "/1sam"]) == 2
    assert capsys.readouterr().err.strip() == ("sam-bridge: namespace '/1sam' is not a valid ROS namespace: "
                                               "segment '1sam' starts with a digit")
    assert nodes_main(["--namespace", "/sam1", "--ros-args", "-r", "__ns:=/sam2"]) == 2
    assert capsys.readouterr().err.strip() == ("sam-nodes: --namespace /sam1 and the ROS argument __ns:=/sam2 "
                                               "disagree")
