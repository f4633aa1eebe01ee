"""A mapping's rate limit and command deadline as pure logic on an injected clock (issue 19); the bridge drives it
from its asyncio loop's timers (``loop.time()``, ``loop.call_at``), the tests from a fake clock.

- :class:`LatestGate`, the rate limit (``max_rate_hz``): the latest item at most once per ``1 / max_rate_hz``
  seconds, trailing edge. An item offered when its slot is free goes out at once; one offered sooner is held, and
  goes out when the slot comes (:meth:`LatestGate.take_due`) unless a newer item replaced it (the replaced one is
  returned as *superseded*: the caller counts it, ``rate_limited`` UAVCAN->ROS, ``coalesced`` ROS->UAVCAN). So the
  last value of a stream that stops is never lost, and two items that go out are never closer than the interval:
  over any closed time window of length T at most ``floor(T * max_rate_hz) + 1`` go out (:func:`most_in`).
- :func:`expired`, the deadline (``deadline_s``, ROS->UAVCAN): a command whose age when it would be sent - now
  minus when the bridge's ROS subscription took it, on the same monotonic clock - exceeds the deadline is not sent.
- :class:`Pacer`: a LatestGate on an event loop (anything with ``time()`` and ``call_at(when, callback)``, as
  asyncio's loop): it delivers what may go now, arms one timer for a held item, and reports superseded items.
  Called on that loop only (not thread-safe, like the loop).

Items are never None (None means "nothing" here).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, Protocol

__all__ = ["LatestGate", "LoopClock", "Pacer", "expired", "most_in"]


def most_in(window_s: float, max_rate_hz: float) -> int:
    """The most items a gate of ``max_rate_hz`` lets out within a closed window of ``window_s`` seconds.

    >>> most_in(1.0, 5.0), most_in(0.0, 5.0), most_in(0.99, 5.0)
    (6, 1, 5)
    """
    return math.floor(window_s * max_rate_hz + 1e-9) + 1


def expired(received_s: float, now_s: float, deadline_s: float | None) -> bool:
    """Whether a command taken at ``received_s`` is too old to send at ``now_s`` (same clock).

    >>> expired(10.0, 10.2, 0.25), expired(10.0, 10.3, 0.25), expired(10.0, 99.0, None)
    (False, True, False)
    """
    return deadline_s is not None and now_s - received_s > deadline_s


class LatestGate:
    """The latest item at most ``max_rate_hz`` times a second, trailing edge (see the module docstring)."""

    def __init__(self, max_rate_hz: float) -> None:
        if not (max_rate_hz > 0 and math.isfinite(max_rate_hz)):
            raise ValueError(f"max_rate_hz must be a positive finite number, not {max_rate_hz!r}")
        self.interval = 1.0 / float(max_rate_hz)
        self._last_out: float | None = None
        self.pending: Any = None

    @property
    def due_at(self) -> float | None:
        """When the held item may go out (None: nothing held)."""
        if self.pending is None:
            return None
        assert self._last_out is not None  # an item is held only while a slot is taken
        return self._last_out + self.interval

    def offer(self, item: Any, now: float) -> tuple[Any, Any]:
        """(the item to pass on now or None, the held item ``item`` replaced or None)."""
        if item is None:
            raise ValueError("items are never None")
        if self.pending is None and (self._last_out is None or now - self._last_out >= self.interval):
            self._last_out = now
            return item, None
        superseded, self.pending = self.pending, item
        return None, superseded

    def take_due(self, now: float) -> Any:
        """The held item if its slot has come by ``now`` (it goes out now), else None."""
        due = self.due_at
        if due is None or now < due:
            return None
        item, self.pending = self.pending, None
        self._last_out = now
        return item

    def clear(self) -> Any:
        """Forget the held item (returned, or None)."""
        item, self.pending = self.pending, None
        return item


class LoopClock(Protocol):
    """What a Pacer needs of an event loop (asyncio.AbstractEventLoop has it)."""

    def time(self) -> float: ...

    def call_at(self, when: float, callback: Callable[[], Any]) -> Any: ...


class Pacer:
    """A :class:`LatestGate` driven by an event loop's clock and timers.

    :param deliver: ``deliver(item)`` for every item that goes out (at once, or from the timer).
    :param supersede: ``supersede(item)`` for every held item a newer one replaced.

    ``loop`` is set when the bridge starts. One timer at most is armed, for the held item's slot."""

    def __init__(self, max_rate_hz: float, deliver: Callable[[Any], None], supersede: Callable[[Any], None]) -> None:
        self.gate = LatestGate(max_rate_hz)
        self.max_rate_hz = float(max_rate_hz)
        self.loop: LoopClock | None = None
        self._deliver, self._supersede = deliver, supersede
        self._timer: Any = None

    def offer(self, item: Any) -> None:
        loop = self.loop
        if loop is None:
            raise RuntimeError("the pacer has no loop yet")
        out, superseded = self.gate.offer(item, loop.time())
        if superseded is not None:
            self._supersede(superseded)
        if out is not None:
            self._deliver(out)
        elif self._timer is None:
            due = self.gate.due_at
            assert due is not None
            self._timer = loop.call_at(due, self._on_timer)

    def _on_timer(self) -> None:
        self._timer = None
        due = self.gate.due_at
        if due is None or self.loop is None:
            return
        # the loop runs a timer when its time is within the clock's resolution of `when`: the slot has come
        item = self.gate.take_due(max(self.loop.time(), due))
        if item is not None:
            self._deliver(item)

    def close(self) -> Any:
        """Disarm the timer; the held item (returned, or None) will not go out."""
        if self._timer is not None and hasattr(self._timer, "cancel"):
            self._timer.cancel()
        self._timer = None
        return self.gate.clear()
