"""A progress line for steps that take many seconds (a CMake build, the first DSDL compile), on a terminal only.

``with TerminalProgress("building ROS package sam_msgs") as bar: ...`` shows, after a second without an end,
``building ROS package sam_msgs ... 12 s`` on the terminal, rewritten in place once a second until the step ends,
then erased (the callers say the outcome in their own lines). ``bar.set(label)`` changes the label (the step).

Invariants: nothing is written unless the stream is a terminal (a log file or a pipe gets no control characters
and no extra lines); a step shorter than ``delay`` writes nothing at all; the ticker thread never outlives the
``with`` block; a write that fails (the terminal went away) stops the line, never the step.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from types import TracebackType
from typing import TextIO

__all__ = ["TerminalProgress"]

_CLEAR = "\r\x1b[K"  # to the line's start, erase it


class TerminalProgress:
    """:param label: what is going on; :param stream: default sys.stderr; :param delay: seconds before the first
    line; :param interval: seconds between updates."""

    def __init__(self, label: str, stream: TextIO | None = None, *, delay: float = 1.0, interval: float = 1.0,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.delay, self.interval, self.clock = delay, interval, clock
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._shown = False
        self._started = 0.0

    @property
    def enabled(self) -> bool:
        """Whether the stream is a terminal."""
        try:
            return bool(self.stream.isatty())
        except (AttributeError, ValueError, OSError):  # no isatty, or a closed stream
            return False

    def set(self, label: str) -> None:
        """Another label from the next update on (the step within the task)."""
        self.label = label

    def line(self) -> str:
        """The text shown now (without the control characters)."""
        return f"{self.label} ... {self.clock() - self._started:.0f} s"

    def __enter__(self) -> TerminalProgress:
        self._started = self.clock()
        if self.enabled:
            self._thread = threading.Thread(target=self._tick, name="terminal-progress", daemon=True)
            self._thread.start()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        if self._shown:
            self._write(_CLEAR)

    def _tick(self) -> None:
        if self._stop.wait(self.delay):
            return
        while True:
            if not self._write(_CLEAR + self.line()):
                return
            self._shown = True
            if self._stop.wait(self.interval):
                return

    def _write(self, text: str) -> bool:
        try:
            self.stream.write(text)
            self.stream.flush()
            return True
        except (OSError, ValueError):  # the terminal went away: the step goes on without its line
            return False
