"""The whole stack across processes for the closed-loop scenarios: the simulated devices (``sam-sim``, with a truth
file), the bridge and the node host (``sam-nodes``) as child processes on Cyphal/UDP 127.0.0.1 under the
machine-wide UDP lock, ROS on a private ROS_DOMAIN_ID, and a probe (an rclpy node in the test process) that reads
TF, /diagnostics, /abort, the plan and the commands, publishes goals or plans, and sets parameters through the
nodes' ~/set_parameters services.

Ground truth comes from the simulator's truth file (JSON lines, ``truth_rate`` samples per second with the wall
clock of each). The nodes run on the system clock, so a transform's stamp and a truth sample's ``wall_ns``
compare directly. Every wait polls with a deadline.
"""

from __future__ import annotations

import bisect
import json
import math
import os
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from helpers.ros_probe import SpunNode
from helpers.runtime_support import (
    Proc,
    child_env,
    cyphal_udp_lock,
    domain_id,
    generated_or_skip,
    poll_until,
    ros_prefix_for,
    runtime_cmd,
)

wait_for = poll_until  # (the scenario tests' name for it)
START_TIMEOUT_S = 90.0  # three Python processes compiling nothing (the DSDL cache is warm) on a loaded machine
WORLD_TIMEOUT_S = 45.0  # world -> base_link: discovery, the first GPS fix, SLAM's first correction


