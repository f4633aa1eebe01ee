"""The pure logic of the document's nodes (sections IV.E-IV.H), without ROS: plain numbers in, plain numbers out,
times in seconds passed in by the caller. The ROS nodes (sam_runtime.nodes) feed these from their callbacks; each
``nodes/X.py`` has its logic in ``nav/X.py``.

- :mod:`.dead_reckoning` - odom -> base_link from IMU, magnetometer, pressure and thruster feedback (IV.E.1)
- :mod:`.slam` - world -> odom from GPS fixes at the surface (IV.E.2)
- :mod:`.motion_planner` - goals, the z convention, safety clamps and the path (IV.F)
- :mod:`.controller` - path following to actuator commands (IV.G)
- :mod:`.performance_monitor` - the emergency state machine (IV.H)
- :mod:`.mission` - a mission's goals and when each is reached (an addition)

Layer: above physics (geometry, the vehicle's nominal model); the closed loop on the simulated vehicle is
sam_runtime.sim.closed_loop.
"""

from __future__ import annotations

from sam_runtime.nav.controller import Commands, Controller, ControllerConfig, ControllerPose
from sam_runtime.nav.dead_reckoning import DeadReckoning, DeadReckoningConfig, DrPose
from sam_runtime.nav.motion_planner import (
    GOAL_FRAME,
    Goal,
    GoalDecision,
    Plan,
    Planner,
    PlannerConfig,
    PlanResult,
)
from sam_runtime.nav.performance_monitor import MonitorLimits, MonitorOutput, PerformanceMonitor
from sam_runtime.nav.slam import SlamConfig, SlamCorrector

__all__ = [
    "GOAL_FRAME", "Commands", "Controller", "ControllerConfig", "ControllerPose", "DeadReckoning",
    "DeadReckoningConfig", "DrPose", "Goal", "GoalDecision", "MonitorLimits", "MonitorOutput", "PerformanceMonitor",
    "Plan", "PlanResult", "Planner", "PlannerConfig", "SlamConfig", "SlamCorrector",
]
