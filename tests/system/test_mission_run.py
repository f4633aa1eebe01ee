"""The main job flies the demo mission with the hosted nodes (`sam-codegen run`, the README's first command), shows
it in its view, and no demo sweep competes with the nodes; its node host ends with it however it ends."""

from __future__ import annotations

import json
import os
import re
import signal
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

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
from helpers.user_project import start_time, wait_gone

from sam_runtime.cli_support import ORPHAN_GRACE_S, PARENT_POLL_S

pytestmark = [pytest.mark.ros, pytest.mark.slow]

HEADER = re.compile(r"sim pid (\d+)\s+bridge pid (\d+)\s+nodes pid (\d+)")


def _run_cmd(gen: Any, prefix: Path, log_dir: Path, *extra: str) -> list[str]:
    cmd = runtime_cmd("run", "--no-build", "--plain", "--generated", str(gen.root), "--log-dir", str(log_dir), *extra)
    return cmd + ([] if prefix == Path(sys.prefix).absolute() else ["--ros-prefix", str(prefix)])


def test_the_main_job_flies_the_demo_mission(tmp_path: Path) -> None:
    gen = generated_or_skip()
    prefix = ros_prefix_for(gen)
    env = child_env(prefix, domain_id(90))
    with cyphal_udp_lock():
        p = Proc("run", _run_cmd(gen, prefix, tmp_path), env, tmp_path)
        try:
            # Dive to 3 m, 15 m east, to (30, 15), up: about 50 s at 1.25 m/s, after the start.
            poll_until(lambda: any("mission complete (3 goal(s))" in ln for ln in p.lines), 180,
                       "the demo mission to complete", interval=0.5)
            os.kill(p.proc.pid, signal.SIGINT)
            assert p.wait(30) == 0, p.stderr_tail()
        finally:
            p.stop()
    out = p.lines
    final = out[next(i for i, ln in enumerate(out) if ln.startswith("final (SIGINT)")):]
    text = "\n".join(final)
    nodes = {ln.split()[0]: ln.split()[1] for ln in final if ln.startswith("  ") and len(ln.split()) > 1
             and ln.split()[0] in ("dead_reckoning", "slam", "motion_planner", "controller", "performance_monitor",
                                   "mission")}
    assert nodes == dict.fromkeys(("dead_reckoning", "slam", "motion_planner", "controller", "performance_monitor",
                                   "mission"), "OK"), text
    assert "mission complete (3 goal(s))" in text and "ABORT          clear" in text, text
    assert re.search(r"PLAN +\d+ poses, [\d.]+ m, target depth 0\.00 m, clamped: no", text), text
    rows = {ln.split()[0]: ln.split() for ln in final if ln.startswith("/")}
    for topic in ("/thruster_rpms", "/thruster_angles", "/buoyancy_piston_position"):
        assert int(rows[topic][4]) > 0 and int(rows[topic][5]) == 0, rows[topic]  # COUNT, DROPS
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert truth["max_depth"] > 2.5 and truth["depth"] < 0.3 + 0.05, truth  # it dove, and came back up
    assert truth["floor_contacts"] == 0
    logs = {f.name: f.read_text(errors="replace") for f in tmp_path.glob("*.log")}
    assert set(logs) == {"sim.log", "bridge.log", "nodes.log"}
    assert "Traceback" not in "".join(logs.values()) + p.stderr_tail(200), logs
    assert "goal 3/3 reached" in logs["nodes.log"]


def test_the_node_host_ends_with_the_main_job(tmp_path: Path) -> None:
    gen = generated_or_skip()
    prefix = ros_prefix_for(gen)
    env = child_env(prefix, domain_id(91))
    with cyphal_udp_lock():
        p = Proc("run", _run_cmd(gen, prefix, tmp_path, "--duration", "600"), env, tmp_path)
        children: dict[int, int] = {}
        try:
            header = poll_until(lambda: next((m for ln in p.lines if (m := HEADER.search(ln))), None), 120,
                                "the main job's table with its three children")
            children = {int(pid): start_time(int(pid)) or 0 for pid in header.groups()}
            poll_until(lambda: "READY nodes" in (tmp_path / "nodes.log").read_text(), 60, "the node host")
            os.kill(p.proc.pid, signal.SIGKILL)
            p.wait(10)
            left = wait_gone(children, PARENT_POLL_S + ORPHAN_GRACE_S + 10.0)
            assert not left, f"still running after the main job was killed: {left}"
        finally:
            for pid, started in children.items():
                if started and start_time(pid) == started:
                    os.kill(pid, signal.SIGKILL)
            p.stop()


def test_no_demo_sweep_on_the_topics_of_hosted_nodes(monkeypatch: pytest.MonkeyPatch) -> None:
    """The monitor's demo publisher stays for specs without node implementations; with SAM's nodes hosted it
    publishes on none of their topics (here: all five command topics)."""
    gen = generated_or_skip()
    if ros_prefix_for(gen) != Path(sys.prefix).absolute():
        pytest.skip("needs the generated ROS packages in this environment")
    monkeypatch.setenv("ROS_DOMAIN_ID", domain_id(92))
    from sam_runtime.main_job.job import LiveView
    from sam_runtime.nodes import implemented

    tables = gen.tables()
    commands = sorted({m.topic.name for m in tables.MAPPINGS if m.direction == "ros_to_uavcan"})

    def demo_topics(**kwargs: Any) -> tuple[list[str], bool]:
        monitor = LiveView(tables, gen, demo_commands=True, **kwargs)  # one at a time: one node name
        try:
            return sorted(name for *_, name in monitor._demo), monitor.view is not None
        finally:
            monitor.close()

    assert demo_topics() == (commands, False)
    assert demo_topics(hosted=implemented(tables)) == ([], True)
    assert demo_topics(hosted=["performance_monitor"]) == (
        ["/ballast_angles", "/longitudinal_weight_position", "/thruster_angles"], True)
