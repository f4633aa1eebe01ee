"""The bridge's board settings (issue 28) against an independent DroneCAN board: a plain ``dronecan`` node that
answers uavcan.protocol.param.GetSet and ExecuteOpcode as AP_Periph-style firmware does (tests/helpers/
dronecan_board.py, written from the DroneCAN specification, not from the project's simulator), on a private
loopback bus, and an rclpy client of the standard parameter services (tests/helpers/param_client.py):

- the bridge reads the board's values on first contact: ROS shows the board's value, not the spec's default;
- a set is written to the board (the board's own state shows it) and confirmed by its answer;
- a setting the board keeps (read-only in its firmware) fails with the board's reason, the board's value unchanged;
- <device>/store_settings reaches the board as ExecuteOpcode SAVE and succeeds on its ok;
- an atomic set (set_parameters_atomically) that the board fails part way is written back: all or nothing.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_support import private_iface
from helpers.runtime_support import helper_cmd, poll_until
from helpers.service_run import ServiceRun
from helpers.spec_build import spec_workdir

pytestmark = [pytest.mark.ros, pytest.mark.slow]

# lolo_v0's esc_port (node 50): ESC_INDEX, ESC_NUM_POLES, ESC_REV, ESC_MAX_RPM; the board's poles differ from the
# spec's default (14), its maximum RPM is fixed in its firmware.
BOARD = ["--param", "ESC_INDEX=int:0:0:19", "--param", "ESC_NUM_POLES=int:20:2:48", "--param", "ESC_REV=bool:0",
         "--param", "ESC_MAX_RPM=int:3000:0:6000", "--read-only", "ESC_MAX_RPM"]


def _state(path: Path) -> dict[str, Any]:
    return dict(json.loads(path.read_text()))


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    _, d, env = spec_workdir(tmp_path_factory, "lolo_v0", "independent_board", 90)
    iface = private_iface()
    state = d / "board.json"
    with ServiceRun(env, d) as r:
        board = r.start("board", helper_cmd("dronecan_board.py", "--iface", iface, "--node-id", "50",
                                            "--state", str(state), *BOARD))
        board.wait_line("READY", 60)
        bridge = r.bridge("--protocol", "dronecan", "--dronecan-iface", iface)
        bridge.wait_line("READY", 90)
        poll_until(lambda: ((r.bridge_stats() or {}).get("device_parameters", {}).get("reads", 0)) >= 4, 30,
                   "the bridge reading the board's four settings on first contact")
        before = _state(state)
        result = r.param_client("--node", "/sabre_bridge", "--prefix", "esc_port",
                                "--wait-value", "esc_port.esc.poles=20",
                                "--set", "esc_port.esc.poles=28", "--set", "esc_port.esc.reverse=true",
                                "--set", "esc_port.esc.rpm_limit=2500", "--trigger", "/esc_port/store_settings",
                                "--atomic", "esc_port.esc.poles=30;esc_port.esc.rpm_limit=2500")
        # the stats file follows the bridge's counters once a second: 3 sets reached the board, 1 store
        poll_until(lambda: ((r.bridge_stats() or {}).get("device_parameters", {}).get("rollbacks", 0)) >= 1, 20,
                   "the bridge's stats file counting the store and the atomic set's rollback")
        return {"before": before, "after": _state(state), "client": result} | r.outcome()


def test_the_bridge_shows_the_boards_values_read_on_first_contact(run: dict[str, Any]) -> None:
    client = run["client"]
    assert "error" not in client, client
    assert client["list"] == [f"esc_port.esc.{s}" for s in ("index", "poles", "reverse", "rpm_limit")], client
    assert client["get"] == {"esc_port.esc.index": 0, "esc_port.esc.poles": 20, "esc_port.esc.reverse": False,
                             "esc_port.esc.rpm_limit": 3000}, client["get"]
    assert run["before"]["seen"]["get_by_name"] >= 4 and run["before"]["seen"]["set"] == 0  # reads, no writes


def test_a_set_is_written_to_the_board_and_confirmed(run: dict[str, Any]) -> None:
    sets = {s["name"]: s for s in run["client"]["sets"]}
    assert sets["esc_port.esc.poles"]["successful"] and sets["esc_port.esc.poles"]["after"] == 28, sets
    assert sets["esc_port.esc.reverse"]["successful"] and sets["esc_port.esc.reverse"]["after"] is True, sets
    assert run["after"]["values"]["ESC_NUM_POLES"] == 28 and run["after"]["values"]["ESC_REV"] is True, run["after"]
    differing = run["bridge_stats"]["device_parameters"]["differing"]  # (board, spec), in the main job's view too
    assert differing["esc_port.esc.poles"] == [28, 14] and differing["esc_port.esc.reverse"] == [True, False]


def test_a_setting_the_board_keeps_fails_with_its_reason(run: dict[str, Any]) -> None:
    kept = {s["name"]: s for s in run["client"]["sets"]}["esc_port.esc.rpm_limit"]
    assert not kept["successful"], kept
    assert "refused by esc_port (node 50): it keeps 3000" in kept["reason"], kept
    assert kept["after"] == 3000 and run["after"]["values"]["ESC_MAX_RPM"] == 3000
    assert run["after"]["seen"]["set_kept"] == 2, run["after"]["seen"]  # the set's, the atomic set's
    counts = run["bridge_stats"]["device_parameters"]
    assert counts.get("refused_by_board") == 2 and counts.get("sets") == 5, counts


def test_store_settings_saves_on_the_board(run: dict[str, Any]) -> None:
    trigger = run["client"]["triggers"][0]
    assert trigger["success"], trigger
    assert run["after"]["seen"]["save"] == 1
    assert run["after"]["saved"] == {"ESC_INDEX": 0, "ESC_NUM_POLES": 28, "ESC_REV": True, "ESC_MAX_RPM": 3000}
    assert "Traceback" not in run["bridge_stderr"]


def test_an_atomic_set_the_board_fails_part_way_is_written_back(run: dict[str, Any]) -> None:
    atomic = run["client"]["atomic"][0]
    assert not atomic["successful"], atomic
    assert atomic["reason"] == ("esc_port.esc.rpm_limit: refused by esc_port (node 50): it keeps 3000; "
                                "written back: esc_port.esc.poles"), atomic
    assert atomic["after"] == {"esc_port.esc.poles": 28, "esc_port.esc.rpm_limit": 3000}
    assert run["after"]["values"]["ESC_NUM_POLES"] == 28  # on the board: 30 was written, then 28 again
    assert run["bridge_stats"]["device_parameters"].get("rollbacks") == 1
