"""Link supervision: the backend's link opened at start, watched, and reopened with back-off when it dies.

A backend says why its open link must be reopened (``link_problem()``: pycyphal's CAN media close themselves for
good on unrecoverable OS errors such as ENETDOWN; a publish found its port closed). That is checked every
``check_period`` (1 s: one wake-up a second shared with the other housekeeping jobs; a dead link is a fault path,
found within a second; a command sent meanwhile is counted as ``publish_error`` or ``link_down``). The backend is
then closed and opened again, with back-off (0.5 s doubling to 2 s), until it works or the bridge closes; meanwhile
the link is down (commands are dropped as ``link_down``, /diagnostics shows the bridge at ERROR). Handlers hear
``down`` and ``up`` at once. The outages are kept (the last 16 windows) for the loss accounting: transfers missed
while the bridge was deaf are estimated apart (:mod:`.loss`).
"""

from __future__ import annotations

import asyncio
import collections
import logging
import time
from collections.abc import Callable
from typing import Any

from sam_runtime.bridge.backend import Backend
from sam_runtime.bridge.counters import log
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.common.tasks import cancel_and_wait

__all__ = ["CHECK_PERIOD_S", "REOPEN_BACKOFF_S", "LinkSupervisor"]

CHECK_PERIOD_S = 1.0
REOPEN_BACKOFF_S = (0.5, 2.0)


class LinkSupervisor:
    def __init__(self, lifetime: Lifetime, backend: Backend, *, check_period: float = CHECK_PERIOD_S,
                 backoff: tuple[float, float] = REOPEN_BACKOFF_S) -> None:
        self.lifetime = lifetime
        self.backend = backend
        self.backoff = backoff
        self.up = False
        self.state = "not started"
        self.outages = 0
        self.down_since: float | None = None
        self.down_s = 0.0
        self.up_since = 0.0  # when the link was last (re)opened: the bridge listens since then
        self.outage_windows: collections.deque[tuple[float, float]] = collections.deque(maxlen=16)
        self._handlers: list[Callable[[str], None]] = []
        self._reopen_task: asyncio.Task[None] | None = None
        self._check_period = check_period

    def attach(self) -> None:
        """Open the backend when the bridge starts (after the parts that declare ports), watch it, close it."""
        self.lifetime.add_hooks("link", start=self._open, close=self._close)
        self.lifetime.every(self._check_period, "link check", self.check)

    def add_handler(self, handler: Callable[[str], None]) -> None:
        """``handler("down")`` / ``handler("up")`` on every change after the start."""
        self._handlers.append(handler)

    async def _open(self) -> None:
        await self.backend.open()
        self._opened()

    def _opened(self) -> None:
        self.up, self.state = True, "up"
        self.up_since = time.monotonic()

    async def _close(self) -> None:
        if self._reopen_task is not None:
            await cancel_and_wait([self._reopen_task])
        await self.backend.close()
        self.up, self.state = False, "closed"

    def check(self) -> None:
        """Start reopening the link when the backend says it must (periodic)."""
        if self.lifetime.closed or (self._reopen_task is not None and not self._reopen_task.done()):
            return
        why = self.backend.link_problem() if self.up else None
        if why is not None:
            self._reopen_task = asyncio.create_task(self._reopen(why), name=f"{self.lifetime.name}-reopen")

    async def _reopen(self, reason: str) -> None:
        b, errors = self.backend, self.lifetime.errors
        self.up, self.state = False, f"down: {reason}"
        self.outages += 1
        self.down_since = time.monotonic()
        errors["transport_down"] += 1
        log.error("%s transport %s failed (%s): reopening", b.label, b.describe(), reason)
        self._notify("down")
        await b.close()
        delay = self.backoff[0]
        attempts = 0
        while not self.lifetime.closed:
            attempts += 1
            try:
                await b.open()
                self._opened()
                break
            except Exception as ex:
                errors["transport_reopen_failed"] += 1
                self.state = f"down: {reason}; reopen attempt {attempts}: {type(ex).__name__}: {ex}"
                self.lifetime.rlog.note((b.protocol, "reopen_failed"), logging.WARNING,
                                        "reopening the transport: %s: %s", type(ex).__name__, ex)
                await asyncio.sleep(delay)
                delay = min(delay * 2.0, self.backoff[1])
        if self.down_since is not None:
            down = time.monotonic() - self.down_since
            self.outage_windows.append((self.down_since, time.monotonic()))
            self.down_s += down
            self.down_since = None
            if self.up:
                errors["transport_reopened"] += 1
                log.warning("%s transport reopened after %.1f s (%d attempts)", b.label, down, attempts)
                self._notify("up")

    def _notify(self, event: str) -> None:
        for handler in self._handlers:
            handler(event)

    def snapshot(self) -> dict[str, Any]:
        down_s = self.down_s + (time.monotonic() - self.down_since if self.down_since is not None else 0.0)
        return {"up": self.up, "state": self.state, "outages": self.outages, "down_s": round(down_s, 3)}
