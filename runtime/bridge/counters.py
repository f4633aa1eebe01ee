"""What the bridge counts: per mapping (received, published, drops by reason, saturated and rejected fields,
out-of-order stamps) and its bounded-rate log. Both event loops touch the counters: they are thread-safe.

Every part of the bridge logs to the one logger ``sam_runtime.bridge`` (:data:`log`), whatever module it is in.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Iterable
from typing import Any

__all__ = ["DEFAULT_LOG_INTERVAL_S", "DROP_REASONS", "MappingStats", "RateLimitedLog", "count_handler_error", "log"]

log = logging.getLogger("sam_runtime.bridge")

DEFAULT_LOG_INTERVAL_S = 10.0
DROP_REASONS = ("unknown_source", "rejected", "convert_error", "handler_error", "publish_error", "not_sent",
                "queue_full", "link_down", "shutdown", "lost", "lost_link_down", "unselected")


class RateLimitedLog:
    """At most one log line per key (e.g. (mapping, reason)) per ``interval`` seconds, with the count since the
    previous line. The first occurrence of a key is logged at once. Thread-safe; formatting is lazy."""

    def __init__(self, logger: logging.Logger, interval: float = DEFAULT_LOG_INTERVAL_S) -> None:
        self.logger = logger
        self.interval = float(interval)
        self._lock = threading.Lock()
        # key -> [last_emit_monotonic, pending, total, level, msg, args]
        self._state: dict[tuple[str, str], list[Any]] = {}
        self.lines: collections.Counter[tuple[str, str]] = collections.Counter()  # lines written per key

    def note(self, key: tuple[str, str], level: int, msg: str, *args: Any, count: int = 1) -> None:
        now = time.monotonic()
        emit: tuple[int, float, int] | None = None
        with self._lock:
            st = self._state.get(key)
            if st is None:
                self._state[key] = [now, 0, count, level, msg, args]
                emit = (count, 0.0, count)
            else:
                st[1] += count
                st[2] += count
                st[3], st[4], st[5] = level, msg, args
                if now - st[0] >= self.interval:
                    emit = (st[1], now - st[0], st[2])
                    st[0], st[1] = now, 0
            if emit is not None:
                self.lines[key] += 1
        if emit is not None:
            self._emit(key, level, msg, args, *emit)

    def flush(self, force: bool = False) -> None:
        """Write the pending counts whose interval has passed (all of them with ``force``)."""
        now = time.monotonic()
        out = []
        with self._lock:
            for key, st in self._state.items():
                if st[1] and (force or now - st[0] >= self.interval):
                    out.append((key, st[3], st[4], st[5], st[1], now - st[0], st[2]))
                    st[0], st[1] = now, 0
                    self.lines[key] += 1
        for key, level, msg, args, n, dt, total in out:
            self._emit(key, level, msg, args, n, dt, total)

    def _emit(self, key: tuple[str, str], level: int, msg: str, args: tuple[Any, ...], n: int, dt: float,
              total: int) -> None:
        if not self.logger.isEnabledFor(level):
            return
        try:
            detail = msg % args if args else msg
        except Exception:  # a bad format must not break the caller
            detail = f"{msg} {args!r}"
        if dt == 0.0 and n == total:
            self.logger.log(level, "%s: %s: %s (%d; more are summed at most every %.0f s)", key[0], key[1],
                            detail, n, self.interval)
        else:
            self.logger.log(level, "%s: %s: %d in the last %.1f s (%d in all); the last: %s", key[0], key[1], n,
                            dt, total, detail)


class MappingStats:
    """Counters of one mapping. Also the ``stats`` object handed to the generated converters
    (``saturate(key)``, ``reject(key)``). Thread-safe: both event loops may touch it.

    ``name`` and ``log`` (optional) make saturations and rejections logged at a bounded rate."""

    def __init__(self, lock: threading.Lock, name: str = "", log: RateLimitedLog | None = None) -> None:
        self._lock = lock
        self.name = name
        self._log = log
        self.received = 0
        self.published = 0
        self.out_of_order = 0
        self.dropped: collections.Counter[str] = collections.Counter()
        self.saturated: collections.Counter[str] = collections.Counter()
        self.rejected: collections.Counter[str] = collections.Counter()
        self.last_published_monotonic: float | None = None
        self.last_drop_monotonic: float | None = None

    # converter interface
    def saturate(self, key: str) -> None:
        with self._lock:
            self.saturated[str(key)] += 1
        if self._log is not None:
            self._log.note((self.name, "saturated"), logging.WARNING, "saturated %s", key)

    def reject(self, key: str) -> None:
        with self._lock:
            self.rejected[str(key)] += 1
        if self._log is not None:
            self._log.note((self.name, "rejected"), logging.WARNING, "rejected a message for %s", key)

    # bridge interface
    def receive(self) -> None:
        with self._lock:
            self.received += 1

    def publish(self) -> None:
        with self._lock:
            self.published += 1
            self.last_published_monotonic = time.monotonic()

    def drop(self, reason: str, count: int = 1) -> None:
        if count <= 0:
            return
        with self._lock:
            self.dropped[reason] += count
            self.last_drop_monotonic = time.monotonic()

    def reorder(self) -> None:
        with self._lock:
            self.out_of_order += 1

    def snapshot(self) -> dict[str, Any]:
        with self._lock:
            return {
                "received": self.received,
                "published": self.published,
                "dropped": dict(self.dropped),
                "dropped_total": sum(self.dropped.values()),
                "saturated": dict(self.saturated),
                "saturated_total": sum(self.saturated.values()),
                "rejected_fields": dict(self.rejected),
                "out_of_order": self.out_of_order,
                "last_drop_age_s": None if self.last_drop_monotonic is None
                else round(time.monotonic() - self.last_drop_monotonic, 3),
            }


def count_handler_error(stats: Iterable[MappingStats], where: str, ex: Exception,
                        errors: collections.Counter[str], rlog: RateLimitedLog) -> None:
    """A receive handler raised (a bug): one ``handler_error`` drop per mapping it serves, one bridge error, and
    a rate-bounded log line. Never raises."""
    for st in stats:
        st.drop("handler_error")
    errors["handler_error"] += 1
    rlog.note((where, "handler_error"), logging.ERROR, "%s: %s", type(ex).__name__, ex)
