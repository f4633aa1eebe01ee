"""Issue 17's patterns together, across processes on DroneCAN, with tests/specs/lolo_v0.yaml (an AUV whose firmware
uses all of them): ``sam-sim`` plays the relays (node 40) and two ESCs (50, 51); helper processes play the power
board (tests/helpers/power_board.py: node 30, the spec's sabre.power.ConsumedChargeArray at vendor id 20100, and a
Panic), the leak sensor (tests/helpers/leak_sensor_peer.py: node 41, positions 100 and others) and ESCs with dynamic
node ids (tests/helpers/esc_status_peer.py: 77, 78); ``sam-bridge --protocol dronecan`` on a private ``mcast-lo:``
bus; ROS probes (tests/helpers/ros_probe.py) listen and publish. Each pattern's values are checked where they arrive:

- relays (class 1): std_msgs/Bool false x3, true x3 on /relay/dvl -> the relays' ArrayCommand item 7, command_value
  0.0 x3 then 1.0 x3;
- leak (class 2): actuator.Status positions 100, 0, 100, 99.5, 100 -> /leak true, false, true, false, true;
- consumed charge (classes 4, 8): the board's array at 20100 (15 circuits, then none) -> /power/charges element by
  element, each with the message's header; dronecan's com.hobbywing type at 20100 is not loaded;
- legacy RPM (class 5): /thrusters/rpm ([r1, r2]) and /legacy/rpm ([r]) each broadcast as RPMCommand: the port ESC
  takes both, the starboard one the new topic's only;
- routing (classes 6, 7): esc.Status from any node routed by esc_index (also published as y), node 77's ten on
  /esc1/status, node 78's index 9 counted ``unselected``;
- Panic (class 9): the board's Panic on /panic_in; /panic_out broadcast as Panic to the relays, cut to 7 bytes and
  counted.

The bridge starts on its default wire path, the generated wire codecs: every mapping of this spec has one, the
element mapping (charges) included. Every wait is on a condition (counts the bridge, the
simulator or the probe report), never a fixed sleep.
"""

from __future__ import annotations

import json
import signal
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
from helpers.spec_build import built_spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

