"""When a Cyphal/CAN frame left through pycyphal's python-can media: the bounds of the python-can ``send`` call in
the media's transmit thread, for the frames of one subject from one node (the time-sync master's).

pycyphal's own transmission feedback through python-can without hardware loopback (the ``virtual`` bus, most USB
adapters) is the time its send coroutine resumed on the asyncio loop after the transmit thread finished: on a
loaded loop tens of milliseconds late. The transmit thread itself is not held up by the loop: the window around
its ``bus.send`` is the time the frame was handed to python-can (on ``virtual`` the time the other buses receive it
with; on an adapter, its driver's queue), within the thread's own preemption, which the window's width shows.

This reaches into pycyphal 1.x's python-can media (``PythonCANMedia._bus``, through ``CANTransport._maybe_media``):
:func:`CanTxTimes.attach` checks both and returns None when either is not there (another media, another pycyphal),
so the caller falls back to its own measure. The bus is wrapped, not replaced: every other call goes through.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from sam_runtime.common.tx_timestamps import TxWindow

__all__ = ["CanTxTimes"]


class _TimedBus:
    """A python-can bus that notes the window of every ``send`` of a watched frame."""

    def __init__(self, inner: Any, times: CanTxTimes) -> None:
        self._inner, self._times = inner, times

    def send(self, msg: Any, timeout: float | None = None) -> None:
        before = time.time_ns()
        self._inner.send(msg, timeout)
        after = time.time_ns()
        self._times.note(int(msg.arbitration_id), before, after)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)


class CanTxTimes:
    """The transmission windows of the frames of ``subject_id`` from ``node_id`` on one python-can media."""

    def __init__(self, subject_id: int, node_id: int) -> None:
        self.subject_id, self.node_id = subject_id, node_id
        self._lock = threading.Lock()
        self._count = 0  # watched frames sent
        self._last: tuple[int, int] | None = None

    @classmethod
    def attach(cls, transport: Any, subject_id: int, node_id: int) -> CanTxTimes | None:
        media: Any = getattr(transport, "_maybe_media", None)
        bus = getattr(media, "_bus", None)
        if bus is None or not callable(getattr(bus, "send", None)):
            return None
        times = cls(subject_id, node_id)
        inner = bus._inner if isinstance(bus, _TimedBus) else bus  # a reopened port: wrap the bus once
        media._bus = _TimedBus(inner, times)  # (see the module docstring)
        return times

    def watched(self, can_id: int) -> bool:
        """A message frame (not service, not anonymous) of the subject from the node."""
        return (not can_id & (3 << 24) and (can_id >> 8) & 0x1FFF == self.subject_id
                and can_id & 0x7F == self.node_id)

    def note(self, can_id: int, before_ns: int, after_ns: int) -> None:
        if self.watched(can_id):
            with self._lock:
                self._count += 1
                self._last = (before_ns, after_ns)

    @property
    def count(self) -> int:
        with self._lock:
            return self._count

    def take(self, count_before: int) -> TxWindow | None:
        """The window of the one watched frame sent since ``count`` was ``count_before``; None when none or
        several were."""
        with self._lock:
            if self._count != count_before + 1 or self._last is None:
                return None
            return TxWindow(self._last[0], self._last[1], "can_thread")
