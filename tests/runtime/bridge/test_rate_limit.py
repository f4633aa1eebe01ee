"""A mapping's rate limit, command deadline and enable switch in the bridge core (issue 19), on a fake clock: no
transport, no ROS node, no wall clock in any verdict.

- rate_limit.LatestGate / Pacer: the latest item at most max_rate_hz, trailing edge (the last one of a stream that
  stops goes out), never two closer than the interval, at most most_in(T, rate) in any window, every item either
  out or superseded (counted);
- rate_limit.expired: older than the deadline when it would be sent;
- inbound (UAVCAN -> ROS): rate_limited drops, the held message published when its slot comes, a disabled mapping
  converting nothing and counting ``disabled``, a held message dropped when the mapping is disabled meanwhile;
- outbound (ROS -> UAVCAN): commands coalesced, expired ones not sent (the worker's injected clock), disabled ones
  dropped before conversion and in the queue; a managed bridge's inactive outbound (issue 30) sends nothing it
  takes, queued or held, and counts it ``inactive`` without a WARN;
- switches: the SetBool answer; diagnostics: intended drops do not WARN, an expired command does.
"""

from __future__ import annotations

import asyncio
import heapq
import itertools
import logging
import random
import threading
from collections.abc import Callable
from types import SimpleNamespace as NS
from typing import Any

import pytest

from sam_runtime.bridge.counters import MappingStats
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.loss import TransferLoss
from sam_runtime.bridge.rate_limit import LatestGate, Pacer, expired, most_in
from sam_runtime.bridge.switches import MappingSwitch, switches_of
from sam_runtime.common.rate_log import RateLimitedLog


class FakeLoop:
    """An event loop's clock and timers (time, call_at, call_soon_threadsafe), advanced by the test."""

    def __init__(self, now: float = 100.0) -> None:
        self.now = now
        self._timers: list[tuple[float, int, Callable[[], Any], NS]] = []
        self._seq = itertools.count()

    def time(self) -> float:
        return self.now

    def call_at(self, when: float, callback: Callable[[], Any]) -> NS:
        handle = NS(cancelled=False)
        handle.cancel = lambda: setattr(handle, "cancelled", True)
        heapq.heappush(self._timers, (when, next(self._seq), callback, handle))
        return handle

    def call_soon_threadsafe(self, callback: Callable[[], Any], *args: Any) -> None:
        callback(*args)

    def is_closed(self) -> bool:
        return False

    def advance(self, to: float) -> None:
        """Run the timers due by ``to`` in time order, the clock at each one's time."""
        while self._timers and self._timers[0][0] <= to:
            when, _, callback, handle = heapq.heappop(self._timers)
            self.now = max(self.now, when)
            if not handle.cancelled:
                callback()
        self.now = max(self.now, to)

    @property
    def armed(self) -> int:
        return sum(not h.cancelled for *_, h in self._timers)


# ============================================================================================ the gate
def test_gate_passes_the_first_holds_the_latest_and_lets_it_out_at_its_slot() -> None:
    gate = LatestGate(8.0)  # 0.125 s slots (exact in binary)
    assert gate.offer("a", 1.0) == ("a", None)
    assert gate.offer("b", 1.0625) == (None, None) and gate.due_at == 1.125
    assert gate.offer("c", 1.09375) == (None, "b")  # the newer one replaces the held one
    assert gate.take_due(1.1) is None  # not yet
    assert gate.take_due(1.125) == "c" and gate.pending is None and gate.due_at is None
    assert gate.offer("d", 1.1875) == (None, None)  # 0.0625 s after "c" went out: held
    assert gate.take_due(1.25) == "d"
    assert gate.offer("e", 1.5) == ("e", None)  # a free slot: at once
    assert gate.clear() is None
    with pytest.raises(ValueError):
        LatestGate(0.0)
    with pytest.raises(ValueError):
        LatestGate(float("inf"))


def test_most_in_and_expired() -> None:
    assert [most_in(t, 5.0) for t in (0.0, 0.19, 0.2, 1.0, 2.01)] == [1, 1, 2, 6, 11]
    assert not expired(5.0, 5.25, 0.25) and expired(5.0, 5.2501, 0.25) and not expired(5.0, 1e9, None)


