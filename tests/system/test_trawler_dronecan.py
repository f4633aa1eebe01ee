"""Issue 17 classes 8 and 9 across processes on DroneCAN, with tests/specs/trawler_v0.yaml (``dronecan_namespaces:
[uavcan, ardupilot]``, its own trawler.io.Switch at data type id 20100, where dronecan bundles
com.hobbywing.esc.RawCommand; Panic mapped onto /panic_in and /panic_out with ``panic_duty: mappings``):

- ``sam-sim`` plays the relay board (node 31), a helper process (tests/helpers/trawler_panel.py, plain dronecan with
  the spec's types as the runtime gives them) the switch panel (node 30), ``sam-bridge`` runs on its wire path
  (codecs) or its object path (dronecan decodes), and a ROS probe in this process publishes and listens;
- the panel's Switch broadcasts (20100) reach /panel_level with their values, the one no mapping selects is counted
  (``unselected``); /relay_level reaches the relay board as a Switch, which the simulated device decodes as the spec's
  type (and the panel too);
- Panic both ways as ordinary mappings: the panel's Panic on /panic_in; /panic_out broadcast once as Panic, its text
  cut to reason_text's 7 bytes and counted (``saturated``); the built-in duty is off (no /trawler_bridge/panic_received
  publisher, no triple broadcast);
- the same spec with ``panic_duty: both`` (wire path: the mapping's tap shares Panic with the duty): the mappings as
  above and the built-in duty beside them (the panel's Panic also on /trawler_bridge/panic_received,
  /trawler_bridge/panic broadcast three times).
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
from helpers.ros_probe import DroneCanTopics, ThreadedProbe
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

SPECS = Path(__file__).parents[1] / "specs"
BRIDGE_ID, PANEL_ID, RELAY_ID = 100, 30, 31
BRIDGE = "trawler_bridge"
LEVELS = [7, 107, 207, 307, 407]


class Probe(ThreadedProbe):
    node_name = "test_trawler_probe"

    def setup(self) -> None:
        from std_msgs.msg import String

        self.messages: dict[str, list[Any]] = {}
        self.builtin: list[str] = []
        self.string = String

    def watch_builtin(self) -> None:
        """The built-in Panic duty's topics (used by the `both` run; never published in the others)."""
        self.node.create_subscription(self.string, f"/{BRIDGE}/panic_received",
                                      lambda m: self.builtin.append(m.data), 10)
        self.builtin_pub = self.node.create_publisher(self.string, f"/{BRIDGE}/panic", 10)

    def on_message(self, topic: str, msg: Any) -> None:
        self.messages.setdefault(topic, []).append(msg.data)


def _summary(proc: Proc) -> dict[str, Any]:
    line = proc.wait_line("SUMMARY ", 20)
    return json.loads(line.split(" ", 1)[1])


