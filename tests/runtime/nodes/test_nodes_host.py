"""The node host (``sam-codegen nodes``, sam_runtime.nodes.host): which nodes it runs, its refusals, its clean stop,
and that nothing a node does ends it; the controller's stop on a stale transform, in process.

The in-process checks need the generated ROS packages in this environment (``sam-codegen ros-install``, as nox
does); the command-line checks run the host as a child process.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy")

from helpers.runtime_support import Proc, child_env, domain_id, generated_or_skip, ros_prefix_for, runtime_cmd
from helpers.spec_build import generated_spec

from sam_runtime.nodes.host import HostConfigError, plan_host

pytestmark = [pytest.mark.ros]


def _nodes(*args: str, env: dict[str, str] | None = None, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run(runtime_cmd("nodes", *args), capture_output=True, text=True, timeout=timeout, env=env)



# ============================================================================================ what runs
def test_the_plan_of_the_sam_spec_and_its_refusals() -> None:
    tables = generated_or_skip().tables()
    everything = [n.name for n in tables.NODES]
    assert plan_host(tables).run == tuple(everything) and plan_host(tables).missing == ()
    assert plan_host(tables, ["controller", "slam"]).run == ("slam", "controller")  # the spec's order
    with pytest.raises(HostConfigError, match=r"--only: no node pilot in the spec \(its nodes: dead_reckoning, "):
        plan_host(tables, ["pilot"])


def test_a_spec_without_implementations_says_so_and_exits_cleanly() -> None:
    """The boat spec declares nodes, none of which has an implementation here (implementations belong to the SAM
    spec's generated interface)."""
    generated = generated_spec("boat")
    proc = _nodes("--generated", str(generated))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == ("sam-nodes: no implementation for node(s) localizer, navigator, helm, operator of the "
                           "spec; nothing to run\n")


@pytest.mark.parametrize(("args", "code", "message"), [
    (["--only", "pilot"], 2, "sam-nodes: --only: no node pilot in the spec (its nodes: dead_reckoning, slam, "
                             "motion_planner, controller, performance_monitor, mission)\n"),
    (["--only", "controller", "--goal", "1", "2", "-3"], 2,
     "sam-nodes: --goal/--mission need the mission node, which is not run\n"),
    (["--params-file", "/nonexistent/params.yaml"], 1,
     "sam-nodes: parameters file /nonexistent/params.yaml does not exist\n"),
], ids=["unknown-node", "goal-without-mission", "missing-params-file"])
def test_refusals_on_the_command_line(args: list[str], code: int, message: str) -> None:
    gen = generated_or_skip()
    env = child_env(ros_prefix_for(gen), domain_id(80))
    proc = _nodes("--generated", str(gen.root), *args, env=env)
    assert (proc.returncode, proc.stderr) == (code, message)


def test_a_bad_mission_file_is_refused_with_every_problem(tmp_path: Path) -> None:
    gen = generated_or_skip()
    mission = tmp_path / "m.yaml"
    mission.write_text("goals:\n  - {x: 1, y: .nan, z: -2}\n  - {heading_deg: 90, z: -2, speed: 3}\n  - [1, 2]\n")
    proc = _nodes("--generated", str(gen.root), "--mission", str(mission))
    assert proc.returncode == 1
    assert proc.stderr == (
        f"sam-nodes: {mission}: goal 1.y: expected a finite number, got nan\n"
        f"{mission}: goal 2: unknown key(s) ['speed'] for a heading goal (allowed: ['duration', 'heading', "
        "'heading_deg', 'z'])\n"
        f"{mission}: goal 3: expected a mapping such as {{x: 10, y: 0, z: -3}}, got [1, 2]\n")


def test_parameters_breaking_a_rule_stop_the_start_with_the_rule(tmp_path: Path) -> None:
    gen = generated_or_skip()
    params = tmp_path / "p.yaml"
    params.write_text("/**:\n  ros__parameters:\n    critical_depth: 10.0\n")  # safe_depth stays 50
    env = child_env(ros_prefix_for(gen), domain_id(81))
    proc = _nodes("--generated", str(gen.root), "--params-file", str(params), "--only", "performance_monitor",
                  env=env)
    assert proc.returncode == 1
    assert proc.stderr.startswith("sam-nodes: node performance_monitor cannot start: ParameterConfigError: the "
                                  "initial parameters of performance_monitor breaks parameter rule "
                                  "'critical_depth > safe_depth'"), proc.stderr


@pytest.mark.slow
def test_sigterm_stops_the_host_cleanly(tmp_path: Path) -> None:
    gen = generated_or_skip()
    env = child_env(ros_prefix_for(gen), domain_id(82))
    p = Proc("nodes", runtime_cmd("nodes", "--generated", str(gen.root)), env, tmp_path)
    try:
        ready = p.wait_line("READY nodes", 60)
        assert ready.startswith("READY nodes dead_reckoning,slam,motion_planner,controller,performance_monitor,"
                                "mission params=")
        p.proc.send_signal(signal.SIGTERM)
        assert p.wait(20) == 0, p.stderr_tail()
        p.wait_line("DONE nodes errors=0", 5)
    finally:
        p.stop()
    assert "Traceback" not in p.log.read_text()


# ============================================================================================ in process
@pytest.fixture
def host_of() -> Iterator[Callable[..., Any]]:
    """NodeHost(s) in this process (the generated ROS packages must be importable here)."""
    gen = generated_or_skip()
    if ros_prefix_for(gen) != Path(sys.prefix).absolute():
        pytest.skip("needs the generated ROS packages in this environment (sam-codegen ros-install)")
    from sam_runtime.nodes.host import NodeHost

    hosts: list[Any] = []

    def make(*only: str, **kwargs: Any) -> Any:
        host = NodeHost(gen, plan_host(gen.tables(), list(only)), domain_id=int(domain_id(83 + len(hosts))),
                        **kwargs)
        hosts.append(host)
        return host

    yield make
    for h in hosts:
        h.close()


def _spin_until(host: Any, done: Callable[[], Any], timeout: float, what: str) -> Any:
    deadline = time.monotonic() + timeout
    while True:
        value = done()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"not within {timeout} s: {what}")
        host.executor.spin_once(timeout_sec=0.02)


