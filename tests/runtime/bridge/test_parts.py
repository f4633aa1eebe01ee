"""The bridge core's parts alone (runtime/bridge/): no transport, no ROS node, times and timers faked.

- loss: transfer-id gaps per source, exact on 64-bit ids, on ids modulo 32 exact within the transfer-id timeout and
  estimated apart across an outage of the bridge's own link; restarts count nothing.
- health: heartbeats, the offline timer, lost/back/restarted events, strangers, a timer firing early.
- lifetime: start in order, close in reverse, a failing start closes what started, periodic jobs counted on error.
- link: a backend whose link dies is reopened with back-off; outages, errors and events.
- inbound: source filter, lost transfers, stamps (unknown, out of order, forgotten after a restart), converter and
  publisher failures counted.
- diagnostics: device levels from the health a backend reports, STALE, the link down.
"""

from __future__ import annotations

import asyncio
import logging
import threading
from collections import Counter
from dataclasses import replace
from types import SimpleNamespace as NS
from typing import Any

import pytest

from sam_runtime.bridge.backend import DeviceStatus
from sam_runtime.bridge.counters import MappingStats
from sam_runtime.bridge.health import DeviceHealth
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.loss import TransferLoss
from sam_runtime.common.rate_log import RateLimitedLog

UDP, CAN = 2**64, 32


def _loss(modulo: int, rates: dict[tuple[int, int], float] | None = None, uptime: int | None = None,
          outages: list[tuple[float, float]] | None = None) -> tuple[TransferLoss, list[int]]:
    restarted: list[int] = []
    return TransferLoss(7, rates or {}, lambda: modulo, lambda nid: uptime, lambda: outages or [],
                        restarted.append), restarted


# ============================================================================================ loss
def test_loss_on_64_bit_ids_is_exact_and_a_restart_counts_nothing() -> None:
    loss, restarted = _loss(UDP)
    got = [loss.track(11, tid, 0.1 * i) for i, tid in enumerate([100, 101, 105, 105, 106])]
    # a gap of 3, and a duplicate (pycyphal discards those before the bridge: it costs nothing here either)
    assert got == [(0, 0), (0, 0), (3, 0), (0, 0), (0, 0)] and restarted == []
    assert loss.track(11, 0, 1.0) == (0, 0) and restarted == [11]  # the ids started over: the node restarted
    assert loss.track(12, 5, 1.0) == (0, 0)  # sources are independent
    assert loss.last_message(11) == 1.0 and loss.last_message(13) is None


def test_loss_modulo_32_within_the_transfer_id_timeout_is_exact() -> None:
    loss, _ = _loss(CAN)
    assert loss.track(11, 30, 0.00) == (0, 0)
    assert loss.track(11, 31, 0.01) == (0, 0)
    assert loss.track(11, 3, 0.05) == (3, 0)  # 31 -> 3 wraps: 0, 1, 2 lost


def test_loss_modulo_32_after_a_long_gap_uses_the_rate() -> None:
    # nominal 5 Hz, 2.4 s without data: 12 due, the gap says 11 lost (fewer than 16: no wrap possible): exact
    loss, _ = _loss(CAN, rates={(11, 7): 5.0}, uptime=100)
    loss.track(11, 0, 10.0)
    assert loss.track(11, 12, 12.4) == (11, 0)
    # 100 Hz for 3 s: 300 due, the ids say only 5 modulo 32: unknowable, nothing counted
    loss, _ = _loss(CAN, rates={(11, 7): 100.0}, uptime=100)
    loss.track(11, 0, 10.0)
    assert loss.track(11, 6, 13.0) == (0, 0)
    # no rate known at all: nothing
    loss, _ = _loss(CAN)
    loss.track(11, 0, 10.0)
    assert loss.track(11, 4, 13.0) == (0, 0)


def test_loss_modulo_32_across_an_outage_of_the_bridge_is_estimated_apart() -> None:
    # 100 Hz, 3 s deaf (link down from 10.5 to 13.0): 299 missed; the ids give 299 % 32 = 11 -> 11 + 9 * 32
    loss, _ = _loss(CAN, rates={(11, 7): 100.0}, uptime=100, outages=[(10.5, 13.0)])
    loss.track(11, 0, 10.0)
    assert loss.track(11, (300) % 32, 13.0) == (0, 11 + 9 * 32)
    # an outage that ended before the gap began is not this gap's
    loss, _ = _loss(CAN, rates={(11, 7): 100.0}, uptime=100, outages=[(1.0, 2.0)])
    loss.track(11, 0, 10.0)
    assert loss.track(11, 12, 13.0) == (0, 0)


