"""Names the spec's entities take on the ROS side, shared by the generator and the runtime.

Pure functions of the spec's text: the node bases the generator writes and the runtime's parameter handling must
agree on them, so each is defined here once.
"""

from __future__ import annotations


def ros_parameter_name(spec_name: str) -> str:
    """A spec parameter (written like a ROS 1 global, /safe_depth) as the node-local ROS 2 name.

    >>> ros_parameter_name("/safe_depth"), ros_parameter_name("/limits/depth")
    ('safe_depth', 'limits.depth')
    """
    return spec_name.lstrip("/").replace("/", ".")
