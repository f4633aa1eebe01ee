"""The main job's view of the vehicle and its mission (beside the topic/device table of main_job.live_view), for a
spec whose nodes are hosted: where the vehicle is, where it goes and what the nodes say.

- The vehicle: position, depth and heading from world -> base_link (/tf, as the nodes see it), the depth from
  /pressure and the altitude from /altitude (sensors), the speed from the dead reckoning's status; beside it the
  simulator's true state from its truth file (converted into world through SLAM's origin, the first GPS fix).
- The goal (/nav_goal, /nav_heading, the mission's progress), the plan (/global_plan: poses, length, target depth,
  and whether the planner clamped it), the commands (the command topics' last values), the abort (/abort).
- Every hosted node's state from /diagnostics, and the performance monitor's.

All rows are indented: the topic table's parsers take lines starting with "/" or a device name.
"""

from __future__ import annotations

import itertools
import json
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sam_runtime.node_support import stamp_to_ns
from sam_runtime.physics.geo import depth_from_pressure, euler_from_quaternion, local_from_latlon
from sam_runtime.tf_buffer import TfBuffer, TfError

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule

__all__ = ["VehicleView"]

_LEVELS = {0: "OK", 1: "WARN", 2: "ERROR", 3: "STALE"}
TF_MAX_AGE_S = 3.0


def _f(v: float | None, fmt: str = "6.2f", unit: str = "") -> str:
    return "-" if v is None or not math.isfinite(v) else f"{v:{fmt}}{unit}"


def _number(text: str | None) -> float | None:
    """A /diagnostics value as a number (None: absent or not one), so it is shown in the view's own format: the
    dead-reckoning node writes its speed with repr() (3.165e-78 m/s at rest)."""
    try:
        return None if text is None else float(text)
    except ValueError:
        return None