@pytest.fixture(scope="module", params=["codec", "object"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    wire = request.param
    d = tmp_path_factory.mktemp(f"trawler_{wire}")
    return _scenario(d, generated_spec("trawler_v0"), wire, domain_id(47 if wire == "codec" else 48), both=False)


@pytest.fixture(scope="module")
def run_both(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The trawler with `panic_duty: both`, generated here, on the wire path."""
    from sam_codegen.build import build

    d = tmp_path_factory.mktemp("trawler_both")
    spec = d / "spec" / "trawler_v0.yaml"
    spec.parent.mkdir()
    text = (SPECS / "trawler_v0.yaml").read_text(encoding="utf-8")
    assert text.count("  panic_duty: mappings\n") == 1
    spec.write_text(text.replace("  panic_duty: mappings\n", "  panic_duty: both\n"), encoding="utf-8")
    build(spec, d / "generated")
    return _scenario(d, d / "generated", "codec", domain_id(49), both=True)


def _scenario(d: Path, generated: Path, wire: str, domain: str, both: bool) -> dict[str, Any]:
    from sam_runtime.genpkg import GeneratedPackage

    # The probe's topics and QoS, from the spec's package as tests/specs has it (the `both` variant has the same ones;
    # one process imports one copy of a generated package).
    gen = GeneratedPackage(generated_spec("trawler_v0"))
    env = child_env(Path(sys.prefix).absolute(), domain)
    iface = private_iface()
    common = ["--generated", str(generated), "--dronecan-iface", iface]
    bridge = Proc("bridge", runtime_cmd("bridge", *common, "--wire", wire, "--stats-file", str(d / "bridge.json")),
                  env, d)
    sim = Proc("sim", runtime_cmd("sim", *common, "--devices", "relay_board", "--record", str(d / "sim.jsonl"),
                                  "--report", str(d / "sim.json")), env, d)
    panel = Proc("panel", helper_cmd("trawler_panel.py", "--generated", str(generated), "--iface", iface,
                                     "--start-file", str(d / "go")), env, d)
    probe = None
    out: dict[str, Any] = {"wire": wire}
    try:
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("ROS_DOMAIN_ID", domain)
            mp.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            probe = Probe(DroneCanTopics(gen), ["/panel_level", "/panic_in"], ["/relay_level", "/panic_out"])
            probe.watch_builtin()
        out["panel_ready"] = json.loads(panel.wait_line("READY ", 60).split(" ", 1)[1])
        bridge.wait_line("READY", 90)
        sim.wait_line("READY", 90)

        def ready() -> bool:
            s = read_json(d / "bridge.json")
            return bool(s) and all(v.get("alive") for v in s["devices"].values()) \
                and all((s["mappings"][m].get("ros_subscribers") or 0) > 0 for m in ("panel_level", "panic_in")) \
                and all(p.get_subscription_count() > 0 for p in probe.pubs.values())

        poll_until(ready, 30, "the bridge hearing both devices and matching the probe")
        duties = f"{BRIDGE}_dronecan_duties"  # the Panic duty's own ROS node (no endpoints under panic_duty: mappings)

        def duty_endpoints() -> tuple[list[str], list[str]] | None:
            if duties not in probe.node.get_node_names():
                return None
            return ([n for n, _ in probe.node.get_publisher_names_and_types_by_node(duties, "/")],
                    [n for n, _ in probe.node.get_subscriber_names_and_types_by_node(duties, "/")])

        out["duty_publishes"], out["duty_subscribes"] = poll_until(duty_endpoints, 20, "the duties' ROS node")

        probe.publish("/relay_level", {"data": 1234})
        probe.publish("/panic_out", {"data": "WATER-INGRESS"})
        if both:
            poll_until(lambda: probe.builtin_pub.get_subscription_count() > 0, 20, "the built-in duty's /panic")
            probe.builtin_pub.publish(probe.string(data="ROS-ABORT"))
        (d / "go").touch()
        panel.wait_line("PUBLISHED", 20)

        def rx(kind: str) -> list[dict[str, Any]]:
            return [r for r in load_records(d / "sim.jsonl") if r["dir"] == "rx" and r["data_type"] == kind]

        poll_until(lambda: len(probe.messages.get("/panel_level", [])) >= len(LEVELS)
                   and probe.messages.get("/panic_in") and (probe.builtin or not both), 20,
                   "the panel's Switch and Panic on ROS")
        panics = 4 if both else 1  # the mapping's, and the built-in duty's three
        poll_until(lambda: sum(line.startswith(f"GOT uavcan.protocol.Panic {BRIDGE_ID} ") for line in panel.lines)
                   >= panics, 20, f"{panics} Panic from the bridge at the panel")
        poll_until(lambda: rx("trawler.io.Switch") and rx("uavcan.protocol.Panic"), 20,
                   "the relay board receiving the bridge's Switch and Panic")
        poll_until(lambda: (read_json(d / "bridge.json") or {}).get("mappings", {}).get("panel_level", {})
                   .get("dropped", {}).get("unselected"), 10, "the unselected Switch counted")
        out["records"] = load_records(d / "sim.jsonl")
        assert sim.stop(signal.SIGTERM) == 0, sim.stderr_tail()
        assert panel.stop(signal.SIGTERM) == 0, panel.stderr_tail()
        out["panel"] = _summary(panel)
        assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
        out["messages"] = {t: list(v) for t, v in probe.messages.items()}
        out["builtin"] = list(probe.builtin)
        out["stats"] = read_json(d / "bridge.json")
        out["sim"] = read_json(d / "sim.json")
    finally:
        for p in (panel, sim, bridge):
            p.stop()
        if probe is not None:
            probe.close()
    return out


def test_dronecan_decodes_20100_as_the_specs_own_type(run: dict[str, Any]) -> None:
    assert run["panel_ready"]["20100"] == "trawler.io.Switch"


def test_switch_at_20100_from_the_panel_reaches_ros(run: dict[str, Any]) -> None:
    assert run["messages"]["/panel_level"] == LEVELS
    st = run["stats"]["mappings"]["panel_level"]
    assert st["data_type_id"] == 20100 and st["published"] == len(LEVELS)
    assert st["dropped"] == {"unselected": 1}  # switch_id 3: no mapping selects it, counted


def test_relay_level_reaches_the_simulated_relay_board_as_the_specs_type(run: dict[str, Any]) -> None:
    switches = [r for r in run["records"] if r["dir"] == "rx" and r["data_type"] == "trawler.io.Switch"]
    from_bridge = [r for r in switches if r["source"] == BRIDGE_ID]
    assert [r["value"] for r in from_bridge] == [{"switch_id": 2, "level": 1234, "flags": 0}]
    assert from_bridge[0]["data_type_id"] == 20100 and from_bridge[0]["accepted"]
    commands = run["sim"]["devices"]["relay_board"]["commands"]["dronecan:trawler.io.Switch"]
    assert commands["accepted"] == 1 and commands["last"] == {"switch_id": 2, "level": 1234, "flags": 0}
    panel = [r for r in run["panel"]["received"] if r["type"] == "trawler.io.Switch"]
    assert panel == [{"source": BRIDGE_ID, "type": "trawler.io.Switch", "data_type_id": 20100,
                      "values": {"switch_id": 2, "level": 1234, "flags": 0}}]


def test_panic_mapped_both_ways_with_the_cut_counted(run: dict[str, Any]) -> None:
    assert run["messages"]["/panic_in"] == ["LEAK"]
    panics = [r for r in run["panel"]["received"] if r["type"] == "uavcan.protocol.Panic"]
    assert panics == [{"source": BRIDGE_ID, "type": "uavcan.protocol.Panic", "data_type_id": 5,
                       "values": {"reason_text": "WATER-I"}}]  # once: the mapping's, not the built-in triple
    relay = [r for r in run["records"] if r["dir"] == "rx" and r["data_type"] == "uavcan.protocol.Panic"
             and r["source"] == BRIDGE_ID]  # (the panel's Panic reaches the relay board too: not from the bridge)
    assert len(relay) == 1 and relay[0]["accepted"], relay
    assert relay[0]["value"]["reason_text"] == "WATER-I", relay  # the simulator records v0 text as a str
    m = run["stats"]["mappings"]
    assert m["panic_out"]["published"] == 1 and m["panic_out"]["saturated"] == {"panic_out.reason_text": 1}
    assert m["panic_in"]["published"] == 1 and m["panic_in"]["dropped"] == {}


def test_the_builtin_panic_duty_is_off(run: dict[str, Any]) -> None:
    assert f"/{BRIDGE}/panic_received" not in run["duty_publishes"]
    assert f"/{BRIDGE}/panic" not in run["duty_subscribes"]
    assert run["builtin"] == []


def test_with_both_the_builtin_duty_runs_beside_the_mappings(run_both: dict[str, Any]) -> None:
    r = run_both
    assert f"/{BRIDGE}/panic_received" in r["duty_publishes"] and f"/{BRIDGE}/panic" in r["duty_subscribes"]
    assert r["messages"]["/panic_in"] == ["LEAK"]  # the mapping, on the wire path: its tap shares Panic ...
    assert r["builtin"] == [f"node {PANEL_ID}: LEAK"]  # ... with the built-in duty
    panics = [p["values"]["reason_text"] for p in r["panel"]["received"]
              if p["type"] == "uavcan.protocol.Panic" and p["source"] == BRIDGE_ID]
    assert sorted(panics) == ["ROS-ABO"] * 3 + ["WATER-I"]
    m = r["stats"]["mappings"]
    assert m["panic_out"]["saturated"] == {"panic_out.reason_text": 1} and m["panic_in"]["published"] == 1
    assert r["messages"]["/panel_level"] == LEVELS
