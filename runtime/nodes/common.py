"""What the node implementations share: their clock in seconds, guarded timers, rate-limited status reports and a
few message helpers. Imported only by the node modules (it needs rclpy).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

from sam_runtime.node_support import Level, stamp_to_ns

__all__ = ["Level", "StatusReporter", "guarded_timer", "now_s", "stamp_s"]

STATUS_MIN_INTERVAL_S = 1.0  # an unchanged level and message is re-reported at most this often


def now_s(node: Any) -> float:
    """The node's clock (ROS time: the system clock, or /clock with use_sim_time) in seconds."""
    return node.get_clock().now().nanoseconds * 1e-9


def stamp_s(stamp: Any) -> float:
    """A builtin_interfaces/Time in seconds (0.0 for an unset stamp)."""
    return stamp_to_ns(stamp) * 1e-9


def guarded_timer(node: Any, period_s: float, name: str, fn: Callable[[], None]) -> Any:
    """A timer whose callback never ends the executor: an exception is counted (``errors.<name>``), logged with
    its traceback (rate-limited) and shown as ERROR on /diagnostics, like a subscriber callback of the base."""
    call = node._gen_support.callback(name, lambda _unused: fn())
    return node.create_timer(period_s, lambda: call(None))


class StatusReporter:
    """The node's report_status, at once when the level or the message changes, otherwise at most once per
    STATUS_MIN_INTERVAL_S (so a 10 Hz loop can report every tick without flooding /diagnostics)."""

    def __init__(self, node: Any, min_interval_s: float = STATUS_MIN_INTERVAL_S) -> None:
        self.node = node
        self.min_interval_s = min_interval_s
        self.level: int | None = None
        self.message = ""
        self._last = -math.inf

    def __call__(self, level: int, message: str, **values: Any) -> None:
        now = time.monotonic()
        if (level, message) == (self.level, self.message) and now - self._last < self.min_interval_s:
            return
        self.level, self.message, self._last = int(level), message, now
        self.node.report_status(level, message, **{k: _value_text(v) for k, v in values.items()})


def _value_text(v: Any) -> Any:
    """Floats with a sensible number of digits on /diagnostics.

    >>> _value_text(1.23456789), _value_text(3), _value_text(None)
    ('1.235', 3, '-')
    """
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4g}" if math.isfinite(v) else str(v)
    return v
