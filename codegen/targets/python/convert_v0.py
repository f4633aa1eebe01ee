"""DroneCAN (UAVCAN v0) converters: ``python/<vehicle>_bridge/convert_v0.py``, converters between dronecan message
objects and ROS messages (the emitter is mapping_v0's; tables.py's DroneCAN entries are targets/python/tables.py's).

The converters follow convert.py's rules (every value computed and checked first, saturation or rejection counted
in ConversionStats under "<mapping>.<field>") with dronecan's objects on the UAVCAN side: fields are attributes,
arrays are read with list(), messages are built by calling the data type (``_TYPENAMES[name](field=...)``, looked
up at each call: dronecan.load_dsdl() replaces every type object). ROS messages are built with their classes (a
dronecan transfer costs far more than the constructor).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.spec import V0Struct
from sam_codegen.render.filters import py_str
from sam_codegen.render.templating import render
from sam_codegen.targets import dsdl_v0
from sam_codegen.targets.python.elements import element_function_names
from sam_codegen.targets.python.mapping import MappingEmitter, ObjectSignatures, RosObjectReader
from sam_codegen.targets.python.mapping_v0 import TYPENAMES, DroneCanObjects, V0ObjectReader, matches
from sam_codegen.targets.python.module import ConvertModule
from sam_codegen.targets.python.names import isort_key, ros_aliases
from sam_codegen.validate.resolve import Resolved

__all__ = ["emit", "used_types"]


def _convert_context(resolved: Resolved) -> dict[str, Any]:
    aliases = ros_aliases(resolved, resolved.dronecan_mappings)
    objects = DroneCanObjects(resolved, aliases)
    objects.used_ros = {rm.ros_message.full_name for rm in resolved.dronecan_mappings}
    module = ConvertModule(resolved, objects, ros_aliases=aliases)
    module.module_names = (
        set(module.ros_aliases.values())
        | {f"{rm.mapping.name}_to_ros" for rm in resolved.dronecan_mappings}
        | {f"{rm.mapping.name}_to_uavcan" for rm in resolved.dronecan_mappings}
        | {f"_matches_{rm.mapping.name}" for rm in resolved.dronecan_mappings}
        | {"CONVERTERS", "MATCHES", "TYPES", "CUSTOM_DSDL_DIRS", "ConversionStats", "Callable", "Any", "Path",
           "_NAN", "_INF", TYPENAMES, "dronecan", "_item", "_always", "check_types", "load_types", "_support"}
        | element_function_names(resolved.dronecan_mappings)
    )
    functions, predicates = [], []
    for rm in resolved.dronecan_mappings:
        emitter = MappingEmitter(module, rm, V0ObjectReader(), RosObjectReader(), ObjectSignatures())
        to_ros = emitter.to_ros()
        to_uavcan = emitter.to_uavcan()
        functions.append((to_ros, to_uavcan))
        predicates.append((rm.mapping.name, matches(emitter)))
    functions.extend(module.extra_functions)  # element mappings' functions, after the registry's
    ros_imports: dict[str, list[str]] = {}
    for full, alias in sorted(module.ros_aliases.items()):
        if full not in objects.used_ros:
            continue  # built by its parent's class
        package, name = full.split("/")
        ros_imports.setdefault(package, []).append(name if alias == name else f"{name} as {alias}")
    for names in ros_imports.values():
        names.sort(key=isort_key)
    return {
        "ros_imports": sorted(ros_imports.items()),
        "tables": module.tables,
        "functions": functions,
        "matches": predicates,
        "mappings": [rm.mapping.name for rm in resolved.dronecan_mappings],
        "types": [(py_str(t.name), str(t.data_type_id), f"0x{t.signature:016X}") for t in used_types(resolved)],
        "custom_dirs": [py_str(d) for d in dsdl_v0.load_dirs(resolved)],
    }


def used_types(resolved: Resolved) -> list[V0Struct]:
    """The message types of the DroneCAN mappings and ports, and the spec's own types, sorted by name."""
    catalog = resolved.dronecan
    assert catalog is not None
    names = {rm.dsdl_struct.name for rm in resolved.dronecan_mappings} | {t.name for t in resolved.dronecan_types
                                                                          if t.data_type_id is not None}
    for device in resolved.spec.devices.values():
        if DRONECAN.name in device.protocols:
            names |= {p.type for p in [*device.dronecan_publishes, *device.dronecan_subscribes]}
    result = []
    for name in sorted(names):
        struct = catalog.signed(name)
        assert isinstance(struct, V0Struct), name
        result.append(struct)
    return result


def emit(resolved: Resolved) -> dict[str, str]:
    """convert_v0.py, for a spec with DroneCAN mappings."""
    if not resolved.dronecan_mappings:
        return {}
    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    return {f"python/{package}/convert_v0.py": render("python/convert_v0.py.j2", **common,
                                                      **_convert_context(resolved))}
