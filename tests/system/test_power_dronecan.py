"""Issue 17 class 4 across processes on DroneCAN, with tests/specs/power_v0.yaml (arrays of composites mapped
element by element):

- a helper process (tests/helpers/power_board.py, plain dronecan with the spec's types) plays the power board
  (node 30): its ConsumedChargeArray of 15 elements and one of none reach /power/charges as ConsumedCharges, every
  element with its circuit, its charge and the message's header (the board's timestamp, frame base_link);
- ``sam-sim`` plays the servos (node 31): 20 commands published on /actuators reach them as one ArrayCommand of the
  first 15, the cut counted once (``saturated: actuators.commands``), 70000 saturated into float16 and counted;
- ``sam-bridge`` is started on its default wire path: codec_v0.py converts these mappings element by element on the
  payload and CDR bytes (no object converter), with the same values and counts.

The spec's ROS package is usable only by a process started with its library path: the scenario runs in a child
pytest (this file with SAM_POWER_E2E_WORKER set); the parent builds the package and starts it.
"""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

pytestmark = [pytest.mark.ros, pytest.mark.slow]

WORKER_ENV = "SAM_POWER_E2E_WORKER"
WORKER = os.environ.get(WORKER_ENV)
BRIDGE_ID, BOARD_ID, SERVOS_ID = 100, 30, 31
USEC = 1_700_000_000_250_000

if not WORKER:
    from helpers.ros_packages import run_child
    from helpers.runtime_support import domain_id
    from helpers.spec_build import built_spec

    def test_power_bridge_across_processes() -> None:
        b = built_spec("power_v0")
        proc = run_child(["-m", "pytest", __file__, "-q", "-p", "no:cacheprovider", "--rootdir",
                          str(Path(__file__).parents[2])], b.prefix, domain_id(53),
                         {WORKER_ENV: json.dumps({"generated": str(b.generated)})}, timeout=600)
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout and " failed" not in proc.stdout, report

if WORKER:
    from helpers.dronecan_support import private_iface
    from helpers.ros_probe import DroneCanTopics, ThreadedProbe
    from helpers.runtime_support import Proc, child_env, helper_cmd, load_records, poll_until, read_json, runtime_cmd

    GENERATED = Path(json.loads(WORKER)["generated"])

    class Probe(ThreadedProbe):
        node_name = "test_power_probe"

        def setup(self) -> None:
            self.charges: list[Any] = []

        def on_message(self, topic: str, msg: Any) -> None:
            self.charges.append(msg)

    @pytest.fixture(scope="module")
    def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
        from power_msgs.msg import Command

        from sam_runtime.genpkg import GeneratedPackage

        d = tmp_path_factory.mktemp("power")
        gen = GeneratedPackage(GENERATED)
        env = child_env(_prefix(), _domain())  # this child's environment: the spec's ROS package usable
        iface = private_iface()
        common = ["--generated", str(GENERATED), "--dronecan-iface", iface]
        bridge = Proc("bridge", runtime_cmd("bridge", *common, "--stats-file", str(d / "bridge.json")), env, d)
        sim = Proc("sim", runtime_cmd("sim", *common, "--devices", "servos", "--record", str(d / "sim.jsonl"),
                                      "--report", str(d / "sim.json")), env, d)
        board = Proc("board", helper_cmd("power_board.py", "--generated", str(GENERATED), "--iface", iface,
                                         "--start-file", str(d / "go")), env, d)
        probe = None
        out: dict[str, Any] = {}
        try:
            probe = Probe(DroneCanTopics(gen), ["/power/charges"], ["/actuators"])
            board.wait_line("READY", 60)
            bridge.wait_line("READY", 90)
            sim.wait_line("READY", 90)

            def ready() -> bool:
                s = read_json(d / "bridge.json")
                return bool(s) and all(v.get("alive") for v in s["devices"].values()) \
                    and (s["mappings"]["charges"].get("ros_subscribers") or 0) > 0 \
                    and all(p.get_subscription_count() > 0 for p in probe.pubs.values())

            poll_until(ready, 30, "the bridge hearing both devices and matching the probe")
            commands = [Command(actuator_id=i, command_type=1, value=float(i)) for i in range(20)]
            commands[2] = Command(actuator_id=2, command_type=1, value=70000.0)
            probe.publish("/actuators", {"commands": commands})
            (d / "go").touch()
            board.wait_line("PUBLISHED", 20)
            poll_until(lambda: len(probe.charges) >= 2, 20, "both ConsumedChargeArray on /power/charges")

            def rx() -> list[dict[str, Any]]:
                return [r for r in load_records(d / "sim.jsonl") if r["dir"] == "rx"
                        and r["data_type"] == "uavcan.equipment.actuator.ArrayCommand"]

            poll_until(rx, 20, "the servos receiving the bridge's ArrayCommand")
            out["records"] = rx()
            out["charges"] = [
                {"stamp": (m.header.stamp.sec, m.header.stamp.nanosec), "frame_id": m.header.frame_id,
                 "elements": [((e.header.stamp.sec, e.header.stamp.nanosec), e.header.frame_id, e.circuit_id,
                               e.charge) for e in m.charges]} for m in probe.charges]
            assert sim.stop(signal.SIGTERM) == 0, sim.stderr_tail()
            assert board.stop(signal.SIGTERM) == 0, board.stderr_tail()
            assert bridge.stop(signal.SIGTERM) == 0, bridge.stderr_tail()
            out["stats"] = read_json(d / "bridge.json")
            out["bridge_log"] = "\n".join(bridge.lines) + "\n" + bridge.stderr_tail(400)
        finally:
            for p in (board, sim, bridge):
                p.stop()
            if probe is not None:
                probe.close()
        return out

    def _prefix() -> Path:
        import sys

        return Path(sys.prefix).absolute()

    def _domain() -> str:
        return os.environ["ROS_DOMAIN_ID"]

    def test_charges_reach_ros_element_by_element_with_the_message_header(run: dict[str, Any]) -> None:
        full, empty = run["charges"]
        stamp = (USEC // 1_000_000, USEC % 1_000_000 * 1000)
        assert full["stamp"] == stamp and full["frame_id"] == "base_link"
        assert full["elements"] == [(stamp, "base_link", c, c * 0.5) for c in range(1, 16)]
        assert empty["elements"] == [] and empty["stamp"] == (stamp[0] + 1, stamp[1])
        m = run["stats"]["mappings"]["charges"]
        assert m["published"] == 2 and m["dropped"] == {} and m["saturated"] == {}

    def test_twenty_commands_reach_the_servos_as_fifteen_with_the_cut_counted(run: dict[str, Any]) -> None:
        (record,) = [r for r in run["records"] if r["source"] == BRIDGE_ID]
        assert record["accepted"]
        values = [(c["actuator_id"], c["command_type"], c["command_value"]) for c in record["value"]["commands"]]
        assert values == [(i, 1, 65504.0 if i == 2 else float(i)) for i in range(15)]
        m = run["stats"]["mappings"]["actuators"]
        assert m["saturated"] == {"actuators.commands": 1, "actuators.commands[].command_value": 1}

    def test_the_bridge_runs_these_mappings_on_the_wire_codecs(run: dict[str, Any]) -> None:
        assert "no wire codecs" not in run["bridge_log"]
        assert "wire=codec" in run["bridge_log"]
