"""The bridge on a spec that is not SAM's (tests/specs/glider.yaml), with devices the test plays (issue 11):

- defect 6: a mapping that never receives, or stops receiving, while its device's heartbeat is alive is WARN on
  /diagnostics ("no message for N s while device X is alive; nominal R Hz"); a device without heartbeat is not;
- defect 12: the bridge's Cyphal registers: ``uavcan.node.id`` and named ports ``uavcan.sub.<mapping>.id/.type``,
  ``uavcan.pub.<mapping>.id/.type`` with the spec's subject ids as defaults, overridable from the environment
  (read by a Cyphal tool with uavcan.register.List/Access);
- defect 13: a device that reboots (its clock starts over) is not ``out_of_order``, on Cyphal/CAN (the heartbeat's
  uptime tells) and on Cyphal/UDP with the data before the first heartbeat (the transfer ids tell);
- defect 14: nodes that are no device (tools) coming and going are no warnings.

The scenarios run in a helper process (tests/helpers/glider_scenario.py). Time bounds come from the spec's rates:
grace = max(3 s, 5 periods); lower bounds are measured from events that precede the cause (a device's boot, the
stop of its publications), upper bounds are only the generous deadlines of the scenario's waits.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("can")
pytest.importorskip("rclpy")

from helpers.runtime_support import HELPERS, child_env, cyphal_udp_lock, domain_id
from helpers.spec_build import built_spec

from sam_runtime.bridge.liveness import grace_s

pytestmark = [pytest.mark.ros, pytest.mark.slow]

GRACE_ALTIMETER = grace_s(10.0)  # 3 s
GRACE_CTD = grace_s(2.0)  # 3 s (5 periods = 2.5 s < 3 s)


def _scenario(tmp: Path, mode: str, *extra: str, offset: int) -> dict[str, Any]:
    b = built_spec("glider")
    out = tmp / f"{mode}.json"
    cmd = [sys.executable, str(HELPERS / "glider_scenario.py"), mode, "--generated", str(b.generated),
           "--out", str(out), *extra]
    proc = subprocess.run(cmd, env=child_env(b.prefix, domain_id(offset)), capture_output=True, text=True,
                          timeout=300)
    (tmp / f"{mode}.stderr").write_text(proc.stderr)
    assert proc.returncode == 0 and out.exists(), f"scenario failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-6000:]}"
    res = json.loads(out.read_text())
    res["stderr"] = proc.stderr
    return res


@pytest.fixture(scope="module")
def can_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    import os

    return _scenario(tmp_path_factory.mktemp("glider_can"), "can", "--iface", f"virtual:glider{os.getpid()}",
                     offset=51)


@pytest.fixture(scope="module")
def udp_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    with cyphal_udp_lock():
        return _scenario(tmp_path_factory.mktemp("glider_udp"), "udp", offset=52)


def test_every_glider_mapping_with_a_publishing_device_reaches_ros(can_run: dict[str, Any]) -> None:
    """The messages the bridge builds for this spec (float32[2] from float16[2], bools, one subject to two
    topics) are accepted by rclpy and arrive: a wrongly shaped field would have crashed the scenario."""
    counts = can_run["probe_counts"]
    for topic in ("/fins/state", "/pump/status", "/pump/volume", "/ctd/altitude"):
        assert counts.get(topic, 0) > 0, counts
    assert "/altitude" not in counts  # the altimeter never publishes
    maps = can_run["bridge"]["mappings"]
    assert maps["pump_status"]["published"] == maps["pump_volume"]["published"] > 0


# ============================================================================================ defect 12
def test_registers_name_the_ports_after_the_mappings(can_run: dict[str, Any]) -> None:
    regs = can_run["phases"]["registers"]
    assert regs["uavcan.node.id"] == [110]
    subs = {"fin_state": (600, "glider.fin.State.0.1"), "pump_status": (610, "glider.pump.Status.0.1"),
            "altitude": (620, "glider.sensor.Altitude.0.1"),
            "ctd_altitude": (631, "glider.sensor.Altitude.0.1")}  # 630 in the spec, 631 from the environment
    pubs = {"fin_command": (601, "glider.fin.Command.0.1"), "pump_command": (611, "glider.pump.Command.0.1")}
    for kind, ports in (("sub", subs), ("pub", pubs)):
        for name, (subject, dtype) in ports.items():
            assert regs[f"uavcan.{kind}.{name}.id"] == [subject], name
            assert regs[f"uavcan.{kind}.{name}.type"] == dtype, name
    port_regs = {n for n in regs if n.startswith(("uavcan.sub.", "uavcan.pub."))}
    assert port_regs == {f"uavcan.{k}.{n}.{x}" for k, p in (("sub", subs), ("pub", pubs)) for n in p
                         for x in ("id", "type")}  # pump_volume shares pump_status's port; no numbered names
    # The override is what the bridge listens on: the CTD publishes on 631 and its messages are bridged.
    assert can_run["phases"]["stopped"]["published_at_stop"] >= 3
    assert can_run["bridge"]["mappings"]["ctd_altitude"]["subject_id"] == 631
    assert can_run["bridge"]["mappings"]["pump_volume"]["port"] == "uavcan.sub.pump_status"


# ============================================================================================ defect 6
MESSAGE = r"no message for (\d+) s while device {dev} \(node {nid}\) is alive; nominal {rate} Hz; {tail}"


def test_mapping_that_never_receives_while_its_device_is_alive_is_warned(can_run: dict[str, Any]) -> None:
    ph = can_run["phases"]["never_received"]
    d = ph["diagnostics"]
    assert d["level"] == 1
    assert re.fullmatch(MESSAGE.format(dev="altimeter", nid=22, rate=10, tail="never received"), d["message"]), d
    v = d["values"]
    assert v["liveness"] == "never_received" and v["received"] == "0"
    assert float(v["grace_s"]) == GRACE_ALTIMETER and float(v["silent_s"]) > GRACE_ALTIMETER
    assert ph["boot_to_warn_s"] >= GRACE_ALTIMETER  # not before the grace after the device appeared
    assert ph["stats"]["liveness"]["state"] == "never_received"
    warned = [r for r in can_run["log"] if r["level"] == "WARNING" and r["message"].startswith("altitude: ")]
    assert len(warned) == 1 and "never received" in warned[0]["message"]  # once, not every period


def test_mapping_that_stops_while_its_device_is_alive_is_warned_until_it_resumes(can_run: dict[str, Any]) -> None:
    ph = can_run["phases"]["stopped"]
    assert ph["level_before"] == 0 and ph["device_alive_at_warn"] is True
    d = ph["diagnostics_at_warn"]
    assert d["level"] == 1
    assert re.fullmatch(MESSAGE.format(dev="ctd", nid=23, rate=2, tail=r"the last one \d+ s ago"), d["message"]), d
    assert d["values"]["liveness"] == "stopped" and float(d["values"]["silent_s"]) > GRACE_CTD
    # The last message came at most one period before the stop.
    assert ph["stop_to_warn_s"] >= GRACE_CTD - 1.0 / 2.0
    assert ph["stats"]["liveness"] == {"state": "ok"}  # OK again once it publishes
    msgs = [r["message"] for r in can_run["log"] if r["message"].startswith("ctd_altitude: ")]
    assert any(m.startswith("ctd_altitude: no message for") for m in msgs)
    assert "ctd_altitude: messages again from device ctd (node 23)" in msgs


def test_device_without_heartbeat_is_not_flagged_silent(can_run: dict[str, Any]) -> None:
    """The pump powered off: its device is ERROR (its own status), its mappings are not 'silent'."""
    ph = can_run["phases"]["device_off"]
    assert ph["seconds_off"] > grace_s(5.0) + 1.0
    assert ph["pump_status"]["liveness"] == {"state": "ok"} and ph["pump_volume"]["liveness"] == {"state": "ok"}
    # The mappings that had their data all along never warned; the altimeter's once (for good). (The CTD's
    # also warned when it stopped; its reboot later may warn again: it is off for 2.5 s, its heartbeat not
    # yet timed out.)
    ev = {m: len(e) for m, e in can_run["warn_events"].items()}
    assert ev.pop("ctd_altitude") >= 1
    assert ev == {"fin_state": 0, "fin_command": 0, "pump_status": 0, "pump_volume": 0, "pump_command": 0,
                  "altitude": 1}, can_run["warn_events"]


# ============================================================================================ defect 13
@pytest.mark.parametrize("run", ["can_run", "udp_run"])
def test_a_rebooted_device_is_not_out_of_order(run: str, request: pytest.FixtureRequest) -> None:
    ph = request.getfixturevalue(run)["phases"]["restart"]
    assert ph["heartbeat_first"] is (run == "can_run")
    assert ph["first_stamp_after_reboot_us"] < ph["stamp_before_reboot_us"]  # its clock really started over
    assert ph["restarts"] == 1 and ph["published_after_reboot"] >= 4
    assert ph["out_of_order_before"] == 0 == ph["out_of_order_after_reboot"]
    assert ph["out_of_order_after_older_stamp"] == 1  # an older stamp within one boot still counts


# ============================================================================================ defect 14
def test_tools_coming_and_going_are_no_warnings(can_run: dict[str, Any]) -> None:
    tools = can_run["phases"]["tools"]
    assert tools["cycles"] == 2 and tools["stats"]["heartbeats"] >= 2 and not tools["stats"]["alive"]
    log = can_run["log"]
    about = [r for r in log if r["logger"] == "sam_runtime.bridge" and re.search(r"\bnode 12[56]\b", r["message"])]
    assert [r for r in about if r["level"] not in ("INFO", "DEBUG")] == [], about
    assert sorted(r["message"] for r in about) == [
        "node 125 (no device of the spec) appeared on the bus", "node 126 (no device of the spec) appeared on the bus"]
    # Devices still get their warnings.
    assert any(r["level"] == "WARNING" and r["message"].startswith("device pump (node 21): heartbeat lost")
               for r in log)
