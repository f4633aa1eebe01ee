"""The bridge on the glider test spec (tests/specs/glider.yaml) with devices the test plays itself (issue 11).

python glider_scenario.py can --iface virtual:NAME --generated DIR --out OUT.json
    All in this process, on one python-can virtual CAN FD bus: the bridge, the simulated fins and pump
    (sam_runtime.sim), the altimeter and the CTD played by :class:`ScriptedDevice` (heartbeats, and messages when
    and with what stamps the scenario says; their clock starts at 0 on every boot), an rclpy probe on the topics
    and /diagnostics, and Cyphal tools (node 125 reads the bridge's registers; node 126 comes and goes).
    Phases: registers; tools; a device that never publishes; one that stops and resumes; a device powered
    off; a device that reboots (heartbeat first, as devices boot) and then an older stamp without a reboot.
    UAVCAN__SUB__CTD_ALTITUDE__ID=631 moves the CTD's subscription (the CTD publishes on 631).
python glider_scenario.py udp --generated DIR --out OUT.json
    Cyphal/UDP on 127.0.0.1 (take the machine-wide lock): the bridge and the CTD only; the CTD reboots and
    sends three messages BEFORE its first heartbeat (the bridge can tell only from the transfer ids starting
    over), then an older stamp without a reboot.
Writes the figures as JSON; every log record of sam_runtime at INFO and above is in "log".
"""

from __future__ import annotations

import os

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

import argparse
import asyncio
import contextlib
import json
import logging
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fault_scenario import Probe, clean, wait_for

BRIDGE = "glider_bridge"
CTD_PORT_OVERRIDE = 631
TOOL_NODE_IDS = (125, 126)


class LogRecords(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.INFO)
        self.records: list[dict[str, Any]] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append({"t": time.monotonic(), "level": record.levelname, "logger": record.name,
                             "message": record.getMessage()})


class ScriptedDevice:
    """A device of the spec played by the test: its node id and heartbeat; it publishes its subject only when
    told, stamped by its own clock (microseconds since boot: it restarts at every boot)."""

    def __init__(self, gen: Any, name: str, transport: dict[str, Any], subject: int | None = None) -> None:
        self.gen = gen
        self.info = next(d for d in gen.tables().DEVICES if d.name == name)
        self.port = self.info.publishes[0]
        self.subject = self.port.subject_id if subject is None else subject
        self.transport = transport
        self.node: Any = None
        self.pub: Any = None
        self.booted = 0.0
        self.boots = 0
        self.sent = 0
        self.last_stamp_us = 0
        self.stamps: list[tuple[int, int]] = []  # (boot, stamp) of every message sent
        self._task: asyncio.Task[None] | None = None
        self._stop = asyncio.Event()

    def clock_us(self) -> int:
        return 1 + int((time.monotonic() - self.booted) * 1e6)

    async def boot(self, heartbeat: bool = True) -> None:
        from sam_runtime.cyphal_io.transport import make_node

        self.node = make_node(f"org.test.{self.info.name}", self.info.node_id, start=heartbeat, **self.transport)
        self.pub = self.node.make_publisher(self.gen.dsdl_class(self.port), self.subject)
        self.booted = time.monotonic()
        self.boots += 1

    def start_heartbeat(self) -> None:
        self.node.start()

    async def send(self, stamp_us: int | None = None) -> None:
        from sam_runtime.sim.simulator import generic_fill

        stamp = self.clock_us() if stamp_us is None else stamp_us
        msg = generic_fill(self.gen.dsdl_class(self.port)(), time.monotonic() - self.booted, stamp)
        if await self.pub.publish(msg):
            self.sent += 1
            self.last_stamp_us = stamp
            self.stamps.append((self.boots, stamp))

    def start_publishing(self) -> None:
        stop = self._stop = asyncio.Event()

        async def loop() -> None:
            period = 1.0 / self.port.rate_hz
            nxt = time.monotonic()
            while not stop.is_set():
                await self.send()
                nxt += period
                with contextlib.suppress(asyncio.TimeoutError):
                    await asyncio.wait_for(stop.wait(), max(0.0, nxt - time.monotonic()))

        self._task = asyncio.create_task(loop())

    async def stop_publishing(self) -> None:
        """Stops between two messages, never inside one: a publication cancelled after its frames left but before
        it was counted would make ``sent`` lag what the bridge received (the restart phase waits on that count)."""
        if self._task is not None:
            self._stop.set()
            await self._task
            self._task = None

    async def power_off(self) -> None:
        from sam_runtime.cyphal_io.transport import aclose

        await self.stop_publishing()
        await aclose(self.pub)
        await aclose(self.node)
        self.node = self.pub = None


