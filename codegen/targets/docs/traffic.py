"""How interfaces.md words a mapping's run-time traffic control (the spec keys of sam_codegen.frontend.traffic):
its rate limit, its command deadline and its enable switch, in the words the bridge acts on
(sam_runtime.bridge.rate_limit, sam_runtime.bridge.switches). Plain text but the service name, which the template
shows as code (a validated ROS name)."""

from __future__ import annotations

from typing import Any

from sam_codegen.model.spec import UAVCAN_TO_ROS, Mapping
from sam_codegen.targets.docs.wording import fmt_number, fmt_rate

__all__ = ["traffic_words"]


def traffic_words(m: Mapping) -> dict[str, Any]:
    """``rate``, ``deadline`` (None for UAVCAN->ROS), ``service``, ``where`` (how it resolves) and ``initially``."""
    to_ros = m.direction == UAVCAN_TO_ROS
    if m.max_rate_hz is None:
        rate = "every message " + ("published" if to_ros else "sent")
    else:
        what = "published to ROS" if to_ros else "sent (commands coalesced)"
        rate = (f"at most {fmt_rate(m.max_rate_hz)}, the latest message {what}: one that comes sooner waits for "
                "its slot and goes out then unless a newer one replaced it (counted as "
                f"{'rate_limited' if to_ros else 'coalesced'})")
    deadline = None
    if not to_ros:
        deadline = ("none" if m.deadline_s is None else
                    f"a command older than {fmt_number(m.deadline_s)} s since the bridge received it when it would "
                    "be sent is not sent (counted as expired)")
    service = m.enable_service_name
    where = ("under the bridge node's name" if service.startswith("~/") else "absolute" if service.startswith("/")
             else "in the bridge's namespace")
    return {"rate": rate, "deadline": deadline, "service": service, "where": where,
            "initially": "enabled" if m.enabled else "disabled (dropping and counting as disabled)"}