def test_loss_modulo_32_a_source_that_restarted_in_the_gap_counts_nothing() -> None:
    loss, _ = _loss(CAN, rates={(11, 7): 5.0}, uptime=1)  # up 1 s, silent for 2.4 s: it rebooted
    loss.track(11, 0, 10.0)
    assert loss.track(11, 12, 12.4) == (0, 0)


def test_loss_prefers_the_measured_rate_to_the_nominal_one() -> None:
    loss, _ = _loss(CAN, rates={(11, 7): 100.0}, uptime=100)  # nominal 100 Hz, but it really sends 5 Hz
    t = 0.0
    for i in range(20):  # 4 s in sequence at 5 Hz
        loss.track(11, i % 32, t)
        t += 0.2
    # 2.4 s gap: at the measured 5 Hz 11 lost (exact); at the nominal 100 Hz it would be unknowable
    assert loss.track(11, (19 + 12) % 32, t - 0.2 + 2.4) == (11, 0)


# ============================================================================================ health
class FakeTimers:
    """call_later on a fake clock: ``advance(dt)`` runs what is due, in time order."""

    def __init__(self) -> None:
        self.now = 0.0
        self._due: list[list[Any]] = []

    def clock(self) -> float:
        return self.now

    def call_later(self, delay: float, fn: Any) -> Any:
        entry = [self.now + delay, fn, False]
        self._due.append(entry)
        return NS(cancel=lambda: entry.__setitem__(2, True))

    def advance(self, dt: float) -> None:
        end = self.now + dt
        while True:
            due = sorted((e for e in self._due if not e[2] and e[0] <= end), key=lambda e: e[0])
            if not due:
                break
            e = due[0]
            e[2] = True
            self.now = max(self.now, e[0])
            e[1]()
        self.now = end


def _status(nid: int, uptime: int, health: str = "NOMINAL", level: int = 0) -> DeviceStatus:
    return DeviceStatus(nid, health, level, "OPERATIONAL", uptime, 0)


def _health(first: bool = False) -> tuple[DeviceHealth, FakeTimers, list[tuple[int, str, bool]]]:
    """The tracker and the events its handler heard (a device's "first" contact only when asked for)."""
    t = FakeTimers()
    h = DeviceHealth({11: "imu", 13: "gps"}, 100, clock=t.clock, call_later=t.call_later)
    events: list[tuple[int, str, bool]] = []
    h.add_handler(lambda nid, ev, dev: events.append((nid, ev, dev)) if first or ev != "first" else None)
    return h, t, events


def test_health_first_contact_is_an_event_of_devices_only() -> None:
    h, _t, events = _health(first=True)
    h.on_status(_status(11, 0))
    h.on_status(_status(11, 1))
    h.on_status(_status(99, 0))  # a tool: no first-contact event
    assert events == [(11, "first", True)]


def test_health_timeout_lost_back_and_restart(caplog: pytest.LogCaptureFixture) -> None:
    h, t, events = _health()
    assert h.entry(11) == {"node_id": 11, "seen": False, "alive": False, "state": "never seen"}
    caplog.set_level(logging.INFO, logger="sam_runtime.bridge")
    for up in range(5):  # 1 Hz heartbeats
        h.on_status(_status(11, up))
        t.advance(1.0)
    assert events == [] and h.entry(11)["alive"] and h.entry(11)["heartbeats"] == 5
    t.advance(1.999)  # the last heartbeat is 2.999 s old
    assert events == [] and h.alive_since(11) == 0.0
    t.advance(0.001)
    assert events == [(11, "lost", True)] and h.alive_since(11) is None
    e = h.entry(11)
    assert (e["alive"], e["state"], e["lost_events"], e["age_s"]) == (False, "stale", 1, 3.0)
    t.advance(10.0)
    assert events == [(11, "lost", True)]  # once
    h.on_status(_status(11, 1))  # it rebooted while away: restarted, then back
    assert events[1:] == [(11, "restarted", True), (11, "back", True)]
    assert h.entry(11)["restarts"] == 1 and h.alive_since(11) == t.now
    assert [r.getMessage() for r in caplog.records] == [
        "device imu (node 11): heartbeat lost (none for 3.0 s)",
        "device imu (node 11) restarted (uptime 1 s, before 4 s)",
        "device imu (node 11): heartbeat back (uptime 1 s, 1 restarts seen)"]