async def read_registers(node: Any, server: int) -> dict[str, Any]:
    """uavcan.register.List then Access of every name, as a Cyphal tool (yakut) does."""
    import uavcan.register

    lister = node.make_client(uavcan.register.List_1_0, server)
    access = node.make_client(uavcan.register.Access_1_0, server)
    out: dict[str, Any] = {}
    try:
        for index in range(1000):
            res = await lister.call(uavcan.register.List_1_0.Request(index=index))
            if res is None:
                raise TimeoutError(f"no answer to uavcan.register.List index {index}")
            name = res[0].name.name.tobytes().decode()
            if not name:
                break
            acc = await access.call(uavcan.register.Access_1_0.Request(name=uavcan.register.Name_1_0(name)))
            if acc is None:
                raise TimeoutError(f"no answer to uavcan.register.Access {name}")
            v = acc[0].value
            if v.natural16 is not None:
                out[name] = [int(x) for x in v.natural16.value]
            elif v.string is not None:
                out[name] = v.string.value.tobytes().decode()
            else:
                out[name] = str(v)
    finally:
        lister.close()
        access.close()
    return out


def mapping_stats(bridge: Any, name: str) -> dict[str, Any]:
    return bridge.stats()["mappings"][name]


def diag(probe: Probe, mapping: str) -> dict[str, Any] | None:
    return probe.diag_latest.get(f"{BRIDGE}/mapping/{mapping}")


def warn_events(probe: Probe, mapping: str) -> list[dict[str, Any]]:
    return [e for e in probe.diag_events if e["name"] == f"{BRIDGE}/mapping/{mapping}" and e["level"] != 0]


async def tools_come_and_go(transport: dict[str, Any], bridge: Any) -> dict[str, Any]:
    """Node 126 (a tool such as yakut) appears, leaves, appears, leaves: the bridge must not warn about it."""
    from sam_runtime.cyphal_io.transport import aclose, make_node

    seen = []
    for _ in range(2):
        node = make_node("org.test.tool", TOOL_NODE_IDS[1], **transport)
        await wait_for(lambda: bridge.stats()["other_nodes"].get(str(TOOL_NODE_IDS[1]), {}).get("alive"), 10,
                       "the bridge seeing tool node 126")
        seen.append(True)
        await aclose(node)
        await wait_for(lambda: not bridge.stats()["other_nodes"][str(TOOL_NODE_IDS[1])]["alive"], 10,
                       "the bridge noticing tool node 126 gone")
    return {"cycles": len(seen), "stats": bridge.stats()["other_nodes"].get(str(TOOL_NODE_IDS[1]))}


async def phase_never_received(bridge: Any, probe: Probe, alt: ScriptedDevice) -> dict[str, Any]:
    """The altimeter heartbeats and never publishes."""
    await alt.boot()
    t_boot = time.monotonic()
    await wait_for(lambda: bridge.stats()["devices"]["altimeter"]["alive"], 10, "the altimeter's heartbeat")
    t_alive = time.monotonic()
    await wait_for(lambda: (diag(probe, "altitude") or {}).get("level") == 1, 20,
                   "the altitude mapping at WARN on /diagnostics")
    t_warn = time.monotonic()
    return {"boot_to_alive_s": t_alive - t_boot, "alive_to_warn_s": t_warn - t_alive,
            "boot_to_warn_s": t_warn - t_boot, "diagnostics": diag(probe, "altitude"),
            "stats": mapping_stats(bridge, "altitude")}


async def phase_stopped(bridge: Any, probe: Probe, ctd: ScriptedDevice) -> dict[str, Any]:
    """The CTD publishes (on its overridden port), stops while its heartbeat goes on, then resumes."""
    await wait_for(lambda: mapping_stats(bridge, "ctd_altitude")["published"] >= 3, 15, "CTD messages bridged")
    ok_before = (diag(probe, "ctd_altitude") or {}).get("level")
    await ctd.stop_publishing()
    t_stop = time.monotonic()
    published_at_stop = mapping_stats(bridge, "ctd_altitude")["published"]
    await wait_for(lambda: (diag(probe, "ctd_altitude") or {}).get("level") == 1, 20,
                   "the ctd_altitude mapping at WARN on /diagnostics")
    t_warn = time.monotonic()
    at_warn = diag(probe, "ctd_altitude")
    device_alive = bridge.stats()["devices"]["ctd"]["alive"]
    ctd.start_publishing()
    t_resume = time.monotonic()
    await wait_for(lambda: (diag(probe, "ctd_altitude") or {}).get("level") == 0, 15,
                   "the ctd_altitude mapping OK again")
    return {"level_before": ok_before, "stop_to_warn_s": t_warn - t_stop, "resume_to_ok_s": time.monotonic() - t_resume,
            "published_at_stop": published_at_stop, "diagnostics_at_warn": at_warn,
            "device_alive_at_warn": device_alive, "stats": mapping_stats(bridge, "ctd_altitude")}


