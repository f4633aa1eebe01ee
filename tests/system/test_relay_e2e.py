"""Mapping expressions end to end across processes (tests/specs/relay.yaml, issue 17 classes 1-3):
``sam-sim`` (the spec's DroneCAN devices on a private loopback bus) -> ``sam-bridge --protocol dronecan`` -> ROS
probes: the leak sensor's actuator.Status becomes /leak (`position == 100`, the bools the probe receives agree with
the positions the sensor sent); a std_msgs/Bool on /relay/dvl becomes the relay's float16 command 0.0 / 1.0 in its
ArrayCommand item, and a relay_msgs/Led on /led the lamp's LightsCommand colour `(alpha * r) >> 3` (saturated into
uint5, counted by the bridge): what the simulated devices accepted from the bridge's node id. The same on Cyphal/UDP
(127.0.0.1, under the machine-wide UDP lock): the hull's predicate and integer arithmetic into /hull_leak and
/hull_depth, and one ROS float on /rail into the rail's bool, rounded uint7 and shifted int18 (saturated, never
wrapped).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.bridge_sim_probe import bridge_sim_probe
from helpers.dronecan_support import private_iface
from helpers.runtime_support import cyphal_udp_lock, poll_until, read_json
from helpers.spec_build import spec_workdir

pytestmark = [pytest.mark.ros, pytest.mark.slow]

DEVICES = "relays,leak_sensor,led"  # the DroneCAN devices the mappings under test talk to


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    b, d, env = spec_workdir(tmp_path_factory, "relay", "relay_e2e", 47)
    iface = private_iface()
    dc = ["--layout", "all_dronecan", "--dronecan-iface", iface]
    plan = {"rate_hz": 5, "topics": {
        "/relay/dvl": [{"data": False}] * 3 + [{"data": True}] * 3,
        "/led": [{"r": 200, "g": 0, "b": 0, "alpha": 255}] * 3 + [{"r": 30, "g": 200, "b": 255, "alpha": 8}] * 3,
    }}
    (d / "plan.json").write_text(json.dumps(plan))
    with bridge_sim_probe(d, env, b.generated, dc, "dronecan", DEVICES, ["/leak"], d / "leak.jsonl",
                          lambda counts: counts.get("/leak", 0) >= 5, "leak flags at the probe"):

        def commands_sent() -> bool:
            maps = (read_json(d / "bridge.json") or {}).get("mappings", {})
            return all(maps.get(m, {}).get("published", 0) >= 6 for m in ("relay_dvl", "led"))

        poll_until(commands_sent, 60, "the bridge sending every command")
    return {"report": read_json(d / "sim.json"), "stats": read_json(d / "bridge.json"), "dir": Path(d),
            "sent": [json.loads(line) for line in (d / "sim.jsonl").read_text().splitlines()],
            "leak": [json.loads(line) for line in (d / "leak.jsonl").read_text().splitlines()]}


def test_leak_predicate_reaches_ros(run: dict[str, Any]) -> None:
    """Every actuator.Status the sensor broadcast became one /leak message, none dropped by the bridge."""
    stats = run["stats"]["mappings"]["leak"]
    assert stats["published"] >= 5 and stats["dropped"] == {}, stats
    got = [r["msg"]["data"] for r in run["leak"]]
    expected = [r["value"]["position"] == 100 for r in run["sent"]
                if r["dir"] == "tx" and r["data_type"] == "uavcan.equipment.actuator.Status"]
    assert got and all(isinstance(v, bool) for v in got)
    # the probe heard a contiguous run of what the sensor sent (it subscribed after the first ones)
    assert any(expected[i:i + len(got)] == got for i in range(len(expected) - len(got) + 1)), (got, expected)


def test_relay_and_light_commands_reach_the_devices(run: dict[str, Any]) -> None:
    """The last commands the devices accepted are the expressions' values: the relay's float16 1.0 after the
    `true`s, the lamp's (8 * 30) >> 3 = 30, (8 * 200) >> 10 = 1, (8 * 255) >> 11 = 0; before them the red of
    (255 * 200) >> 3, beyond uint5, was saturated at 31 (counted by the bridge, three times)."""
    devices = run["report"]["devices"]
    relay = next(iter(devices["relays"]["commands"].values()))
    led = next(iter(devices["led"]["commands"].values()))
    assert relay["accepted"] >= 6 and led["accepted"] >= 6, (relay, led)
    assert relay["rejected"] == led["rejected"] == 0
    assert relay["last"]["commands[actuator_id=7]"] == {"actuator_id": 7, "command_type": 0, "command_value": 1.0}
    assert led["last"]["commands[light_id=0]"]["color"] == {"red": 30, "green": 1, "blue": 0}
    saturated = run["stats"]["mappings"]["led"].get("saturated", {})
    assert saturated == {"led.commands[light_id=0].color.red": 3}, run["stats"]["mappings"]["led"]


@pytest.fixture(scope="module")
def cyphal_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    b, d, env = spec_workdir(tmp_path_factory, "relay", "relay_e2e_cyphal", 48)
    udp = ["--transport", "udp", "--iface", "127.0.0.1"]
    (d / "plan.json").write_text(json.dumps({"rate_hz": 5, "topics": {
        "/rail": [{"data": 0.3}] * 3 + [{"data": 300.0}] * 3}}))
    with cyphal_udp_lock(), bridge_sim_probe(d, env, b.generated, udp, "cyphal", "hull,rail",
                                             ["/hull_leak", "/hull_depth"], d / "hull.jsonl",
                                             lambda counts: bool(counts) and min(counts.values()) >= 5,
                                             "hull messages at the probe"):
        poll_until(lambda: (read_json(d / "bridge.json") or {}).get("mappings", {}).get("rail", {}).get(
            "published", 0) >= 6, 60, "the bridge sending every rail command")
    return {"report": read_json(d / "sim.json"), "stats": read_json(d / "bridge.json"),
            "sent": [json.loads(line) for line in (d / "sim.jsonl").read_text().splitlines()],
            "got": [json.loads(line) for line in (d / "hull.jsonl").read_text().splitlines()]}


def test_cyphal_predicate_and_arithmetic_reach_ros(cyphal_run: dict[str, Any]) -> None:
    """/hull_leak and /hull_depth carry the expressions of what the hull sent, in order."""
    sent = [r["value"] for r in cyphal_run["sent"] if r["dir"] == "tx" and r["device"] == "hull"]
    expected = {
        "/hull_leak": [v["flooded"] or v["probes"][1] or (v["water_mm"] > 40 and v["pressure_pa"] >= 1.5e5)
                       for v in sent],
        "/hull_depth": [max(-32768, min(32767, math.trunc(v["pressure_pa"] / 9.81) - v["water_mm"] * 2))
                        for v in sent],
    }
    for topic, values in expected.items():
        got = [r["msg"]["data"] for r in cyphal_run["got"] if r["topic"] == topic]
        assert len(got) >= 5
        assert any(values[i:i + len(got)] == got for i in range(len(values) - len(got) + 1)), (topic, got, values)


def test_cyphal_rail_command_saturates_never_wraps(cyphal_run: dict[str, Any]) -> None:
    """300 V: enabled, level round(30000) saturated at 127, millivolts trunc(300000) >> 1 = 150000 saturated at
    131071 (an int18 that wrapped would be negative)."""
    rail = next(iter(cyphal_run["report"]["devices"]["rail"]["commands"].values()))
    assert rail["accepted"] >= 6 and rail["rejected"] == 0, rail
    assert rail["last"] == {"enabled": True, "level": 127, "millivolts": 131071}, rail
    saturated = cyphal_run["stats"]["mappings"]["rail"]["saturated"]
    assert saturated == {"rail.level": 3, "rail.millivolts": 3}, saturated