def test_health_a_restart_while_alive_and_the_health_level() -> None:
    h, t, events = _health()
    h.on_status(_status(13, 50))
    t.advance(1.0)
    h.on_status(_status(13, 0, "CAUTION", 1))
    assert events == [(13, "restarted", True)] and h.alive_since(13) == 1.0
    e = h.entry(13)
    assert (e["health"], e["level"], e["uptime_s"], e["restarts"]) == ("CAUTION", 1, 0, 1)


def test_health_a_restart_the_transport_saw_counts_though_the_uptime_did_not_fall(
        caplog: pytest.LogCaptureFixture) -> None:
    h, t, events = _health()
    caplog.set_level(logging.INFO, logger="sam_runtime.bridge")
    for up in range(3):  # up 2 s
        h.on_status(_status(11, up))
        t.advance(1.0)
    # It rebooted in 1 s; the transport dropped its new node's first heartbeats (transfer ids from 0 within the 2 s
    # transfer-id timeout), and the first one heard carries an uptime no lower: its transfer ids went back.
    t.advance(1.9)
    h.on_status(replace(_status(11, 2), ids_restarted=True))
    assert events == [(11, "restarted", True)] and h.entry(11)["restarts"] == 1 and h.entry(11)["lost_events"] == 0
    assert [r.getMessage() for r in caplog.records] == [
        "device imu (node 11) restarted (uptime 2 s, before 2 s, its transfer ids started over)"]
    # A bridge held up for seconds hears the next heartbeat late, its uptime behind the time that passed: no
    # restart (the time between heartbeats is no evidence); nor after an outage
    t.advance(2.9)
    h.on_status(_status(11, 3))
    t.advance(120.0)
    h.on_status(_status(11, 122))
    assert events == [(11, "restarted", True), (11, "lost", True), (11, "back", True)]
    assert h.entry(11)["restarts"] == 1


def test_health_strangers_are_tracked_quietly(caplog: pytest.LogCaptureFixture) -> None:
    h, t, events = _health()
    caplog.set_level(logging.INFO, logger="sam_runtime.bridge")
    h.on_status(_status(125, 3))
    h.on_status(_status(100, 3))  # the bridge itself
    t.advance(3.5)
    h.on_status(_status(125, 7))
    assert events == [(125, "lost", False), (100, "lost", False), (125, "back", False)]
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.INFO] == [
        "node 125 (no device of the spec) appeared on the bus"]
    devices, others = h.snapshot()
    assert set(devices) == {"imu", "gps"} and not devices["gps"]["seen"]
    assert set(others) == {"125"} and others["125"]["alive"] and others["125"]["lost_events"] == 1


def test_health_a_timer_that_fires_early_is_rearmed() -> None:
    t = FakeTimers()
    early = [1e-6]  # the first timer fires 1 us early, as a loop's clock resolution may let it

    def call_later(delay: float, fn: Any) -> Any:
        return t.call_later(delay - (early.pop() if early else 0.0), fn)

    h = DeviceHealth({11: "imu"}, 100, clock=t.clock, call_later=call_later)
    events: list[Any] = []
    h.add_handler(lambda *a: events.append(a) if a[1] != "first" else None)
    h.on_status(_status(11, 1))
    t.advance(3.0 - 5e-7)  # the timer fired 1 us before 3 s: not lost yet, re-armed
    assert events == [] and h.entry(11)["alive"]
    t.advance(1e-3)
    assert events == [(11, "lost", True)]


