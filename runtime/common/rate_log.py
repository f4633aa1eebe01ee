"""A log that cannot flood: at most one line per key per interval, with the count since the previous line.

The first occurrence of a key is written at once; later ones are summed and written at most once per ``interval``
seconds (when one arrives after the interval, or at :meth:`RateLimitedLog.flush`, which the owner calls
periodically and with ``force`` at close, so that nothing stays unwritten). Thread-safe; formatting is lazy.

The bridge writes ``key = (mapping or part, reason)`` lines with the default format; the DroneCAN drop log
(sam_runtime.dronecan_io.drops.DropLog) gives its own ``write``.

>>> lines = []
>>> now = [0.0]
>>> rlog = RateLimitedLog(logging.getLogger("doctest"), 10.0, write=lambda ln: lines.append(ln), clock=lambda: now[0])
>>> for _ in range(3): rlog.note(("imu", "lost"), logging.WARNING, "gap of %d", 2)
>>> now[0] = 10.0; rlog.flush()
>>> [(ln.first, ln.fresh, ln.count, ln.seconds, ln.total, ln.text()) for ln in lines]
[(True, True, 1, 0.0, 1, 'gap of 2'), (False, False, 2, 10.0, 3, 'gap of 2')]
>>> rlog.lines[("imu", "lost")]
2
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Any

__all__ = ["DEFAULT_INTERVAL_S", "LogLine", "RateLimitedLog"]

DEFAULT_INTERVAL_S = 10.0


@dataclass(frozen=True)
class LogLine:
    """One line to write: ``count`` occurrences of ``key`` in the last ``seconds`` (``total`` in all); ``level``,
    ``msg`` and ``args`` of the last one."""

    key: Hashable
    level: int
    msg: str
    args: tuple[Any, ...]
    count: int
    seconds: float
    total: int
    first: bool  # the key's first line
    fresh: bool  # nothing was pending: the line reports only the occurrence just noted

    def text(self) -> str:
        """``msg % args``, never raising (a bad format must not break the caller)."""
        try:
            return self.msg % self.args if self.args else self.msg
        except Exception:
            return f"{self.msg} {self.args!r}"


class RateLimitedLog:
    """At most one line per key per ``interval`` seconds, with the count since the previous line.

    ``write(line)`` writes a :class:`LogLine` (default: to ``logger``, keyed ``(who, what)``); ``clock`` is
    monotonic seconds. ``lines`` counts the lines written per key."""

    def __init__(self, logger: logging.Logger, interval: float = DEFAULT_INTERVAL_S, *,
                 write: Callable[[LogLine], None] | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.logger = logger
        self.interval = float(interval)
        self._write = write or self.write_default
        self._clock = clock
        self._lock = threading.Lock()
        # key -> [last line (clock), pending, total, level, msg, args]
        self._state: dict[Hashable, list[Any]] = {}
        self.lines: collections.Counter[Hashable] = collections.Counter()

    def note(self, key: Hashable, level: int, msg: str, *args: Any, count: int = 1) -> None:
        """``count`` occurrences of ``key`` now; ``msg % args`` describes the last one."""
        now = self._clock()
        line: LogLine | None = None
        with self._lock:
            st = self._state.get(key)
            if st is None:
                self._state[key] = [now, 0, count, level, msg, args]
                line = LogLine(key, level, msg, args, count, 0.0, count, True, True)
            else:
                fresh = st[1] == 0
                st[1] += count
                st[2] += count
                st[3], st[4], st[5] = level, msg, args
                if now - st[0] >= self.interval:
                    line = LogLine(key, level, msg, args, st[1], now - st[0], st[2], False, fresh)
                    st[0], st[1] = now, 0
            if line is not None:
                self.lines[key] += 1
        if line is not None:
            self._write(line)

    def flush(self, force: bool = False) -> None:
        """Write the pending counts whose interval has passed (all of them with ``force``)."""
        now = self._clock()
        out = []
        with self._lock:
            for key, st in self._state.items():
                if st[1] and (force or now - st[0] >= self.interval):
                    out.append(LogLine(key, st[3], st[4], st[5], st[1], now - st[0], st[2], False, False))
                    st[0], st[1] = now, 0
                    self.lines[key] += 1
        for line in out:
            self._write(line)

    def write_default(self, line: LogLine) -> None:
        """``who: what: detail (n; ...)`` for a key's first line, then ``who: what: n in the last s (total in all);
        the last: detail``."""
        if not self.logger.isEnabledFor(line.level):
            return
        key: Any = line.key  # the default format's keys are (who, what)
        who, what = key
        if line.first:
            self.logger.log(line.level, "%s: %s: %s (%d; more are summed at most every %.0f s)", who, what,
                            line.text(), line.count, self.interval)
        else:
            self.logger.log(line.level, "%s: %s: %d in the last %.1f s (%d in all); the last: %s", who, what,
                            line.count, line.seconds, line.total, line.text())
