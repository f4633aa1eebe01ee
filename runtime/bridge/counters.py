"""What the bridge counts: per mapping (received, published, drops by reason, saturated and rejected fields,
out-of-order stamps). Both event loops touch the counters: they are thread-safe. The bridge's bounded-rate log is
a sam_runtime.common.rate_log.RateLimitedLog on :data:`log`.

Every part of the bridge logs to the one logger ``sam_runtime.bridge`` (:data:`log`), whatever module it is in.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Iterable
from typing import Any

from sam_runtime.common.rate_log import DEFAULT_INTERVAL_S, RateLimitedLog

__all__ = ["DEFAULT_LOG_INTERVAL_S", "DROP_REASONS", "INTENDED_DROPS", "MappingStats", "count_handler_error",
           "count_superseded", "log"]

log = logging.getLogger("sam_runtime.bridge")

DEFAULT_LOG_INTERVAL_S = DEFAULT_INTERVAL_S
DROP_REASONS = ("unknown_source", "rejected", "convert_error", "bad_cdr", "handler_error", "publish_error",
                "not_sent", "not_a_number", "queue_full", "link_down", "shutdown", "lost", "lost_link_down",
                "transfer_id_jump", "unselected",
                "rate_limited", "coalesced", "expired", "disabled", "inactive",
                "interface_mismatch")  # (a board whose firmware is from another spec: bridge.interface_check)
# Drops the spec or the operator asked for (max_rate_hz, a disabled mapping, a managed bridge deactivated by its
# lifecycle manager): counted like the others, but no sign of trouble, so they do not make the mapping WARN on
# /diagnostics (an expired command does: it waited too long somewhere; nor is a board's mismatched firmware).
INTENDED_DROPS = frozenset({"rate_limited", "coalesced", "disabled", "inactive"})


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
        self.last_drop_monotonic: float | None = None
        self._nan_rejects = 0  # rejections for NaN whose drop is still to be counted (see drop)

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

    def reject_nan(self, key: str) -> None:
        """A message rejected because a value was NaN (a NaN command, a NaN into an integer): counted under
        `rejected.<key>` as every rejection, and its drop, which the bridge counts as "rejected" right after the
        converter returned None, as `not_a_number` instead (a mapping converts on one thread at a time)."""
        with self._lock:
            self.rejected[str(key)] += 1
            self._nan_rejects += 1
        if self._log is not None:
            self._log.note((self.name, "not_a_number"), logging.WARNING, "rejected a message: %s is NaN", key)

    # bridge interface
    def receive(self) -> None:
        with self._lock:
            self.received += 1

    def publish(self) -> None:
        with self._lock:
            self.published += 1

    def bridged(self) -> None:
        """One message received and published (UAVCAN -> ROS's usual case: one lock instead of two)."""
        with self._lock:
            self.received += 1
            self.published += 1

    def drop(self, reason: str, count: int = 1) -> None:
        if count <= 0:
            return
        with self._lock:
            if reason == "rejected" and self._nan_rejects:
                taken = min(count, self._nan_rejects)
                self._nan_rejects -= taken
                self.dropped["not_a_number"] += taken
                count -= taken
            if count:
                self.dropped[reason] += count
            if reason not in INTENDED_DROPS:
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


def count_superseded(stats: MappingStats, reason: str, _item: Any) -> None:
    """A held message or command a newer one replaced (a Pacer's ``supersede``: functools.partial of this)."""
    stats.drop(reason)


def count_handler_error(stats: Iterable[MappingStats], where: str, ex: Exception,
                        errors: collections.Counter[str], rlog: RateLimitedLog) -> None:
    """A receive handler raised (a bug): one ``handler_error`` drop per mapping it serves, one bridge error, and
    a rate-bounded log line. Never raises."""
    for st in stats:
        st.drop("handler_error")
    errors["handler_error"] += 1
    rlog.note((where, "handler_error"), logging.ERROR, "%s: %s", type(ex).__name__, ex)
