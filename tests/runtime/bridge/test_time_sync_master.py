"""The bridge's time-sync master and stamp watch (sam_runtime.bridge.time_sync) with a fake port and a fake clock:
each message carries the previous one's transmission time (the transport's when it gives one, else the middle of
the send call), 0 first, after a failure, a link down, a send that took too long (judged against the recent
ones), or a previous transmission older than the protocol allows; the watch counts
unknown (== receive time) and off stamps per device and reports the error; /diagnostics shows both."""

from __future__ import annotations

import asyncio
import logging
import time
from typing import Any

import pytest

from sam_runtime.bridge.diagnostics import Naming, diagnostic_array
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.time_sync import MAX_SEND_CALL_SPAN_NS, MAX_TX_SPAN_NS, StampWatch, TimeSyncMaster
from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.common.tx_timestamps import TxWindow


class FakeOutlet:
    port_name, port_id, send_timeout = "uavcan.pub.time_sync", 7168, 1.0

    def __init__(self, clock: FakeClock) -> None:
        self.clock, self.ready, self.sent, self.fail, self.send_ns = clock, True, [], False, 100_000
        self.tx_times = False
        # a transmission window measured below the bridge: (offset from the call's start, width) or None
        self.below: tuple[int, int] | None = None
        self._window: TxWindow | None = None

    def want_tx_times(self) -> None:
        self.tx_times = True

    async def publish(self, obj: Any) -> bool:
        start = self.clock.ns
        self.clock.ns += self.send_ns  # the send takes this long
        self._window = None
        if self.fail:
            raise OSError("bus off")
        self.sent.append(obj)
        if self.below is not None:
            at, width = self.below
            # CLOCK_REALTIME, as the transports give it: the fake ROS clock is this far from it
            shift = self.clock.ns - time.time_ns()
            self._window = TxWindow(start + at - shift, start + at + width - shift, "kernel")
        return True

    def take_tx_time(self) -> TxWindow | None:
        window, self._window = self._window, None
        return window


class FakeClock:
    def __init__(self) -> None:
        self.ns = 1_700_000_000_000_000_000

    def __call__(self) -> int:
        return self.ns


def _master(max_interval_s: float = 1.0) -> tuple[TimeSyncMaster, FakeOutlet, FakeClock, Lifetime]:
    clock = FakeClock()
    outlet = FakeOutlet(clock)
    lifetime = Lifetime("b", RateLimitedLog(logging.getLogger("test"), 10.0))
    master = TimeSyncMaster(lifetime, outlet, lambda us: us, clock, 0.5, max_interval_s, "sync")  # type: ignore[arg-type]
    master.attach()
    return master, outlet, clock, lifetime


