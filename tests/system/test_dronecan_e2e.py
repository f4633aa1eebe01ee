"""End to end on DroneCAN across processes: ``sam-sim --layout dronecan`` (every SAM device a dronecan node on a
private loopback bus) -> ``sam-bridge --layout dronecan`` -> a ROS probe process, every DroneCAN UAVCAN->ROS
mapping at its nominal rate for WINDOW_S seconds: every broadcast bridged and received, none lost or dropped.
Then ROS commands from the probe reach the simulated actuators (accepted from the bridge's node id)."""

from __future__ import annotations

import signal
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_support import private_iface
from helpers.ros_probe import listen_cmd
from helpers.runtime_support import (
    Proc,
    child_env,
    domain_id,
    generated_or_skip,
    poll_until,
    read_json,
    ros_prefix_for,
    runtime_cmd,
)

pytestmark = [pytest.mark.ros, pytest.mark.slow]

WINDOW_S = 8.0


def _sent(report: dict[str, Any], m: Any, devices: dict[int, str]) -> int:
    """What the mapping's source devices broadcast of its data type (the sim's report keys v0 ports by type)."""
    key = f"dronecan:{m.data_type.name}"
    return sum(report["devices"][devices[n]]["published"].get(key, 0) for n in m.source_node_ids if n in devices)


def _skipped(report: dict[str, Any], m: Any, devices: dict[int, str]) -> int:
    """The ticks of the mapping's source devices skipped (counted) because their event loop was held up."""
    key = f"dronecan:{m.data_type.name}"
    return sum(report["devices"][devices[n]]["late"].get(key, 0) for n in m.source_node_ids if n in devices)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    gen = generated_or_skip()
    tables = gen.tables()
    if tables.VEHICLE != "sam":
        pytest.skip("written for the SAM spec's dronecan layout")
    d = tmp_path_factory.mktemp("dronecan_e2e")
    env = child_env(ros_prefix_for(gen), domain_id(45), {"SAM_GENERATED_DIR": str(gen.root)})
    iface = private_iface()
    dc = ["--layout", "dronecan", "--dronecan-iface", iface]
    in_maps = [m for m in tables.DRONECAN_MAPPINGS if m.direction == "uavcan_to_ros"]
    topics = sorted({m.topic.name for m in in_maps})
    bridge = Proc("bridge", runtime_cmd("bridge", *dc, "--stats-file", str(d / "bridge.json")), env, d)
    sim = Proc("sim", runtime_cmd("sim", *dc, "--start-file", str(d / "go"), "--duration", str(WINDOW_S),
                                  "--report", str(d / "sim.json")), env, d)
    probe = Proc("probe", listen_cmd(gen.root, topics, d / "probe.json"), env, d)
    try:
        bridge.wait_line("READY", 90)
        sim.wait_line("READY", 90)
        probe.wait_line("READY", 60)

        def ready() -> dict[str, Any] | None:
            s = read_json(d / "bridge.json")
            if not s:
                return None
            subs = all((s["mappings"][m.name].get("ros_subscribers") or 0) > 0 for m in in_maps)
            return s if subs and all(v.get("alive") for v in s["devices"].values()) else None

        poll_until(ready, 30, "the bridge matching the probe and hearing every device")
        (d / "go").touch()
        sim.wait_line("DONE", WINDOW_S + 60)
        assert sim.wait(20) == 0, sim.stderr_tail()
        report = read_json(d / "sim.json")
        devices = {dev["node_id"]: name for name, dev in report["devices"].items()}
        expected = {t: sum(_sent(report, m, devices) for m in in_maps if m.topic.name == t) for t in topics}

        def all_at_probe() -> bool:
            p = read_json(d / "probe.json")
            return bool(p) and all(p["counts"].get(t, 0) >= expected[t] for t in topics)

        try:
            poll_until(all_at_probe, 20, "every broadcast at the probe")
        except AssertionError:
            pass  # compared and reported by the test
        assert probe.stop(signal.SIGTERM) == 0, probe.stderr_tail()
        assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
    finally:
        for p in (probe, bridge, sim):
            p.stop()
    return {"in_maps": in_maps, "topics": topics, "report": report, "devices": devices, "expected": expected,
            "stats": read_json(d / "bridge.json"), "probe": read_json(d / "probe.json"), "dir": Path(d)}


def test_every_dronecan_mapping_at_its_nominal_rate_nothing_lost(run: dict[str, Any]) -> None:
    stats, probe = run["stats"]["mappings"], run["probe"]
    rows = []
    for m in run["in_maps"]:
        sent, skipped = _sent(run["report"], m, run["devices"]), _skipped(run["report"], m, run["devices"])
        st = stats[m.name]
        rows.append(f"{m.topic.name:28} {m.data_type.name:42} nominal {m.rate_hz * WINDOW_S:5.0f} sent {sent:5d} "
                    f"skipped {skipped:4d} bridged {st['published']:5d}")
        # The device kept its schedule: each tick sent, or skipped (counted) when the machine held its loop up.
        assert sent + skipped >= 0.8 * m.rate_hz * WINDOW_S, f"{m.name}: the device fell behind its schedule"
        assert sent > 0, m.name
        assert st["published"] == sent and st["dropped"] == {}, (m.name, sent, st)
    for t in run["topics"]:
        assert probe["counts"][t] == run["expected"][t], (t, probe["counts"][t], run["expected"][t])
    print("\nFIGURES DroneCAN end to end over mcast-lo, 0 lost:\n" + "\n".join(rows))
