"""Python emitter: the bridge's tables (pure data) and its converters (ROS messages <-> pycyphal objects).

Output, under generated/:
- ``python/<vehicle>_bridge/__init__.py``
- ``python/<vehicle>_bridge/tables.py``: devices, topics, mappings, parameters and frames as frozen dataclasses;
  standard library only, so the runtime can read it without ROS or DSDL.
- ``python/<vehicle>_bridge/convert.py``: per mapping ``<name>_to_ros(src, receive_ns, stats)`` and
  ``<name>_to_uavcan(src, stats)``, straight-line code with every range decided here, at generation time.

What each converter does to each value is decided once, in the conversion plan (conversion_plan.lower_mapping);
mapping.MappingEmitter renders the plan's operations as typed statements (statements.py) into module.py's
FunctionDraft, this module assembles the files (tables.py's context is tables.py's), and the templates in
templates/python/ decide how they look. Everything is deterministic: no timestamps, no absolute paths, and every
text from the spec reaches the output as a Python literal (repr).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sam_codegen.model.expr import uses_function
from sam_codegen.render.templating import render
from sam_codegen.targets.python.elements import element_function_names
from sam_codegen.targets.python.factories import dsdl_factory, ros_factory
from sam_codegen.targets.python.mapping import CyphalObjectReader, MappingEmitter, ObjectSignatures, RosObjectReader
from sam_codegen.targets.python.module import ConvertModule, PycyphalObjects
from sam_codegen.targets.python.names import isort_key, py_attr, referenced_roots, ros_aliases
from sam_codegen.targets.python.tables import tables_context
from sam_codegen.validate.mapping_rules import ResolvedMapping
from sam_codegen.validate.resolve import Resolved

__all__ = ["convert_module", "emit", "object_emitter"]


# ---- convert.py ----------------------------------------------------------------------------------------------


def convert_module(resolved: Resolved) -> ConvertModule:
    """convert.py's module: pycyphal objects and ROS messages, the Cyphal mappings' ROS classes aliased."""
    aliases = ros_aliases(resolved)
    return ConvertModule(resolved, PycyphalObjects(resolved, aliases), ros_aliases=aliases)


def object_emitter(module: ConvertModule, rm: ResolvedMapping) -> MappingEmitter:
    """The emitter of one Cyphal mapping's object converters."""
    return MappingEmitter(module, rm, CyphalObjectReader(), RosObjectReader(), ObjectSignatures())


def _convert_context(resolved: Resolved) -> dict[str, Any]:
    module = convert_module(resolved)
    objects = module.build
    assert isinstance(objects, PycyphalObjects)
    roots = {resolved.spec.dsdl_root, "uavcan", "reg"} | referenced_roots(resolved)
    for rm in resolved.mappings:
        module.dsdl_ref(rm.dsdl_struct)
    module.module_names = (
        set(module.ros_aliases.values())
        | {py_attr(r) for r in roots}
        | {f"{rm.mapping.name}_to_ros" for rm in resolved.mappings}
        | {f"{rm.mapping.name}_to_uavcan" for rm in resolved.mappings}
        | {"CONVERTERS", "ConversionStats", "Callable", "Any", "_NAN", "_INF", "FAST_CONSTRUCTORS", "_np", "_support"}
        | element_function_names(resolved.mappings)
    )
    functions = []
    for rm in resolved.mappings:
        emitter = object_emitter(module, rm)
        functions.append((emitter.to_ros(), emitter.to_uavcan()))
    functions.extend(module.extra_functions)  # element mappings' functions, after the registry's
    ros_imports: dict[str, list[str]] = {}
    for full, alias in sorted(module.ros_aliases.items()):
        package, name = full.split("/")
        ros_imports.setdefault(package, []).append(name if alias == name else f"{name} as {alias}")
    for names in ros_imports.values():
        names.sort(key=isort_key)
    factories = [ros_factory(objects, full) for full in sorted(module.ros_aliases)]
    done: set[str] = set()
    while len(done) < len(objects.dsdl_factories):  # a constructor's defaults may bring in nested ones
        for name in sorted(set(objects.dsdl_factories) - done):
            factories.append(dsdl_factory(objects, objects.dsdl_factories[name]))
            done.add(name)
    if any(f.uses_numpy for f in factories):
        objects.dsdl_modules.add("numpy as _np")
    return {
        "factories": factories,
        "uses_copy": any(f.uses_copy for f in factories),
        "dsdl_imports": sorted(objects.dsdl_modules),
        "ros_imports": sorted(ros_imports.items()),
        "tables": module.tables,
        "functions": functions,
        "mappings": [rm.mapping.name for rm in resolved.mappings],
    }


def uses_float32(resolved: Resolved) -> bool:
    """Whether an expression of the spec calls float32() (the support module then defines f32; a spec that
    does not gets the module it always had)."""
    pending = [s for rm in [*resolved.mappings, *resolved.dronecan_mappings] for s in rm.steps]
    while pending:
        step = pending.pop()
        if step.expr is not None and uses_function(step.expr, "float32"):
            return True
        if step.elements is not None:
            pending += step.elements.steps
    return False


def emit(resolved: Resolved) -> dict[str, str]:
    """Render the bridge package: {path under generated/: text}."""
    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    root = f"python/{package}"
    return {
        f"{root}/__init__.py": render("python/__init__.py.j2", **common),
        f"{root}/tables.py": render("python/tables.py.j2", **common, **tables_context(resolved)),
        f"{root}/conversion_support.py": render("python/conversion_support.py.j2", **common,
                                               float32=uses_float32(resolved)),
        f"{root}/convert.py": render("python/convert.py.j2", **common, **_convert_context(resolved)),
    }