async def phase_device_off(bridge: Any, probe: Probe, sim: Any) -> dict[str, Any]:
    """The pump loses power: its device is ERROR, its mappings are not flagged as silent (it is not alive)."""
    await sim.power_off("pump")
    t_off = time.monotonic()
    await wait_for(lambda: (probe.diag_latest.get(f"{BRIDGE}/device/pump") or {}).get("level") == 2, 15,
                   "the pump at ERROR on /diagnostics")
    grace = mapping_stats(bridge, "pump_status")  # nothing silent-flagged so far
    # Well past the mapping's grace (5 Hz: 3 s) after its last message, and two more /diagnostics after that.
    await asyncio.sleep(max(0.0, t_off + 3.0 + 1.0 - time.monotonic()))
    n0 = probe.diag_messages
    await wait_for(lambda: probe.diag_messages >= n0 + 2, 10, "two more /diagnostics")
    res = {"stats_at_error": grace, "pump_status": mapping_stats(bridge, "pump_status"),
           "pump_volume": mapping_stats(bridge, "pump_volume"), "diag_pump_status": diag(probe, "pump_status"),
           "seconds_off": time.monotonic() - t_off}
    await sim.power_on("pump")
    return res


async def phase_restart(bridge: Any, ctd: ScriptedDevice, *, heartbeat_first: bool) -> dict[str, Any]:
    """The CTD reboots (its clock starts at 0 again), publishes on; then a stamp older than the previous one
    without a reboot: exactly that one is out_of_order."""
    m = "ctd_altitude"
    await wait_for(lambda: mapping_stats(bridge, m)["published"] >= 3, 15, "CTD messages bridged")
    await wait_for(lambda: bridge.stats()["devices"]["ctd"]["uptime_s"] >= 1, 10, "the CTD's uptime >= 1 s")
    before = mapping_stats(bridge, m)
    restarts0 = bridge.stats()["devices"]["ctd"]["restarts"]
    stamp_before = ctd.last_stamp_us
    await ctd.power_off()
    await asyncio.sleep(2.5)  # longer than the 2 s transfer-id timeout: the new transfer ids are accepted
    await ctd.boot(heartbeat=heartbeat_first)
    sent0 = ctd.sent
    if heartbeat_first:
        await asyncio.sleep(0.3)  # the device initialises, then publishes
        ctd.start_publishing()
    else:
        for _ in range(3):
            await ctd.send()
            await asyncio.sleep(0.5)
        ctd.start_heartbeat()
        ctd.start_publishing()
    await wait_for(lambda: mapping_stats(bridge, m)["published"] >= before["published"] + 4, 15,
                   "the rebooted CTD's messages bridged")
    after_reboot = mapping_stats(bridge, m)
    await wait_for(lambda: bridge.stats()["devices"]["ctd"]["restarts"] > restarts0, 10, "the restart counted")
    # A message bridged after the restart was counted: the heartbeat that tells of the restart may arrive after a
    # message of the new boot and rightly forget its stamp; the control below needs a stamp to compare with.
    published_at_restart = mapping_stats(bridge, m)["published"]
    await wait_for(lambda: mapping_stats(bridge, m)["published"] > published_at_restart, 10,
                   "a CTD message after the restart was counted")
    # Control: a stamp older than the previous one, from the same boot, is out of order.
    await ctd.stop_publishing()
    # Everything the CTD sent since it first booted (after the bridge started) has arrived: nothing in flight.
    await wait_for(lambda: mapping_stats(bridge, m)["received"] >= ctd.sent, 10, "every CTD message at the bridge")
    await ctd.send(stamp_us=ctd.last_stamp_us - 100_000)
    await wait_for(lambda: mapping_stats(bridge, m)["received"] >= ctd.sent, 10, "the older stamp at the bridge")
    final = mapping_stats(bridge, m)
    ctd.start_publishing()
    after = [stamp for boot, stamp in ctd.stamps if boot == ctd.boots]
    return {"stamp_before_reboot_us": stamp_before, "first_stamp_after_reboot_us": after[0],
            "sent_after_reboot": ctd.sent - sent0,
            "out_of_order_before": before["out_of_order"], "out_of_order_after_reboot": after_reboot["out_of_order"],
            "out_of_order_after_older_stamp": final["out_of_order"],
            "published_after_reboot": after_reboot["published"] - before["published"],
            "restarts": bridge.stats()["devices"]["ctd"]["restarts"] - restarts0, "heartbeat_first": heartbeat_first}


