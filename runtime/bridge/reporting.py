"""The bridge's counters and states: a JSON-serialisable snapshot (:meth:`Reporter.snapshot`, the bridge's
``stats()``) and /diagnostics (diagnostic_msgs/DiagnosticArray, :mod:`.diagnostics`) once per period and at once
when a device, a mapping's silence or the link changes state (:meth:`Reporter.publish_now`).

The period's /diagnostics is a job of the bridge's lifetime on the asyncio loop (at the default 1 s, in the one
housekeeping round a second: no timer of its own on the rclpy executor, whose thread then sleeps until a command
comes), serialized straight to CDR (:func:`~.diagnostics.diagnostic_array_cdr`) and published raw."""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Mapping, Sequence
from typing import Any

from sam_codegen.model.spec import UAVCAN_TO_ROS
from sam_runtime.bridge.backend import Backend
from sam_runtime.bridge.counters import MappingStats
from sam_runtime.bridge.diagnostics import Naming, diagnostic_array, diagnostic_array_cdr
from sam_runtime.bridge.health import DeviceHealth
from sam_runtime.bridge.inbound import Inbound
from sam_runtime.bridge.layout import destinations_of, port_id_of
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.link import LinkSupervisor
from sam_runtime.bridge.outbound import Outbound
from sam_runtime.bridge.silence import SilenceWatch
from sam_runtime.bridge.switches import MappingSwitch
from sam_runtime.common.rate_log import RateLimitedLog

__all__ = ["DIAGNOSTICS_TOPIC", "Reporter"]

DIAGNOSTICS_TOPIC = "/diagnostics"


