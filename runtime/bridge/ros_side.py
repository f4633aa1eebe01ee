"""The bridge's ROS node: its own rclpy context, the spec's parameters (ranges and rules, as the generated nodes
through sam_runtime.node_support), each topic's QoS from the spec, the receive clock, and the executor spinning in
its own thread.

- QoS: each topic's side of the generated tables: publishers its ``qos``, command subscriptions its
  ``subscriber_qos`` (sensor data published reliable as REP 2003 says, so any subscriber matches; commands and
  states reliable, ...);
  ``qos_depth`` and ``command_reliability`` override the depth of every endpoint and the reliability of the
  command subscriptions when given. Publishers are keep-last: a slow or stuck ROS subscriber never blocks the
  bridge (DDS drops that subscriber's oldest samples, or never waits for it on a best-effort topic).
- Receive stamps: the node's ROS clock reads the system clock (CLOCK_REALTIME, as time.time_ns) unless
  use_sim_time made ROS time active; time.time_ns costs ~0.06 us against ~2.4 us for Clock.now(), so the clock is
  asked only while ROS time is active (tracked after every parameter set: use_sim_time may change at run time).
- The executor: rclpy's EventsExecutor where it exists (it does not rebuild a wait set per wake-up: ~3x the
  command throughput of SingleThreadedExecutor here, bench/profile_bridge.py), spun by spin_until_future_complete
  on a future that completes only when the bridge stops, instead of returning to Python after every callback as
  spin_once does (~15 % less CPU per command in the rclpy thread). No polling: the thread sleeps until a callback
  is due, however long (the slice is an hour: without a timeout, rclpy 7's EventsExecutor keeps the GIL while it
  waits); stopping completes the future and wakes the executor. The Python executors (the fallback) spin for the
  same future without a timeout (they add a done callback to it per call: one call here). It is the one executor
  of the bridge's ROS nodes but the service mappings' (their calls wait for a device, on threads of their own):
  the node duties (sam_runtime.bridge.backends.dronecan_duties) add their node to it (:meth:`RosSide.add_node`).
  An exception out of a callback is counted (``spin_error``) and the executor goes on.
- Managed (``host``, sam_runtime.bridge.managed.ManagedNode): the node, its context and its executor thread belong to
  the host and outlive the bridge (a lifecycle node exists from start to shutdown; a bridge is made at each
  configure and closed at each cleanup). The bridge then uses the host's node and executor, starts no spinner, and
  at close destroys only what it created on the node (the host's baseline of endpoints stays) and the other parts'
  nodes. The spec's parameters are declared on the first configure and kept, as a lifecycle node keeps its
  parameters across cleanup and configure.
"""

from __future__ import annotations

import functools
import logging
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from sam_runtime.bridge.backend import BridgeConfigError
from sam_runtime.bridge.backends.spin_thread import WaitingCalls
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.common.executors import make_executor
from sam_runtime.node_support import ParameterConfigError, declare_parameters, qos_profile

__all__ = ["RosSide"]

# How long one spin_until_future_complete waits at most: not a poll (stopping wakes it), a bound that keeps the
# call's timeout finite (rclpy 7's EventsExecutor holds the GIL while it waits without one).
_SPIN_SLICE_S = 3600.0


