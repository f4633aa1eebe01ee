"""The bridge's time: the bus's time-synchronisation master (:class:`TimeSyncMaster`, spec key ``bridge.time_sync``)
and the watch on the devices' stamps (:class:`StampWatch`), protocol-agnostic (the message and its port come from
``backends.time_sync_messages``).

- Master (both protocols' algorithm, Cyphal ``uavcan.time.Synchronization.1.0`` and DroneCAN
  ``uavcan.protocol.GlobalTimeSync``): every ``period_s`` one message whose field is the time at which the previous
  one was transmitted, in the bridge's ROS clock (``ros.receive_ns``: the clock the bridge stamps receive times and
  rclpy its messages with), so that the devices' stamps become ROS time.
  The transmission time, measured where a held-up asyncio loop cannot delay it (``tx_time`` in the snapshot
  counts where each message's came from):
  ``kernel``: Cyphal/UDP, the kernel's software transmission timestamp of the session's socket (exact);
  ``can_thread``: Cyphal/CAN through python-can, the bounds of the send call in pycyphal's transmit thread
  (sam_runtime.cyphal_io.can_tx_times, some 10-60 us);
  ``driver``: DroneCAN on ``mcast-lo:``, the bounds of the driver's send system call (some 10 us);
  ``send_call`` where nothing below the bridge measures it (SocketCAN media, other DroneCAN drivers): the bounds
  of the publish call, during which the frame left (on a loaded loop including the loop's lag: the call awaits).
  Each is a window [earliest, latest], read when the next message is built (a transport may report a
  transmission after the send returned: a real interface's queue); the message carries its middle, so the time
  carried is off by at most half the window. A window wider than its limit gives no time (counted ``imprecise``
  and ``<source>_refused``; the next message says 0, so the slaves keep their offset instead of adopting a wrong
  one). The limit of a measured window is MAX_TX_SPAN_NS (1 ms); of a send call, twice the median of the last
  SPAN_WINDOW send calls, at least MAX_TX_SPAN_NS and at most MAX_SEND_CALL_SPAN_NS (4 ms): an idle loop's
  outliers are refused, a loop whose every send takes a few ms still synchronises.
  Invariant (the bound): a message never carries a time more than MAX_TX_ERROR_NS (2 ms) from the previous
  message's transmission; with a measured window 0.5 ms, with the kernel's 0.
  The field is 0 for the first message, after a failed or imprecise send or a link down, and
  when the previous transmission is more than ``max_interval_s`` old (the types' rule): a slave then starts its
  chain again.
  Runs on the asyncio loop (the protocol stacks are not thread-safe); a failed send is counted
  (``errors.time_sync_error``), logged at a bounded rate, never raised.
- Stamp watch (inbound calls :meth:`StampWatch.on_stamp` for every published message with a header): for the
  mappings whose header.stamp is the device's own timestamp (the tables' ``DEVICE_STAMPED_MAPPINGS``), per device:
  stamps ``known`` and ``unknown`` (0 on the wire: a device that has not synchronised yet; the bridge stamps the
  receive time, counted and logged, so no consumer takes it for the device's time without the counters saying so),
  ``off`` (a known stamp more than OFF_LIMIT_S from the receive time: a device that does not follow the master,
  published as it came, counted and logged), and the distribution of the error ``receive time - stamp`` over the
  last ERROR_WINDOW stamps (with the master: the one-way latency of the sample plus that of the sync message).
  An unknown stamp is recognised as one equal to the receive time to the nanosecond (a device's stamp is in whole
  microseconds, the receive time in nanoseconds).
"""

from __future__ import annotations

import asyncio
import collections
import logging
import statistics
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.bridge.backend import Outlet
from sam_runtime.bridge.lifetime import Lifetime

__all__ = ["DEFAULT_TIME_SYNC_PERIOD_S", "ERROR_WINDOW", "MAX_SEND_CALL_SPAN_NS", "MAX_TX_ERROR_NS", "MAX_TX_SPAN_NS",
           "OFF_LIMIT_S", "StampWatch", "TimeSyncMaster"]

DEFAULT_TIME_SYNC_PERIOD_S = 0.5  # as the spec's default (sam_codegen.frontend.time_sync)
ERROR_WINDOW = 64
MAX_TX_SPAN_NS = 1_000_000  # a measured window (kernel, driver) wider than this gives no transmission time
MAX_SEND_CALL_SPAN_NS = 4_000_000  # nor ever a send call longer than this
MAX_TX_ERROR_NS = MAX_SEND_CALL_SPAN_NS // 2  # the most a carried time can be off (the middle of the window)
SPAN_WINDOW = 16  # the recent send-call spans judged against
SPAN_FACTOR = 2  # a send call longer than this many times their median is refused
OFF_LIMIT_S = 1.0


