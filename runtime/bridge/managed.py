"""The bridge as a ROS 2 managed (lifecycle) node (issue 30): ``sam-codegen bridge`` (active at once, as before) and
``sam-codegen bridge --managed`` (waits unconfigured for a manager).

A vehicle's bringup starts its drivers in order and must be able to stop a bridge from commanding the actuators
without killing it. ROS 2 does this with managed nodes: the standard lifecycle_msgs services of the node
(``<node>/change_state``, ``get_state``, ``get_available_states``, ``get_available_transitions``,
``get_transition_graph``) and its ``transition_event`` topic, which any tool (``ros2 lifecycle``, a launch file's
lifecycle events, nav2's lifecycle manager, a few lines of rclpy) drives.

=================  =================================================================================================
transition         what the bridge does
=================  =================================================================================================
(start)            the lifecycle node (rclpy.lifecycle.LifecycleNode, the bridge's name and namespace) and its
                   executor thread; unconfigured: no bus, no topics, nothing but the lifecycle services (without
                   ``--managed`` the node configures and activates itself at once: :meth:`ManagedNode.trigger`)
``configure``      the bridge: the generated tables loaded, the bus opened, every topic, service and /diagnostics
                   (:class:`~sam_runtime.bridge.composition.Bridge` made and started on the host's node);
                   inactive: telemetry (bus -> ROS) flows, every command (ROS -> bus) is dropped as ``inactive``
``activate``       commands are bridged
``deactivate``     commands stop at once: the next one the executor takes, and any queued or held at that moment,
                   is dropped and counted ``inactive`` (per mapping, on /diagnostics, the bridge's status says
                   ``inactive``); service mappings fail their calls as ``inactive``; telemetry goes on
``cleanup``        the bridge closed (bus closed, its topics and services destroyed); unconfigured again
``shutdown``       from any state: the bridge closed if it was open; the process exits
error              a transition that raised: the bridge closed, unconfigured again (rclpy's error processing)
=================  =================================================================================================

A configure that fails (a bad spec parameter, a transport that does not open) returns FAILURE: the node stays
unconfigured and the manager may try again. The DroneCAN Panic duty is not gated: a Panic stops the devices, which
is what a deactivated bridge wants too.

Cost: the transitions run on the node's executor thread (the one that spins the bridge's subscriptions, as
:mod:`.ros_side`'s thread does for an unmanaged bridge: no thread, no timer more) and hand their work to the
asyncio loop, waiting for it; the hot path pays one bool read per command (:attr:`.outbound.Outbound.active`).
"""

from __future__ import annotations

import asyncio
import functools
import logging
import threading
from collections.abc import Callable, Coroutine, Sequence
from typing import Any

from sam_runtime.bridge.counters import log
from sam_runtime.common.executors import make_executor

__all__ = ["TRANSITIONS", "ManagedBridge", "ManagedNode"]

TRANSITIONS = ("configure", "activate", "deactivate", "cleanup", "shutdown", "error")

# The spin call's bound: not a poll (stopping wakes the executor); rclpy 7's EventsExecutor keeps the GIL while it
# waits without a timeout (as in ros_side).
_SPIN_SLICE_S = 3600.0