def test_each_message_carries_the_previous_transmission_time() -> None:
    master, outlet, clock, lifetime = _master()

    async def go() -> None:
        start = clock.ns
        assert await master.tick()
        assert await master.tick()
        # the middle of the first send: start + 50 us
        assert outlet.sent == [0, (start + 50_000) // 1000]
        outlet.fail = True
        assert not await master.tick()
        outlet.fail = False
        assert await master.tick() and outlet.sent[-1] == 0  # after a failure: no previous time
        outlet.ready = False
        assert not await master.tick()
        outlet.ready = True
        assert await master.tick() and outlet.sent[-1] == 0  # after a link down
        assert await master.tick() and outlet.sent[-1] != 0
        outlet.send_ns = 5_000_000  # a send held up 5 ms: its time is not known well enough
        assert await master.tick()
        outlet.send_ns = 100_000
        assert await master.tick() and outlet.sent[-1] == 0
        assert master.imprecise == 1 and master.failed == 1 and lifetime.errors["time_sync_error"] == 1

    asyncio.run(go())


def test_the_transports_window_wins_over_a_held_up_send_call(monkeypatch: pytest.MonkeyPatch) -> None:
    """A send call held up 30 ms (a loaded loop) whose frame the kernel timestamped 12 us into it: the kernel's time
    is carried, exact; a measured window wider than MAX_TX_SPAN_NS gives none."""
    # The master and the fake transport each read CLOCK_REALTIME to relate it to the ROS clock: one frozen reading,
    # so the carried time does not depend on how long the scheduler kept this process between the two reads.
    frozen = time.time_ns()
    monkeypatch.setattr(time, "time_ns", lambda: frozen)
    master, outlet, clock, _ = _master()
    assert outlet.tx_times  # asked for before the link opens

    async def go() -> None:
        outlet.send_ns, outlet.below = 30_000_000, (12_000, 0)
        start = clock.ns
        assert await master.tick() and await master.tick()
        assert outlet.sent[1] == (start + 12_000) // 1000, (outlet.sent[1], start)
        outlet.below = (10_000, MAX_TX_SPAN_NS + 1)  # the driver's send system call preempted for long
        assert await master.tick()
        outlet.below = (12_000, 0)
        assert await master.tick() and outlet.sent[-1] == 0
        assert master.imprecise == 1
        assert master.snapshot()["tx_time"] == {"kernel": 2, "kernel_refused": 1}  # the last: at the next tick

    asyncio.run(go())


def test_send_call_spans_are_judged_against_the_recent_ones() -> None:
    """Without a transport's time: an idle loop's outlier is refused (1.5 ms when sends take 0.1 ms), a loaded
    loop whose every send takes 3 ms is accepted (the middle: at most 1.5 ms off), nothing beyond
    MAX_SEND_CALL_SPAN_NS however slow every send is."""
    master, outlet, clock, _ = _master()

    async def go() -> None:
        for _ in range(8):
            assert await master.tick()
        assert master.imprecise == 0
        outlet.send_ns = 1_500_000
        assert await master.tick()
        outlet.send_ns = 100_000
        assert await master.tick() and outlet.sent[-1] == 0 and master.imprecise == 1
        outlet.send_ns = 3_000_000  # a loaded loop: after a few such sends they are the norm
        for _ in range(16):
            await master.tick()
        before = master.imprecise
        start = clock.ns
        assert await master.tick() and await master.tick()
        assert master.imprecise == before and outlet.sent[-1] == (start + 1_500_000) // 1000
        outlet.send_ns = MAX_SEND_CALL_SPAN_NS + 1_000  # every send too slow: never a time
        for _ in range(20):
            assert await master.tick()
        assert outlet.sent[-19:] == [0] * 19 and master.imprecise == before + 19  # the 20th: at the next tick
        snap = master.snapshot()
        assert snap["tx_span_us"]["send_call_median"] == (MAX_SEND_CALL_SPAN_NS + 1_000) / 1000

    asyncio.run(go())


def test_a_stale_previous_transmission_is_not_sent(monkeypatch: pytest.MonkeyPatch) -> None:
    master, outlet, _clock, _ = _master(max_interval_s=1.0)
    now = [100.0]
    monkeypatch.setattr("sam_runtime.bridge.time_sync.time.monotonic", lambda: now[0])

    async def go() -> None:
        await master.tick()
        now[0] += 1.5  # more than MAX_PUBLICATION_PERIOD since: the field must be 0
        await master.tick()
        now[0] += 0.5
        await master.tick()

    asyncio.run(go())
    assert outlet.sent[0] == outlet.sent[1] == 0 and outlet.sent[2] != 0


def test_stamp_watch_counts_unknown_and_off_stamps_and_reports_the_error() -> None:
    lifetime = Lifetime("b", RateLimitedLog(logging.getLogger("test"), 10.0))
    master, _, _, _ = _master()
    watch = StampWatch(lifetime, frozenset({"imu"}), {11: "imu"}, master)
    rx = 1_700_000_000_000_000_000
    watch.on_stamp("imu", 11, rx, rx)  # a device stamp of 0 became the receive time
    watch.on_stamp("pressure", 11, rx, rx)  # not a device-stamped mapping: ignored
    for k in range(10):
        watch.on_stamp("imu", 11, rx - 2_000_000 - k * 1000, rx)  # 2 ms late
    snap = watch.snapshot()
    imu = snap["devices"]["imu"]
    assert (imu["stamps_unknown"], imu["stamps_known"], imu["stamps_off"], imu["synchronised"]) == (1, 10, 0, True)
    assert imu["error_ms"]["min"] == 2.0 and imu["error_ms"]["n"] == 10
    watch.on_stamp("imu", 11, rx - 40_000_000_000, rx)  # 40 s off: a device that does not follow the master
    imu = watch.snapshot()["devices"]["imu"]
    assert imu["stamps_off"] == 1 and not imu["synchronised"] and imu["error_ms"]["n"] == 10


def test_diagnostics_status_of_the_time_sync() -> None:
    snap: dict[str, Any] = {
        "bridge": {"node_id": 100, "transport": "udp", "uptime_s": 1.0, "errors": {},
                   "link": {"up": True, "state": "up", "outages": 0, "down_s": 0.0}},
        "mappings": {}, "devices": {},
        "time_sync": {"master": {"message": "m", "period_s": 0.5, "sent": 9, "failed": 0, "imprecise": 1,
                                 "last_sent_age_s": 0.2, "tx_time": {"kernel": 8, "kernel_refused": 1}},
                      "devices": {"imu": {"node_id": 11, "synchronised": True, "stamps_known": 5,
                                          "stamps_unknown": 2, "stamps_off": 0,
                                          "error_ms": {"median": 1.5, "min": 1.0, "max": 2.0, "last": 1.2,
                                                       "n": 5}},
                                  "gps": {"node_id": 13, "synchronised": False, "stamps_known": 0,
                                          "stamps_unknown": 3, "stamps_off": 0}}},
    }
    arr = diagnostic_array(snap, Naming("br", "cyphal", "Cyphal", "pycyphal"), None)
    st = next(s for s in arr.status if s.name == "br/time_sync")
    values = {kv.key: kv.value for kv in st.values}
    assert st.level == b"\x01" and "not synchronised: gps" in st.message
    assert values["master"] == "running" and values["imu.error_ms.median"] == "1.5"
    assert values["master.imprecise"] == "1" and values["master.tx_time"] == "kernel=8, kernel_refused=1"
    assert values["gps.stamps_unknown"] == "3"
    snap["time_sync"]["master"]["last_sent_age_s"] = 5.0
    st = next(s for s in diagnostic_array(snap, Naming("br", "cyphal", "C", "p"), None).status
              if s.name == "br/time_sync")
    assert st.level == b"\x02" and "the master is not sending" in st.message


@pytest.mark.parametrize("us", [0, 1, 1_234_567_890_123, (1 << 56) - 1, 1 << 60])
def test_dronecan_sync_payload_is_dronecans_own_encoding(us: int) -> None:
    """The DroneCAN master sends GlobalTimeSync on the wire path (issue 26): its payload bytes are what dronecan
    serializes for the message (the uint56 truncated as dronecan truncates it), and dronecan decodes them back."""
    pytest.importorskip("dronecan")
    import dronecan
    from dronecan import transport

    from sam_runtime.bridge.backends.time_sync_messages import UINT56, sync_message

    msg = sync_message("dronecan")
    cls = dronecan.TYPENAMES["uavcan.protocol.GlobalTimeSync"]
    assert msg.raw and msg.port_id == cls.default_dtid
    payload = msg.make(us)
    assert payload == bytes(transport.Transfer(payload=cls(previous_transmission_timestamp_usec=us & UINT56)).payload)
    decoded = cls()
    decoded._unpack(transport.bits_from_bytes(bytearray(payload)), True)
    assert int(decoded.previous_transmission_timestamp_usec) == us & UINT56