class TimeSyncMaster:
    """:param outlet: the backend's port of the sync message; ``make(prev_us)`` builds one message.
    :param clock_ns: the bridge's ROS clock (nanoseconds).
    :param max_interval_s: the protocol's longest time between two messages (beyond: the field is 0)."""

    def __init__(self, lifetime: Lifetime, outlet: Outlet, make: Callable[[int], Any], clock_ns: Callable[[], int],
                 period_s: float, max_interval_s: float, label: str) -> None:
        self.lifetime, self.outlet, self.make, self.clock_ns = lifetime, outlet, make, clock_ns
        self.period_s, self.max_interval_s, self.label = float(period_s), float(max_interval_s), label
        self.sent = 0
        self.failed = 0
        self.imprecise = 0  # sent, but the next message says 0: its transmission window was too wide (counted then)
        self.tx_sources: collections.Counter[str] = collections.Counter()  # transmission times by source
        self._spans: deque[int] = deque(maxlen=SPAN_WINDOW)  # the last send-call spans
        self._last_span_ns: int | None = None
        self._pending: tuple[int, int] | None = None  # the last message sent, its send call's bounds
        self._prev_mono: float | None = None
        self._last_sent_mono: float | None = None
        self._task: asyncio.Task[None] | None = None

    def attach(self) -> None:
        self.outlet.want_tx_times()  # before the link opens: the backend measures from its first open
        self.lifetime.add_hooks(f"{self.label} master", start=self._start, close=self._close)

    def _start(self) -> None:
        self._task = asyncio.get_running_loop().create_task(self._run(), name=f"{self.lifetime.name}-time-sync")

    async def _close(self) -> None:
        if self._task is not None:
            self._task.cancel()
            try:
                await self._task
            except asyncio.CancelledError:
                pass
            self._task = None

    async def _run(self) -> None:
        due = time.monotonic()
        while not self.lifetime.closed:
            await self.tick()
            due += self.period_s
            now = time.monotonic()
            if due < now:  # held up longer than a period: a new schedule from now, no burst
                due = now + self.period_s
            await asyncio.sleep(due - now)

    async def tick(self) -> bool:
        """Send one message; True when it went out."""
        if not self.outlet.ready:
            self._pending = None
            return False
        mono = time.monotonic()
        prev_us = self._previous_us()
        fresh = prev_us is not None and self._prev_mono is not None and mono - self._prev_mono <= self.max_interval_s
        obj = self.make(prev_us if fresh and prev_us is not None else 0)
        before_ns = self.clock_ns()
        try:
            ok = await self.outlet.publish(obj)
        except asyncio.CancelledError:
            raise
        except Exception as ex:
            ok = False
            self.lifetime.rlog.note(("time_sync", "error"), logging.WARNING, "%s: %s: %s", self.label,
                                    type(ex).__name__, ex)
        if not ok:
            self.failed += 1
            self.lifetime.errors["time_sync_error"] += 1
            return False
        after_ns = self.clock_ns()
        self._last_sent_mono = self._prev_mono = time.monotonic()
        self.sent += 1
        self._pending = (before_ns, after_ns)  # its time is read at the next tick (a transport may report late)
        return True

    def _previous_us(self) -> int | None:
        """The transmission time of the last message sent [us], None when there was none (the first, after a
        failure or a link down) or it is not known well enough (counted ``imprecise``)."""
        pending, self._pending = self._pending, None
        if pending is None:
            return None
        window = self._window(*pending)
        if window is None:  # held up: when the frame left is not known well enough
            self.imprecise += 1
            return None
        return window // 1000

    def _window(self, before_ns: int, after_ns: int) -> int | None:
        """The transmission time of the last message (the bridge's clock, ns): the middle of the window measured
        below the bridge or else of its send call (``before_ns``, ``after_ns``); None when the window is too wide."""
        tx = self.outlet.take_tx_time()
        if tx is not None:
            # the window is CLOCK_REALTIME: to the bridge's clock (the same one unless ROS time is simulated)
            shift = self.clock_ns() - time.time_ns()
            source, lo, hi, limit = tx.source, tx.earliest_ns + shift, tx.latest_ns + shift, MAX_TX_SPAN_NS
        else:
            source, lo, hi = "send_call", before_ns, after_ns
            self._spans.append(hi - lo)
            typical = statistics.median(self._spans)
            limit = min(MAX_SEND_CALL_SPAN_NS, max(MAX_TX_SPAN_NS, int(SPAN_FACTOR * typical)))
        span = hi - lo
        self._last_span_ns = span
        if not 0 <= span <= limit:
            self.tx_sources[f"{source}_refused"] += 1
            return None
        self.tx_sources[source] += 1
        return (lo + hi) // 2

    def snapshot(self) -> dict[str, Any]:
        age = None if self._last_sent_mono is None else round(time.monotonic() - self._last_sent_mono, 3)
        spans = sorted(self._spans)
        return {"message": self.label, "period_s": self.period_s, "sent": self.sent, "failed": self.failed,
                "imprecise": self.imprecise, "last_sent_age_s": age, "tx_time": dict(sorted(self.tx_sources.items())),
                "tx_span_us": {"last": None if self._last_span_ns is None else round(self._last_span_ns / 1000, 1),
                               **({"send_call_median": round(statistics.median(spans) / 1000, 1),
                                   "send_call_max": round(spans[-1] / 1000, 1)} if spans else {})}}


