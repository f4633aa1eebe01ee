"""The node host (``sam-codegen nodes``): the spec's nodes that have an implementation, in one process.

One rclpy context (started with ``--ros-args --params-file <file>``: generated/params/<vehicle>.params.yaml by
default, so every node declares its parameters with one value), one executor, each node its own rclpy Node; a
small host node publishes the spec's static frames on /tf_static once (latched). The mission node gets its goals
from ``goals`` (``--goal``/``--mission``; default: the demo mission).

``namespace`` (sam_runtime.common.ros_namespace: ``--namespace``, or ``__ns:=`` among ``ros_args``): every node
of the host, the host node too, is created in it (the spec's relative topics resolve under it, the parameters file's
``/**`` still matches) with its frame prefix (the static frames too), so a second vehicle's host can run beside.

Nothing a node does ends the host: subscriber callbacks are guarded by the generated bases, timers by
:func:`sam_runtime.nodes.common.guarded_timer`; anything else that escapes the executor is counted and logged here
and the host spins on. It stops on ``stop()`` (the CLI: SIGINT/SIGTERM) or after ``duration``.
"""

from __future__ import annotations

import importlib
import logging
import time
import traceback
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sam_runtime.common.executors import make_executor
from sam_runtime.common.ros_namespace import RosNamespace
from sam_runtime.nav.mission import MissionGoal
from sam_runtime.nodes import ImplementationError, implemented, load_implementation, unimplemented

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule

__all__ = ["HostConfigError", "HostPlan", "NodeHost", "plan_host"]

_log = logging.getLogger("sam_runtime.nodes")
ERROR_LOG_INTERVAL_S = 10.0


class HostConfigError(Exception):
    """The host cannot run as asked (unknown node, a node without implementation asked for, a missing file...)."""


@dataclass(frozen=True)
class HostPlan:
    """What a host will run for a spec: ``run`` (implemented and selected, in the spec's order) and ``missing``
    (the spec's nodes without an implementation)."""

    run: tuple[str, ...]
    missing: tuple[str, ...]


def plan_host(tables: TablesModule, only: Sequence[str] | None = None) -> HostPlan:
    """The nodes to run; ``only`` restricts them (HostConfigError for a name the spec does not have, or one
    without an implementation)."""
    names = [n.name for n in tables.NODES]
    have = implemented(tables)
    if only is not None:
        unknown = [n for n in only if n not in names]
        if unknown:
            raise HostConfigError(f"--only: no node {', '.join(unknown)} in the spec (its nodes: "
                                  f"{', '.join(names) or 'none'})")
        without = [n for n in only if n not in have]
        if without:
            raise HostConfigError(f"--only: {', '.join(without)} {'has' if len(without) == 1 else 'have'} no "
                                  f"implementation (implemented: {', '.join(have) or 'none'})")
        have = [n for n in have if n in only]
    return HostPlan(tuple(have), tuple(unimplemented(tables)))


class NodeHost:
    """The nodes of ``plan`` in one rclpy context; ``spin`` until stopped, then ``close``."""

    def __init__(self, gen: Any, plan: HostPlan, *, params_file: Path | None = None,
                 goals: tuple[MissionGoal, ...] | None = None, domain_id: int | None = None,
                 namespace: RosNamespace | None = None, ros_args: Sequence[str] = ()) -> None:
        import rclpy
        from rclpy.node import Node
        from rclpy.signals import SignalHandlerOptions

        self.tables = gen.tables()
        self.plan = plan
        params = Path(params_file) if params_file is not None else gen.root / self.tables.PARAMS_FILE
        if not params.is_file():
            raise HostConfigError(f"parameters file {params} does not exist"
                                  + ("" if params_file is not None else " (run `sam-codegen build`)"))
        self.params_file = params
        self.namespace = ns = namespace or RosNamespace()
        extra = list(ros_args)[1:] if list(ros_args)[:1] == ["--ros-args"] else list(ros_args)
        classes = {}
        for name in plan.run:
            try:
                classes[name] = load_implementation(self.tables, name)
            except (ImplementationError, ImportError) as ex:
                raise HostConfigError(f"node {name}: {ex}") from None
        self.ctx = rclpy.Context()
        rclpy.init(args=["--ros-args", "--params-file", str(params), *extra], context=self.ctx, domain_id=domain_id,
                   signal_handler_options=SignalHandlerOptions.NO)
        self.executor, _events = make_executor(self.ctx)
        self.nodes: dict[str, Any] = {}
        self.errors = 0
        self._last_error_log = -float("inf")
        self._stop = False
        try:
            self.host_node = Node(f"{self.tables.VEHICLE}_node_host", namespace=ns.node_namespace, context=self.ctx)
            nodes_package = importlib.import_module(self.tables.NODES_PACKAGE)
            self.static_publisher = nodes_package.publish_static_transforms(self.host_node, ns.frame_prefix)
            self.executor.add_node(self.host_node)
            for name, cls in classes.items():
                kwargs: dict[str, Any] = {"context": self.ctx, "namespace": ns.node_namespace,
                                          "frame_prefix": ns.frame_prefix}
                if name == "mission" and goals is not None:
                    kwargs["goals"] = goals
                try:
                    node = cls(**kwargs)
                except Exception as ex:  # ParameterConfigError (a bad value in the params file), a bad mission...
                    raise HostConfigError(f"node {name} cannot start: {type(ex).__name__}: {ex}") from None
                self.nodes[name] = node
                self.executor.add_node(node)
        except BaseException:
            self.close()
            raise

    def stop(self) -> None:
        self._stop = True

    def spin(self, duration: float | None = None) -> None:
        """Run the executor until ``stop()`` or ``duration`` seconds; an exception that escapes a callback is
        counted, logged (its traceback, at most once per ERROR_LOG_INTERVAL_S) and the host goes on."""
        deadline = None if duration is None else time.monotonic() + duration
        while not self._stop and self.ctx.ok():
            if deadline is not None and time.monotonic() >= deadline:
                return
            try:
                self.executor.spin_once(timeout_sec=0.1)
            except Exception:
                self.errors += 1
                now = time.monotonic()
                if now - self._last_error_log >= ERROR_LOG_INTERVAL_S:
                    self._last_error_log = now
                    _log.error("a callback raised (%d so far); the host goes on:\n%s", self.errors,
                               traceback.format_exc().rstrip())

    def close(self) -> None:
        for node in [*getattr(self, "nodes", {}).values(), getattr(self, "host_node", None)]:
            if node is None:
                continue
            try:
                self.executor.remove_node(node)
                node.destroy_node()
            except Exception as ex:  # closing: report, never raise
                _log.warning("destroying %s: %s: %s", node.get_name(), type(ex).__name__, ex)
        try:
            self.executor.shutdown(timeout_sec=1.0)
        finally:
            if self.ctx.ok():
                self.ctx.shutdown()