BRIDGE_ID, BOARD_ID, RELAYS_ID, LEAK_ID = 100, 30, 40, 41
USEC = 1_700_000_000_250_000  # power_board.py's timestamp
N_RPM = 5
RELAY = [False] * 3 + [True] * 3
LEAK_POSITIONS = [100.0, 0.0, 100.0, 99.5, 100.0]
PEER_SELECTED, PEER_UNSELECTED, PEER_RPM = 10, 3, 4321
IN_TOPICS = ("/leak", "/power/charges", "/esc0/status", "/esc1/status", "/panic_in")
COMMANDS = {
    "/relay/dvl": [{"data": v} for v in RELAY],
    "/thrusters/rpm": [{"x": 1000.0 + i, "y": 2000.0 + i} for i in range(N_RPM)],
    "/legacy/rpm": [{"data": 500 + i} for i in range(N_RPM)],
    "/panic_out": [{"data": "WATER-INGRESS"}],
}
OUT_MAPPINGS = {"relay_dvl": len(RELAY), "thrusters": N_RPM, "legacy_rpm": N_RPM, "panic_out": 1}


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    b = built_spec("lolo_v0")
    gen = str(b.generated)
    d = tmp_path_factory.mktemp("lolo")
    env = child_env(b.prefix, domain_id(57), {"SAM_GENERATED_DIR": gen})
    iface = private_iface()
    bridge = Proc("bridge", runtime_cmd("bridge", "--protocol", "dronecan", "--dronecan-iface", iface,
                                        "--stats-file", str(d / "bridge.json")), env, d)
    sim = Proc("sim", runtime_cmd("sim", "--devices", "relays,esc_port,esc_stbd", "--dronecan-iface", iface,
                                  "--record", str(d / "sim.jsonl"), "--report", str(d / "sim.json")), env, d)
    board = Proc("board", helper_cmd("power_board.py", "--generated", gen, "--iface", iface, "--namespace",
                                     "sabre.power", "--node-id", str(BOARD_ID), "--panic", "FLOOD",
                                     "--start-file", str(d / "go")), env, d)
    listen = Proc("listen", listen_cmd(gen, IN_TOPICS, d / "listen.json", d / "listen.jsonl"), env, d)
    (d / "plan.json").write_text(json.dumps({"rate_hz": 10, "topics": COMMANDS}))
    procs = [listen, board, sim, bridge]
    try:
        bridge.wait_line("READY", 120)
        sim.wait_line("READY", 120)
        board_ready = json.loads(board.wait_line("READY ", 60).split(" ", 1)[1])

        def ready() -> bool:
            s = read_json(d / "bridge.json")
            return bool(s) and all((s["mappings"][m].get("ros_subscribers") or 0) > 0 for m in
                                   ("leak", "charges", "esc0_status", "esc1_status", "panic_in"))

        poll_until(ready, 60, "the bridge matching the probe")
        publish = Proc("publish", publish_cmd(gen, d / "plan.json", d / "publish.json"), env, d)
        procs.append(publish)
        assert publish.wait(90) == 0, publish.stderr_tail()

        def rx(kind: str) -> list[dict[str, Any]]:
            return [r for r in load_records(d / "sim.jsonl") if r["dir"] == "rx" and r["data_type"] == kind
                    and r["source"] == BRIDGE_ID]

        def commands_in() -> bool:
            maps = (read_json(d / "bridge.json") or {}).get("mappings", {})
            return all(maps.get(m, {}).get("published", 0) >= n for m, n in OUT_MAPPINGS.items()) \
                and len(rx("uavcan.equipment.actuator.ArrayCommand")) >= len(RELAY) \
                and len(rx("uavcan.equipment.esc.RPMCommand")) >= 2 * N_RPM \
                and len(rx("uavcan.protocol.Panic")) >= 1

        poll_until(commands_in, 60, "every command broadcast by the bridge and heard by the simulated devices")
        (d / "go").touch()
        board.wait_line("PUBLISHED", 30)
        peers = [Proc("leak", helper_cmd("leak_sensor_peer.py", "--iface", iface, "--node-id", str(LEAK_ID),
                                         "--wait-for", str(BRIDGE_ID), "--actuator-id", "9", "--positions",
                                         ",".join(str(p) for p in LEAK_POSITIONS)), env, d)]
        for node_id, index, count in ((77, 1, PEER_SELECTED), (78, 9, PEER_UNSELECTED)):
            peers.append(Proc(f"esc{node_id}", helper_cmd("esc_status_peer.py", "--iface", iface, "--node-id",
                                                          str(node_id), "--wait-for", str(BRIDGE_ID), "--esc-index",
                                                          str(index), "--rpm", str(PEER_RPM), "--count",
                                                          str(count)), env, d))
        procs += peers
        for peer in peers:
            peer.wait_line("PUBLISHED", 60)
            assert peer.wait(20) == 0, peer.stderr_tail()

        def bridged() -> dict[str, Any] | None:
            s = read_json(d / "bridge.json")
            if not s:
                return None
            m = s["mappings"]
            done = m["leak"]["published"] >= len(LEAK_POSITIONS) and m["charges"]["published"] >= 2 \
                and m["panic_in"]["published"] >= 1 \
                and m["esc0_status"]["dropped"].get("unselected", 0) >= PEER_UNSELECTED
            return s if done else None

        final = poll_until(bridged, 30, "the board's, the leak sensor's and the peers' messages at the bridge")

        def at_probe() -> dict[str, Any] | None:
            counts = (read_json(d / "listen.json") or {}).get("counts", {})
            needed = {"/leak": len(LEAK_POSITIONS), "/power/charges": 2, "/panic_in": 1,
                      "/esc0/status": max(1, final["mappings"]["esc0_status"]["published"]),
                      "/esc1/status": final["mappings"]["esc1_status"]["published"]}
            return counts if all(counts.get(t, 0) >= n for t, n in needed.items()) else None

        poll_until(at_probe, 30, "every bridged message at the probe")
        assert sim.stop(signal.SIGTERM) == 0, sim.stderr_tail()  # its report, written at exit
        assert board.stop(signal.SIGTERM) == 0, board.stderr_tail()
        assert listen.stop(signal.SIGTERM) == 0, listen.stderr_tail()
        assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
        out = {"board_ready": board_ready, "records": load_records(d / "sim.jsonl"),
               "report": read_json(d / "sim.json"), "stats": read_json(d / "bridge.json"),
               "bridge_log": "\n".join(bridge.lines) + "\n" + bridge.stderr_tail(400),
               "got": [json.loads(line) for line in (d / "listen.jsonl").read_text().splitlines()]}
    finally:
        for p in procs:
            p.stop()
    return out


def _got(run: dict[str, Any], topic: str) -> list[Any]:
    return [r["msg"] for r in run["got"] if r["topic"] == topic]


def _from_bridge(run: dict[str, Any], kind: str) -> list[dict[str, Any]]:
    return [r for r in run["records"] if r["dir"] == "rx" and r["data_type"] == kind and r["source"] == BRIDGE_ID]


