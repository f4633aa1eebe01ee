"""The bridge's lifetime, to which its parts attach (the pattern of pycyphal.application.Node.add_lifetime_hooks,
which pycyphal's NodeTracker uses): each part registers what it does when the bridge starts and when it closes,
and the periodic work it needs; the composition root only creates the parts in order.

- Start hooks run in the order the parts were attached; when one fails, the parts already started are closed
  (in reverse order) and the error propagates.
- Close: :attr:`Lifetime.closed` is set first (every part checks it before it hands on work), the periodic jobs
  are cancelled, then the close hooks of the started parts run in reverse order. A close hook that raises is
  logged; the others still run.
- Periodic jobs run on the asyncio loop, one task per period (the jobs of one period share its wake-up), at fixed
  deadlines (start + k x period: a job's own run time does not stretch the period; a round missed while the loop
  was held up is skipped, not run twice in a row); one that raises is counted (``housekeeping_error``) and logged,
  and the next round runs.
"""

from __future__ import annotations

import asyncio
import collections
import inspect
import logging
import time
from collections.abc import Awaitable, Callable

from sam_runtime.bridge.counters import log
from sam_runtime.common.rate_log import RateLimitedLog
from sam_runtime.common.tasks import cancel_and_wait

__all__ = ["Hook", "Lifetime", "next_round"]

Hook = Callable[[], Awaitable[None] | None]


class Lifetime:
    """Start/close hooks and periodic jobs of one bridge; ``errors`` are the bridge's own error counters
    (``stats()["bridge"]["errors"]``) and ``rlog`` its bounded-rate log, shared by every part."""

    def __init__(self, name: str, rlog: RateLimitedLog) -> None:
        self.name = name
        self.rlog = rlog
        self.errors: collections.Counter[str] = collections.Counter()
        self.loop: asyncio.AbstractEventLoop | None = None
        self.closed = False
        self.started_monotonic: float | None = None
        self._hooks: list[tuple[str, Hook | None, Hook | None]] = []
        self._started: list[tuple[str, Hook | None]] = []
        self._jobs: dict[float, list[tuple[str, Callable[[], None]]]] = {}
        self._tasks: list[asyncio.Task[None]] = []

    def add_hooks(self, name: str, start: Hook | None = None, close: Hook | None = None) -> None:
        """Attach a part: ``start()`` when the bridge starts, ``close()`` when it closes (sync or async)."""
        if self.loop is not None:
            raise RuntimeError(f"{name}: the bridge has started; attach parts before")
        self._hooks.append((name, start, close))

    def every(self, period: float, name: str, job: Callable[[], None]) -> None:
        """Run ``job()`` every ``period`` seconds on the asyncio loop while the bridge runs (jobs of one period run
        in the order they were added)."""
        if self.loop is not None:
            raise RuntimeError(f"{name}: the bridge has started; add periodic jobs before")
        self._jobs.setdefault(float(period), []).append((name, job))

    async def start(self) -> None:
        if self.loop is not None:
            raise RuntimeError("Bridge.start() called twice")
        self.loop = asyncio.get_running_loop()
        try:
            for name, start, close in self._hooks:
                if start is not None:
                    await _call(start)
                self._started.append((name, close))
        except BaseException:
            await self.close()
            raise
        self.started_monotonic = time.monotonic()
        for period, jobs in self._jobs.items():
            self._tasks.append(asyncio.create_task(self._run_every(period, jobs), name=f"{self.name}-every-{period}"))

    async def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        stuck = await cancel_and_wait(self._tasks)
        while self._started:
            name, close = self._started.pop()
            if close is None:
                continue
            try:
                await _call(close)
            except Exception as ex:  # never let one part's close problem hide the others'
                log.warning("closing %s: %s: %s", name, type(ex).__name__, ex)
        if stuck:
            log.warning("%d bridge tasks did not stop", len(stuck))
        self.rlog.flush(force=True)  # no count stays unlogged

    @property
    def schedule(self) -> dict[float, list[str]]:
        """The periodic jobs' names by period (each period is one task, one wake-up per round)."""
        return {period: [name for name, _ in jobs] for period, jobs in self._jobs.items()}

    async def _run_every(self, period: float, jobs: list[tuple[str, Callable[[], None]]]) -> None:
        loop = asyncio.get_running_loop()
        due = loop.time()
        while not self.closed:
            due = next_round(due, period, loop.time())
            await asyncio.sleep(due - loop.time())
            for name, job in jobs:
                if self.closed:
                    return
                try:
                    job()
                except Exception as ex:
                    self.errors["housekeeping_error"] += 1
                    self.rlog.note(("bridge", "housekeeping_error"), logging.ERROR, "housekeeping (%s): %s: %s",
                                   name, type(ex).__name__, ex)


def next_round(due: float, period: float, now: float) -> float:
    """The deadline of the next round after the one ``due``: ``due + period``, or the first later multiple of the
    period when the loop was held up past it (the rounds missed are skipped).

    >>> next_round(10.0, 1.0, 10.02), next_round(10.0, 1.0, 11.5), next_round(10.0, 1.0, 13.0)
    (11.0, 12.0, 14.0)
    """
    nxt = due + period
    if nxt <= now:
        nxt += (int((now - nxt) / period) + 1) * period
    return nxt


async def _call(hook: Hook) -> None:
    res = hook()
    if inspect.isawaitable(res):
        await res
