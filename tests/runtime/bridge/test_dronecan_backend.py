"""The DroneCAN backend of the bridge core (runtime/bridge/backends/dronecan.py) against plain dronecan nodes on a
private loopback bus (sam_runtime.dronecan_io ``mcast-lo:``), in one process and one asyncio loop; not yet wired
to the spec (that is the v0 codegen's part).

- subscription by data type id: every RawIMU transfer reaches the handler with its source node id, transfer id and
  receive time; with the core's UAVCAN -> ROS path in front, a node the mapping does not accept is dropped and
  counted (``unknown_source``) and a skipped transfer id is ``lost``;
- broadcast: an RPMCommand the backend publishes reaches a dronecan listener from the bridge's node id;
- NodeStatus -> DeviceStatus -> the core's device health (OK / WARNING levels, restarts);
- a corrupted multi-frame transfer is counted below the bridge for its data type and source;
- the driver dying asks for a reopen; after close/open the ports work again;
- configuration errors: a data type id that does not match, an unknown type, a node id out of range.
"""

from __future__ import annotations

import asyncio
import collections
import logging
import threading
from types import SimpleNamespace as NS
from typing import Any

import pytest

dronecan = pytest.importorskip("dronecan")

from dronecan.driver.common import CANFrame  # noqa: E402
from helpers.dronecan_peer import raw_imu_message  # noqa: E402
from helpers.dronecan_support import frames_of, private_iface, until  # noqa: E402

from sam_runtime.bridge.backend import BridgeConfigError  # noqa: E402
from sam_runtime.bridge.backends.dronecan import DroneCanBackend, node_status  # noqa: E402
from sam_runtime.bridge.counters import MappingStats  # noqa: E402
from sam_runtime.bridge.health import DeviceHealth  # noqa: E402
from sam_runtime.common.rate_log import RateLimitedLog  # noqa: E402
from sam_runtime.dronecan_io import LoopbackMulticastDriver, NodeLoop, make_node, parse_iface  # noqa: E402

RAW_IMU = "uavcan.equipment.ahrs.RawIMU"
BRIDGE, IMU, STRANGER, ESC = 100, 10, 42, 20


def _backend(iface: str) -> DroneCanBackend:
    return DroneCanBackend(iface, BRIDGE, rlog=RateLimitedLog(logging.getLogger("test_dronecan_backend")),
                           errors=collections.Counter(), node_status_interval=0.2)


class Device:
    """A plain dronecan node (dronecan_io's receive path) on the bus, driven by its own NodeLoop."""

    def __init__(self, iface: str, node_id: int) -> None:
        self.node = make_node(iface, node_id, node_status_interval=0.2)
        self.loop = NodeLoop(self.node)
        self.rpm: list[tuple[int, list[int]]] = []
        self.loop.add_handler(dronecan.uavcan.equipment.esc.RPMCommand,
                              lambda e: self.rpm.append((e.transfer.source_node_id, list(e.message.rpm))))
        self.loop.start()

    def imu(self, seq: int) -> None:
        self.node.broadcast(raw_imu_message(seq, 1000 + seq))

    def close(self) -> None:
        self.loop.stop()
        self.node.close()


def test_subscribe_broadcast_and_node_status() -> None:
    iface = private_iface()

    async def main() -> dict[str, Any]:
        backend = _backend(iface)
        got: list[tuple[Any, int | None, int, float]] = []
        statuses: list[Any] = []
        inlet = backend.subscribe("imu", 1003, RAW_IMU, lambda *a: got.append(a))
        outlet = backend.advertise("esc", 1031, dronecan.uavcan.equipment.esc.RPMCommand)
        backend.on_device_status(statuses.append)
        assert not outlet.ready
        await backend.open()
        imu, stranger = Device(iface, IMU), Device(iface, STRANGER)
        try:
            await until(lambda: {s.node_id for s in statuses} >= {IMU, STRANGER}, 10, "both NodeStatus")
            for seq in range(5):
                imu.imu(seq)
            stranger.imu(99)
            await until(lambda: len(got) >= 6, 10, "six RawIMU")
            imu.node.health, imu.node.mode = 1, 0  # WARNING, OPERATIONAL
            n = len(statuses)
            await until(lambda: any(s.node_id == IMU and s.health == "WARNING" for s in statuses[n:]), 10,
                        "the WARNING NodeStatus")
            assert outlet.ready and await outlet.publish(dronecan.uavcan.equipment.esc.RPMCommand(rpm=[100, -200]))
            await until(lambda: imu.rpm, 10, "the RPMCommand at the device")
            backend.poll_statistics()
            return {"got": got, "statuses": statuses, "rpm": imu.rpm, "below": inlet.below.snapshot(),
                    "problem": backend.link_problem()}
        finally:
            imu.close()
            stranger.close()
            await backend.close()

    res = asyncio.run(main())
    got = res["got"]
    assert [(src, tid) for _, src, tid, _ in got] == [(IMU, t) for t in range(5)] + [(STRANGER, 0)]
    assert [m.timestamp.usec for m, *_ in got] == [1000, 1001, 1002, 1003, 1004, 1099]
    assert all(isinstance(t, float) and t > 0 for *_, t in got)
    assert res["rpm"] == [(BRIDGE, [100, -200])]
    imu_status = [s for s in res["statuses"] if s.node_id == IMU]
    first, last = imu_status[0], imu_status[-1]
    assert (first.health, first.level, first.mode) == ("OK", 0, "INITIALIZATION")  # as dronecan starts a node
    assert (last.health, last.level, last.mode) == ("WARNING", 1, "OPERATIONAL")
    totals, kinds, _ = res["below"]
    assert totals == {"transfers": 6} and kinds == {} and res["problem"] is None