# ============================================================================================ truth
class Truth:
    """The simulator's truth file (JSON lines), read again on every access."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def samples(self) -> list[dict[str, Any]]:
        out = []
        try:
            text = self.path.read_text()
        except OSError:
            return []
        for line in text.splitlines():
            try:
                out.append(json.loads(line))
            except ValueError:  # the line being written
                pass
        return out

    def latest(self) -> dict[str, Any]:
        return wait_for(lambda: (self.samples() or [None])[-1], 10, f"a truth sample in {self.path}")

    def at(self, wall_ns: int, samples: list[dict[str, Any]] | None = None) -> dict[str, float]:
        """x, y, depth, yaw, altitude interpolated at a wall time (the nearest ends outside the samples)."""
        s = samples if samples is not None else self.samples()
        stamps = [x["wall_ns"] for x in s]
        i = bisect.bisect_left(stamps, wall_ns)
        if i <= 0 or i >= len(s):
            near = s[0] if i <= 0 else s[-1]
            return {k: near[k] for k in ("x", "y", "depth", "yaw", "altitude")}
        a, b = s[i - 1], s[i]
        f = (wall_ns - a["wall_ns"]) / max(1, b["wall_ns"] - a["wall_ns"])
        out = {k: a[k] + f * (b[k] - a[k]) for k in ("x", "y", "depth", "altitude")}
        dyaw = math.remainder(b["yaw"] - a["yaw"], 2 * math.pi)
        out["yaw"] = a["yaw"] + f * dyaw
        return out

    def first(self, predicate: Callable[[dict[str, Any]], bool], after_ns: int = 0) -> dict[str, Any] | None:
        return next((s for s in self.samples() if s["wall_ns"] >= after_ns and predicate(s)), None)


# ============================================================================================ probe
@dataclass
class Status:
    wall_ns: int  # when the probe received it
    level: int
    message: str
    values: dict[str, str]
    stamp_ns: int = 0  # the report's own stamp (its node's clock when it published it)


@dataclass
class Records:
    odom: list[tuple[int, tuple[float, float, float], float]] = field(default_factory=list)  # (stamp, xyz, yaw)
    diagnostics: dict[str, list[Status]] = field(default_factory=dict)
    # (wall_ns received, active, reason, the message's own stamp [ns]: when the monitor decided)
    aborts: list[tuple[int, bool, str, int]] = field(default_factory=list)
    plans: list[tuple[int, str, list[tuple[float, float, float]]]] = field(default_factory=list)
    # (wall_ns received, rpm 1, rpm 2, the command's own stamp [ns]: its publisher's clock when it computed it)
    rpms: list[tuple[int, int, int, int]] = field(default_factory=list)
    buoyancy: list[tuple[int, float]] = field(default_factory=list)


class Probe(SpunNode):
    """An rclpy node of the test in its own context and domain, spun by a thread."""

    def __init__(self, domain: int) -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import PoseStamped
        from nav_msgs.msg import Path as PathMsg
        from sam_msgs.msg import Abort, HeadingStamped, PercentStamped, ThrusterRPMs
        from tf2_msgs.msg import TFMessage

        from sam_runtime.node_support import qos_profile
        from sam_runtime.tf_buffer import TfBuffer

        super().__init__("scenario_probe", domain)
        self.tf = TfBuffer(cache_time_s=30.0)
        self.rec = Records()
        self._lock = threading.Lock()
        reliable, latched = qos_profile("reliable", "volatile", 100), qos_profile("reliable", "transient_local", 1)
        n = self.node
        self._subs = [
            n.create_subscription(TFMessage, "/tf", lambda m: self._on_tf(m, False), reliable),
            n.create_subscription(TFMessage, "/tf_static", lambda m: self._on_tf(m, True), latched),
            n.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, qos_profile("reliable", "volatile",
                                                                                                 200)),
            n.create_subscription(Abort, "/abort", self._on_abort, latched),
            n.create_subscription(PathMsg, "/global_plan", self._on_plan, reliable),
            n.create_subscription(ThrusterRPMs, "/thruster_rpms", self._on_rpms, reliable),
            n.create_subscription(PercentStamped, "/buoyancy_piston_position",
                                  lambda m: self.rec.buoyancy.append((time.time_ns(), m.percent)), reliable),
        ]
        self.goal_pub = n.create_publisher(PoseStamped, "/nav_goal", qos_profile("reliable", "volatile", 10))
        self.heading_pub = n.create_publisher(HeadingStamped, "/nav_heading", qos_profile("reliable", "volatile", 10))
        self.plan_pub = n.create_publisher(PathMsg, "/global_plan", qos_profile("reliable", "volatile", 10))
        self._clients: dict[str, Any] = {}
        self.start_spinning("probe")

    # ---------------------------------------------------------------------------------- callbacks
    def _on_tf(self, msg: Any, static: bool) -> None:
        from sam_runtime.node_support import stamp_to_ns
        from sam_runtime.physics.geo import euler_from_quaternion

        for ts in msg.transforms:
            t, r = ts.transform.translation, ts.transform.rotation
            stamp = stamp_to_ns(ts.header.stamp)
            self.tf.set_transform(ts.header.frame_id, ts.child_frame_id, stamp, (t.x, t.y, t.z),
                                  (r.x, r.y, r.z, r.w), static=static)
            if (ts.header.frame_id, ts.child_frame_id) == ("odom", "base_link"):
                yaw = euler_from_quaternion((r.x, r.y, r.z, r.w))[2]
                self.rec.odom.append((stamp, (t.x, t.y, t.z), yaw))

    def _on_diag(self, arr: Any) -> None:
        from sam_runtime.node_support import stamp_to_ns

        now, stamp = time.time_ns(), stamp_to_ns(arr.header.stamp)
        for s in arr.status:
            level = s.level[0] if isinstance(s.level, bytes) else int(s.level)
            self.rec.diagnostics.setdefault(s.name, []).append(
                Status(now, level, s.message, {kv.key: kv.value for kv in s.values}, stamp))

    def _on_abort(self, msg: Any) -> None:
        from sam_runtime.node_support import stamp_to_ns

        self.rec.aborts.append((time.time_ns(), bool(msg.active), msg.reason, stamp_to_ns(msg.header.stamp)))

    def _on_plan(self, msg: Any) -> None:
        poses = [(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in msg.poses]
        self.rec.plans.append((time.time_ns(), msg.header.frame_id, poses))

    def _on_rpms(self, msg: Any) -> None:
        from sam_runtime.node_support import stamp_to_ns

        self.rec.rpms.append((time.time_ns(), msg.thruster_1_rpm, msg.thruster_2_rpm, stamp_to_ns(msg.header.stamp)))

    # ---------------------------------------------------------------------------------- reading
    def status(self, name: str) -> Status | None:
        history = self.rec.diagnostics.get(name)
        return history[-1] if history else None

    def world_pose(self, max_age_s: float = 3.0) -> Any:
        from sam_runtime.tf_buffer import TfError

        try:
            return self.tf.lookup("world", "base_link", now_ns=time.time_ns(), max_age_s=max_age_s)
        except TfError:
            return None

    def world_origin_in_sim(self, gps_origin: Sequence[float]) -> tuple[float, float]:
        """Where world's origin (SLAM's first fix, from its status) lies in the simulator's frame."""
        from sam_runtime.physics.geo import local_from_latlon

        slam = wait_for(lambda: (s := self.status("slam")) and "origin_lat" in s.values and s, 30, "SLAM's origin")
        return local_from_latlon(float(slam.values["origin_lat"]), float(slam.values["origin_lon"]), *gps_origin)

    # ---------------------------------------------------------------------------------- acting
    def wait_subscribed(self, publisher: Any, timeout: float = 20.0) -> None:
        """Until a subscription of another node matched the publisher (this probe's own subscription to the topic,
        e.g. /global_plan, matches it too and does not count)."""
        own = sum(1 for sub in self._subs if sub.topic_name == publisher.topic_name)
        wait_for(lambda: publisher.get_subscription_count() > own, timeout, f"a subscriber on {publisher.topic_name}")

    def send_goal(self, x: float, y: float, z: float, frame: str = "world") -> int:
        from geometry_msgs.msg import PoseStamped

        self.wait_subscribed(self.goal_pub)
        msg = PoseStamped()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = frame
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = x, y, z
        msg.pose.orientation.w = 1.0
        self.goal_pub.publish(msg)
        return time.time_ns()

    def send_heading(self, heading: float, z: float, frame: str = "world") -> int:
        from sam_msgs.msg import HeadingStamped

        self.wait_subscribed(self.heading_pub)
        msg = HeadingStamped(heading=heading, z=z)
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = frame
        self.heading_pub.publish(msg)
        return time.time_ns()

    def _plan(self, poses: Sequence[tuple[float, float, float]], frame: str) -> tuple[Any, int]:
        from geometry_msgs.msg import PoseStamped
        from nav_msgs.msg import Path as PathMsg

        stamp = self.node.get_clock().now()
        path = PathMsg()
        path.header.stamp, path.header.frame_id = stamp.to_msg(), frame
        for x, y, z in poses:
            p = PoseStamped()
            p.header = path.header
            p.pose.position.x, p.pose.position.y, p.pose.position.z = x, y, z
            p.pose.orientation.w = 1.0
            path.poses.append(p)
        return path, stamp.nanoseconds

    def send_plan(self, poses: Sequence[tuple[float, float, float]], frame: str = "world") -> int:
        """A plan stamped now; returns the stamp [ns]."""
        self.wait_subscribed(self.plan_pub)
        path, stamp = self._plan(poses, frame)
        self.plan_pub.publish(path)
        return stamp

    def plans_counted(self, node: str = "controller") -> int:
        """How many plans ``node`` has counted (its ``plans`` value on /diagnostics; 0 before it reported one)."""
        return max((int(st.values.get("plans", 0)) for st in self.rec.diagnostics.get(node, [])), default=0)

    def deliver_plan(self, poses: Sequence[tuple[float, float, float]], frame: str = "world", *,
                     within_s: float, node: str = "controller") -> tuple[int, int]:
        """A plan stamped now, published until ``node`` counts it on /diagnostics; returns (stamp [ns], copies).

        A publication is delivered only to subscriptions matched both ways: the probe's side matching the node's
        subscription does not show that the node's side has matched the probe's publisher yet (discovery runs
        each way on its own; volatile data sent before is not resent). So the same message (same stamp: the plan's
        age does not change) goes again whenever a report of the node that came after the last copy does not count
        it yet. The wait is bounded by ``within_s`` after the stamp (a plan's timeout: undelivered by then, it could
        not be followed anyway), by the node's own clock: its reports' stamps."""
        wait_for(lambda: self.status(node), 30, f"a first report of {node} on /diagnostics")  # 1 Hz at least
        before = self.plans_counted(node)
        self.wait_subscribed(self.plan_pub)
        path, stamp = self._plan(poses, frame)
        end_ns = stamp + int(within_s * 1e9)
        copies = 0
        while True:
            self.plan_pub.publish(path)
            copies += 1
            published = time.time_ns()
            report = wait_for(lambda published=published: next(
                (st for st in reversed(self.rec.diagnostics.get(node, [])) if st.stamp_ns > published), None),
                30, f"a report of {node} after the plan")  # reported every second (STATUS_PERIOD_S)
            if self.plans_counted(node) > before:
                return stamp, copies
            assert report.stamp_ns <= end_ns, (
                f"{node} did not count a plan sent {copies} times within {within_s:g} s of its stamp: "
                f"{report.message} {report.values}")

    def set_parameter(self, node: str, name: str, value: Any, timeout: float = 10.0) -> tuple[bool, str]:
        """Through /<node>/set_parameters (rcl_interfaces/SetParameters): (successful, reason)."""
        from rcl_interfaces.srv import SetParameters
        from rclpy.parameter import Parameter

        client = self._clients.get(node)
        if client is None:
            client = self._clients[node] = self.node.create_client(SetParameters, f"/{node}/set_parameters")
        wait_for(client.service_is_ready, timeout, f"the service /{node}/set_parameters")
        future = client.call_async(SetParameters.Request(parameters=[Parameter(name, value=value)
                                                                     .to_parameter_msg()]))
        wait_for(future.done, timeout, f"the answer of /{node}/set_parameters")
        result = future.result().results[0]
        return bool(result.successful), str(result.reason)