# ============================================================================================ lifetime
def test_lifetime_order_failure_and_periodic_errors() -> None:
    calls: list[str] = []
    rlog = RateLimitedLog(logging.getLogger("test_bridge_parts"))

    async def main() -> Lifetime:
        lt = Lifetime("t", rlog)
        for name in "abc":
            lt.add_hooks(name, start=lambda n=name: calls.append(f"start {n}"),
                         close=lambda n=name: calls.append(f"close {n}"))
        ticks: list[int] = []

        def tick() -> None:
            ticks.append(1)
            raise ValueError("a bug")

        lt.every(0.01, "tick", tick)
        await lt.start()
        with pytest.raises(RuntimeError):
            lt.add_hooks("late")
        while len(ticks) < 3:
            await asyncio.sleep(0.01)
        await lt.close()
        assert lt.errors["housekeeping_error"] == len(ticks) >= 3
        return lt

    asyncio.run(main())
    assert calls == ["start a", "start b", "start c", "close c", "close b", "close a"]

    calls.clear()

    async def failing() -> None:
        lt = Lifetime("t", rlog)
        lt.add_hooks("a", start=lambda: calls.append("start a"), close=lambda: calls.append("close a"))

        def boom() -> None:
            raise OSError("no bus")

        lt.add_hooks("b", start=boom, close=lambda: calls.append("close b"))
        lt.add_hooks("c", start=lambda: calls.append("start c"), close=lambda: calls.append("close c"))
        with pytest.raises(OSError):
            await lt.start()
        assert lt.closed

    asyncio.run(failing())
    assert calls == ["start a", "close a"]  # b never started, c never tried


# ============================================================================================ link
class FakeBackend:
    protocol, label, stack = "fake", "Fake", "fakestack"
    node_id = 1

    def __init__(self, failures: int) -> None:
        self.failures = failures
        self.opened = 0
        self.closed = 0
        self.problem: str | None = None

    def describe(self) -> str:
        return "fake:bus"

    async def open(self) -> None:
        if self.opened and self.failures:
            self.failures -= 1
            raise OSError("still down")
        self.opened += 1
        self.problem = None

    async def close(self) -> None:
        self.closed += 1

    def link_problem(self) -> str | None:
        return self.problem


def test_link_reopens_a_dead_backend_with_backoff() -> None:
    from sam_runtime.bridge.link import LinkSupervisor

    backend = FakeBackend(failures=2)
    events: list[str] = []

    async def main() -> dict[str, Any]:
        lt = Lifetime("t", RateLimitedLog(logging.getLogger("test_bridge_parts")))
        link = LinkSupervisor(lt, backend, check_period=0.01, backoff=(0.01, 0.02))  # type: ignore[arg-type]
        link.add_handler(events.append)
        link.attach()
        await lt.start()
        assert link.up and backend.opened == 1
        backend.problem = "the media closed itself"
        while not link.outage_windows:
            await asyncio.sleep(0.01)
        snap = link.snapshot() | {"errors": dict(lt.errors)}
        await lt.close()
        assert not link.up and link.state == "closed"
        return snap

    snap = asyncio.run(main())
    assert snap["up"] and snap["outages"] == 1 and snap["state"] == "up" and snap["down_s"] > 0
    assert snap["errors"] == {"transport_down": 1, "transport_reopen_failed": 2, "transport_reopened": 1}
    assert events == ["down", "up"] and backend.opened == 2 and backend.closed == 2


# ============================================================================================ inbound
class FakeRos:
    def __init__(self) -> None:
        self.published: list[Any] = []
        self.now_ns = 5_000_000_000

    def receive_ns(self) -> int:
        return self.now_ns

    def publisher(self, topic: Any, cls: Any) -> Any:
        return NS(publish=self.published.append)