class RosSide:
    """:param parameters, rules: the spec's (tables.PARAMETERS, tables.PARAMETER_RULES).
    :param overrides: initial parameter values by spec or ROS name."""

    def __init__(self, lifetime: Lifetime, name: str, *, ros_args: Sequence[str] = (), parameters: Sequence[Any] = (),
                 rules: Sequence[Any] = (), overrides: Mapping[str, Any] | None = None, qos_depth: int | None = None,
                 command_reliability: str | None = None, namespace: str | None = None, host: Any = None) -> None:
        if command_reliability not in (None, "reliable", "best_effort"):
            raise BridgeConfigError(f"command_reliability must be reliable or best_effort, not {command_reliability!r}")
        self.lifetime = lifetime
        self.name = name
        self._ros_args = list(ros_args)
        self._parameters, self._rules = list(parameters), list(rules)
        self._overrides = dict(overrides or {})
        self.qos_depth = None if qos_depth is None else int(qos_depth)
        self.command_reliability = command_reliability
        self.namespace = namespace  # the node's (None: "/" or an __ns remap in ros_args); relative topics resolve there
        self.context: Any = None
        self.node: Any = None
        self.clock: Any = None
        self.executor: Any = None
        self.ros_time_active = False
        self._publishers: dict[str, Any] = {}
        self._subscriptions: dict[str, Any] = {}
        self._spin_future: Any = None
        self._events = False  # the executor is rclpy's EventsExecutor
        self._spin_thread: threading.Thread | None = None
        self._stop_spin = threading.Event()
        self._extra_nodes: list[Any] = []  # other parts' ROS nodes on this executor (RosSide.add_node)
        self.host = host  # a ManagedNode: its node, context and executor (see the module's doc)
        # the one executor thread of the parts whose callbacks wait for a device (service mappings, board stores)
        self.waiting_calls = WaitingCalls(lifetime, f"{name}-calls")

    def attach(self) -> None:
        """The node first when the bridge starts; destroyed last."""
        self.lifetime.add_hooks("ROS node", start=self._open, close=self._close)

    # -------------------------------------------------------------------------------------------- lifetime
    def _open(self) -> None:
        if self.host is not None:
            self._open_hosted()
            return
        import rclpy
        from rclpy.node import Node
        from rclpy.signals import SignalHandlerOptions

        self.context = rclpy.Context()
        rclpy.init(args=[], context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        cli_args = None
        if self._ros_args:
            cli_args = self._ros_args if self._ros_args[0] == "--ros-args" else ["--ros-args", *self._ros_args]
        self.node = Node(self.name, namespace=self.namespace, context=self.context, cli_args=cli_args)
        self.clock = self.node.get_clock()
        self.ros_time_active = bool(self.clock.ros_time_is_active)
        self.node.add_post_set_parameters_callback(self._after_set_parameters)
        try:
            declare_parameters(self.node, self._parameters, self._rules, overrides=self._overrides)
        except ParameterConfigError as ex:
            raise BridgeConfigError(str(ex)) from None
        self.executor, self._events = make_executor(self.context)
        self.executor.add_node(self.node)

    def _open_hosted(self) -> None:
        host = self.host
        self.context, self.node, self.executor, self._events = host.context, host.node, host.executor, host.events
        self.clock = self.node.get_clock()
        self.ros_time_active = bool(self.clock.ros_time_is_active)
        self.node.add_post_set_parameters_callback(self._after_set_parameters)
        if not host.parameters_declared:
            try:
                declare_parameters(self.node, self._parameters, self._rules, overrides=self._overrides)
            except ParameterConfigError as ex:
                raise BridgeConfigError(str(ex)) from None
            host.parameters_declared = True

    def _close_hosted(self) -> None:
        """Destroy what this bridge made on the host's node and its parts' nodes; the host keeps the node."""
        steps: list[Callable[[], Any]] = [
            lambda: self.node.remove_post_set_parameters_callback(self._after_set_parameters)]
        for node in self._extra_nodes:
            steps += [functools.partial(self.executor.remove_node, node), node.destroy_node]
        steps += self.host.release_steps()
        for step in steps:
            try:
                step()
            except Exception:
                pass

    def add_node(self, node: Any) -> None:
        """Another ROS node of the bridge on this executor (before the spinner starts); destroyed at close, before
        the bridge's node."""
        self.executor.add_node(node)
        self._extra_nodes.append(node)

    def _close(self) -> None:
        """After everything else: the executor, the nodes, the context (each may already be gone)."""
        if self.host is not None:
            self._close_hosted()
            return
        steps = [lambda: self.executor.shutdown(timeout_sec=1.0) if self.executor is not None else None,
                 *[node.destroy_node for node in self._extra_nodes],
                 lambda: self.node.destroy_node() if self.node is not None else None,
                 lambda: self.context.shutdown() if self.context is not None and self.context.ok() else None]
        for step in steps:
            try:
                step()
            except Exception:
                pass

    def attach_spinner(self) -> None:
        """Spin the executor in its own thread from here on in the start order (attach it last: it stops first,
        so no hand-off happens after that)."""
        if self.host is not None:
            return  # the host's executor thread spins from before configure to shutdown
        self.lifetime.add_hooks("rclpy executor", start=self._start_spinning, close=self._stop_spinning)

    def _start_spinning(self) -> None:
        from rclpy.task import Future

        self._stop_spin.clear()
        self._spin_future = Future()  # a new one per start: the last stop completed the old one
        self._spin_thread = threading.Thread(target=self._spin, name=f"{self.name}-rclpy", daemon=True)
        self._spin_thread.start()

    async def _stop_spinning(self) -> None:
        import asyncio

        self._stop_spin.set()
        if self._spin_future is not None and not self._spin_future.done():
            self._spin_future.set_result(None)
        if self._events:
            try:
                self.executor.wake()  # (the EventsExecutor does not wake for the future alone)
            except Exception:  # the context is going down: the executor stops anyway
                pass
        if self._spin_thread is not None:
            await asyncio.get_running_loop().run_in_executor(None, self._spin_thread.join, 5.0)

    def _spin(self) -> None:
        executor, future = self.executor, self._spin_future
        while not self._stop_spin.is_set():
            try:
                if self._events:
                    executor.spin_until_future_complete(future, timeout_sec=_SPIN_SLICE_S)
                else:  # no timeout: a Python executor wakes when the future completes
                    executor.spin_until_future_complete(future)
            except Exception as ex:  # a callback bug or a context going down: keep spinning until told
                if self._stop_spin.is_set() or not self.context.ok():
                    break
                self.lifetime.errors["spin_error"] += 1
                self.lifetime.rlog.note(("executor", "spin_error"), logging.ERROR, "rclpy executor: %s: %s",
                                        type(ex).__name__, ex)

    # -------------------------------------------------------------------------------------------- time
    def _after_set_parameters(self, params: list[Any]) -> None:
        self.ros_time_active = bool(self.clock.ros_time_is_active)

    def receive_ns(self) -> int:
        """The ROS receive time in nanoseconds (the node's clock: system time, or ROS time under use_sim_time)."""
        return self.clock.now().nanoseconds if self.ros_time_active else time.time_ns()

    # -------------------------------------------------------------------------------------------- endpoints
    def qos(self, topic: Any, *, command: bool = False) -> Any:
        """The topic's QoS from the spec, with the overrides: its publishers' side, or for a command subscription
        its subscribers' side."""
        q = topic.subscriber_qos if command else topic.qos
        reliability = (self.command_reliability if command else None) or q.reliability
        return qos_profile(reliability, q.durability, q.depth if self.qos_depth is None else self.qos_depth)

    def publisher(self, topic: Any, cls: Any) -> Any:
        """The node's publisher of ``topic`` (one per topic, shared by its mappings)."""
        pub = self._publishers.get(topic.name)
        if pub is None:
            pub = self._publishers[topic.name] = self.node.create_publisher(cls, topic.name, self.qos(topic))
        return pub

    def subscribe(self, topic: Any, cls: Any, callback: Callable[[Any], None], *, raw: bool = False) -> Any:
        """A command subscription of ``topic``; ``raw``: the callback gets each message's CDR bytes (the wire
        path: rclpy does not deserialize them)."""
        sub = self._subscriptions[topic.name] = self.node.create_subscription(
            cls, topic.name, callback, self.qos(topic, command=True), raw=raw)
        return sub

    def matched(self, topic: str) -> int | None:
        """ROS subscribers of a published topic, or ROS publishers of a subscribed one (None: no such endpoint)."""
        obj, method = ((self._publishers[topic], "get_subscription_count") if topic in self._publishers
                       else (self._subscriptions.get(topic), "get_publisher_count"))
        if obj is None:
            return None
        try:
            return int(getattr(obj, method)())
        except Exception:
            return None
