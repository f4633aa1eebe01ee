"""What a frame's ``rpy`` in the spec means, as a quaternion: the one definition the generator (the static
transforms it writes into the node package) and the runtime (sam_runtime.tf_buffer) both use.

Conventions: roll, pitch, yaw in radians about the fixed x, y, z axes (URDF's rpy, tf2's setRPY); quaternions as
(x, y, z, w), ROS's order.
"""

from __future__ import annotations

import math

__all__ = ["quat_from_rpy"]


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of roll, pitch, yaw about the fixed x, y, z axes.

    >>> quat_from_rpy(0.0, 0.0, 0.0)
    (0.0, 0.0, 0.0, 1.0)
    >>> [round(c, 12) for c in quat_from_rpy(0.0, 0.0, math.pi)]
    [0.0, 0.0, 1.0, 0.0]
    """
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)
