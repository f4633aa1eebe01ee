"""The bench's CPU section (bench/cpu.py, issue 26): the regression guard's verdicts, the splice that updates
results.md's CPU section alone, the /proc readings and the profile summary's attribution. Pure functions on made-up
figures; the measurement itself runs in `nox -s bench`, not in the tests."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from bench.cpu import guard, guard_lines
from bench.cpu_diag import Counters, counters_of
from bench.cpu_profile import subsystem, summarise
from bench.cpu_rig import cpu_s, threads
from bench.report_cpu import HEADING, splice


def _cpu(bridge: list[float], idle: list[float], threads_: int = 35) -> dict[str, Any]:
    def stat(v: list[float]) -> dict[str, Any]:
        return {"median": sorted(v)[len(v) // 2], "min": min(v), "max": max(v), "values": v}

    return {"code": {"commit": "abc1234"}, "machine": {"date": "2026-11-27"}, "protocols": {"cyphal": {"figures": {
        "nominal": {"bridge_percent": stat(bridge), "bridge_threads": stat([threads_] * len(bridge))},
        "idle": {"bridge_percent": stat(idle)}}}}}


def _verdicts(g: dict[str, Any]) -> dict[tuple[str, str], str]:
    return {(r["condition"], r["figure"]): r["verdict"] for r in g["rows"]}


def test_first_run_says_there_is_no_previous_figure() -> None:
    g = guard(None, _cpu([19.0, 20.0, 21.0], [3.4, 3.5, 3.6]), "none committed")
    assert g["previous"] is None and g["worse"] == 0
    assert set(_verdicts(g).values()) == {"no previous figure"}
    assert "no previous figure" in guard_lines(g)[0]


def test_worse_beyond_the_noise_is_flagged_and_named() -> None:
    before = _cpu([19.0, 20.0, 21.0], [3.4, 3.5, 3.6])
    g = guard(before, _cpu([24.0, 25.0, 26.0], [3.5, 3.6, 3.7], threads_=36), "HEAD")
    v = _verdicts(g)
    assert v[("nominal", "bridge_percent")] == "worse"  # +5 pts against a 2-pt spread
    assert v[("nominal", "bridge_threads")] == "worse"  # one thread more
    assert v[("idle", "bridge_percent")] == "same"  # +0.1 within the 0.2 spread
    assert g["worse"] == 2
    lines = guard_lines(g)
    assert lines[0].endswith("WORSE: 2 figure(s) beyond their noise.")
    assert any(ln.startswith("- WORSE: cyphal bridge CPU % at nominal: 20 -> 25") for ln in lines)


def test_within_the_noise_is_same_and_a_drop_is_better() -> None:
    before = _cpu([19.0, 20.0, 21.0], [3.4, 3.5, 3.6])
    g = guard(before, _cpu([1.5, 1.6, 1.7], [3.5, 3.5, 3.5]), "HEAD")
    v = _verdicts(g)
    assert v[("nominal", "bridge_percent")] == "better"
    assert v[("idle", "bridge_percent")] == "same"
    assert g["worse"] == 0 and g["verdict"] == "no figure worse beyond its noise"


def test_splice_replaces_only_the_cpu_section() -> None:
    md = "# Benchmark results\n\n## 5. Bridge on DroneCAN\n\nkept\n\n## What limits the figures\n\n- a note\n"
    once = splice(md, [HEADING, "", "first"])
    assert once.index(HEADING) < once.index("## What limits the figures")
    assert once.replace(f"{HEADING}\n\nfirst\n\n", "") == md
    twice = splice(once, [HEADING, "", "second"])
    assert "first" not in twice and twice.replace("second", "first") == once
    at_end = splice("# Benchmark results\n\n## 1. Generator\n\nx\n", [HEADING, "", "only"])
    assert at_end.endswith(f"x\n\n{HEADING}\n\nonly\n")


def test_proc_readings_of_this_process() -> None:
    assert threads(os.getpid()) >= 1
    t0 = cpu_s(os.getpid())
    x = 0
    while cpu_s(os.getpid()) - t0 < 0.05:  # burn CPU until the kernel's tick counters show it
        x += 1
    assert cpu_s(os.getpid()) >= t0 + 0.05


def test_profile_attribution(tmp_path: Path) -> None:
    base = "Thread.run (threading.py:982)"
    assert subsystem([base, "imu_to_ros (sam_bridge/codec.py:10)", "pack (struct.py:1)"]).startswith("codec")
    assert subsystem([base, "Publisher.publish (rclpy/publisher.py:70)"]) == "rclpy publish"
    assert subsystem([base, "UDPFrame.parse (pycyphal/transport/udp/_frame.py:134)"]).startswith("transport receive")
    assert subsystem([base, "mystery (nowhere.py:1)"]) == "other"
    # the runtime from the checkout (an editable install: runtime/...) as well as installed (sam_runtime/...)
    for root in ("runtime", "sam_runtime", "/work/p/runtime"):
        assert subsystem([base, f"Inbound._one ({root}/bridge/inbound.py:236)"]) == "bridge inbound / outbound"
        assert subsystem([base, f"SubjectPort.feed ({root}/cyphal_io/udp_receiver.py:250)"]).startswith("transport")
        assert subsystem([base, f"statuses_cdr ({root}/bridge/diagnostics.py:77)"]) == "diagnostics"
    prof = tmp_path / "profile.txt"
    prof.write_text("thread (1): MainThread;" + base + ";Publisher.publish (rclpy/publisher.py:70) 3\n"
                    "thread (2): PromiscuousUDPInputSession(x);" + base
                    + ";UDPFrame.parse (pycyphal/transport/udp/_frame.py:134) 1\n")
    s = summarise(prof, seconds=1.0, rate_hz=100)
    assert s["samples"] == 4 and s["cpu_percent_est"] == 4.0 and s["threads_seen"] == 2
    assert s["by_subsystem_percent"]["rclpy publish"] == 75.0
    assert s["by_thread_percent"]["pycyphal input-session reader threads"] == 25.0


def test_counters_from_the_bridges_diagnostics() -> None:
    from types import SimpleNamespace as NS

    def status(**values: object) -> NS:
        return NS(values=[NS(key=k, value=str(v)) for k, v in values.items()])

    msg = NS(status=[status(uptime_s=12.5, link_state="up", dropped_total=1),
                     status(direction="uavcan_to_ros", published=100, dropped=1),
                     status(direction="ros_to_uavcan", published=7, dropped=0),
                     status(heartbeats=3)])  # a device's status: not counted
    assert counters_of(msg) == Counters(published=107, dropped=1, uptime_s=12.5, mappings=2)
    assert counters_of(NS(status=[status(heartbeats=3)])) is None  # another node's /diagnostics


def test_a_bridge_figure_that_moved_with_the_raw_receiver_points_at_the_machine() -> None:
    before, now = _cpu([19.0, 20.0, 21.0], [3.5, 3.5, 3.5]), _cpu([24.0, 25.0, 26.0], [3.5, 3.5, 3.5])
    for cpu, raw in ((before, [10.0, 10.0, 10.0]), (now, [13.0, 13.0, 13.0])):
        cpu["protocols"]["cyphal"]["figures"]["nominal"]["raw_percent"] = {
            "median": raw[1], "min": min(raw), "max": max(raw), "values": raw}
    lines = guard_lines(guard(before, now, "HEAD"))
    line = next(ln for ln in lines if "bridge CPU % at nominal" in ln)
    assert line.startswith("- WORSE") and "the raw receiver moved the same way (worse): the machine?" in line
