"""Element mappings on the Cyphal wire codec across processes (issue 17 class 4, tests/specs/dredger.yaml):
``sam-bridge --protocol cyphal`` (its default wire path: the generated codec.py) on Cyphal/UDP 127.0.0.1 between
``sam-sim`` (the pump controller publishing dredger.pump.Readings with up to three delimited Reading elements; the
valve controller receiving the commands) and ROS probes, under the machine-wide UDP lock:

- UAVCAN -> ROS: every Readings becomes one /pumps message whose PumpReading elements hold what the pumps sent
  (a uint4, a bool, an int7, an unaligned float64 and a nested delimited Health among them) and whose element
  headers carry the message's header: its stamp (from the device's timestamp) and the mapping's frame;
- ROS -> UAVCAN: ValveCommands on /valves (a bounded array, `on_out_of_range: reject`) reach the valves in range,
  with the constant `mode: 2` and their nested limits in every element; more than 4 elements, or a valve id beyond
  uint6, drop the message, counted; on /valve_pair (a fixed array of 2, saturating) one element is padded with a
  zero element and three are cut to two, counted once each, a float16 opening saturated and counted.

The bridge's stats say it ran them on the codec (`wire: codec`), not on the object converters' fallback. The
same again with the bridge as vehicle /sam1 (issue 26: a namespaced run stays on the codec, bound to the frame prefix
at start): the same values, every frame id (the message's and its elements') ``sam1/pump_link``; the spec's topics
are absolute, so they stay global.
"""

from __future__ import annotations

import json
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.bridge_sim_probe import bridge_sim_probe
from helpers.runtime_support import cyphal_udp_lock, poll_until, read_json
from helpers.spec_build import spec_workdir

pytestmark = [pytest.mark.ros, pytest.mark.slow]

UDP = ["--transport", "udp", "--iface", "127.0.0.1"]


def _valve(valve_id: int, opening: float, speed: float) -> dict[str, Any]:
    return {"valve_id": valve_id, "opening": opening, "speed": speed, "label": f"v{valve_id}",
            "max_opening": opening / 2, "steps": valve_id % 8}


VALVES = [  # /valves: bounded [<=4], reject
    [_valve(1, 0.5, 2.0), _valve(2, 0.25, -1.5)],
    [_valve(i, 0.125, 1.0) for i in range(5)],  # 5 > 4: dropped, counted under valve_commands.valves
    [_valve(64, 0.5, 1.0)],  # beyond uint6: dropped, counted under valve_commands.valves[].valve_id
    [_valve(7, 1.0, 0.5), _valve(8, 0.0, 0.25), _valve(63, -0.5, 3.0)],
]
PAIR = [  # /valve_pair: fixed [2], saturate
    [_valve(5, 0.75, 1.0)],  # padded with a zero element
    [_valve(9, 1e6, 2.0), _valve(10, 0.5, 4.0), _valve(11, 0.5, 8.0)],  # cut to 2; 1e6 saturated into float16
    [_valve(12, 0.5, 0.5), _valve(13, 0.25, 0.75)],
]


@pytest.fixture(scope="module", params=["", "/sam1"], ids=["root", "namespaced"])
def run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    namespace = request.param
    b, d, env = spec_workdir(tmp_path_factory, "dredger", "dredger_cyphal", 97)
    (d / "plan.json").write_text(json.dumps({"rate_hz": 5, "topics": {
        "/valves": [{"seq": i, "valves": v} for i, v in enumerate(VALVES)],
        "/valve_pair": [{"seq": i, "valves": v} for i, v in enumerate(PAIR)]}}))
    with cyphal_udp_lock(), bridge_sim_probe(d, env, b.generated, UDP, "cyphal", "pumps,valves", ["/pumps"],
                                             d / "pumps.jsonl", lambda counts: counts.get("/pumps", 0) >= 5,
                                             "pump readings at the probe",
                                             ("--namespace", namespace) if namespace else ()):

        def handled() -> bool:
            maps = (read_json(d / "bridge.json") or {}).get("mappings", {})
            return all(maps.get(m, {}).get("received", 0) >= n
                       for m, n in (("valve_commands", len(VALVES)), ("valve_pair", len(PAIR))))

        poll_until(handled, 60, "the bridge handling every command")
        poll_until(lambda: sum(1 for line in (d / "sim.jsonl").read_text().splitlines()
                               if json.loads(line)["dir"] == "rx") >= 2 + len(PAIR), 30,
                   "the valves receiving every command the bridge sent")
    records = [json.loads(line) for line in (d / "sim.jsonl").read_text().splitlines()]
    return {"stats": read_json(d / "bridge.json"), "records": records,
            "frame_prefix": f"{namespace[1:]}/" if namespace else "",
            "got": [json.loads(line) for line in (d / "pumps.jsonl").read_text().splitlines()]}


