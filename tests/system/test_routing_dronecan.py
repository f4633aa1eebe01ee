"""Routing as real bridges do it, across processes on DroneCAN (issue 17 classes 5, 6, 7 and 11), on
tests/specs/seiner.yaml: ``sam-sim`` (its DroneCAN devices on a private ``mcast-lo:`` bus) -> ``sam-bridge
--protocol dronecan`` -> a ROS probe, then an ESC the spec never names (tests/helpers/esc_status_peer.py).

- 11: each simulated ESC is accepted by both esc.Status mappings (``source_node_ids: any``), so it sends both
  esc_index values in turn: every select-routed topic publishes in simulation, and nothing is ``unselected``;
- 7: the esc_index a topic is routed on is also in its messages;
- 6: a node id from dynamic allocation (77) is bridged, routed by esc_index alone; an index no mapping selects
  (from node 78) is counted ``unselected``; nothing is ``unknown_source``;
- 5: three RPM topics and two rudder topics command one broadcast type each (``shares_data_type``): every command
  of every topic is broadcast as its own message, and each device takes the ones with its element.
"""

from __future__ import annotations

import json
import signal
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_support import private_iface
from helpers.ros_probe import listen_cmd, publish_cmd
from helpers.runtime_support import (
    Proc,
    child_env,
    domain_id,
    helper_cmd,
    load_records,
    poll_until,
    read_json,
    runtime_cmd,
)
from helpers.spec_build import generated_spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

WINDOW_S = 6.0
N_COMMANDS = 10
PEER_SELECTED, PEER_UNSELECTED = 20, 5
SIM_DEVICES = "esc_port,esc_stbd,rudder,hook"
IN_TOPICS = ("/esc0/status", "/esc1/status", "/rudder/position")
COMMANDS = {
    "/thrusters/rpm": [{"x": 100.0 + i, "y": 200.0 + i} for i in range(N_COMMANDS)],
    "/legacy/rpm": [{"data": 300 + i} for i in range(N_COMMANDS)],
    "/legacy/stbd_rpm": [{"data": 400 + i} for i in range(N_COMMANDS)],
    "/rudder/angle": [{"data": 0.25} for _ in range(N_COMMANDS)],
    "/legacy/rudder": [{"data": -0.5} for _ in range(N_COMMANDS)],
}


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    gen = generated_spec("seiner")
    d = tmp_path_factory.mktemp("routing_dronecan")
    env = child_env(Path(sys.prefix).absolute(), domain_id(93), {"SAM_GENERATED_DIR": str(gen)})
    iface = private_iface()
    bridge = Proc("bridge", runtime_cmd("bridge", "--protocol", "dronecan", "--dronecan-iface", iface,
                                        "--stats-file", str(d / "bridge.json")), env, d)
    sim = Proc("sim", runtime_cmd("sim", "--devices", SIM_DEVICES, "--dronecan-iface", iface, "--start-file",
                                  str(d / "go"), "--duration", str(WINDOW_S), "--report", str(d / "sim.json")),
               env, d)
    probe = Proc("probe", listen_cmd(gen, IN_TOPICS, d / "probe.json", d / "probe.jsonl", diagnostics=True), env, d)
    (d / "plan.json").write_text(json.dumps({"rate_hz": 20, "topics": COMMANDS}))
    procs = [probe, bridge, sim]
    try:
        bridge.wait_line("READY", 90)
        sim.wait_line("READY", 90)
        probe.wait_line("READY", 60)

        def ready() -> dict[str, Any] | None:
            s = read_json(d / "bridge.json")
            if not s:
                return None
            maps = s["mappings"]
            subs = all((maps[m].get("ros_subscribers") or 0) > 0 for m in ("esc0_status", "esc1_status",
                                                                            "rudder_position"))
            return s if subs and all(v.get("alive") for v in s["devices"].values()) else None

        poll_until(ready, 30, "the bridge matching the probe and hearing every device")
        # The commands first (the devices take commands as soon as their nodes are up), then the broadcasts.
        publisher = Proc("publisher", publish_cmd(gen, d / "plan.json", d / "sent.json"), env, d)
        procs.append(publisher)
        publisher.wait_line("DONE", 60)
        assert publisher.wait(20) == 0, publisher.stderr_tail()
        sent_topics = [m for m in ("thrusters", "legacy_rpm", "legacy_stbd_rpm", "rudder", "legacy_rudder")]

        def commands_out() -> bool:
            s = read_json(d / "bridge.json")
            return bool(s) and all(s["mappings"][m]["published"] == N_COMMANDS for m in sent_topics)

        poll_until(commands_out, 20, "every command broadcast by the bridge")
        (d / "go").touch()
        sim.wait_line("DONE", WINDOW_S + 60)
        assert sim.wait(20) == 0, sim.stderr_tail()
        report = read_json(d / "sim.json")
        sent = sum(report["devices"][n]["published"]["dronecan:uavcan.equipment.esc.Status"]
                   for n in ("esc_port", "esc_stbd"))

        def sim_bridged() -> dict[str, Any] | None:
            s = read_json(d / "bridge.json")
            got = s and s["mappings"]["esc0_status"]["received"] + s["mappings"]["esc1_status"]["received"]
            return s if got and got >= sent else None

        after_sim = poll_until(sim_bridged, 20, "every simulated esc.Status at the bridge")
        for node_id, index, count in ((77, 1, PEER_SELECTED), (78, 9, PEER_UNSELECTED)):
            peer = Proc(f"peer{node_id}", helper_cmd("esc_status_peer.py", "--iface", iface, "--node-id",
                                                     str(node_id), "--wait-for", "100", "--esc-index", str(index),
                                                     "--rpm", "4321", "--count", str(count)), env, d)
            procs.append(peer)
            peer.wait_line("PUBLISHED", 60)
            assert peer.wait(20) == 0, peer.stderr_tail()

        def peers_bridged() -> dict[str, Any] | None:
            s = read_json(d / "bridge.json")
            if not s:
                return None
            m = s["mappings"]
            done = (m["esc1_status"]["published"] >= after_sim["mappings"]["esc1_status"]["published"]
                    + PEER_SELECTED and m["esc0_status"]["dropped"].get("unselected", 0) >= PEER_UNSELECTED)
            return s if done else None

        final = poll_until(peers_bridged, 20, "the peers' esc.Status at the bridge")

        def all_at_probe() -> bool:
            p = read_json(d / "probe.json")
            return bool(p) and all(p["counts"].get(f"/esc{i}/status", 0) >= final["mappings"][f"esc{i}_status"]
                                   ["published"] for i in (0, 1))

        poll_until(all_at_probe, 20, "every esc.Status at the probe")
        assert probe.stop(signal.SIGTERM) == 0, probe.stderr_tail()
        assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
    finally:
        for p in procs:
            p.stop()
    return {"report": report, "after_sim": after_sim, "stats": read_json(d / "bridge.json"),
            "records": load_records(d / "probe.jsonl"), "probe": read_json(d / "probe.json")}