@pytest.mark.parametrize("seed", range(5))
def test_pacer_over_random_arrivals_keeps_every_promise(seed: int) -> None:
    """Bursts, gaps and a final stop at random times: outputs never closer than the interval, at most most_in in
    any window, every item out or superseded exactly once, and the last one always out (trailing edge)."""
    rng = random.Random(seed)
    rate = rng.choice([2.0, 5.0, 20.0, 50.0])
    loop, out, superseded = FakeLoop(), [], []
    pacer = Pacer(rate, lambda item: out.append((loop.now, item)), superseded.append)
    pacer.loop = loop
    t, items = loop.now, []
    for i in range(400):
        t += rng.choice([0.0, 0.001, rng.uniform(0, 0.05), rng.uniform(0.1, 0.6)])
        loop.advance(t)
        pacer.offer(i)
        items.append(i)
    loop.advance(t + 10.0)  # the stream stopped: the held one goes out when its slot comes
    times = [when for when, _ in out]
    interval = 1.0 / rate
    assert all(b - a >= interval - 1e-9 for a, b in itertools.pairwise(times))
    for i, start in enumerate(times):  # every window starting at an output (the worst ones)
        for window in (interval * 0.999, interval * 3.5, 1.0):
            assert sum(1 for x in times[i:] if x <= start + window) <= most_in(window, rate)
    sent = [item for _, item in out]
    assert sorted(sent + superseded) == items and not set(sent) & set(superseded)
    assert sent[-1] == items[-1] and sent == sorted(sent)  # the last value is never lost, order is kept
    assert loop.armed == 0 and pacer.gate.pending is None
    assert len(sent) < len(items)  # it did limit something


def test_pacer_close_disarms_and_returns_the_held_item() -> None:
    loop, out = FakeLoop(), []
    pacer = Pacer(1.0, out.append, lambda _: None)
    pacer.loop = loop
    pacer.offer("a")
    pacer.offer("b")
    assert loop.armed == 1 and pacer.close() == "b" and loop.armed == 0
    loop.advance(loop.now + 5)
    assert out == ["a"]


# ============================================================================================ inbound
class FakeRos:
    def __init__(self) -> None:
        self.published: list[Any] = []

    def receive_ns(self) -> int:
        return 5_000_000_000

    def publisher(self, topic: Any, cls: Any) -> Any:
        return NS(publish=self.published.append)


def _lifetime() -> Lifetime:
    return Lifetime("t", RateLimitedLog(logging.getLogger("test_rate_limit")))


def _inbound(max_rate_hz: float | None) -> tuple[Any, Any, FakeRos, Any, FakeLoop, list[Any]]:
    from sam_runtime.bridge.inbound import Inbound, InMapping, PortGroup

    converted: list[Any] = []

    def to_ros(msg: Any, receive_ns: int, stats: Any) -> Any:
        converted.append(msg)
        return NS(value=msg)

    info = NS(name="level", source_node_ids=(10,), frame_id=None, topic=NS(name="/level"), max_rate_hz=max_rate_hz)
    im = InMapping(info, to_ros, MappingStats(threading.Lock(), "level"))
    group = PortGroup(100, "level", object, [im],
                      TransferLoss(100, {}, lambda: 2**64, lambda nid: None, lambda: [], lambda nid: None))
    ros, loop = FakeRos(), FakeLoop()
    inbound = Inbound(_lifetime(), [group], ros, backend=None)  # type: ignore[arg-type]
    im.ros_publisher = ros.publisher(info.topic, None)
    if im.pacer is not None:
        im.pacer.loop = loop
    return inbound, inbound.handler(group), ros, im, loop, converted


def test_inbound_rate_limit_publishes_the_latest_and_counts_the_rest() -> None:
    _, on_transfer, ros, im, loop, _ = _inbound(5.0)  # 0.2 s slots
    for i in range(10):  # 10 transfers within 0.09 s
        loop.advance(loop.now + 0.01)
        on_transfer(i, 10, i, loop.now)
    assert [m.value for m in ros.published] == [0]
    loop.advance(loop.now + 1.0)
    assert [m.value for m in ros.published] == [0, 9]  # the last value was not lost
    st = im.stats.snapshot()
    assert st["received"] == 10 and st["published"] == 2 and st["dropped"] == {"rate_limited": 8}
    assert st["last_drop_age_s"] is None  # an intended drop: no WARN on /diagnostics


def test_inbound_disabled_mapping_converts_nothing_and_counts() -> None:
    _, on_transfer, ros, im, loop, converted = _inbound(5.0)
    on_transfer(1, 10, 0, 1.0)
    on_transfer(2, 10, 1, 1.01)  # held for its slot ...
    im.switch = MappingSwitch("level", "~/enable_level")
    assert im.switch.set(False) == "mapping level: disabled"
    loop.advance(loop.now + 1.0)  # ... and the mapping was disabled meanwhile: not published
    on_transfer(3, 10, 2, 1.5)
    on_transfer(4, 10, 4, 1.6)  # one lost before it: still counted while disabled
    assert converted == [1, 2] and [m.value for m in ros.published] == [1]
    st = im.stats.snapshot()
    assert st["dropped"] == {"disabled": 3, "lost": 1} and st["received"] == 4
    assert im.switch.set(True) == "mapping level: enabled" and im.switch.set(True) == "mapping level: already enabled"
    loop.advance(loop.now + 1.0)
    on_transfer(5, 10, 5, 2.0)
    assert [m.value for m in ros.published] == [1, 5] and im.switch.changes == 2 and im.switch.requests == 3