async def main_can(args: argparse.Namespace, log: LogRecords) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge, TransportConfig
    from sam_runtime.cyphal_io.transport import aclose, make_node
    from sam_runtime.genpkg import GeneratedPackage
    from sam_runtime.sim.simulator import SimConfig, Simulator

    gen = GeneratedPackage(args.generated)
    gen.compile_dsdl()
    tables = gen.tables()
    transport = {"kind": "can", "iface": args.iface, "mtu": 64}
    os.environ["UAVCAN__SUB__CTD_ALTITUDE__ID"] = str(CTD_PORT_OVERRIDE)  # the bridge's registers read it
    bridge = Bridge(gen, transport=TransportConfig("can", args.iface, 64), diagnostics_period=0.5, log_interval=2.0)
    await bridge.start()
    sim = Simulator(gen, SimConfig("can", args.iface, 64, devices=["fins", "pump"]))
    await sim.start(publish_now=True)
    in_topics = sorted({m.topic.name for m in tables.MAPPINGS if m.direction == "uavcan_to_ros"})
    probe = Probe(gen, in_topics, [])
    alt = ScriptedDevice(gen, "altimeter", transport)
    ctd = ScriptedDevice(gen, "ctd", transport, subject=CTD_PORT_OVERRIDE)
    result: dict[str, Any] = {"iface": args.iface}
    phases: dict[str, Any] = {}
    try:
        await wait_for(lambda: all(probe.node.count_publishers(t) > 0 for t in in_topics), 20, "ROS discovery")
        await ctd.boot()
        ctd.start_publishing()
        tool = make_node("org.test.registers", TOOL_NODE_IDS[0], **transport)
        try:
            phases["registers"] = await read_registers(tool, bridge.node_id)
        finally:
            await aclose(tool)
        tools, phases["never_received"] = await asyncio.gather(tools_come_and_go(transport, bridge),
                                                               phase_never_received(bridge, probe, alt))
        phases["tools"] = tools
        phases["stopped"] = await phase_stopped(bridge, probe, ctd)
        phases["device_off"] = await phase_device_off(bridge, probe, sim)
        phases["restart"] = await phase_restart(bridge, ctd, heartbeat_first=True)
        n0 = probe.diag_messages
        await wait_for(lambda: probe.diag_messages >= n0 + 2, 10, "two more /diagnostics")
        result["warn_events"] = {m.name: warn_events(probe, m.name) for m in tables.MAPPINGS}
        result["diag_events"] = probe.diag_events
        result["probe_counts"] = dict(probe.counts)
        result["diagnostics"] = probe.diag_latest
        result["bridge"] = bridge.stats()
    finally:
        probe.close()
        for dev in (alt, ctd):
            if dev.node is not None:
                await dev.power_off()
        await sim.close()
        await bridge.close()
    result["phases"] = phases
    return result


async def main_udp(args: argparse.Namespace, log: LogRecords) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge, TransportConfig
    from sam_runtime.genpkg import GeneratedPackage

    gen = GeneratedPackage(args.generated)
    gen.compile_dsdl()
    transport = {"kind": "udp", "iface": "127.0.0.1"}
    bridge = Bridge(gen, transport=TransportConfig("udp", "127.0.0.1"), diagnostics_period=0.5, log_interval=2.0)
    await bridge.start()
    ctd = ScriptedDevice(gen, "ctd", transport)
    result: dict[str, Any] = {}
    try:
        await ctd.boot()
        ctd.start_publishing()
        result["phases"] = {"restart": await phase_restart(bridge, ctd, heartbeat_first=False)}
        result["bridge"] = bridge.stats()
    finally:
        if ctd.node is not None:
            await ctd.power_off()
        await bridge.close()
    return result


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=("can", "udp"))
    p.add_argument("--iface", default="virtual:glider")
    p.add_argument("--generated", type=Path, required=True)
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    log = LogRecords()
    logging.getLogger("sam_runtime").addHandler(log)
    t0 = time.monotonic()
    res = asyncio.run(main_can(args, log) if args.mode == "can" else main_udp(args, log))
    res["log"] = [dict(r, t=round(r["t"] - t0, 3)) for r in log.records]
    res["seconds"] = round(time.monotonic() - t0, 1)
    args.out.write_text(json.dumps(clean(res), default=str))
    print("DONE", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
