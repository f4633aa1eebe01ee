"""Python emitter: the bridge's tables (pure data) and its converters (ROS messages <-> pycyphal objects).

Output, under generated/:
- ``python/<vehicle>_bridge/__init__.py``
- ``python/<vehicle>_bridge/tables.py``: devices, topics, mappings, parameters and frames as frozen dataclasses;
  standard library only, so the runtime can read it without ROS or DSDL.
- ``python/<vehicle>_bridge/convert.py``: per mapping ``<name>_to_ros(src, receive_ns, stats)`` and
  ``<name>_to_uavcan(src, stats)``, straight-line code with every range decided here, at generation time.

What each converter does to each value is decided once, in the conversion plan (conversion_plan.lower_mapping);
python_mapping renders the plan's operations as Python (through python_statements: names, literals, statements)
into python_module's functions, this module assembles the files, and the templates in templates/python/ decide how
they look. Everything is deterministic: no timestamps, no absolute paths, and every text from the spec reaches the
output as a Python literal (repr).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sam_codegen.conversion_plan import (  # the constants stay importable from here (tests use them)
    FLOAT16_MAX,
    FLOAT32_MAX,
    INT32_MAX,
    TIME_US_MAX_FROM_ROS,
    TIME_US_MAX_TO_ROS,
    TIME_US_MIN,
)
from sam_codegen.render.templating import render
from sam_codegen.targets import nodes as emit_nodes  # the tables' QoS, transforms and nodes
from sam_codegen.targets.python.factories import _dsdl_factory, _ros_factory
from sam_codegen.targets.python.mapping import _MappingEmitter
from sam_codegen.targets.python.mapping import (
    _st as _st,  # each `X as X`: re-exported (emit_codec*, emit_python_v0, emit_nodes, tests)
)
from sam_codegen.targets.python.module import _Arr as _Arr
from sam_codegen.targets.python.module import _Ctor as _Ctor
from sam_codegen.targets.python.module import _Function as _Function
from sam_codegen.targets.python.module import _Module
from sam_codegen.targets.python.names import _isort_key, _referenced_roots, _ros_aliases, py_attr, py_class_ref
from sam_codegen.targets.python.names import _Names as _Names
from sam_codegen.targets.python.names import _ros_closure as _ros_closure
from sam_codegen.targets.python.names import py_class_name as py_class_name
from sam_codegen.targets.python.names import py_module as py_module
from sam_codegen.targets.python.statements import py_literal
from sam_codegen.targets.python.statements import typed_literal as _typed_literal  # noqa: F401  (re-exported: the v0 emitters)
from sam_codegen.targets.python.tables import _tables_context
from sam_codegen.targets.python.tables import _text as _text
from sam_codegen.targets.python.tables import _tuple as _tuple
from sam_codegen.validate.resolve import Resolved

__all__ = ["FLOAT16_MAX", "FLOAT32_MAX", "INT32_MAX", "TIME_US_MAX_FROM_ROS", "TIME_US_MAX_TO_ROS", "TIME_US_MIN",
           "emit", "py_attr", "py_class_ref", "py_literal"]


# ---- convert.py ----------------------------------------------------------------------------------------------


def _convert_context(resolved: Resolved) -> dict[str, Any]:
    module = _Module(resolved)
    module.ros_aliases = _ros_aliases(resolved)
    roots = {resolved.spec.dsdl_root, "uavcan", "reg"} | _referenced_roots(resolved)
    for rm in resolved.mappings:
        module.dsdl_ref(rm.dsdl_struct)
    module.module_names = (
        set(module.ros_aliases.values())
        | {py_attr(r) for r in roots}
        | {f"{rm.mapping.name}_to_ros" for rm in resolved.mappings}
        | {f"{rm.mapping.name}_to_uavcan" for rm in resolved.mappings}
        | {"CONVERTERS", "ConversionStats", "Callable", "Any", "_NAN", "_INF", "FAST_CONSTRUCTORS", "_np", "_support"}
    )
    functions = []
    for rm in resolved.mappings:
        emitter = _MappingEmitter(module, rm)
        functions.append((emitter.to_ros(), emitter.to_uavcan()))
    ros_imports: dict[str, list[str]] = {}
    for full, alias in sorted(module.ros_aliases.items()):
        package, name = full.split("/")
        ros_imports.setdefault(package, []).append(name if alias == name else f"{name} as {alias}")
    for names in ros_imports.values():
        names.sort(key=_isort_key)
    factories = [_ros_factory(module, full) for full in sorted(module.ros_aliases)]
    done: set[str] = set()
    while len(done) < len(module.dsdl_factories):  # a constructor's defaults may bring in nested ones
        for name in sorted(set(module.dsdl_factories) - done):
            factories.append(_dsdl_factory(module, module.dsdl_factories[name]))
            done.add(name)
    if any("_np." in str(f["fields"]) for f in factories):
        module.dsdl_modules.add("numpy as _np")
    return {
        "factories": factories,
        "uses_copy": any("_copy(" in str(x) for f in factories for x in f["fields"]),
        "dsdl_imports": sorted(module.dsdl_modules),
        "ros_imports": sorted(ros_imports.items()),
        "tables": module.tables,
        "functions": functions,
        "mappings": [rm.mapping.name for rm in resolved.mappings],
    }


def emit(resolved: Resolved) -> dict[str, str]:
    """Render the bridge package: {path under generated/: text}."""
    from sam_codegen.targets.python import convert_v0 as emit_python_v0  # (it builds on this module)

    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    root = f"python/{package}"
    return {
        f"{root}/__init__.py": render("python/__init__.py.j2", **common),
        f"{root}/tables.py": render("python/tables.py.j2", **common, **_tables_context(resolved),
                                    **emit_nodes.tables_context(resolved), **emit_python_v0.tables_context(resolved)),
        f"{root}/conversion_support.py": render("python/conversion_support.py.j2", **common),
        f"{root}/convert.py": render("python/convert.py.j2", **common, **_convert_context(resolved)),
    }
