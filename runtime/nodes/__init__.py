"""The node implementations: subclasses of the generated node bases (generated/python/<vehicle>_nodes) with the
logic of :mod:`sam_runtime.nav`, and the host that runs them (:mod:`sam_runtime.nodes.host`).

- :mod:`.dead_reckoning`, :mod:`.slam`, :mod:`.motion_planner`, :mod:`.controller`, :mod:`.performance_monitor`:
  the document's five nodes (IV.E-IV.H);
- :mod:`.mission` (its pure logic: :mod:`sam_runtime.nav.mission`): the goals, an addition to the document;
- :data:`IMPLEMENTATIONS`: which generated nodes package and node name each implements. An implementation
  belongs to one spec's generated interface: another spec's nodes, even of the same name, have none.

Importing this package does not import rclpy (the main job asks which nodes have an implementation before it
starts anything).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule


__all__ = ["IMPLEMENTATIONS", "ImplementationError", "implemented", "load_implementation", "unimplemented"]

# nodes package of the generated code -> node name -> "module:Class".
IMPLEMENTATIONS: dict[str, dict[str, str]] = {
    "sam_nodes": {
        "dead_reckoning": "sam_runtime.nodes.dead_reckoning:DeadReckoning",
        "slam": "sam_runtime.nodes.slam:Slam",
        "motion_planner": "sam_runtime.nodes.motion_planner:MotionPlanner",
        "controller": "sam_runtime.nodes.controller:Controller",
        "performance_monitor": "sam_runtime.nodes.performance_monitor:PerformanceMonitor",
        "mission": "sam_runtime.nodes.mission:Mission",
    },
}


class ImplementationError(Exception):
    """An implementation that does not fit the generated interface (not a subclass of its base)."""


def implemented(tables: TablesModule) -> list[str]:
    """The spec's nodes (the generated tables' NODES, in their order) that have an implementation."""
    known = IMPLEMENTATIONS.get(tables.NODES_PACKAGE, {})
    return [n.name for n in tables.NODES if n.name in known]


def unimplemented(tables: TablesModule) -> list[str]:
    """The spec's nodes without an implementation."""
    have = set(implemented(tables))
    return [n.name for n in tables.NODES if n.name not in have]


def load_implementation(tables: TablesModule, name: str) -> type:
    """The implementation class of node ``name``, checked to be a subclass of the node's generated base (the
    generated package must be importable: GeneratedPackage.tables() puts it on sys.path)."""
    target = IMPLEMENTATIONS.get(tables.NODES_PACKAGE, {}).get(name)
    if target is None:
        raise ImplementationError(f"node {name!r} of {tables.NODES_PACKAGE} has no implementation")
    info = next(n for n in tables.NODES if n.name == name)
    module, _, cls_name = target.partition(":")
    cls = getattr(importlib.import_module(module), cls_name)
    base = getattr(importlib.import_module(info.module), info.base_class)
    if not (isinstance(cls, type) and issubclass(cls, base)):
        raise ImplementationError(f"{target} is not a subclass of the generated {info.module}.{info.base_class}")
    return cls
