"""The pure logic of the document's five nodes (sections IV.E-IV.H), without ROS: plain numbers in, plain numbers
out, times in seconds passed in by the caller. The ROS nodes (sam_runtime.nodes) feed these from their callbacks.

- :mod:`.dead_reckoning` - odom -> base_link from IMU, magnetometer, pressure and thruster feedback (IV.E.1)
- :mod:`.slam` - world -> odom from GPS fixes at the surface (IV.E.2)
- :mod:`.planner` - goals, the z convention, safety clamps and the path (IV.F)
- :mod:`.controller` - path following to actuator commands (IV.G)
- :mod:`.monitor` - the emergency state machine (IV.H)
- :mod:`.geo` - frames, angles, quaternions, the local metric frame, depth from pressure
- :mod:`.closed_loop` - all of them on the simulated vehicle in one process, in simulated time (tests, tuning)
"""

from __future__ import annotations

import importlib
from typing import Any

# Lazy: sam_runtime.vehicle imports sam_runtime.nav.geo, and the estimator imports the vehicle's nominal model.
_EXPORTS = {
    "Commands": "controller", "Controller": "controller", "ControllerConfig": "controller",
    "ControllerPose": "controller",
    "DeadReckoning": "dead_reckoning", "DeadReckoningConfig": "dead_reckoning", "DrPose": "dead_reckoning",
    "MonitorLimits": "monitor", "MonitorOutput": "monitor", "PerformanceMonitor": "monitor",
    "GOAL_FRAME": "planner", "Goal": "planner", "GoalDecision": "planner", "Plan": "planner", "PlanResult": "planner",
    "Planner": "planner", "PlannerConfig": "planner",
    "SlamConfig": "slam", "SlamCorrector": "slam",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{module}"), name)
