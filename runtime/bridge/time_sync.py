"""The bridge's time: the bus's time-synchronisation master (:class:`TimeSyncMaster`, spec key ``bridge.time_sync``)
and the watch on the devices' stamps (:class:`StampWatch`), protocol-agnostic (the message and its port come from
``backends.time_sync_messages``).

- Master (both protocols' algorithm, Cyphal ``uavcan.time.Synchronization.1.0`` and DroneCAN
  ``uavcan.protocol.GlobalTimeSync``): every ``period_s`` one message whose field is the time at which the previous
  one was transmitted, in the bridge's ROS clock (``ros.receive_ns``: the clock the bridge stamps receive times and
  rclpy its messages with), so that the devices' stamps become ROS time. The transmission time is the middle of
  the send call (the frame reaches the OS inside it; the stacks give no transmission timestamp through the
  backend's port); a send that took longer than MAX_TX_SPAN_NS (the loop held up, the send waited) gives no
  usable time: the next message says 0 (counted ``imprecise``), so the slaves keep their offset instead of
  adopting a wrong one. The field is 0 for the first message, after a failed or imprecise send or a link down, and
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

__all__ = ["DEFAULT_TIME_SYNC_PERIOD_S", "ERROR_WINDOW", "OFF_LIMIT_S", "StampWatch", "TimeSyncMaster"]

DEFAULT_TIME_SYNC_PERIOD_S = 0.5  # as the spec's default (sam_codegen.frontend.time_sync)
ERROR_WINDOW = 64
MAX_TX_SPAN_NS = 1_000_000  # a send that took longer gives no transmission time
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
        self.imprecise = 0  # sent, but the next message says 0: the send took longer than MAX_TX_SPAN_NS
        self._prev_us = 0
        self._prev_mono: float | None = None
        self._last_sent_mono: float | None = None
        self._task: asyncio.Task[None] | None = None

    def attach(self) -> None:
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
            self._prev_us, self._prev_mono = 0, None
            return False
        mono = time.monotonic()
        fresh = self._prev_mono is not None and mono - self._prev_mono <= self.max_interval_s
        obj = self.make(self._prev_us if fresh else 0)
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
            self._prev_us, self._prev_mono = 0, None
            return False
        after_ns = self.clock_ns()
        self._last_sent_mono = time.monotonic()
        self.sent += 1
        if after_ns - before_ns > MAX_TX_SPAN_NS:  # held up: when the frame left is not known well enough
            self.imprecise += 1
            self._prev_us, self._prev_mono = 0, None
        else:
            self._prev_us, self._prev_mono = (before_ns + after_ns) // 2000, self._last_sent_mono
        return True

    def snapshot(self) -> dict[str, Any]:
        age = None if self._last_sent_mono is None else round(time.monotonic() - self._last_sent_mono, 3)
        return {"message": self.label, "period_s": self.period_s, "sent": self.sent, "failed": self.failed,
                "imprecise": self.imprecise, "last_sent_age_s": age}


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
                                     "min": round(ordered[0] * 1e-6, 3), "max": round(ordered[-1] * 1e-6, 3),
                                     "last": round(errs[-1] * 1e-6, 3), "n": len(errs)}
            devices[self.devices.get(nid, f"node_{nid}")] = entry
        return {"master": None if self.master is None else self.master.snapshot(), "devices": devices}
