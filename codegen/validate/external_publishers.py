"""Checks of `published_by: external` (frontend.topic_sources): topics that tools outside the spec publish.

An external publisher counts as a publisher wherever validation asks who publishes a topic (validate.nodes.publishers:
a node's subscription, the bridge's ros_to_uavcan commands, QoS compatibility with the topic's QoS). What it may not
do is share a topic with the bridge's UAVCAN->ROS stream: the bridge is then the topic's one source of device data,
and a second source would be taken for the device's. A node that also publishes an external topic is allowed (an
operator may override the mission's goals). Errors point at the `published_by` value.
"""

from __future__ import annotations

from sam_codegen.model.diagnostics import Diagnostics
from sam_codegen.model.spec import UAVCAN_TO_ROS, Spec

__all__ = ["check_external_publishers"]


def check_external_publishers(spec: Spec, diag: Diagnostics) -> None:
    """Every misuse of `published_by: external`, into diag."""
    bridged: dict[str, str] = {}  # topic -> the first uavcan_to_ros mapping that publishes it
    if spec.bridge is not None:
        for m in spec.bridge.all_mappings:
            if m.direction == UAVCAN_TO_ROS:
                bridged.setdefault(m.topic, m.name)
    for topic in spec.topics.values():
        if topic.external_publisher is None or topic.name not in bridged:
            continue
        diag.error(topic.external_pos, f"topic {topic.name} is published_by external, but the bridge publishes it "
                   f"from UAVCAN (mapping {bridged[topic.name]}): a second source would pass for the device's data",
                   "published_by on a topic the bridge does not publish, or another topic for the outside source")
