"""The names a recorded run used, as the recording keeps them: its ROS namespace and frame prefix (issue 30).

A run with ``--namespace /sam1`` resolves the spec's relative topics under ``/sam1`` and writes every frame id with
the prefix ``sam1/`` (:mod:`sam_runtime.common.ros_namespace`). Its recording names each channel as the run
resolved it (``/sam1/core/imu``; absolute names stay as they are) and stores the namespace and prefix in its
``sam_codegen.recording`` metadata, so that the readers (the plot, the replay) find the spec's topics and frames in
it again: :func:`run_names` reads them back (a recording without them ran in ``/`` without a prefix).

Invariants: for the root namespace and no prefix every function here is the identity, so a recording of a plain
run reads exactly as before; nothing here raises for any metadata (a malformed namespace falls back to ``/``).
"""

from __future__ import annotations

from collections.abc import Mapping

from sam_runtime.common.ros_namespace import RosNamespace, ros_namespace

__all__ = ["FRAME_PREFIX_KEY", "NAMESPACE_KEY", "RECORDING_METADATA", "recorded_metadata", "run_names",
           "spec_frame", "spec_status_name"]

RECORDING_METADATA = "sam_codegen.recording"  # the recorder's metadata record
NAMESPACE_KEY = "ros.namespace"
FRAME_PREFIX_KEY = "ros.frame_prefix"


def recorded_metadata(names: RosNamespace) -> dict[str, str]:
    """The metadata entries that keep a run's names."""
    return {NAMESPACE_KEY: names.namespace, FRAME_PREFIX_KEY: names.frame_prefix}


def run_names(meta: Mapping[str, str] | None) -> RosNamespace:
    """The namespace and frame prefix of a recorded run, from its recorder metadata.

    >>> run_names({"ros.namespace": "/sam1", "ros.frame_prefix": "sam1/"}).resolve("core/imu")
    '/sam1/core/imu'
    >>> run_names({}) == RosNamespace()
    True
    """
    meta = meta or {}
    try:
        return ros_namespace(meta.get(NAMESPACE_KEY) or "/", frame_prefix=meta.get(FRAME_PREFIX_KEY, ""))
    except ValueError:  # a recording written by hand or damaged: read it as a plain run's
        return RosNamespace()


def spec_frame(names: RosNamespace, frame_id: str) -> str:
    """A recorded frame id as the spec names it (the run's prefix taken off; another vehicle's stays as it is).

    >>> spec_frame(RosNamespace("/sam1", "sam1/"), "sam1/odom"), spec_frame(RosNamespace("/sam1", "sam1/"), "odom")
    ('odom', 'odom')
    """
    p = names.frame_prefix
    return frame_id[len(p):] if p and frame_id.startswith(p) else frame_id


def spec_status_name(names: RosNamespace, status: str) -> str | None:
    """A /diagnostics status name as the run's own processes name it without the namespace (``sam1/controller`` ->
    ``controller``); None for another vehicle's status (it has another namespace, or none while this one has).

    >>> spec_status_name(RosNamespace("/sam1", "sam1/"), "sam1/controller")
    'controller'
    >>> spec_status_name(RosNamespace("/sam1", "sam1/"), "controller") is None
    True
    """
    if names.namespace == "/":
        return status
    head = names.namespace[1:] + "/"
    return status[len(head):] if status.startswith(head) else None
