"""A ROS executor spun on a thread of its own, for the bridge's service mappings (their calls wait for a device).

Invariants: the thread spins until :meth:`SpinThread.close`, the bridge's lifetime closing or the ROS context
shutting down; it waits for work without a timeout (no polling: an idle bridge costs nothing here), and ``close()``
wakes it. An exception out of a spin (a callback's bug, the context going away) is counted in
``lifetime.errors[error_key]`` and logged, never raised; ``close()`` joins the thread (2 s at most), then shuts the
executor down and destroys the node, ignoring what a context already shut down says.
"""

from __future__ import annotations

import logging
import threading
from typing import Any

log = logging.getLogger(__name__)


class SpinThread:
    def __init__(self, lifetime: Any, context: Any, executor: Any, node: Any, name: str, error_key: str,
                 what: str) -> None:
        self.lifetime, self.context, self.executor, self.node = lifetime, context, executor, node
        self.error_key, self.what = error_key, what
        executor.add_node(node)
        from rclpy.task import Future

        # Done at close(): rclpy's Python executors wake when a future they spin for completes (a guard condition
        # alone only makes them wait again).
        self._stop: Any = Future()
        self.thread = threading.Thread(target=self._spin, name=name, daemon=True)

    def start(self) -> None:
        self.thread.start()

    def _spin(self) -> None:
        while not self._stop.done() and not self.lifetime.closed and self.context.ok():
            try:
                self.executor.spin_until_future_complete(self._stop)  # no timeout: no polling
            except Exception as ex:  # the context shutting down under us, or a callback's bug
                if self._stop.done() or self.lifetime.closed:
                    return
                self.lifetime.errors[self.error_key] += 1
                log.warning("%s: %s: %s", self.what, type(ex).__name__, ex)

    def close(self) -> None:
        if not self._stop.done():
            self._stop.set_result(None)
        if self.thread.is_alive():
            self.thread.join(timeout=2.0)
        for step in (lambda: self.executor.shutdown(timeout_sec=1.0), self.node.destroy_node):
            try:
                step()
            except Exception:  # the context is gone already: nothing left to release
                pass