def test_the_core_in_front_filters_sources_and_counts_losses() -> None:
    """The backend behind the core's UAVCAN -> ROS path and device health, as the bridge composes them."""
    from sam_runtime.bridge.inbound import Inbound, InMapping, PortGroup
    from sam_runtime.bridge.lifetime import Lifetime
    from sam_runtime.bridge.loss import TransferLoss

    iface = private_iface()
    published: list[Any] = []

    async def main() -> tuple[dict[str, Any], dict[str, Any]]:
        backend = _backend(iface)
        lifetime = Lifetime("t", RateLimitedLog(logging.getLogger("test_dronecan_backend")))
        health = DeviceHealth({IMU: "imu"}, BRIDGE)
        health.attach(lifetime)
        backend.on_device_status(health.on_status)
        info = NS(name="imu", source_node_ids=(IMU,), frame_id="", topic=NS(name="/imu"))
        im = InMapping(info, lambda msg, ns, st: msg, MappingStats(threading.Lock(), "imu"))
        loss = TransferLoss(1003, {(IMU, 1003): 100.0}, lambda: backend.transfer_id_modulo, health.uptime_of,
                            lambda: (), lambda nid: None)
        group = PortGroup(1003, "imu", RAW_IMU, [im], loss)
        ros = NS(receive_ns=lambda: 1, publisher=lambda topic, cls: NS(publish=published.append))
        inbound = Inbound(lifetime, [group], ros, backend)
        inbound.attach()
        lifetime.add_hooks("backend", start=backend.open, close=backend.close)
        await lifetime.start()
        imu, stranger = Device(iface, IMU), Device(iface, STRANGER)
        try:
            imu.node.mode = 0  # OPERATIONAL
            await until(lambda: health.entry(IMU).get("mode") == "OPERATIONAL", 10, "the IMU's NodeStatus")
            imu.imu(0)
            imu.node._next_transfer_id(1003)  # a transfer that never reached the bus
            imu.imu(2)
            stranger.imu(7)
            await until(lambda: im.stats.snapshot()["received"] >= 3, 10, "three RawIMU")
            return im.stats.snapshot(), health.entry(IMU)
        finally:
            imu.close()
            stranger.close()
            await lifetime.close()

    st, dev = asyncio.run(main())
    assert st["published"] == 2 and st["dropped"] == {"lost": 1, "unknown_source": 1}
    assert [m.timestamp.usec for m in published] == [1000, 1002]
    assert dev["alive"] and dev["health"] == "OK" and dev["mode"] == "OPERATIONAL"


def test_a_corrupted_transfer_is_counted_below_the_bridge_and_a_dead_driver_reopened() -> None:
    iface = private_iface()
    spec = parse_iface(iface)

    async def main() -> dict[str, Any]:
        backend = _backend(iface)
        got: list[Any] = []
        inlet = backend.subscribe("imu", 1003, RAW_IMU, lambda *a: got.append(a))
        await backend.open()
        raw = LoopbackMulticastDriver(spec.bus, spec.port)
        try:
            frames = [CANFrame(f.id, bytearray(f.data), True) for f in frames_of(raw_imu_message(3, 77), IMU, 5)]
            frames[2].data[1] ^= 0x10  # the transfer's CRC no longer matches
            for f in frames:
                raw.send_frame(f)
            for f in frames_of(raw_imu_message(4, 78), IMU, 6):
                raw.send_frame(f)
            await until(lambda: got, 10, "the valid RawIMU")
            await until(lambda: (backend.poll_statistics(), inlet.below.snapshot()[0].get("errors"))[1], 10,
                        "the corrupted one counted")
            before = inlet.below.snapshot()
            backend.node.can_driver.inner.close()  # the socket is gone (as a SocketCAN interface that went down)
            problem = backend.link_problem()
            await backend.close()
            assert backend.link_problem() == "no DroneCAN node"
            await backend.open()  # what the core's link supervisor does
            for f in frames_of(raw_imu_message(5, 79), IMU, 7):
                raw.send_frame(f)
            await until(lambda: len(got) >= 2, 10, "a RawIMU after the reopen")
            backend.poll_statistics()
            return {"before": before, "after": inlet.below.snapshot(), "problem": problem, "got": got}
        finally:
            raw.close()
            await backend.close()

    res = asyncio.run(main())
    totals, kinds, last_problem = res["before"]
    assert totals == {"transfers": 1, "errors": 1} and kinds == {f"crc_mismatch.node{IMU}": 1}
    assert last_problem is not None
    assert res["problem"] == "the CAN driver closed"
    assert res["after"][0] == {"transfers": 2, "errors": 1}  # cumulative across the reopen
    assert [tid for _, _, tid, _ in res["got"]] == [6, 7]


def test_configuration_errors() -> None:
    iface = private_iface()
    with pytest.raises(BridgeConfigError, match=r"1\.\.125"):
        _backend_with_id(iface, 126)

    async def main(port_id: int, dtype: str) -> None:
        backend = _backend(iface)
        backend.subscribe("x", port_id, dtype, lambda *a: None)
        await backend.open()

    with pytest.raises(BridgeConfigError, match="has data type id 1003, the spec says 1004"):
        asyncio.run(main(1004, RAW_IMU))
    with pytest.raises(BridgeConfigError, match=r"knows no data type 'sam\.Nothing'"):
        asyncio.run(main(20150, "sam.Nothing"))


def _backend_with_id(iface: str, node_id: int) -> DroneCanBackend:
    return DroneCanBackend(iface, node_id, rlog=RateLimitedLog(logging.getLogger("t")), errors=collections.Counter())


def test_node_status_of_a_critical_device_is_an_error() -> None:
    assert node_status(3, NS(health=3, mode=7, uptime_sec=1, vendor_specific_status_code=0)).level == 2