def test_relay_bool_drives_the_float16_command_value(run: dict[str, Any]) -> None:
    records = _from_bridge(run, "uavcan.equipment.actuator.ArrayCommand")
    assert all(r["accepted"] for r in records)
    assert [r["value"]["commands"] for r in records] == [
        [{"actuator_id": 7, "command_type": 0, "command_value": 1.0 if v else 0.0}] for v in RELAY]
    m = run["stats"]["mappings"]["relay_dvl"]
    assert m["published"] == len(RELAY) and m["dropped"] == {} and m.get("saturated", {}) == {}


def test_leak_predicate_reads_true_at_position_100_only(run: dict[str, Any]) -> None:
    assert [m["data"] for m in _got(run, "/leak")] == [p == 100 for p in LEAK_POSITIONS] \
        == [True, False, True, False, True]
    m = run["stats"]["mappings"]["leak"]
    assert m["published"] == len(LEAK_POSITIONS) and m["dropped"] == {}


def test_consumed_charge_array_at_vendor_id_20100_reaches_ros_element_by_element(run: dict[str, Any]) -> None:
    full, empty = _got(run, "/power/charges")
    stamp = {"sec": USEC // 1_000_000, "nanosec": USEC % 1_000_000 * 1000}
    assert full["header"] == {"stamp": stamp, "frame_id": "base_link"}
    assert [(e["header"], e["circuit_id"], e["charge"]) for e in full["charges"]] == [
        ({"stamp": stamp, "frame_id": "base_link"}, c, c * 0.5) for c in range(1, 16)]
    assert empty["charges"] == [] and empty["header"]["stamp"] == {"sec": stamp["sec"] + 1,
                                                                   "nanosec": stamp["nanosec"]}
    assert run["board_ready"] == {"data_type_id": 20100, "decoded_as": "sabre.power.ConsumedChargeArray"}
    m = run["stats"]["mappings"]["charges"]
    assert m["data_type_id"] == 20100 and m["published"] == 2 and m["dropped"] == {} and m["saturated"] == {}


def test_legacy_and_new_rpm_topics_share_rpm_command(run: dict[str, Any]) -> None:
    records = _from_bridge(run, "uavcan.equipment.esc.RPMCommand")
    rpms = sorted(tuple(r["value"]["rpm"]) for r in records if r["device"] == "esc_port")
    assert rpms == sorted([(1000 + i, 2000 + i) for i in range(N_RPM)] + [(500 + i,) for i in range(N_RPM)])
    stats = run["stats"]["mappings"]
    assert all(stats[m]["published"] == N_RPM and stats[m]["dropped"] == {} for m in ("thrusters", "legacy_rpm"))
    rpm = "dronecan:uavcan.equipment.esc.RPMCommand"
    port = run["report"]["devices"]["esc_port"]["commands"][rpm]
    stbd = run["report"]["devices"]["esc_stbd"]["commands"][rpm]
    assert port["accepted"] == 2 * N_RPM and port["not_addressed"] == 0, port
    assert stbd["accepted"] == N_RPM and stbd["not_addressed"] == N_RPM, stbd  # [r] has no starboard element


def test_esc_status_routed_by_index_from_any_node(run: dict[str, Any]) -> None:
    for i in (0, 1):
        assert {m["y"] for m in _got(run, f"/esc{i}/status")} == {float(i)}  # the select field, published
    peer = [m for m in _got(run, "/esc1/status") if m["x"] == PEER_RPM]
    assert len(peer) == PEER_SELECTED  # node 77, a node id the spec never names
    m = run["stats"]["mappings"]
    assert m["esc0_status"]["source_node_ids"] == "any"
    assert m["esc0_status"]["dropped"] == {"unselected": PEER_UNSELECTED} and m["esc1_status"]["dropped"] == {}
    assert not [msg for msg in _got(run, "/esc0/status") if msg["x"] == PEER_RPM]


def test_panic_mapped_onto_the_specs_topics(run: dict[str, Any]) -> None:
    assert [m["data"] for m in _got(run, "/panic_in")] == ["FLOOD"]
    (panic,) = _from_bridge(run, "uavcan.protocol.Panic")  # once: the mapping's, not the built-in duty's three
    assert panic["accepted"] and panic["device"] == "relays" and panic["value"]["reason_text"] == "WATER-I"
    m = run["stats"]["mappings"]
    assert m["panic_out"]["published"] == 1 and m["panic_out"]["saturated"] == {"panic_out.reason_text": 1}
    assert m["panic_in"]["published"] == 1 and m["panic_in"]["dropped"] == {}


def test_the_bridge_runs_every_mapping_on_the_wire_codecs(run: dict[str, Any]) -> None:
    assert "no wire codecs" not in run["bridge_log"], run["bridge_log"]
    assert "wire=codec" in run["bridge_log"], run["bridge_log"]
