"""The rclpy executor the ROS processes of the runtime spin (the bridge, the node host, the main job's view):
rclpy's EventsExecutor where it exists (rclpy >= 7.1.4, Jazzy), else the SingleThreadedExecutor. Not the recorder:
rclpy 7.1.5's EventsExecutor fails on a subscription whose callback takes the message info ("SystemError: null
argument to internal routine" at its first message), which the recorder needs for its stamps.

Why: the SingleThreadedExecutor rebuilds, in Python, its wait set of every timer, subscription, guard condition and
each publisher's and subscription's QoS event handlers at every wake-up. That was ~70 % of the node host's CPU
(py-spy: six nodes, ~300 wake-ups/s; 0.77 of a core here, 0.23 with the EventsExecutor) and ~3x the bridge's cost
per command (bench/profile_bridge.py). The EventsExecutor keeps its entities in C++ and runs a callback per event.

Two things to know when spinning it (rclpy 7): ``spin_once``/``spin_until_future_complete`` without a timeout keep
the GIL while waiting (give a timeout), and an exception out of a callback is raised from the spin call, as the
Python executors do, after rclpy logs it.
"""

from __future__ import annotations

from typing import Any

__all__ = ["make_executor"]


def make_executor(context: Any) -> tuple[Any, bool]:
    """(an executor for ``context``, whether it is the EventsExecutor)."""
    try:
        from rclpy.experimental import EventsExecutor
    except ImportError:
        from rclpy.executors import SingleThreadedExecutor

        return SingleThreadedExecutor(context=context), False
    return EventsExecutor(context=context), True
