"""ROS names as the spec writes them: rcl's rules (exact reasons), relative names resolved under a namespace,
absolute ones kept; and a spec with relative topics builds with its names as written."""

from __future__ import annotations

from pathlib import Path

import pytest

from sam_codegen.model.ros_names import (
    namespace_problem,
    normalize_namespace,
    resolve_name,
    ros_name_problem,
)

SPECS = Path(__file__).parents[1] / "specs"


@pytest.mark.parametrize("name", ["/imu", "core/imu", "imu", "_a/b_2/C", "/a/b/c"])
def test_valid_names(name: str) -> None:
    assert ros_name_problem(name) is None


@pytest.mark.parametrize(("name", "why"), [
    ("", "it is empty"),
    ("/", "it is the root namespace, not a name"),
    ("core//imu", "it has an empty segment ('//')"),
    ("//imu", "it has an empty segment ('//')"),
    ("core/imu/", "it ends with '/'"),
    ("2core/imu", "segment '2core' starts with a digit"),
    ("core/9", "segment '9' starts with a digit"),
    ("core/i-mu", "segment 'i-mu' has a character other than letters, digits and '_'"),
    ("core imu", "segment 'core imu' has a character other than letters, digits and '_'"),
    ("~/imu", "private names ('~') are not supported"),
    ("core/~", "private names ('~') are not supported"),
    ("{node}/imu", "substitutions ('{...}') are not supported"),
])
def test_invalid_names_say_which_rule(name: str, why: str) -> None:
    assert ros_name_problem(name) == why


def test_namespaces() -> None:
    assert namespace_problem("/sam1") is None and namespace_problem("/fleet/sam1") is None
    assert namespace_problem("sam1") == "it must be absolute (start with '/')"
    assert normalize_namespace("") == "/" and normalize_namespace("fleet/sam1/") == "/fleet/sam1"
    with pytest.raises(ValueError, match=r"^namespace '/sam 1' is not a valid ROS namespace: segment 'sam 1'"):
        normalize_namespace("/sam 1")


@pytest.mark.parametrize(("name", "ns", "resolved"), [
    ("core/imu", "/sam1", "/sam1/core/imu"),
    ("core/imu", "/fleet/sam1", "/fleet/sam1/core/imu"),
    ("core/imu", "/", "/core/imu"),
    ("core/imu", None, "/core/imu"),
    ("/imu", "/sam1", "/imu"),  # absolute names are never namespaced
    ("/tf", "/sam2", "/tf"),
])
def test_resolution(name: str, ns: str | None, resolved: str) -> None:
    assert resolve_name(name, ns) == resolved


def test_resolution_agrees_with_rclpy() -> None:
    """The same resolution rclpy's node does (rcl_node_resolve_name), for the names the runtime relies on."""
    rclpy = pytest.importorskip("rclpy")
    from rclpy.node import Node

    ctx = rclpy.Context()
    rclpy.init(args=[], context=ctx)
    try:
        node = Node("probe", namespace="/sam1", context=ctx)
        for name in ("core/imu", "/imu", "a/b/c"):
            assert node.resolve_topic_name(name) == resolve_name(name, "/sam1")
        node.destroy_node()
    finally:
        ctx.shutdown()


def test_a_spec_with_relative_topics_builds_with_its_names_as_written(tmp_path: Path) -> None:
    """minimal.yaml with its topics relative: valid; the tables, the node bases and the docs keep the names."""
    from sam_codegen.build import build

    text = (SPECS / "minimal.yaml").read_text(encoding="utf-8")
    for name in ("level", "valve"):
        text = text.replace(f"/{name}", f"gauge/{name}")
    spec = tmp_path / "minimal.yaml"
    spec.write_text(text, encoding="utf-8")
    out = tmp_path / "generated"
    build(spec, out)
    tables = (out / "python" / "buoy_bridge" / "tables.py").read_text()
    assert "'gauge/level'" in tables and "'/level'" not in tables
    base = (out / "python" / "buoy_nodes" / "valve_control.py").read_text()
    assert '"gauge/valve"' in base and "def publish_gauge_valve" in base and "def on_gauge_level" in base
    assert "gauge/level" in (out / "docs" / "interfaces.md").read_text()
