"""Waiting for counters to stop moving: the quiet point before and after a measured window in the runtime tests."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable
from typing import Any


async def until_stable(snapshot: Callable[[], Any], stable_s: float = 0.3, timeout: float = 5.0) -> bool:
    """Wait (deadline) until ``snapshot()`` has not changed for ``stable_s``; whether it settled in ``timeout``."""
    last, since = snapshot(), time.monotonic()
    deadline = since + timeout
    while time.monotonic() < deadline:
        await asyncio.sleep(0.02)
        now = snapshot()
        if now != last:
            last, since = now, time.monotonic()
        elif time.monotonic() - since >= stable_s:
            return True
    return False
