"""Stopping asyncio tasks reliably."""

from __future__ import annotations

import asyncio
from collections.abc import Sequence
from typing import Any

__all__ = ["cancel_and_wait"]


async def cancel_and_wait(tasks: Sequence[asyncio.Task[Any]], timeout: float = 2.0) -> list[asyncio.Task[Any]]:
    """Cancel tasks and wait for them, cancelling again while they run: on Python 3.11 a cancellation that
    lands inside pycyphal's ``wait_for`` can be lost, and a plain ``gather`` would then wait forever.
    Returns the tasks still running at the deadline.

    >>> async def main():
    ...     task = asyncio.create_task(asyncio.sleep(10))
    ...     return await cancel_and_wait([task]), task.cancelled()
    >>> asyncio.run(main())
    ([], True)
    """
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    pending = [t for t in tasks if not t.done()]
    while pending and loop.time() < deadline:
        for t in pending:
            t.cancel()
        await asyncio.wait(pending, timeout=min(0.05, max(0.0, deadline - loop.time())))
        pending = [t for t in pending if not t.done()]
    for t in tasks:
        if t.done() and not t.cancelled():
            t.exception()  # retrieved: no "exception was never retrieved" noise
    return pending
