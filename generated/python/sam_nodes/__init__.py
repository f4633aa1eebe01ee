# Generated from interfaces.yaml by sam-codegen; do not edit.
"""Typed ROS 2 interfaces of the sam nodes: one module per node of the spec with its base class.

Write a node as a subclass of its base with logic only: topic names, types, QoS, parameters and frames come
from the spec (see each module's docstring for its interface).

- ``sam_nodes.dead_reckoning.DeadReckoningBase``: Dead reckoning; high-rate pose of base_link in odom from the
  IMU, compass, depth and thrusters (IV.E.1).
- ``sam_nodes.slam.SlamBase``: SLAM; low-rate correction of odom in world from GPS fixes at the surface
  (IV.E.2).
- ``sam_nodes.motion_planner.MotionPlannerBase``: Plans a path to a heading or pose goal at a target depth or
  altitude (IV.F).
- ``sam_nodes.controller.ControllerBase``: Follows the planned path by commanding the actuators; obeys an
  abort (IV.G).
- ``sam_nodes.performance_monitor.PerformanceMonitorBase``: Watches depth, altitude and the battery; orders an
  emergency ascent (IV.H).
- ``sam_nodes.mission.MissionBase``: Gives the motion planner its goals, a pose or a heading at a depth or
  altitude (an addition).

For the node host:

- ``NODES``: node name -> (module, base class);
- ``STATIC_TRANSFORMS`` and ``publish_static_transforms(node)``: the spec's static child frames (mounting
  offsets), published once in one message on /tf_static, latched;
- the parameters' defaults for every node: generated/params/sam.params.yaml (ROS 2 ``--params-file`` format).

Nothing is imported here: reading this module never pulls in rclpy.
"""

from __future__ import annotations

from typing import Any

NODES: dict[str, tuple[str, str]] = {
    "dead_reckoning": ("sam_nodes.dead_reckoning", "DeadReckoningBase"),
    "slam": ("sam_nodes.slam", "SlamBase"),
    "motion_planner": ("sam_nodes.motion_planner", "MotionPlannerBase"),
    "controller": ("sam_nodes.controller", "ControllerBase"),
    "performance_monitor": ("sam_nodes.performance_monitor", "PerformanceMonitorBase"),
    "mission": ("sam_nodes.mission", "MissionBase"),
}

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]

# (parent, child, translation [m], rotation (x, y, z, w)) of every static child frame.
STATIC_TRANSFORMS: tuple[tuple[str, str, Vector, Quaternion], ...] = (
    ("base_link", "imu_link", (0.1, 0.0, 0.0),
     (0.0, 0.0, 0.0, 1.0)),
    ("base_link", "magnetometer_link", (0.3, 0.0, 0.04),
     (0.0, 0.0, 0.0, 1.0)),
    ("base_link", "gps_link", (-0.2, 0.0, 0.12),
     (0.0, 0.0, 0.0, 1.0)),
    ("base_link", "pressure_link", (-0.55, 0.0, 0.0),
     (0.0, 0.0, 0.0, 1.0)),
    ("base_link", "altimeter_link", (0.35, 0.0, -0.08),
     (0.0, 0.7071067811865475, 0.0, 0.7071067811865476)),
)


def publish_static_transforms(node: Any, frame_prefix: str = "") -> Any:
    """Publish STATIC_TRANSFORMS once on /tf_static from `node` (an rclpy Node), stamped now,
    each frame id after `frame_prefix` (a vehicle's, e.g. ``sam1/``).

    Returns the publisher: keep a reference, it serves subscribers that start later (transient local).
    """
    from sam_runtime import node_support

    return node_support.publish_static_transforms(
        node, STATIC_TRANSFORMS, "/tf_static", node_support.qos_profile("reliable", "transient_local", 1),
        frame_prefix)