def _stamped(msg: Any, receive_ns: int, stats: Any) -> Any:
    if msg == "bad":
        raise ValueError("no such field")
    if msg == "reject":
        return None
    return NS(header=NS(frame_id="", stamp=NS(sec=msg // 10**9, nanosec=msg % 10**9)))


def _inbound() -> tuple[Any, Any, FakeRos, Any]:
    from sam_runtime.bridge.inbound import Inbound, InMapping, PortGroup

    lt = Lifetime("t", RateLimitedLog(logging.getLogger("test_bridge_parts")))
    info = NS(name="imu", source_node_ids=(11,), frame_id="imu_link", topic=NS(name="/imu"))
    im = InMapping(info, _stamped, MappingStats(threading.Lock(), "imu"), has_header=True)
    group = PortGroup(1100, "imu", object, [im], _loss(UDP)[0])
    ros = FakeRos()
    inbound = Inbound(lt, [group], ros, backend=None)  # type: ignore[arg-type]
    im.ros_publisher = ros.publisher(info.topic, None)
    return inbound, inbound.handler(group), ros, im


def test_inbound_sources_losses_and_stamps() -> None:
    inbound, on_transfer, ros, im = _inbound()
    on_transfer(3 * 10**9, 11, 0, 1.0)
    on_transfer(4 * 10**9, 11, 3, 1.1)  # 2 lost before it
    on_transfer(1 * 10**9, 42, 0, 1.2)  # a spoofer
    on_transfer(0, 11, 4, 1.3)  # unknown stamp: the receive time
    on_transfer(2 * 10**9, 11, 5, 1.4)  # older than the previous: published anyway, counted
    inbound.forget_stamps(11)  # the device restarted: its clock may have too
    on_transfer(1 * 10**9, 11, 6, 1.5)
    on_transfer("bad", 11, 7, 1.6)
    on_transfer("reject", 11, 8, 1.7)
    st = im.stats.snapshot()
    assert st["dropped"] == {"lost": 2, "unknown_source": 1, "convert_error": 1, "rejected": 1}
    assert st["received"] == 8 and st["published"] == 5 and st["out_of_order"] == 1
    stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in ros.published]
    assert stamps == [3 * 10**9, 4 * 10**9, ros.now_ns, 2 * 10**9, 1 * 10**9]
    assert {m.header.frame_id for m in ros.published} == {"imu_link"}
    assert inbound.last_message("imu", 11) == 1.7 and inbound.last_message("imu", 42) is None


def test_inbound_a_failing_publish_or_handler_is_counted_never_raised() -> None:
    inbound, on_transfer, _, im = _inbound()

    def fail(msg: Any) -> None:
        raise RuntimeError("context invalid")

    im.ros_publisher = NS(publish=fail)
    on_transfer(10**9, 11, 0, 1.0)
    group = inbound.groups[1100]

    def bug(*args: Any) -> Any:
        raise KeyError("a bug in the loss accounting")

    group.loss.track = bug
    on_transfer(10**9, 11, 1, 1.1)
    assert im.stats.snapshot()["dropped"] == {"publish_error": 1, "handler_error": 1}
    assert inbound.lifetime.errors == Counter({"handler_error": 1})


# ============================================================================================ diagnostics
def test_diagnostics_levels_from_the_backends_health() -> None:
    pytest.importorskip("diagnostic_msgs")
    from sam_runtime.bridge.diagnostics import Naming, diagnostic_array

    dev = {"node_id": 11, "seen": True, "alive": True, "age_s": 0.2, "state": "alive", "mode": "OPERATIONAL",
           "uptime_s": 9, "vssc": 0, "heartbeats": 9, "lost_events": 0, "restarts": 0}
    snap = {
        "bridge": {"node_id": 100, "transport": "fake:bus", "uptime_s": 9.0, "errors": {"transport_down": 1},
                   "link": {"up": False, "state": "down: ENETDOWN", "outages": 1, "down_s": 0.5}},
        "mappings": {},
        "devices": {"a": dev | {"health": "OK", "level": 0}, "b": dev | {"health": "WARNING", "level": 1},
                    "c": dev | {"health": "CRITICAL", "level": 2}, "d": {"node_id": 14, "seen": False,
                                                                          "alive": False, "state": "never seen"},
                    "e": dev | {"health": "OK", "level": 0, "alive": False, "age_s": 3.2, "state": "stale"}},
    }
    arr = diagnostic_array(snap, Naming("br", "dronecan", "DroneCAN", "dronecan"), None)
    by = {s.name: s for s in arr.status}
    assert by["br"].level == b"\x02" and by["br"].message == "DroneCAN link down: ENETDOWN; 0 mappings, 0 dropped"
    assert by["br"].hardware_id == "dronecan node 100"
    assert [by[f"br/device/{n}"].level for n in "abcde"] == [b"\x00", b"\x01", b"\x02", b"\x03", b"\x02"]
    assert by["br/device/e"].message == "heartbeat lost: none for 3.2 s (the bridge's DroneCAN link is down)"
    assert "level" not in {kv.key for kv in by["br/device/a"].values}