class Reporter:
    """:param mappings: the tables' mappings (the order of the reports); ``counters`` theirs by name.
    :param period: seconds between two /diagnostics messages (0: none)."""

    def __init__(self, lifetime: Lifetime, name: str, mappings: Sequence[Any], counters: dict[str, MappingStats], *,
                 backend: Backend, health: DeviceHealth, link: LinkSupervisor, inbound: Inbound,
                 outbound: Outbound, silence: SilenceWatch, ros: Any, period: float = 1.0,
                 switches: Mapping[str, MappingSwitch] | None = None) -> None:
        self.lifetime, self.name, self.mappings, self.counters = lifetime, name, list(mappings), counters
        self.backend, self.health, self.link = backend, health, link
        self.inbound, self.outbound, self.silence, self.ros = inbound, outbound, silence, ros
        self.period = float(period)
        self.switches = dict(switches or {})
        self.naming = Naming(name, backend.protocol, backend.label, backend.stack)
        self._publisher: Any = None
        self.time_sync: Any = None  # the time-sync master and stamp watch (sam_runtime.bridge.time_sync)
        self.interface_check: Any = None  # the boards' interface versions (sam_runtime.bridge.interface_check)
        # device -> its settings whose board value differs from the spec's default, as text (device_params)
        self.device_settings: Any = None

    def attach(self) -> None:
        """The /diagnostics publisher once the ROS node exists, and its period on the loop."""
        self.lifetime.add_hooks("diagnostics", start=self._start)
        if self.period > 0:
            self.lifetime.every(self.period, "diagnostics", self.publish_now)

    def _start(self) -> None:
        if self.period <= 0:
            return
        from diagnostic_msgs.msg import DiagnosticArray

        self._publisher = self.ros.node.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC, 10)

    @property
    def rlog(self) -> RateLimitedLog:
        return self.lifetime.rlog

    def publish_now(self) -> None:
        """Publish /diagnostics (the period's job on the loop, and on a state change, also from the rclpy thread:
        rclpy's publish is thread-safe). Never raises."""
        if self._publisher is None or self.lifetime.closed:
            return
        try:
            self._publisher.publish(diagnostic_array_cdr(self.snapshot(), self.naming,
                                                         self.ros.clock.now().nanoseconds))
        except Exception as ex:
            self.lifetime.errors["diagnostics_error"] += 1
            self.rlog.note(("diagnostics", "error"), logging.ERROR, "diagnostics: %s: %s", type(ex).__name__, ex)

    def diagnostics_message(self) -> Any:
        return diagnostic_array(self.snapshot(), self.naming, self.ros.clock.now().to_msg())

    def _traffic(self, m: Any) -> dict[str, Any]:
        """A mapping's traffic control: its limits from the tables, its switch now."""
        sw = self.switches.get(m.name)
        return {"max_rate_hz": getattr(m, "max_rate_hz", None), "deadline_s": getattr(m, "deadline_s", None),
                **(sw.snapshot() if sw is not None else {"enabled": True})}

    def snapshot(self) -> dict[str, Any]:
        """Every counter, the devices' heartbeats and the bridge itself. Polls the protocol stack's counters
        first, so the below-bridge drops are current."""
        self.backend.poll_statistics()
        now = time.monotonic()
        empty = MappingStats(threading.Lock()).snapshot()
        proto = self.backend.protocol
        mappings: dict[str, Any] = {}
        for m in self.mappings:
            st = self.counters.get(m.name)
            port_key = "data_type_id" if hasattr(m, "data_type") else "subject_id"
            entry = {"direction": m.direction, "topic": m.topic.name, port_key: port_id_of(m),
                     **({"data_type": m.data_type.name} if hasattr(m, "data_type") else {}),
                     **(st.snapshot() if st else empty), **self._traffic(m)}
            if m.direction == UAVCAN_TO_ROS:
                entry["source_node_ids"] = "any" if getattr(m, "any_node", False) else sorted(m.source_node_ids)
                group = self.inbound.group_of(m.name)
                inlet = group.inlet if group is not None else None
                entry["port"] = inlet.port_name if inlet is not None else (
                    f"uavcan.sub.{group.port_name}" if group is not None else None)
                if inlet is not None and inlet.port_id is not None:
                    entry[port_key] = inlet.port_id  # the register's value (the spec's by default)
                entry["liveness"] = self.silence.entry(m.name)
                if inlet is not None:
                    totals, kinds, last_problem = inlet.below.snapshot()
                    below: dict[str, Any] = {k: totals.get(k, 0) for k in ("transfers", "frames", "errors", "drops",
                                                           "deserialization_failures", "overruns")}
                    if kinds:
                        below["error_kinds"] = kinds
                    if last_problem is not None:
                        below["last_problem_age_s"] = round(now - last_problem, 3)
                    entry[proto] = below
                entry["ros_subscribers"] = self.ros.matched(m.topic.name)
            else:
                if hasattr(m, "destination_node_ids"):
                    entry["destination_node_ids"] = "any" if getattr(m, "any_node", False) else list(
                        destinations_of(m))
                else:
                    entry["destination_node_id"] = m.destination_node_id
                om = self.outbound.mappings.get(m.name)
                outlet = om.outlet if om is not None else None
                entry["port"] = outlet.port_name if outlet is not None else f"uavcan.pub.{m.name}"
                if outlet is not None and outlet.port_id is not None:
                    entry[port_key] = outlet.port_id
                entry["queued"] = om.queue.qsize() if om is not None and om.queue is not None else 0
                entry["ros_publishers"] = self.ros.matched(m.topic.name)
            mappings[m.name] = entry
        devices, others = self.health.snapshot()
        if self.interface_check is not None:
            for name, entry in self.interface_check.device_entries().items():
                devices.setdefault(name, {}).update(entry)
        if self.device_settings is not None:
            for name, text in self.device_settings().items():
                if name in devices:
                    devices[name]["settings"] = text  # a /diagnostics value of the device, shown by the main job
        started = self.lifetime.started_monotonic
        return {
            "bridge": {
                "name": self.name,
                "node_id": self.backend.node_id,
                "transport": self.backend.describe(),
                "uptime_s": round(now - started, 3) if started else 0.0,
                "errors": dict(self.lifetime.errors),
                "link": self.link.snapshot(),
                "log_lines": sum(self.rlog.lines.values()),
                "active": self.outbound.active,  # False: a managed bridge not activated (commands dropped)
            },
            "mappings": mappings,
            "devices": devices,
            "other_nodes": others,
            **({"time_sync": self.time_sync.snapshot()} if self.time_sync is not None else {}),
        }