class ManagedNode:
    """The lifecycle node, its context and its executor thread, from :meth:`open` to :meth:`close`.

    :param on_transition: called on the executor thread with the transition's name (:data:`TRANSITIONS`);
        returns whether it succeeded. An exception is logged and fails the transition."""

    def __init__(self, name: str, *, namespace: str | None = None, ros_args: Sequence[str] = (),
                 on_transition: Callable[[str], bool]) -> None:
        self.name = name
        self.namespace = namespace
        self._ros_args = list(ros_args)
        self._on_transition = on_transition
        self.context: Any = None
        self.node: Any = None
        self.executor: Any = None
        self.events = False  # the executor is rclpy's EventsExecutor
        self.parameters_declared = False  # the spec's parameters, declared by the first configure (ros_side)
        self._baseline: dict[str, set[int]] = {}  # the node's own endpoints (lifecycle, parameter services)
        self._future: Any = None
        self._thread: threading.Thread | None = None
        self._results: tuple[Any, Any] = (True, False)  # rclpy's SUCCESS and FAILURE once open() imported them

    def open(self) -> None:
        import rclpy
        from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
        from rclpy.signals import SignalHandlerOptions
        from rclpy.task import Future

        handler = self._transition

        class _BridgeLifecycleNode(LifecycleNode):
            def on_configure(self, state: Any) -> Any:
                return handler("configure")

            def on_activate(self, state: Any) -> Any:
                # (LifecycleNode's own: its managed entities, none here; then the bridge)
                super().on_activate(state)
                return handler("activate")

            def on_deactivate(self, state: Any) -> Any:
                super().on_deactivate(state)
                return handler("deactivate")

            def on_cleanup(self, state: Any) -> Any:
                return handler("cleanup")

            def on_shutdown(self, state: Any) -> Any:
                return handler("shutdown")

            def on_error(self, state: Any) -> Any:
                return handler("error")

        self._results = (TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE)
        self.context = rclpy.Context()
        rclpy.init(args=[], context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        cli_args = None
        if self._ros_args:
            cli_args = self._ros_args if self._ros_args[0] == "--ros-args" else ["--ros-args", *self._ros_args]
        self.node = _BridgeLifecycleNode(self.name, namespace=self.namespace, context=self.context,
                                         cli_args=cli_args)
        self._baseline = {kind: {id(e) for e in getattr(self.node, kind)} for kind in _ENDPOINTS}
        self.executor, self.events = make_executor(self.context)
        self.executor.add_node(self.node)
        self._future = Future()
        self._thread = threading.Thread(target=self._spin, name=f"{self.name}-rclpy", daemon=True)
        self._thread.start()

    def _transition(self, name: str) -> Any:
        ok = False
        try:
            ok = bool(self._on_transition(name))
        except Exception as ex:
            log.error("lifecycle %s failed: %s: %s", name, type(ex).__name__, ex)
        return self._results[0] if ok else self._results[1]

    def trigger(self, name: str) -> bool:
        """Make transition ``name`` (configure, activate, ...) from here, as a manager's change_state would (the node
        configuring and activating itself); not on the asyncio loop's thread (the transition waits for the loop)."""
        return bool(getattr(self.node, f"trigger_{name}")() == self._results[0])

    def _spin(self) -> None:
        while not self._future.done():
            try:
                if self.events:
                    self.executor.spin_until_future_complete(self._future, timeout_sec=_SPIN_SLICE_S)
                else:
                    self.executor.spin_until_future_complete(self._future)
            except Exception as ex:  # a callback's bug, or the context going down
                if self._future.done() or not self.context.ok():
                    return
                log.error("lifecycle node executor: %s: %s", type(ex).__name__, ex)

    def release_steps(self) -> list[Callable[[], Any]]:
        """Destroying what was made on the node since :meth:`open` (a closing bridge's topics and services)."""
        steps: list[Callable[[], Any]] = []
        for kind, destroy in _ENDPOINTS.items():
            for entity in list(getattr(self.node, kind)):
                if id(entity) not in self._baseline[kind]:
                    steps.append(functools.partial(getattr(self.node, destroy), entity))
        return steps

    def stop_spinning(self) -> None:
        """No transition from here on (the process is stopping)."""
        if self._future is not None and not self._future.done():
            self._future.set_result(None)
            if self.events:
                try:
                    self.executor.wake()  # (the EventsExecutor does not wake for the future alone)
                except Exception:
                    pass
        if self._thread is not None:
            self._thread.join(5.0)

    def close(self) -> None:
        self.stop_spinning()
        for step in (lambda: self.executor.shutdown(timeout_sec=1.0) if self.executor is not None else None,
                     lambda: self.node.destroy_node() if self.node is not None else None,
                     lambda: self.context.shutdown() if self.context is not None and self.context.ok() else None):
            try:
                step()
            except Exception:
                pass


# what a bridge may create on the node, and how it goes again
_ENDPOINTS = {"publishers": "destroy_publisher", "subscriptions": "destroy_subscription",
              "services": "destroy_service", "clients": "destroy_client", "timers": "destroy_timer"}


class ManagedBridge:
    """The lifecycle node (:attr:`host`, a :class:`ManagedNode`) and its transitions, run on the asyncio loop:
    ``make(host)`` makes a bridge on the host's node (not started) at each configure.

    :param on_finalized: called on the loop after shutdown (the process stops)."""

    def __init__(self, name: str, make: Callable[[ManagedNode], Any], loop: asyncio.AbstractEventLoop,
                 on_finalized: Callable[[], None], *, namespace: str | None = None,
                 ros_args: Sequence[str] = (), autostart: bool = False) -> None:
        self.host = ManagedNode(name, namespace=namespace, ros_args=ros_args, on_transition=self.transition)
        # A node that activates itself (no --managed) bridges commands from its first configure on: nothing is dropped
        # between its own configure and activate (the commands a publisher kept for late subscribers, transient
        # local, arrive in that window), as before lifecycles.
        self._start_active = bool(autostart)
        self._make = make
        self._loop = loop
        self._on_finalized = on_finalized
        self.bridge: Any = None
        self.transitions: dict[str, int] = dict.fromkeys(TRANSITIONS, 0)  # succeeded, by name
        self.error: Exception | None = None  # why the last configure failed

    async def start_active(self) -> None:
        """Configure and activate the node itself (``sam-codegen bridge`` without ``--managed``); raises why the bridge
        did not start. The transitions run on a thread of their own that ends with them (they wait for this loop; a
        pool's thread would stay for the life of the process)."""
        done: asyncio.Future[bool] = self._loop.create_future()

        def run() -> None:
            try:
                ok = self.host.trigger("configure") and self.host.trigger("activate")
            except Exception as ex:  # (rclpy's own errors: never a wait without end)
                self._loop.call_soon_threadsafe(done.set_exception, ex)
                return
            self._loop.call_soon_threadsafe(done.set_result, ok)

        threading.Thread(target=run, name=f"{self.host.name}-start", daemon=True).start()
        if not await done:
            raise self.error or RuntimeError("the bridge did not activate")

    def transition(self, name: str) -> bool:
        """The executor thread: do transition ``name`` on the loop and wait for it."""
        steps: dict[str, Callable[[], Coroutine[Any, Any, bool]]] = {
            "configure": self._configure, "activate": self._activate, "deactivate": self._deactivate,
            "cleanup": self._close, "error": self._close, "shutdown": self._shutdown}
        ok = asyncio.run_coroutine_threadsafe(steps[name](), self._loop).result()
        if ok:
            self.transitions[name] += 1
        log.log(logging.INFO if ok else logging.ERROR, "lifecycle %s: %s", name, "done" if ok else "failed")
        return ok

    async def _configure(self) -> bool:
        if self.bridge is not None:  # (the state machine allows no configure twice; a guard all the same)
            return True
        try:
            bridge = self._make(self.host)
            if self._start_active:
                bridge.active = True
            await bridge.start()  # (inactive: a managed bridge starts with commands off)
        except Exception as ex:
            self.error = ex
            log.error("configure: the bridge did not start: %s: %s", type(ex).__name__, ex)
            return False
        self.bridge = bridge
        self._start_active = False  # (a configure after a cleanup waits for activate, as a managed one does)
        return True

    async def _activate(self) -> bool:
        if self.bridge is None:
            return False
        self.bridge.active = True
        return True

    async def _deactivate(self) -> bool:
        if self.bridge is None:
            return False
        self.bridge.active = False
        return True

    async def _close(self) -> bool:
        bridge, self.bridge = self.bridge, None
        if bridge is not None:
            await bridge.close()
        return True

    async def _shutdown(self) -> bool:
        await self._close()
        self._loop.call_soon(self._on_finalized)
        return True
