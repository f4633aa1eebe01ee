"""The namespace a vehicle's processes run in, and the frame prefix that goes with it (two vehicles on one graph).

``--namespace /sam1`` (or ROS's own ``--ros-args -r __ns:=/sam1``) puts every ROS node of the bridge, the node host
and the main job's monitor under ``/sam1``: rclpy then resolves the spec's relative names there (``core/imu`` ->
``/sam1/core/imu``), while absolute names (``/imu``, and by ROS convention ``/tf``, ``/tf_static``,
``/diagnostics``) stay global. ``--frame-prefix`` (default: the namespace without its leading ``/`` plus ``/``, the
tf2 convention ``sam1/base_link``; ``""`` for none) goes before every frame id a process writes or looks up, and the
diagnostic statuses' names carry the same prefix (``sam1/controller``, ``sam1/uavcan_ros_bridge/mapping/imu``), so
two vehicles' transforms and statuses stay apart on the shared topics.

Invariants: the root namespace ``/`` gives the empty frame prefix and unchanged status names, so a run without
``--namespace`` behaves exactly as before; a bad namespace or frame prefix, or a ``--namespace`` that contradicts an
``__ns:=`` remap, is a ValueError with one line, raised before anything starts.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from sam_codegen.model.ros_names import normalize_namespace, resolve_name

__all__ = ["RosNamespace", "namespace_from_ros_args", "ros_namespace"]

_FRAME_PREFIX = re.compile(r"([A-Za-z_][A-Za-z0-9_]*/)*")
_REMAP_FLAGS = ("-r", "--remap")


@dataclass(frozen=True)
class RosNamespace:
    """``namespace``: absolute, ``/`` for none; ``frame_prefix``: ``""`` or ``a/`` ... ending with ``/``."""

    namespace: str = "/"
    frame_prefix: str = ""

    @property
    def node_namespace(self) -> str | None:
        """What rclpy's Node(namespace=...) gets (None: the default, ``/`` or an ``__ns`` remap)."""
        return None if self.namespace == "/" else self.namespace

    def frame(self, name: str) -> str:
        """A spec frame id as this vehicle writes it (an empty id, "unknown", stays empty)."""
        return f"{self.frame_prefix}{name}" if name else name

    def status_name(self, name: str) -> str:
        """A diagnostic status's name: the namespace without its leading ``/`` before it."""
        return name if self.namespace == "/" else f"{self.namespace[1:]}/{name}"

    def resolve(self, topic: str) -> str:
        """The fully qualified topic a node in this namespace uses for a spec name."""
        return resolve_name(topic, self.namespace)

    def argv(self) -> list[str]:
        """The options that give a child process this namespace and prefix (none for the root)."""
        if self.namespace == "/" and not self.frame_prefix:
            return []
        return ["--namespace", self.namespace, "--frame-prefix", self.frame_prefix]


def namespace_from_ros_args(ros_args: Sequence[str]) -> str | None:
    """The value of a global ``-r __ns:=NS`` / ``--remap __ns:=NS`` among ROS arguments (the last wins, as in rcl);
    None without one. A node-specific one (``name:__ns:=``) is left to rcl."""
    found = None
    args = list(ros_args)
    for i, arg in enumerate(args):
        value = None
        if arg in _REMAP_FLAGS and i + 1 < len(args):
            value = args[i + 1]
        elif arg.startswith("--remap="):
            value = arg.split("=", 1)[1]
        if value is not None and value.startswith("__ns:="):
            found = value[len("__ns:="):]
    return found


def ros_namespace(namespace: str | None = None, ros_args: Sequence[str] = (),
                  frame_prefix: str | None = None) -> RosNamespace:
    """The namespace from ``--namespace`` and the ROS arguments' ``__ns`` remap (both given: they must agree), and
    the frame prefix (None: from the namespace). ValueError, one line, for a bad or contradicting value.

    >>> ros_namespace("/sam1")
    RosNamespace(namespace='/sam1', frame_prefix='sam1/')
    >>> ros_namespace(None, ["--ros-args", "-r", "__ns:=/sam2"], "")
    RosNamespace(namespace='/sam2', frame_prefix='')
    """
    remapped = namespace_from_ros_args(ros_args)
    ns = normalize_namespace(namespace if namespace is not None else remapped)
    if namespace is not None and remapped is not None and normalize_namespace(remapped) != ns:
        raise ValueError(f"--namespace {namespace} and the ROS argument __ns:={remapped} disagree")
    if frame_prefix is None:
        frame_prefix = "" if ns == "/" else ns[1:] + "/"
    elif frame_prefix and not frame_prefix.endswith("/"):
        frame_prefix += "/"
    if not _FRAME_PREFIX.fullmatch(frame_prefix):
        raise ValueError(f"frame prefix {frame_prefix!r} is not valid: segments of a letter or underscore then "
                         "letters, digits, underscores, each followed by '/'")
    return RosNamespace(ns, frame_prefix)