@dataclass
class _DeviceStamps:
    known: int = 0
    unknown: int = 0
    off: int = 0
    last_known: bool = False
    errors_ns: deque[int] = field(default_factory=lambda: deque(maxlen=ERROR_WINDOW))


class StampWatch:
    """:param stamped: the names of the mappings whose header.stamp is the device's.
    :param devices: node id -> device name."""

    def __init__(self, lifetime: Lifetime, stamped: frozenset[str], devices: Mapping[int, str],
                 master: TimeSyncMaster | None) -> None:
        self.lifetime, self.stamped, self.devices, self.master = lifetime, frozenset(stamped), dict(devices), master
        self._lock = threading.Lock()
        self._by_node: dict[int, _DeviceStamps] = {}

    def on_stamp(self, mapping: str, src: int, stamp_ns: int, receive_ns: int) -> None:
        """A message of ``mapping`` from ``src`` published with ``stamp_ns`` (receive time ``receive_ns``)."""
        if mapping not in self.stamped:
            return
        rlog = self.lifetime.rlog
        with self._lock:
            st = self._by_node.get(src)
            if st is None:
                st = self._by_node[src] = _DeviceStamps()
            if stamp_ns == receive_ns:
                st.unknown += 1
                st.last_known = False
            else:
                err = receive_ns - stamp_ns
                st.known += 1
                st.last_known = abs(err) <= OFF_LIMIT_S * 1e9
                if st.last_known:
                    st.errors_ns.append(err)
                else:
                    st.off += 1
        if stamp_ns == receive_ns:
            rlog.note(("time_sync", f"unknown.{src}"), logging.INFO, "node %s (%s) stamps 0 (unknown: not synchronised "
                      "yet): published with the receive time", src, self.devices.get(src, "no device"))
        elif not st.last_known:
            rlog.note(("time_sync", f"off.{src}"), logging.WARNING, "node %s (%s): stamp %.6f s is %.3f s from the "
                      "receive time (not synchronised to the bus's time master); published", src,
                      self.devices.get(src, "no device"), stamp_ns * 1e-9, (receive_ns - stamp_ns) * 1e-9)

    def snapshot(self) -> dict[str, Any]:
        devices: dict[str, Any] = {}
        with self._lock:
            items = [(nid, st.known, st.unknown, st.off, st.last_known, list(st.errors_ns))
                     for nid, st in sorted(self._by_node.items())]
        for nid, known, unknown, off, last_known, errs in items:
            entry: dict[str, Any] = {"node_id": nid, "synchronised": last_known, "stamps_known": known,
                                     "stamps_unknown": unknown, "stamps_off": off}
            if errs:
                ordered = sorted(errs)
                entry["error_ms"] = {"median": round(statistics.median(ordered) * 1e-6, 3),
                                     "p95": round(ordered[min(len(ordered) - 1, (95 * len(ordered)) // 100)] * 1e-6, 3),
                                     "min": round(ordered[0] * 1e-6, 3), "max": round(ordered[-1] * 1e-6, 3),
                                     "last": round(errs[-1] * 1e-6, 3), "n": len(errs)}
            devices[self.devices.get(nid, f"node_{nid}")] = entry
        return {"master": None if self.master is None else self.master.snapshot(), "devices": devices}
