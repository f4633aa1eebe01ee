"""The main job's live view (sam_runtime.main_job.job step 5): LiveView, an rclpy node in the main job's process
that subscribes to every bridged topic, /diagnostics and (when nodes are hosted) the vehicle's topics, and draws
them as a table: each topic's rate over a sliding window and its last value (summarize_message), every device's
heartbeat, the bridge's drop counters; for a spec without node implementations it publishes the demo sweeps
(main_job.demo). Imported through main_job.job, which sets the process's ROS discovery to localhost first."""

from __future__ import annotations

import collections
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sam_codegen.model.spec import ROS_TO_UAVCAN, UAVCAN_TO_ROS
from sam_runtime.common.executors import make_executor
from sam_runtime.common.ros_namespace import RosNamespace
from sam_runtime.main_job.demo import demo_message
from sam_runtime.main_job.diag_view import bridge_lines, interface_line, status_key
from sam_runtime.main_job.vehicle_view import VehicleView

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule

__all__ = ["LiveView", "summarize_message"]


# ============================================================================================ formatting
def _fmt_num(v: Any) -> str:
    if isinstance(v, bool):
        return "T" if v else "F"
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return f"{v:.4g}"
    return str(v)


def _flatten(msg: Any, prefix: str = "") -> list[tuple[str, Any]]:
    out: list[tuple[str, Any]] = []
    fields = getattr(msg, "get_fields_and_field_types", None)
    if fields is None:
        return out
    for name in fields():
        if name == "header" or "covariance" in name:
            continue
        v = getattr(msg, name)
        if hasattr(v, "get_fields_and_field_types"):
            try:
                if v == type(v)():
                    continue  # a nested message left at its default (e.g. an orientation not provided)
            except Exception:  # pragma: no cover - a type without a default constructor
                pass
            sub = _flatten(v, "")
            if sub and len(sub) <= 4 and all(isinstance(x, int | float) for _, x in sub):
                out.append((prefix + name, "(" + ",".join(_fmt_num(x) for _, x in sub) + ")"))
            else:
                out.extend((f"{prefix}{name}.{k}", x) for k, x in sub)
        elif isinstance(v, str):
            if v:
                out.append((prefix + name, v))
        elif hasattr(v, "__len__") and not isinstance(v, bytes | bytearray):
            seq = list(v)
            if seq and not hasattr(seq[0], "get_fields_and_field_types"):
                shown = ",".join(_fmt_num(x.item() if hasattr(x, "item") else x) for x in seq[:3])
                out.append((prefix + name, f"[{shown}{',...' if len(seq) > 3 else ''}]"))
        else:
            out.append((prefix + name, v.item() if hasattr(v, "item") else v))
    return out


def summarize_message(msg: Any, width: int = 70) -> str:
    """A short one-line view of any ROS message: header and covariances left out, nested vectors as tuples."""
    parts: list[str] = []
    used = 0
    for k, v in _flatten(msg):
        text = f"{k}={_fmt_num(v) if not isinstance(v, str) else v}"
        if used + len(text) + 1 > width:
            parts.append("…")
            break
        parts.append(text)
        used += len(text) + 1
    return " ".join(parts)


# ============================================================================================ live view node
class _TopicState:
    def __init__(self, name: str, direction: str, nominal: float) -> None:
        self.name, self.direction, self.nominal = name, direction, nominal
        self.count = 0
        self.arrivals: collections.deque[float] = collections.deque()
        self.first: float | None = None
        self.last: Any = None

    def on_msg(self, msg: Any) -> None:
        now = time.monotonic()
        self.count += 1
        self.arrivals.append(now)
        if self.first is None:
            self.first = now
        self.last = msg

    def rate(self, window: float) -> float:
        now = time.monotonic()
        while self.arrivals and self.arrivals[0] < now - window:
            self.arrivals.popleft()
        if self.first is None:
            return 0.0
        span = min(window, now - self.first)
        return len(self.arrivals) / span if span > 0.2 else 0.0