class VehicleView:
    """Subscribes on ``node`` (an rclpy Node of the main job); ``lines()`` renders the view."""

    def __init__(self, node: Any, tables: TablesModule, *, topics: dict[str, Any], diagnostics: dict[str, Any],
                 hosted: list[str], truth_file: Path | None, frame_prefix: str = "") -> None:
        from geometry_msgs.msg import PoseStamped
        from nav_msgs.msg import Path as PathMsg
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from tf2_msgs.msg import TFMessage

        self.tables, self.topics, self.diagnostics = tables, topics, diagnostics
        self.hosted, self.truth_file = hosted, truth_file
        self.frame_prefix = frame_prefix  # the vehicle's (sam1/): its frames on the shared /tf
        self.tf = TfBuffer()
        self.goal: Any = None
        self.plan: Any = None
        self.abort: Any = None
        self.tf_rejected = 0
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        # SAM's topics by their names, absolute or (a spec for a namespaced vehicle) relative: /nav_goal or nav_goal
        names = {"/" + t.name.lstrip("/"): t for t in tables.TOPICS}
        self._subs = [node.create_subscription(TFMessage, "/tf", lambda m: self._on_tf(m, False),
                                               QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)),
                      node.create_subscription(TFMessage, "/tf_static", lambda m: self._on_tf(m, True), latched)]
        if "/nav_goal" in names:
            self._subs.append(node.create_subscription(PoseStamped, names["/nav_goal"].name, self._on_goal, reliable))
        if "/global_plan" in names:
            self._subs.append(node.create_subscription(PathMsg, names["/global_plan"].name, self._on_plan, reliable))
        for topic, cb, qos in (("/nav_heading", self._on_goal, reliable), ("/abort", self._on_abort, latched)):
            if topic in names:
                t = names[topic]
                cls = getattr(__import__(t.ros_module, fromlist=[t.ros_class]), t.ros_class)
                self._subs.append(node.create_subscription(cls, t.name, cb, qos))

    # ---------------------------------------------------------------------------------- inputs
    def _on_tf(self, msg: Any, static: bool) -> None:
        for ts in msg.transforms:
            t, r = ts.transform.translation, ts.transform.rotation
            try:
                self.tf.set_transform(ts.header.frame_id, ts.child_frame_id, stamp_to_ns(ts.header.stamp),
                                      (t.x, t.y, t.z), (r.x, r.y, r.z, r.w), static=static)
            except TfError:
                self.tf_rejected += 1

    def _on_goal(self, msg: Any) -> None:
        self.goal = msg

    def _on_plan(self, msg: Any) -> None:
        self.plan = msg

    def _on_abort(self, msg: Any) -> None:
        self.abort = msg

    # ---------------------------------------------------------------------------------- sources
    def _diag(self, name: str) -> dict[str, Any]:
        return self.diagnostics.get(name) or {"level": None, "message": "no status yet", "values": {}}

    def _truth(self) -> dict[str, Any] | None:
        """The newest truth sample (a JSON object, or the last line of a .jsonl file)."""
        if self.truth_file is None:
            return None
        try:
            text = self.truth_file.read_text()
            lines = [ln for ln in text.splitlines() if ln.strip()]
            return json.loads(lines[-1]) if lines else None
        except (OSError, ValueError):
            return None

    def _world_offset(self, truth: dict[str, Any]) -> tuple[float, float] | None:
        """The sim frame's position of world's origin (SLAM's first fix), from SLAM's status."""
        v = self._diag("slam")["values"]
        try:
            lat, lon = float(v["origin_lat"]), float(v["origin_lon"])
            return local_from_latlon(lat, lon, *truth["gps_origin"])
        except (KeyError, TypeError, ValueError):
            return None

    def _last(self, topic: str) -> Any:
        st = self.topics.get(topic) or self.topics.get(topic[1:])  # as the spec writes it: absolute or relative
        return None if st is None else st.last

    # ---------------------------------------------------------------------------------- rendering
    def lines(self) -> list[str]:
        out = [f"  {'VEHICLE':14} {'estimate (world -> base_link, sensors)':44} true (simulator)"]
        try:
            tr = self.tf.lookup(self.frame_prefix + "world", self.frame_prefix + "base_link", now_ns=time.time_ns(),
                                max_age_s=TF_MAX_AGE_S)
            ex, ey, ez = tr.translation
            yaw = euler_from_quaternion(tr.rotation)[2]
            est: dict[str, float] | None = {"x": ex, "y": ey, "depth": -ez, "yaw": yaw}
            tf_note = ""
        except TfError as e:
            est, tf_note = None, f"no world -> base_link: {e}"
        truth = self._truth()
        true: dict[str, float] | None = None
        if truth is not None:
            off = self._world_offset(truth)
            true = {"x": truth["x"] - off[0] if off else math.nan, "y": truth["y"] - off[1] if off else math.nan,
                    "depth": truth["depth"], "yaw": truth["yaw"], "altitude": truth["altitude"],
                    "speed": truth["speed"]}
        pressure = self._last("/pressure")
        p_depth = None if pressure is None else depth_from_pressure(pressure.fluid_pressure)
        alt = self._last("/altitude")
        dr_speed = self._diag("dead_reckoning")["values"].get("speed")

        def row(name: str, estimate: str, real: str) -> None:
            out.append(f"  {name:14} {estimate:44} {real}")

        def num(d: dict[str, float] | None, key: str, scale: float = 1.0) -> float | None:
            return None if d is None else d[key] * scale

        row("position", f"x {_f(num(est, 'x'), '7.1f')} m  y {_f(num(est, 'y'), '7.1f')} m",
            f"x {_f(num(true, 'x'), '7.1f')} m  y {_f(num(true, 'y'), '7.1f')} m")
        row("depth", f"{_f(num(est, 'depth'))} m  (pressure {_f(p_depth)} m)", f"{_f(num(true, 'depth'))} m")
        row("altitude", f"{_f(None if alt is None else alt.range)} m  (altimeter)",
            f"{_f(num(true, 'altitude'))} m")
        row("heading", f"{_f(num(est, 'yaw', scale=180 / math.pi), '7.1f')} deg (ENU yaw, from east)",
            f"{_f(num(true, 'yaw', scale=180 / math.pi), '7.1f')} deg")
        row("speed", f"{_f(_number(dr_speed))} m/s  (dead reckoning)", f"{_f(num(true, 'speed'))} m/s")
        if tf_note:
            out.append(f"  {'':14} {tf_note}")
        out.append("")
        out.extend(self._goal_lines())
        out.extend(self._command_lines())
        out.append("")
        out.extend(self._node_lines())
        return out

    def _goal_lines(self) -> list[str]:
        lines = []
        mission = self._diag("mission")
        goal = "-"
        if self.goal is not None:
            if hasattr(self.goal, "pose"):
                p = self.goal.pose.position
                goal = f"/nav_goal ({p.x:.1f}, {p.y:.1f}, z {p.z:.1f}) in {self.goal.header.frame_id or '?'}"
            else:
                goal = (f"/nav_heading {math.degrees(self.goal.heading):.0f} deg, z {self.goal.z:.1f} in "
                        f"{self.goal.header.frame_id or '?'}")
        lines.append(f"  {'GOAL':14} {goal}")
        if "mission" in self.hosted:
            v = mission["values"]
            lines.append(f"  {'mission':14} {mission['message']}" + (
                f"  (distance {v['distance']} m)" if v.get("distance", "-") != "-" else ""))
        plan = "-"
        if self.plan is not None:
            poses = [(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in self.plan.poses]
            length = sum(math.dist(a[:2], b[:2]) for a, b in itertools.pairwise(poses))
            clamped = self._diag("motion_planner")["values"].get("clamped", "-")
            plan = (f"{len(poses)} poses, {length:.1f} m, target depth {-poses[-1][2]:.2f} m, clamped: {clamped}"
                    if poses else "empty")
        lines.append(f"  {'PLAN':14} {plan}")
        return lines

    def _command_lines(self) -> list[str]:
        rpm, ang = self._last("/thruster_rpms"), self._last("/thruster_angles")
        buoy, weight = self._last("/buoyancy_piston_position"), self._last("/longitudinal_weight_position")
        parts = []
        if rpm is not None:
            parts.append(f"rpm {rpm.thruster_1_rpm}/{rpm.thruster_2_rpm}")
        if ang is not None:
            parts.append(f"vector h {ang.thruster_horizontal_radians:+.3f} v {ang.thruster_vertical_radians:+.3f} rad")
        if buoy is not None:
            parts.append(f"buoyancy {buoy.percent:.0f} %")
        if weight is not None:
            parts.append(f"weight {weight.percent:.0f} %")
        lines = [f"  {'COMMANDS':14} {'  '.join(parts) or '-'}"]
        if self.abort is not None:
            lines.append(f"  {'ABORT':14} " + (f"ACTIVE: {self.abort.reason}" if self.abort.active else "clear"))
        return lines

    def _node_lines(self) -> list[str]:
        lines = [f"  {'NODE':20} {'STATE':6} STATUS"]
        for name in self.hosted:
            d = self._diag(name)
            state = "-" if d["level"] is None else _LEVELS.get(d["level"], str(d["level"]))
            lines.append(f"  {name:20} {state:6} {d['message']}")
        mon = self._diag("performance_monitor")
        if "performance_monitor" in self.hosted:
            v = mon["values"]
            limits = (f"critical_depth {v.get('critical_depth', '-')} m, critical_altitude "
                      f"{v.get('critical_altitude', '-')} m, min_battery_percent {v.get('min_battery_percent', '-')} %")
            lines.append(f"  {'MONITOR':20} {v.get('state', '-').upper():6} {limits}, battery "
                         f"{v.get('battery_percent', '-')} %")
        return lines