# ============================================================================================ the stack
@dataclass
class Stack:
    gen: Any
    dir: Path
    procs: dict[str, Proc]
    probe: Probe
    truth: Truth
    gps_origin: tuple[float, float]
    started_ns: int

    def logs(self) -> str:
        return "\n".join(f"--- {name} (exit {p.proc.poll()}):\n{p.stderr_tail(25)}" for name, p in self.procs.items())

    def world_to_sim(self, x: float, y: float) -> tuple[float, float]:
        ox, oy = self.probe.world_origin_in_sim(self.gps_origin)
        return x + ox, y + oy

    def check_alive(self) -> None:
        dead = {n: p.proc.poll() for n, p in self.procs.items() if p.proc.poll() is not None}
        assert not dead, f"processes ended: {dead}\n{self.logs()}"


@contextmanager
def stack(tmp: Path, offset: int, *, sim_args: Sequence[str] = (), node_args: Sequence[str] = (),
          truth_rate: float = 10.0, gps_origin: tuple[float, float] = (59.35, 18.07)) -> Iterator[Stack]:
    """Start sim, bridge and node host; yield once world -> base_link is known; stop everything after."""
    gen = generated_or_skip()
    prefix = ros_prefix_for(gen)
    if prefix != Path(sys.prefix).absolute():
        pytest.skip("the probe runs in the test process and needs the generated ROS packages in this environment "
                    "(sam-codegen ros-install)")
    domain = domain_id(offset)
    from sam_runtime.cli_support import PARENT_ENV_VAR

    # The children end with this process however it ends (sam_runtime.cli_support.stay_with_parent).
    env = child_env(prefix, domain, {PARENT_ENV_VAR: str(os.getpid())})
    truth_path = tmp / "truth.jsonl"
    common = ["--generated", str(gen.root), "--transport", "udp", "--iface", "127.0.0.1"]
    with ExitStack() as stop:
        stop.enter_context(cyphal_udp_lock())
        procs: dict[str, Proc] = {}

        def stop_all() -> None:
            for p in reversed(list(procs.values())):
                p.stop()

        stop.callback(stop_all)
        procs["sim"] = Proc("sim", runtime_cmd("sim", *common, "--truth-file", str(truth_path), "--truth-rate",
                                               str(truth_rate), "--gps-origin", f"{gps_origin[0]},{gps_origin[1]}",
                                               *sim_args), env, tmp)
        procs["bridge"] = Proc("bridge", runtime_cmd("bridge", *common), env, tmp)
        procs["nodes"] = Proc("nodes", runtime_cmd("nodes", "--generated", str(gen.root), *node_args), env, tmp)
        for name, prefix_line in (("sim", "READY sim"), ("bridge", "READY bridge"), ("nodes", "READY nodes")):
            procs[name].wait_line(prefix_line, START_TIMEOUT_S)
        probe = Probe(int(domain))
        stop.callback(probe.close)
        s = Stack(gen, tmp, procs, probe, Truth(truth_path), gps_origin, time.time_ns())
        try:
            wait_for(lambda: probe.world_pose() is not None, WORLD_TIMEOUT_S, "world -> base_link")
        except AssertionError as ex:
            raise AssertionError(f"{ex}\n{s.logs()}") from None
        yield s
        s.check_alive()
