"""The bridge's message counters as the CPU section reads them: from its /diagnostics, which it publishes once a
second whether anyone listens or not (one status per mapping with ``published``, the bridge's with ``uptime_s``).

Listening costs the bridge one more matched reader of a 1 Hz topic. The alternative, ``--stats-file``, makes the
bridge build and write a JSON snapshot every second (~1 ms of json.dumps alone on this machine): about 0.2 % of a
core added to the very figures measured, as much as the whole idle budget of issue 26.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any

import bench.common  # noqa: F401  (loopback discovery before rclpy)


@dataclass(frozen=True)
class Counters:
    published: int  # the sum of every mapping's published messages
    dropped: int  # the sum of every mapping's drops
    uptime_s: float  # the bridge's uptime when it made the snapshot
    mappings: int


def counters_of(msg: Any) -> Counters | None:
    """The bridge's counters in a DiagnosticArray, or None when it holds none of the bridge's statuses."""
    uptime, published, dropped, mappings = None, 0, 0, 0
    for st in msg.status:
        v = {kv.key: kv.value for kv in st.values}
        if "uptime_s" in v and "link_state" in v:
            uptime = float(v["uptime_s"])
        elif "published" in v and "direction" in v:
            published += int(v["published"])
            dropped += int(v.get("dropped", 0))
            mappings += 1
    return None if uptime is None else Counters(published, dropped, uptime, mappings)


class DiagnosticsWatch:
    """An rclpy node of its own (own context, own thread) that keeps the bridge's latest counters."""

    def __init__(self) -> None:
        import rclpy
        from diagnostic_msgs.msg import DiagnosticArray
        from rclpy.executors import SingleThreadedExecutor

        self._context = rclpy.context.Context()
        rclpy.init(context=self._context)
        self._node = rclpy.create_node("bench_cpu_watch", context=self._context)
        self._node.create_subscription(DiagnosticArray, "/diagnostics", self._on, 10)
        self._executor = SingleThreadedExecutor(context=self._context)
        self._executor.add_node(self._node)
        self._cond = threading.Condition()
        self._latest: Counters | None = None
        self._seq = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, name="diagnostics-watch", daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while not self._stop.is_set() and self._context.ok():
            self._executor.spin_once(timeout_sec=0.2)

    def _on(self, msg: Any) -> None:
        c = counters_of(msg)
        if c is not None:
            with self._cond:
                self._latest, self._seq = c, self._seq + 1
                self._cond.notify_all()

    def next(self, timeout: float) -> Counters:
        """The first snapshot published after this call (the bridge's 1 s period at most, once discovered)."""
        deadline = time.monotonic() + timeout
        with self._cond:
            seq = self._seq
            while self._seq == seq:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RuntimeError(f"no /diagnostics from the bridge in {timeout:.0f} s")
                self._cond.wait(left)
            assert self._latest is not None
            return self._latest

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5.0)
        self._executor.shutdown()
        self._node.destroy_node()
        self._context.try_shutdown()