def test_the_bridge_ran_the_codec(run: dict[str, Any]) -> None:
    assert run["stats"]["wire"] == "codec", run["stats"].get("wire")


def test_pump_readings_reach_ros_element_by_element(run: dict[str, Any]) -> None:
    """Each /pumps message is one Readings the pumps sent, in order: every element's values, and its header the
    message's (stamp and frame)."""
    stats = run["stats"]["mappings"]["pump_readings"]
    assert stats["published"] >= 5 and stats["dropped"] == {}, stats
    sent = [r["value"] for r in run["records"] if r["dir"] == "tx" and r["device"] == "pumps"]
    assert sent and all(len(v["pumps"]) == 3 for v in sent)  # the simulator fills three elements

    def expected(v: dict[str, Any]) -> list[dict[str, Any]]:
        return [{"pump_id": p["pump_id"], "running": p["running"], "flow": p["flow"], "temp": p["temp"],
                 "pressure": p["pressure"], "state": p["health"]["state"], "fault": p["health"]["fault"]}
                for p in v["pumps"]]

    got = [r["msg"] for r in run["got"]]
    assert len(got) >= 5
    for msg in got:
        assert msg["pumps"] and all(p["header"] == msg["header"] for p in msg["pumps"]), msg
        assert msg["header"]["frame_id"] == f"{run['frame_prefix']}pump_link"
    values = [expected(v) for v in sent]
    received = [[{k: p[k] for k in ("pump_id", "running", "flow", "temp", "pressure", "state", "fault")}
                 for p in m["pumps"]] for m in got]
    assert any(values[i:i + len(received)] == received for i in range(len(values) - len(received) + 1)), \
        (received[:2], values[:2])


def test_valve_commands_reach_the_valves_or_are_dropped_counted(run: dict[str, Any]) -> None:
    stats = run["stats"]["mappings"]["valve_commands"]
    assert stats["received"] == len(VALVES) and stats["published"] == 2, stats
    got = [r["value"] for r in run["records"] if r["dir"] == "rx" and r["subject"] == 801]
    assert all(r["accepted"] for r in run["records"] if r["dir"] == "rx")
    assert [v["seq"] for v in got] == [0, 3]
    for v, valves in zip(got, (VALVES[0], VALVES[3]), strict=True):
        assert v["valves"] == [{"valve_id": x["valve_id"], "mode": 2, "opening": x["opening"], "speed": x["speed"],
                                "limits": {"max_opening": x["max_opening"], "steps": x["steps"]}} for x in valves]
    assert stats["rejected_fields"] == {"valve_commands.valves": 1, "valve_commands.valves[].valve_id": 1}, stats
    assert stats["dropped"] == {"rejected": 2}, stats


def test_valve_pair_padded_cut_and_saturated(run: dict[str, Any]) -> None:
    stats = run["stats"]["mappings"]["valve_pair"]
    assert stats["received"] == stats["published"] == len(PAIR), stats
    got = [r["value"]["valves"] for r in run["records"] if r["dir"] == "rx" and r["subject"] == 802]
    limits = {"max_opening": 1.0, "steps": 7}  # uavcan_values
    zero = {"valve_id": 0, "mode": 0, "opening": 0.0, "speed": 0.0, "limits": {"max_opening": 0.0, "steps": 0}}
    assert got == [
        [{"valve_id": 5, "mode": 1, "opening": 0.75, "speed": 1.0, "limits": limits}, zero],
        [{"valve_id": 9, "mode": 1, "opening": 65504.0, "speed": 2.0, "limits": limits},
         {"valve_id": 10, "mode": 1, "opening": 0.5, "speed": 4.0, "limits": limits}],
        [{"valve_id": 12, "mode": 1, "opening": 0.5, "speed": 0.5, "limits": limits},
         {"valve_id": 13, "mode": 1, "opening": 0.25, "speed": 0.75, "limits": limits}],
    ]
    assert stats["saturated"] == {"valve_pair.valves": 2, "valve_pair.valves[].opening": 1}, stats
