"""DroneCAN across processes: a plain dronecan peer (tests/helpers/dronecan_peer.py) on the loopback multicast bus
and through dronecan's own SLCAN driver and an adapter stand-in on a pty, against a node run by
sam_runtime.dronecan_io.NodeLoop in this process.

Every bus is private to this test session (bus number and UDP port from the pid); every helper process runs in its
own session and its whole process group is killed at teardown.
"""

from __future__ import annotations

import asyncio
import itertools
import statistics
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

dronecan = pytest.importorskip("dronecan")

from helpers.dronecan_peer import imu_seq, raw_imu_fields, raw_imu_message, read_raw_imu  # noqa: E402
from helpers.dronecan_support import Child, private_iface, until  # noqa: E402

from sam_runtime.dronecan_io import NodeLoop, make_node  # noqa: E402

RAW_IMU = dronecan.uavcan.equipment.ahrs.RawIMU
pytestmark = pytest.mark.slow


@pytest.fixture
def children(tmp_path: Path) -> Iterator[Callable[[str, str, list[str]], Child]]:
    made: list[Child] = []

    def start(name: str, script: str, args: list[str]) -> Child:
        made.append(Child(name, script, args, tmp_path))
        return made[-1]

    yield start
    for child in made:
        child.kill()


def _percentiles(values_us: list[int]) -> str:
    q = statistics.quantiles(values_us, n=100)
    return f"p50 {q[49] / 1000:.2f} ms, p99 {q[98] / 1000:.2f} ms"


