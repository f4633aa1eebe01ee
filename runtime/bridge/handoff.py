"""ROS -> UAVCAN: objects from the rclpy executor thread to the asyncio loop, one wake-up of the loop per batch.

``call_soon_threadsafe`` writes to the loop's self-pipe (a syscall, and a GIL hand-over) every time; so objects go
into a deque in arrival order, and only the first one after a drain schedules the next drain. The drain (on the
loop) clears the flag before it empties the deque, so an object appended after its last look finds the flag clear
and schedules another drain: nothing stays behind. Each object then meets ``deliver`` exactly as with one
``call_soon_threadsafe`` per object (same order, same drops downstream).
"""

from __future__ import annotations

import asyncio
import collections
from collections.abc import Callable
from typing import Any, Generic, TypeVar

__all__ = ["Handoff"]

T = TypeVar("T")


class Handoff(Generic[T]):
    """:param deliver: ``deliver(target, obj)`` on the loop, for every object in order.
    :param discard: ``discard(target, obj)`` for an object no drain will take any more (the loop closed).

    ``loop`` is set when the bridge starts (an object put before raises RuntimeError, counted by the caller)."""

    def __init__(self, deliver: Callable[[T, Any], None], discard: Callable[[T, Any], None]) -> None:
        self.loop: asyncio.AbstractEventLoop | None = None
        self._deliver = deliver
        self._discard = discard
        self._items: collections.deque[tuple[T, Any]] = collections.deque()
        self.scheduled = False

    def __len__(self) -> int:
        return len(self._items)

    def put(self, target: T, obj: Any) -> None:
        """From any thread: hand ``obj`` for ``target`` to the loop."""
        loop = self.loop
        if loop is None:  # before the append: what fails here is counted by the caller, never also delivered
            raise RuntimeError("no event loop to hand ROS messages to")
        self._items.append((target, obj))
        if not self.scheduled or loop.is_closed():
            self.scheduled = True
            try:
                loop.call_soon_threadsafe(self.drain)
            except RuntimeError:  # loop closed: shutting down (a drain scheduled before will never run)
                self.scheduled = False
                self.discard_all()

    def drain(self) -> None:
        """On the loop: every object handed off since the last drain to ``deliver``."""
        self.scheduled = False
        items = self._items
        while items:
            target, obj = items.popleft()
            self._deliver(target, obj)

    def discard_all(self) -> None:
        items = self._items
        while True:
            try:
                target, obj = items.popleft()
            except IndexError:
                return
            self._discard(target, obj)
