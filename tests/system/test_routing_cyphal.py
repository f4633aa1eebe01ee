"""`source_node_ids: any` on Cyphal across processes (issue 17 class 6), on tests/specs/seiner.yaml: ``sam-bridge
--protocol cyphal`` on Cyphal/UDP 127.0.0.1 -> a ROS probe; the simulated winch (node 40) and two nodes the spec
never names (tests/helpers/rogue_node.py, nodes 42 and 43) publish its subject 700: every transfer of every node is
bridged to /winch/tension, none dropped as ``unknown_source``."""

from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")

from helpers.ros_probe import listen_cmd
from helpers.runtime_support import (
    Proc,
    child_env,
    cyphal_udp_lock,
    domain_id,
    helper_cmd,
    poll_until,
    read_json,
    runtime_cmd,
)
from helpers.spec_build import generated_spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

ROGUES = {42: 15, 43: 10}  # node id -> transfers
UDP = ["--transport", "udp", "--iface", "127.0.0.1"]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    gen = generated_spec("seiner")
    d = tmp_path_factory.mktemp("routing_cyphal")
    env = child_env(Path(sys.prefix).absolute(), domain_id(94), {"SAM_GENERATED_DIR": str(gen)})
    with cyphal_udp_lock():
        bridge = Proc("bridge", runtime_cmd("bridge", "--protocol", "cyphal", *UDP, "--stats-file",
                                            str(d / "bridge.json")), env, d)
        sim = Proc("sim", runtime_cmd("sim", *UDP, "--devices", "winch", "--start-file", str(d / "go"),
                                      "--duration", "3", "--report", str(d / "sim.json")), env, d)
        probe = Proc("probe", listen_cmd(gen, ["/winch/tension"], d / "probe.json"), env, d)
        procs = [probe, sim, bridge]
        try:
            bridge.wait_line("READY", 90)
            sim.wait_line("READY", 90)
            probe.wait_line("READY", 60)
            poll_until(lambda: ((read_json(d / "bridge.json") or {}).get("mappings", {}).get("winch", {})
                                .get("ros_subscribers") or 0) > 0, 30, "the bridge matching the probe")
            (d / "go").touch()
            sim.wait_line("DONE", 60)
            assert sim.wait(20) == 0, sim.stderr_tail()
            sent = read_json(d / "sim.json")["devices"]["winch"]["published"]
            for node_id, count in ROGUES.items():
                rogue = Proc(f"rogue{node_id}", helper_cmd("rogue_node.py", "--generated", str(gen), "--node-id",
                                                           str(node_id), "--publish", f"700:{count}"), env, d)
                procs.append(rogue)
                rogue.wait_line("DONE", 60)
            total = sum(sent.values()) + sum(ROGUES.values())

            def bridged() -> dict[str, Any] | None:
                s = read_json(d / "bridge.json")
                return s if s and s["mappings"]["winch"]["received"] >= total else None

            poll_until(bridged, 20, "every winch transfer at the bridge")
            poll_until(lambda: (read_json(d / "probe.json") or {}).get("counts", {}).get("/winch/tension", 0)
                       >= total, 20, "every message at the probe")
            assert probe.stop(signal.SIGTERM) == 0, probe.stderr_tail()
            assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
        finally:
            for p in procs:
                p.stop()
    return {"sent": sent, "total": total, "stats": read_json(d / "bridge.json"), "probe": read_json(d / "probe.json")}


def test_any_node_accepts_nodes_the_spec_never_names(run: dict[str, Any]) -> None:
    winch = run["stats"]["mappings"]["winch"]
    assert sum(run["sent"].values()) > 0
    assert winch["source_node_ids"] == "any"
    assert winch["received"] == winch["published"] == run["total"], winch
    assert winch["dropped"] == {}, winch
    assert run["probe"]["counts"]["/winch/tension"] == run["total"]