async def _exchange_imu(iface: str, peer: Child, n: int, rate: float) -> tuple[NodeLoop, dict[str, Any], str]:
    """Node 10 here and the peer (node 42) each send n RawIMU at `rate` once they see each other."""
    node = make_node(iface, 10, node_status_interval=0.5)
    nl = NodeLoop(node)
    received: list[int] = []
    mismatched: list[int] = []
    latencies: list[int] = []
    statuses: dict[int, Any] = {}
    publish_times: list[float] = []

    def on_imu(e: Any) -> None:
        now_us = time.monotonic_ns() // 1000
        got = read_raw_imu(e.message)
        received.append(imu_seq(e.message))
        latencies.append(now_us - got["timestamp"])
        if got != raw_imu_fields(received[-1], got["timestamp"]) or e.transfer.source_node_id != 42:
            mismatched.append(received[-1])

    def publish() -> None:
        if len(publish_times) < n:
            node.broadcast(raw_imu_message(len(publish_times), time.monotonic_ns() // 1000))
            publish_times.append(time.monotonic())

    nl.add_handler(RAW_IMU, on_imu)
    nl.add_handler(dronecan.uavcan.protocol.NodeStatus, lambda e: statuses.setdefault(e.transfer.source_node_id, 1))
    try:
        async with nl:
            await peer.wait_line("READY", 60.0)
            await until(lambda: 42 in statuses, 20.0, "the peer's NodeStatus")
            node.periodic(1.0 / rate, publish)
            nl.wake()
            budget = n / rate + 60.0  # the nominal time plus a margin for a loaded machine
            failure = ""
            try:
                await until(lambda: (len(received) >= n and len(publish_times) >= n) or peer.proc.poll() is not None,
                            budget, f"{n} RawIMU each way")
                await peer.wait_line("RECEIVED", budget)
                await peer.wait_line("PUBLISHED", budget)
            except AssertionError as ex:
                failure = f"{ex}; "
            summary = await peer.finish("SUMMARY")
            here = (f"here: published {len(publish_times)}, received {len(received)}, missing "
                    f"{sorted(set(range(n)) - set(received))[:20]}, drops {nl.snapshot()}, {nl.stats}; peer: "
                    f"published {summary['published']}, received {len(summary['received'])}, missing "
                    f"{sorted(set(range(n)) - set(summary['received']))[:20]}; peer log: {peer.stderr_tail()}")
            assert not failure, failure + here
    finally:
        node.close()
    assert received == list(range(n)) and mismatched == [], here
    assert summary["received"] == list(range(n)) and summary["mismatched"] == [], here
    assert nl.snapshot() == {}, here
    # Timing is the machine's business (dronecan's scheduler catches up after a stall); printed, not asserted.
    gap = statistics.median(b - a for a, b in itertools.pairwise(publish_times))
    figures = (f"peer->node {_percentiles(latencies)}; node->peer {_percentiles(summary['latencies_us'])}; "
               f"median publish interval {gap * 1000:.2f} ms; {nl.stats}")
    return nl, summary, figures


def test_raw_imu_200hz_both_ways_across_processes(children: Callable[..., Child]) -> None:
    iface = private_iface()
    peer = children("peer", "dronecan_peer.py", ["--iface", iface, "--node-id", "42", "--wait-for", "10",
                                                 "--publish-imu", "600", "--rate", "200", "--listen-imu-from", "10",
                                                 "--expect-imu", "600"])
    _, _, figures = asyncio.run(_exchange_imu(iface, peer, 600, 200.0))
    print(f"\nRawIMU 200 Hz x 3 s over mcast-lo, 0 lost: {figures}")


def test_node_status_and_get_node_info_across_processes(children: Callable[..., Child]) -> None:
    iface = private_iface()
    peer = children("peer", "dronecan_peer.py", ["--iface", iface, "--node-id", "42", "--query-info-of", "10"])

    async def scenario() -> None:
        info = dronecan.uavcan.protocol.GetNodeInfo.Response()
        info.name = "org.sam.test.bridge"
        node = make_node(iface, 10, node_status_interval=0.5, node_info=info)
        statuses: list[Any] = []
        replies: dict[int, Any] = {}
        async with NodeLoop(node) as nl:
            nl.add_handler(dronecan.uavcan.protocol.NodeStatus,
                           lambda e: statuses.append(e.message) if e.transfer.source_node_id == 42 else None)
            await peer.wait_line("READY", 60.0)
            await until(lambda: statuses, 20.0, "the peer's NodeStatus")
            assert (statuses[0].health, statuses[0].mode) == (0, 0)  # OK, OPERATIONAL
            t0 = time.monotonic()
            for target in (42, 99):  # 99 does not exist: dronecan's request timeout, run by the NodeLoop timer
                node.request(dronecan.uavcan.protocol.GetNodeInfo.Request(), target,
                             lambda e, t=target: replies.__setitem__(t, (e, time.monotonic() - t0)), timeout=0.3)
            nl.wake()
            await until(lambda: len(replies) == 2, 20.0, "the GetNodeInfo response and the timeout")
            event, _ = replies[42]
            assert event.response.name.decode() == "org.sam.test.peer"
            assert bytes(event.response.hardware_version.unique_id) == bytes(range(16))
            assert (event.response.software_version.major, event.response.software_version.minor) == (1, 27)
            assert replies[99][0] is None and replies[99][1] >= 0.3
            summary = await peer.finish("SUMMARY")
            assert summary["info"]["name"] == "org.sam.test.bridge" and summary["info"]["source"] == 10
            assert nl.snapshot() == {}
        node.close()

    asyncio.run(scenario())


def test_slcan_adapter_standin_exchanges_with_loopback_bus(children: Callable[..., Child]) -> None:
    """dronecan's own SLCAN driver (make_node('slcan:/dev/pts/N')) in one process, a node on the loopback bus in
    another, an adapter stand-in on a pty between them."""
    iface = private_iface()
    standin = children("standin", "slcan_standin.py", ["--bus", iface])

    async def scenario() -> tuple[str, dict[str, Any]]:
        pty = (await standin.wait_line("PTY ", 30.0)).split()[1]
        peer = children("slcan-peer", "dronecan_peer.py", [
            "--iface", f"slcan:{pty}", "--node-id", "42", "--wait-for", "10", "--publish-imu", "600",
            "--rate", "200", "--listen-imu-from", "10", "--expect-imu", "600"])
        try:
            _, _, figures = await _exchange_imu(iface, peer, 600, 200.0)
        except AssertionError as ex:
            raise AssertionError(f"{ex}; stand-in: {await standin.finish('STATS')}") from None
        # dronecan's SLCAN driver forked an IO process: it must have ended with the peer.
        await until(lambda: not peer.group_alive(), 20.0, f"the peer's process group to end: {peer.group_alive()}")
        stats = await standin.finish("STATS")
        return figures, stats

    figures, stats = asyncio.run(scenario())
    assert stats["bitrate"] == 1_000_000 and stats["rejected_lines"] == 0 and stats["bus_drops"] == {}
    print(f"\nRawIMU 200 Hz x 3 s, SLCAN (dronecan driver, pty stand-in) <-> mcast-lo, 0 lost: {figures}")