def test_inbound_without_a_rate_limit_publishes_every_message() -> None:
    _, on_transfer, ros, im, _, _ = _inbound(None)
    for i in range(5):
        on_transfer(i, 10, i, 1.0)
    assert im.pacer is None and len(ros.published) == 5


# ============================================================================================ outbound
def _outbound(max_rate_hz: float | None, deadline_s: float | None) -> tuple[Any, Any, FakeLoop]:
    from sam_runtime.bridge.outbound import Outbound, OutMapping

    lifetime = _lifetime()
    info = NS(name="valve", topic=NS(name="/valve"), max_rate_hz=max_rate_hz, deadline_s=deadline_s)

    def to_uavcan(msg: Any, stats: Any) -> Any:
        return None if msg == "reject" else msg

    om = OutMapping(info, to_uavcan, MappingStats(threading.Lock(), "valve", lifetime.rlog))
    out = Outbound(lifetime, [om], lambda: True, queue_size=100)
    loop = FakeLoop()
    out.handoff.loop = loop  # type: ignore[assignment]
    om.queue = asyncio.Queue(maxsize=100)
    if om.pacer is not None:
        om.pacer.loop = loop
    return out, om, loop


def _queued(om: Any) -> list[Any]:
    return [om.queue.get_nowait() for _ in range(om.queue.qsize())]


def test_outbound_coalesces_commands_to_the_latest() -> None:
    out, om, loop = _outbound(2.0, None)
    for i in range(6):
        out.on_ros([om], i)
        loop.advance(loop.now + 0.05)
    assert _queued(om) == [0]
    loop.advance(loop.now + 1.0)
    assert _queued(om) == [5]
    assert om.stats.snapshot()["dropped"] == {"coalesced": 4}


def test_outbound_disabled_drops_before_conversion() -> None:
    out, om, _ = _outbound(None, None)
    om.switch = switches_of([NS(name="valve", enabled=False, enable_service="start_stop_valve")])["valve"]
    assert om.switch.service == "start_stop_valve" and not om.switch.enabled
    out.on_ros([om], 1)
    assert _queued(om) == [] and om.stats.snapshot()["dropped"] == {"disabled": 1}
    assert switches_of([NS(name="x")])["x"] == MappingSwitch("x", "~/enable_x", True)  # older tables


class FakeOutlet:
    ready = True
    send_timeout = 1.0

    def __init__(self) -> None:
        self.sent: list[Any] = []

    async def publish(self, obj: Any) -> bool:
        self.sent.append(obj)
        return True


def test_outbound_worker_drops_expired_and_disabled_commands() -> None:
    """The deadline is judged when the command would be sent, on the worker's clock (injected)."""
    out, om, _ = _outbound(None, 0.25)
    outlet = om.outlet = FakeOutlet()
    now = [50.0]
    out.clock = lambda: now[0]
    out.on_ros([om], "taken")  # stamped with the clock when the rclpy callback takes it
    assert _queued(om) == [("taken", 50.0)]

    async def main() -> None:
        assert om.queue is not None
        worker = asyncio.create_task(out._worker(om))
        for item, at in ((("a", 10.00), 10.25), (("b", 10.00), 10.26), (("c", 20.0), 20.1)):
            now[0] = at
            om.queue.put_nowait(item)
            await asyncio.sleep(0)
        om.switch = MappingSwitch("valve")
        om.switch.set(False)
        om.queue.put_nowait(("d", 20.1))  # queued before it was disabled: not sent either
        await asyncio.sleep(0)
        await asyncio.sleep(0)
        worker.cancel()
        await asyncio.gather(worker, return_exceptions=True)

    asyncio.run(main())
    assert outlet.sent == ["a", "c"]
    st = om.stats.snapshot()
    assert st["dropped"] == {"expired": 1, "disabled": 1} and st["published"] == 2
    assert st["last_drop_age_s"] is not None  # an expired command is trouble: WARN on /diagnostics


