"""A ROS executor spun on a thread of its own, for the bridge's callbacks that wait for a device (the service
mappings' calls, the boards' store services): :class:`WaitingCalls` is the one such executor of a bridge, which every
part that needs it adds its node to (one thread for all of them, not one per part).

Invariants: the thread spins until :meth:`SpinThread.close`, the bridge's lifetime closing or the ROS context
shutting down; it waits for work without a timeout (no polling: an idle bridge costs nothing here), and ``close()``
wakes it. An exception out of a spin (a callback's bug, the context going away) is counted in
``lifetime.errors[error_key]`` and logged, never raised; ``close()`` joins the thread (2 s at most), then shuts the
executor down and destroys its nodes, ignoring what a context already shut down says.
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
        try:
            nodes = list(self.executor.get_nodes())
        except Exception:  # the context is gone already
            nodes = [self.node]
        for step in (lambda: self.executor.shutdown(timeout_sec=1.0), *(n.destroy_node for n in nodes)):
            try:
                step()
            except Exception:  # the context is gone already: nothing left to release
                pass


# The pool of the shared executor: rclpy's MultiThreadedExecutor makes a thread only when a callback finds none idle
# (concurrent.futures), so an idle bridge has none; this is how many calls may wait for devices at once.
WAITING_CALL_THREADS = 16


class WaitingCalls:
    """The bridge's one executor for callbacks that wait for a device, on one thread (``<bridge>-calls``) and a pool.

    A part adds its node when it starts and removes it when it closes (the loop's thread, both); the thread starts
    with the first node and stops with the last, so a bridge with neither service mappings nor boards' settings has
    none, and a managed bridge's cleanup leaves none behind."""

    def __init__(self, lifetime: Any, name: str) -> None:
        self.lifetime, self.name = lifetime, name
        self._spinner: SpinThread | None = None

    @property
    def nodes(self) -> list[Any]:
        return [] if self._spinner is None else list(self._spinner.executor.get_nodes())

    def add(self, context: Any, node: Any) -> None:
        if self._spinner is None:
            from rclpy.executors import MultiThreadedExecutor

            executor = MultiThreadedExecutor(num_threads=WAITING_CALL_THREADS, context=context)
            self._spinner = SpinThread(self.lifetime, context, executor, node, self.name, "waiting_calls_error",
                                       "the executor of waiting calls")
            self._spinner.start()
        else:
            self._spinner.executor.add_node(node)  # (wakes the spinning executor: its wait set is rebuilt)

    def remove(self, node: Any) -> None:
        """Take ``node`` off the executor and destroy it; the last one stops the thread."""
        spinner = self._spinner
        if spinner is None:
            return
        if len(spinner.executor.get_nodes()) <= 1:
            self._spinner = None
            spinner.close()  # destroys it
            return
        for step in (lambda: spinner.executor.remove_node(node), node.destroy_node):
            try:
                step()
            except Exception:  # the context is gone already
                pass