class LiveView:
    """An rclpy node subscribing to every bridged topic and to /diagnostics (own context): what the run shows.
    Its ROS node is ``<bridge>_monitor`` (the name it always had)."""

    def __init__(self, tables: TablesModule, gen: Any, *, window: float = 2.0, demo_commands: bool = False,
                 hosted: list[str] | None = None, truth_file: Path | None = None, namespace: Any = None) -> None:
        import rclpy
        from diagnostic_msgs.msg import DiagnosticArray
        from rclpy.node import Node
        from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
        from rclpy.signals import SignalHandlerOptions

        self.tables, self.window = tables, window
        self.ctx = rclpy.Context()
        rclpy.init(args=[], context=self.ctx, signal_handler_options=SignalHandlerOptions.NO)
        self.namespace = namespace or RosNamespace()
        self.node = Node(f"{tables.BRIDGE_NAME}_monitor", namespace=self.namespace.node_namespace, context=self.ctx)
        best_effort = QoSProfile(depth=50, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.topics: dict[str, _TopicState] = {}
        for m in tables.MAPPINGS:
            st = self.topics.get(m.topic.name)
            if st is None:
                st = _TopicState(m.topic.name, "in" if m.direction == UAVCAN_TO_ROS else "out", m.rate_hz)
                self.topics[m.topic.name] = st
                self.node.create_subscription(gen.ros_class(m.topic), m.topic.name, st.on_msg, best_effort)
        self.diagnostics: dict[str, Any] = {}
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, 10)
        self._demo: list[tuple[Any, type, float, str]] = []
        self.demo_published: collections.Counter[str] = collections.Counter()
        self.demo_errors: collections.Counter[str] = collections.Counter()
        self._demo_t0 = time.monotonic()
        hosted = list(hosted or ())
        # The hosted nodes command the actuators: no demo sweep may compete with them on a topic.
        seen = {ep.topic for n in tables.NODES if n.name in hosted for ep in n.publishes}
        self.view = None
        if hosted:
            self.view = VehicleView(self.node, tables, topics=self.topics, diagnostics=self.diagnostics,
                                    hosted=hosted, truth_file=truth_file, frame_prefix=self.namespace.frame_prefix)
        if demo_commands:
            for m in tables.MAPPINGS:
                if m.direction == ROS_TO_UAVCAN and m.topic.name not in seen:
                    seen.add(m.topic.name)
                    cls = gen.ros_class(m.topic)
                    pub = self.node.create_publisher(cls, m.topic.name, 10)
                    rate = m.rate_hz if m.rate_hz and m.rate_hz > 0 else 10.0
                    self._demo.append((pub, cls, rate, m.topic.name))
            for i, (_pub, _cls, rate, _name) in enumerate(self._demo):
                self.node.create_timer(1.0 / rate, lambda i=i: self._publish_demo(i))
        self.executor, _events = make_executor(self.ctx)
        self.executor.add_node(self.node)

    def _on_diag(self, arr: Any) -> None:
        bridge = str(self.tables.BRIDGE_NAME)
        own = self.namespace.status_name("")  # "" or "sam1/": another vehicle's statuses are not this view's
        for s in arr.status:
            if not s.name.startswith(own):
                continue
            self.diagnostics[status_key(s.name[len(own):], bridge)] = {
                "level": int(s.level[0]) if isinstance(s.level, bytes | bytearray) else int(s.level),
                "message": s.message, "hardware_id": s.hardware_id,
                "values": {kv.key: kv.value for kv in s.values}, "at": time.monotonic(),
            }

    def _publish_demo(self, i: int) -> None:
        """One demo command on topic i: every field from its own rosidl type (sam_runtime.main_job.demo), checked by
        rclpy as it is set. A message that cannot be built is counted and logged once, never published."""
        import logging

        pub, cls, _rate, name = self._demo[i]
        try:
            pub.publish(demo_message(cls, time.monotonic() - self._demo_t0, self.node.get_clock().now().to_msg()))
        except Exception as ex:  # a value rclpy refuses (a bug of main_job.demo) or a closing context: never a crash
            self.demo_errors[name] += 1
            if self.demo_errors[name] == 1:
                logging.getLogger("sam_runtime.main_job.job").error("demo command on %s not published: %s: %s", name,
                                                               type(ex).__name__, ex)
            return
        self.demo_published[name] += 1

    def spin_for(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return
            self.executor.spin_once(timeout_sec=min(left, 0.05))

    def close(self) -> None:
        try:
            self.executor.shutdown(timeout_sec=1.0)
            self.node.destroy_node()
        finally:
            if self.ctx.ok():
                self.ctx.shutdown()

    # ---------------------------------------------------------------------------------- table
    def table(self, header: str) -> list[str]:
        bridge = self.tables.BRIDGE_NAME or ""
        drops_by_topic: dict[str, int] = collections.Counter()
        for name, d in self.diagnostics.items():
            if name.startswith(f"{bridge}/mapping/"):
                v = d["values"]
                drops_by_topic[v.get("topic", "?")] += int(v.get("dropped", "0") or 0)
        lines = [header, ""]
        if self.view is not None:
            lines += [*self.view.lines(), ""]
        lines.append(f"{'TOPIC':32} {'DIR':3} {'RATE Hz':>8} {'NOMINAL':>7} {'COUNT':>7} {'DROPS':>5}  LAST VALUE")
        for st in self.topics.values():
            last = summarize_message(st.last, 60) if st.last is not None else "-"
            lines.append(f"{st.name:32} {st.direction:3} {st.rate(self.window):8.1f} {st.nominal:7.0f} "
                         f"{st.count:7d} {drops_by_topic.get(st.name, 0):5d}  {last}")
        lines.append("")
        lines.append(f"{'DEVICE':22} {'NODE':>4} {'HEARTBEAT':>10} {'HEALTH':9} {'MODE':12} STATUS")
        now = time.monotonic()
        for d in self.tables.DEVICES:
            diag = self.diagnostics.get(f"{bridge}/device/{d.name}")
            if diag is None:
                lines.append(f"{d.name:22} {d.node_id:4d} {'-':>10} {'-':9} {'-':12} waiting for the bridge")
                continue
            v = diag["values"]
            age = v.get("age_s")
            age_txt = f"{float(age) + (now - diag['at']):.1f} s" if age not in (None, "") else "never"
            status = "ok" if diag["level"] == 0 else diag["message"]
            if v.get("settings"):  # the board's settings differ from the spec's defaults (the bridge read them)
                status += f"; settings: {v['settings']}"
            lines.append(f"{d.name:22} {d.node_id:4d} {age_txt:>10} {v.get('health', '-'):9} "
                         f"{v.get('mode', '-'):12} {status}")
        line = interface_line(self.diagnostics, bridge, [d.name for d in self.tables.DEVICES])
        if line is not None:
            lines.append(line)
        warnings = []  # mappings not OK: recent drops, or silent while their device is alive
        for n, d in sorted(self.diagnostics.items()):
            if n.startswith(f"{bridge}/mapping/") and d["level"] != 0:
                why = ", ".join(f"{k}={x}" for k, x in d["values"].items() if k.startswith("dropped."))
                warnings.append(f"{n.split('/')[-1]}: {d['message']}" + (f" ({why})" if why else ""))
        lines.append("")
        lines.extend(bridge_lines(self.diagnostics, bridge))
        lines.extend("  warn " + x for x in warnings)
        return lines