def test_an_inactive_outbound_sends_nothing_taken_queued_or_held_and_counts_it() -> None:
    """A managed bridge deactivated (sam_runtime.bridge.managed): the command taken after it, the one queued before
    it and the one its pacer held are all dropped as ``inactive``; active again, commands go out."""
    out, om, loop = _outbound(2.0, None)
    outlet = om.outlet = FakeOutlet()
    out.on_ros([om], "queued")  # the pacer lets the first out at once: queued
    out.on_ros([om], "held")  # held for its slot
    out.active = False
    out.on_ros([om], "taken")  # dropped before conversion
    loop.advance(loop.now + 1.0)  # the held one reaches the queue after the deactivation

    async def main() -> None:
        assert om.queue is not None
        worker = asyncio.create_task(out._worker(om))
        await asyncio.sleep(0)
        await asyncio.sleep(0)
        assert om.queue.empty()
        out.active = True
        out.on_ros([om], "again")
        loop.advance(loop.now + 1.0)
        await asyncio.sleep(0)
        await asyncio.sleep(0)
        worker.cancel()
        await asyncio.gather(worker, return_exceptions=True)

    asyncio.run(main())
    assert outlet.sent == ["again"]
    st = om.stats.snapshot()
    assert st["dropped"] == {"inactive": 3} and st["published"] == 1 and st["received"] == 4
    assert st["last_drop_age_s"] is None  # asked for by the lifecycle manager: no WARN


# ============================================================================================ diagnostics
def test_diagnostics_show_the_traffic_control() -> None:
    pytest.importorskip("diagnostic_msgs")
    from sam_runtime.bridge.diagnostics import Naming, diagnostic_array

    base = {"direction": "ros_to_uavcan", "topic": "/valve", "subject_id": 101, "port": "uavcan.pub.valve",
            "received": 9, "published": 2, "dropped_total": 7, "dropped": {"coalesced": 5, "disabled": 2},
            "saturated": {}, "saturated_total": 0, "rejected_fields": {}, "out_of_order": 0, "last_drop_age_s": None,
            "max_rate_hz": 2.0, "deadline_s": 0.25, "enabled": False, "enable_service": "~/enable_valve"}
    snap = {"bridge": {"node_id": 100, "transport": "fake", "uptime_s": 1.0, "errors": {},
                       "link": {"up": True, "state": "up", "outages": 0, "down_s": 0.0}},
            "mappings": {"valve": base}, "devices": {}}
    arr = diagnostic_array(snap, Naming("bridge", "cyphal", "Cyphal", "pycyphal"), None)
    status = next(s for s in arr.status if s.name == "bridge/mapping/valve")
    values = {kv.key: kv.value for kv in status.values}
    assert values["enabled"] == "False" and values["enable_service"] == "~/enable_valve"
    assert values["max_rate_hz"] == "2.0" and values["deadline_s"] == "0.25"
    assert values["dropped.coalesced"] == "5" and values["dropped.disabled"] == "2"
    assert status.level == b"\x00" and status.message.startswith("disabled (std_srvs/SetBool ~/enable_valve)")
    bridge = next(s for s in arr.status if s.name == "bridge")
    assert "inactive" not in bridge.message and {kv.key: kv.value for kv in bridge.values}["active"] == "True"
    snap["bridge"]["active"] = False  # a managed bridge not activated (issue 30)
    bridge = next(s for s in diagnostic_array(snap, Naming("bridge", "cyphal", "Cyphal", "pycyphal"), None).status
                  if s.name == "bridge")
    assert bridge.message.startswith("inactive (lifecycle): commands dropped")
    assert {kv.key: kv.value for kv in bridge.values}["active"] == "False" and bridge.level == b"\x00"


# ============================================================================================ SetBool services
def test_enable_services_names_resolve_under_the_node_and_its_namespace() -> None:
    """`~/enable_<mapping>` lands under the bridge node's name, a relative name in its namespace; a call flips the
    switch, answers, and asks for /diagnostics at once."""
    rclpy = pytest.importorskip("rclpy")
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.signals import SignalHandlerOptions
    from std_srvs.srv import SetBool

    from sam_runtime.bridge.switches import EnableServices

    ctx = rclpy.Context()
    rclpy.init(args=[], context=ctx, domain_id=97, signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = Node("weir_bridge", namespace="/v1", context=ctx)
        switches = switches_of([NS(name="level", enabled=True, enable_service="~/enable_level"),
                                NS(name="gate", enabled=False, enable_service="start_stop_gate")])
        changed: list[int] = []
        services = EnableServices(_lifetime(), NS(node=node), switches, on_change=lambda: changed.append(1))
        services._start()
        assert services.resolved("level") == "/v1/weir_bridge/enable_level"
        assert services.resolved("gate") == "/v1/start_stop_gate"
        assert switches["level"].snapshot()["enable_service"] == "/v1/weir_bridge/enable_level"  # /diagnostics
        client = node.create_client(SetBool, "/v1/start_stop_gate")
        executor = SingleThreadedExecutor(context=ctx)
        executor.add_node(node)
        future = client.call_async(SetBool.Request(data=True))
        executor.spin_until_future_complete(future, timeout_sec=10.0)
        answer = future.result()
        assert answer is not None and answer.success and answer.message == "mapping gate: enabled"
        assert switches["gate"].enabled and changed == [1]
        executor.shutdown(timeout_sec=1.0)
        node.destroy_node()
    finally:
        ctx.shutdown()