def test_every_select_routed_topic_publishes_in_simulation(run: dict[str, Any]) -> None:
    """Class 11: both ESCs send both esc_index values (both mappings accept both), the rudder its actuator id."""
    report, maps = run["report"], run["after_sim"]["mappings"]
    for name in ("esc0_status", "esc1_status", "rudder_position"):
        assert maps[name]["published"] > 0, (name, maps[name])
        assert maps[name]["dropped"] == {}, (name, maps[name])
    sent = {n: report["devices"][n]["published"]["dronecan:uavcan.equipment.esc.Status"] for n in
            ("esc_port", "esc_stbd")}
    assert maps["esc0_status"]["published"] + maps["esc1_status"]["published"] == sum(sent.values())
    # in turn: each topic gets half of each ESC's broadcasts (one more when a device sent an odd number)
    assert abs(maps["esc0_status"]["published"] - maps["esc1_status"]["published"]) <= 2
    assert maps["rudder_position"]["published"] == report["devices"]["rudder"]["published"][
        "dronecan:uavcan.equipment.actuator.Status"]


def test_the_select_field_is_published_too(run: dict[str, Any]) -> None:
    """Class 7: /escN/status carries the esc_index N it is routed on (y)."""
    for i in (0, 1):
        ys = {r["msg"]["y"] for r in run["records"] if r["topic"] == f"/esc{i}/status"}
        assert ys == {float(i)}, (i, ys)


def test_an_esc_the_spec_never_names_is_bridged_by_its_index(run: dict[str, Any]) -> None:
    """Class 6: node 77 (dynamic node id) on /esc1/status; node 78's index 9 unselected; no unknown_source."""
    before, after = run["after_sim"]["mappings"], run["stats"]["mappings"]
    assert after["esc1_status"]["published"] - before["esc1_status"]["published"] == PEER_SELECTED
    assert after["esc0_status"]["published"] == before["esc0_status"]["published"]
    assert after["esc0_status"]["dropped"] == {"unselected": PEER_UNSELECTED}
    assert after["esc1_status"]["dropped"] == {}
    assert after["esc0_status"]["source_node_ids"] == "any"
    peer = [r for r in run["records"] if r["topic"] == "/esc1/status" and r["msg"]["x"] == 4321.0]
    assert len(peer) == PEER_SELECTED and {r["msg"]["y"] for r in peer} == {1.0}
    assert run["probe"]["counts"]["/esc1/status"] == after["esc1_status"]["published"]
    diagnostics = run["probe"]["diagnostics"]
    status = next(v for k, v in diagnostics.items() if k.endswith("/mapping/esc1_status"))
    assert status["values"]["source_node_ids"] == "any"  # the choice is visible on /diagnostics
    static = next(v for k, v in diagnostics.items() if k.endswith("/mapping/legacy_rpm"))
    assert "destination_node_ids" not in static["values"]


def test_topics_sharing_a_broadcast_type_each_send_their_own(run: dict[str, Any]) -> None:
    """Class 5: [r1, r2], [r] and [c, r] on one RPMCommand, two topics on one rudder item: every command of every
    topic went out as its own broadcast, and each ESC took those with its element (rpm[0] port, rpm[1] starboard:
    the legacy single-thruster topic is not a command for the starboard ESC)."""
    stats, devices = run["stats"]["mappings"], run["report"]["devices"]
    for name in ("thrusters", "legacy_rpm", "legacy_stbd_rpm", "rudder", "legacy_rudder"):
        assert stats[name]["published"] == N_COMMANDS and stats[name]["dropped"] == {}, (name, stats[name])
    rpm = "dronecan:uavcan.equipment.esc.RPMCommand"
    port, stbd = devices["esc_port"]["commands"][rpm], devices["esc_stbd"]["commands"][rpm]
    assert port["accepted"] == 3 * N_COMMANDS and port["not_addressed"] == 0, port
    assert stbd["accepted"] == 2 * N_COMMANDS and stbd["not_addressed"] == N_COMMANDS, stbd
    rudder = devices["rudder"]["commands"]["dronecan:uavcan.equipment.actuator.ArrayCommand"]
    assert rudder["accepted"] == 2 * N_COMMANDS and rudder["rejected"] == 0, rudder