def test_a_timer_that_raises_is_counted_and_the_host_goes_on(host_of: Callable[..., Any]) -> None:
    host = host_of("controller")
    controller = host.nodes["controller"]

    def broken(*_args: Any) -> None:
        raise RuntimeError("a bug in the control law")

    controller.law.step = broken
    support = controller._gen_support
    _spin_until(host, lambda: support.counters.get("errors.control", 0) >= 3, 5, "three failed control steps")
    status = support.status()
    assert status.level == bytes([2]) and "control raised RuntimeError: a bug in the control law" in status.message
    assert host.errors == 0  # guarded where it happened: nothing reached the executor


def test_the_controller_stops_when_the_dead_reckoning_goes_stale(host_of: Callable[..., Any]) -> None:
    """world -> odom and odom -> base_link from a test node, a plan: the controller drives; then odom -> base_link
    stops: zero RPM within ODOM_MAX_AGE_S and one control period, status ERROR (a pose lost, not the start-up)."""
    from nav_msgs.msg import Path as PathMsg
    from rclpy.node import Node
    from sam_msgs.msg import ThrusterRPMs
    from tf2_msgs.msg import TFMessage

    from sam_runtime.node_support import publish_transform, qos_profile
    from sam_runtime.nodes.controller import CONTROL_HZ, ODOM_MAX_AGE_S

    host = host_of("controller")
    helper = Node("tf_and_plan", context=host.ctx)
    host.executor.add_node(helper)
    tf = helper.create_publisher(TFMessage, "/tf", qos_profile("reliable", "volatile", 100))
    plan = helper.create_publisher(PathMsg, "/global_plan", qos_profile("reliable", "volatile", 10))
    rpms: list[tuple[float, int]] = []
    helper.create_subscription(ThrusterRPMs, "/thruster_rpms", lambda m: rpms.append((time.monotonic(),
                                                                                      m.thruster_1_rpm)),
                               qos_profile("reliable", "volatile", 10))
    feeding = [True]

    def feed() -> None:
        now = helper.get_clock().now()
        publish_transform(tf, "world", "odom", now, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
        if feeding[0]:
            publish_transform(tf, "odom", "base_link", now, (0.0, 0.0, -1.0), (0.0, 0.0, 0.0, 1.0))

    helper.create_timer(0.04, feed)
    _spin_until(host, lambda: plan.get_subscription_count() > 0, 10, "the controller subscribing")
    msg = PathMsg()
    msg.header.frame_id = "world"
    msg.header.stamp = helper.get_clock().now().to_msg()
    from geometry_msgs.msg import PoseStamped

    for x in range(0, 40, 2):
        ps = PoseStamped()
        ps.header = msg.header
        ps.pose.position.x, ps.pose.position.z = float(x), -1.0
        msg.poses.append(ps)
    plan.publish(msg)
    _spin_until(host, lambda: rpms and rpms[-1][1] > 0, 10, "the controller driving")
    feeding[0] = False
    lost = time.monotonic()
    stop = _spin_until(host, lambda: next((t for t, r in rpms if t > lost and r == 0), None), 5, "zero RPM")
    assert stop - lost < ODOM_MAX_AGE_S + 2.0 / CONTROL_HZ + 0.5
    status = host.nodes["controller"]._gen_support.status()
    assert status.level == bytes([2]) and status.message == "stopped: no pose (world -> base_link stale)"
    host.executor.remove_node(helper)
    helper.destroy_node()
