"""Python emitter for the DroneCAN (UAVCAN v0) mappings: ``python/<vehicle>_bridge/convert_v0.py`` (converters
between dronecan message objects and ROS messages) and the DroneCAN entries of tables.py.

The converters follow convert.py's rules (every value computed and checked first, saturation or rejection counted
in ConversionStats under "<mapping>.<field>") with dronecan's objects on the UAVCAN side: fields are attributes,
arrays are read with list(), messages are built by calling the data type (``_TYPENAMES[name](field=...)``, looked
up at each call: dronecan.load_dsdl() replaces every type object). ROS messages are built with their classes (a
dronecan transfer costs far more than the constructor).
"""

from __future__ import annotations

import keyword
from pathlib import Path
from typing import Any

from sam_codegen.conversion_plan import Constant, RequireItem
from sam_codegen.model.spec import DsdlStruct, RosMessage, V0Struct
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.filters import py_str
from sam_codegen.render.templating import render
from sam_codegen.targets import dsdl_v0 as emit_dsdl_v0
from sam_codegen.targets.python.convert import (
    _Ctor,
    _Function,
    _isort_key,
    _MappingEmitter,
    _Module,
    _Names,
    _ros_aliases,
    _st,
    _text,
    _tuple,
    _typed_literal,
    py_literal,
)
from sam_codegen.validate.mapping_rules import Key, ResolvedMapping, Step, format_path
from sam_codegen.validate.resolve import Resolved

__all__ = ["emit", "tables_context"]

TYPENAMES = "_TYPENAMES"


def _attr(name: str) -> str:
    assert not keyword.iskeyword(name), name  # the validator refuses such field names
    return name


class _Items:
    """An array of composites built item by item, each chosen by a key (ArrayCommand.commands[actuator_id=3])."""

    def __init__(self) -> None:
        self.items: dict[Key, _Ctor] = {}


class _V0Module(_Module):
    """convert_v0.py's view of types: dronecan data types called by name, ROS classes called directly."""

    lengths: dict[tuple, int]  # per mapping: bounded arrays built element by element -> their length
    used_ros: set[str]  # the ROS classes the converters call or name


    def dsdl_ref(self, struct: DsdlStruct) -> str:
        return "Any"

    def struct(self, name: str) -> DsdlStruct:
        assert self.resolved.dronecan is not None
        struct = self.resolved.dronecan.get(name)
        assert struct is not None, name
        return struct

    def dsdl_ctor(self, struct: DsdlStruct) -> _Ctor:
        return _Ctor(f"{TYPENAMES}[{struct.name!r}]", [(f.name, f.type) for f in struct.fields], _attr)

    def ros_ctor(self, message: RosMessage) -> _Ctor:
        self.used_ros.add(message.full_name)
        return _Ctor(self.ros_aliases[message.full_name], [(f.name, f.type) for f in message.fields])

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType):
            if t.kind == "composite":
                return f"{TYPENAMES}[{t.composite!r}]()"
            return _typed_literal(0, "float" if t.kind == "float" else t.kind)
        if not t.is_primitive:
            self.used_ros.add(t.base)
            return f"{self.ros_aliases[t.base]}()"
        return _typed_literal(0, t.base)

    def insert_step(self, node: Any, name: str, index: Any, value: str | None, prefix: tuple) -> Any:
        """As _Module.insert_step, and on the DroneCAN side: items chosen by key (the key field set to its value)."""
        if not isinstance(index, Key):
            return super().insert_step(node, name, index, value, prefix)
        t = node.types.get(name)
        assert t is not None and value is None, (prefix, name)
        items = node.kwargs.setdefault(name, _Items())
        if index not in items.items:
            item = self.child(t.element)
            item.kwargs[index.field] = py_literal(index.value)
            items.items[index] = item
        return items.items[index]

    def array_size(self, t: Any, array_path: tuple) -> int:
        """Bounded DroneCAN arrays are built with the elements the mapping names (their positions)."""
        size = t.capacity if t.array == "fixed" or isinstance(t, RosType) else self.lengths[array_path]
        return size or 0

    def format_node(self, node: Any, indent: int) -> list[str]:
        if isinstance(node, _Items):
            lines = ["["]
            for item in node.items.values():
                part = self.format_node(item, indent + 4)
                lines.append(" " * (indent + 4) + part[0])
                lines.extend(part[1:])
                lines[-1] += ","
            lines.append(" " * indent + "]")
            return lines
        return super().format_node(node, indent)


class _V0MappingEmitter(_MappingEmitter):
    def __init__(self, module: _V0Module, rm: ResolvedMapping) -> None:
        super().__init__(module, rm)
        self.items: dict[tuple, str] = {}  # path ending in an item chosen by key -> its local
        module.lengths = {path: max(uses) + 1 for path, uses in rm.elements.items()
                          if uses and not isinstance(uses[0], Key)}

    def uav_list(self, expr: str) -> str:
        return f"list({expr})"

    def uav_access(self, base: str, path: tuple) -> str:
        for cut in range(len(path), 0, -1):
            local = self.items.get(tuple(path[:cut]))
            if local is not None:
                return local + "".join(f".{_attr(n)}" + (f"[{i}]" if i is not None else "") for n, i in path[cut:])
        return base + "".join(f".{_attr(n)}" + (f"[{i}]" if i is not None else "") for n, i in path)

    def bind_uavcan_arrays(self, fn: _Function, names: _Names, steps: list[Step]) -> dict[tuple, str]:
        """The elements of DroneCAN arrays the mapping reads: items by key (found, or the message is dropped) and
        positions (present, or dropped); then the fixed arrays read by index, one list each."""
        listed: dict[tuple, str] = {}
        for need in self.plan.required:
            source = self.uav_access("src", need.array)
            if isinstance(need, RequireItem):
                path = (*need.array[:-1], (need.array[-1][0], need.key))
                local = names.new(format_path(list(path)))
                self.items[path] = local
                fn.binds.append(_st("required_item", var=local, array=source, field=repr(need.key.field),
                                    value=py_literal(need.key.value),
                                    key=repr(f"{self.name}.{format_path(list(path))}")))
            else:
                local = names.new(format_path(list(need.array)))
                listed[need.array] = local
                fn.binds.append(_st("assign", target=local, expr=self.uav_list(source)))
                last = f"{self.name}.{format_path(list(need.array))}[{need.length - 1}]"
                fn.binds.append(_st("min_length", var=local, size=need.length, key=repr(last)))
        return super().bind_uavcan_arrays(fn, names, steps, listed)

    def matches(self) -> dict[str, Any] | None:
        """The predicate of MATCHES: the `select` values, and the elements the mapping reads are there."""
        conditions = []
        for fs in self.plan.uavcan_fields:
            if isinstance(fs.op, Constant) and fs.op.select:
                assert isinstance(fs.type, DsdlType)
                conditions.append(f"src.{'.'.join(_attr(n) for n, _ in fs.path)} == "
                                  f"{_typed_literal(fs.op.value, fs.type.kind)}")
        for need in self.plan.required:
            if any(i is not None for _, i in need.array):
                continue  # inside an item: the converter checks it
            source = "src." + ".".join(_attr(n) for n, _ in need.array)
            if isinstance(need, RequireItem):
                conditions.append(f"_item({source}, {need.key.field!r}, {need.key.value}) is not None")
            else:
                conditions.append(f"len({source}) > {need.length - 1}")
        if not conditions:
            return None
        return {"name": f"_matches_{self.name}", "conditions": conditions}


def _convert_context(resolved: Resolved) -> dict[str, Any]:
    module = _V0Module(resolved)
    module.used_ros = {rm.ros_message.full_name for rm in resolved.dronecan_mappings}
    module.ros_aliases = _ros_aliases(resolved, resolved.dronecan_mappings)
    module.module_names = (
        set(module.ros_aliases.values())
        | {f"{rm.mapping.name}_to_ros" for rm in resolved.dronecan_mappings}
        | {f"{rm.mapping.name}_to_uavcan" for rm in resolved.dronecan_mappings}
        | {f"_matches_{rm.mapping.name}" for rm in resolved.dronecan_mappings}
        | {"CONVERTERS", "MATCHES", "TYPES", "CUSTOM_DSDL_DIRS", "ConversionStats", "Callable", "Any", "Path",
           "_NAN", "_INF", TYPENAMES, "dronecan", "_item", "_always", "check_types", "load_types", "_support"}
    )
    functions, matches = [], []
    for rm in resolved.dronecan_mappings:
        emitter = _V0MappingEmitter(module, rm)
        to_ros = emitter.to_ros()
        to_uavcan = emitter.to_uavcan()
        functions.append((to_ros, to_uavcan))
        matches.append((rm.mapping.name, emitter.matches()))
    ros_imports: dict[str, list[str]] = {}
    for full, alias in sorted(module.ros_aliases.items()):
        if full not in module.used_ros:
            continue  # built by its parent's class
        package, name = full.split("/")
        ros_imports.setdefault(package, []).append(name if alias == name else f"{name} as {alias}")
    for names in ros_imports.values():
        names.sort(key=_isort_key)
    return {
        "ros_imports": sorted(ros_imports.items()),
        "tables": module.tables,
        "functions": functions,
        "matches": matches,
        "types": [(py_str(t.name), str(t.data_type_id), f"0x{t.signature:016X}") for t in _used_types(resolved)],
        "custom_dirs": [py_str(d) for d in emit_dsdl_v0.load_dirs(resolved)],
    }


def _used_types(resolved: Resolved) -> list[V0Struct]:
    """The message types of the DroneCAN mappings and ports, and the spec's own types, sorted by name."""
    catalog = resolved.dronecan
    assert catalog is not None
    names = {rm.dsdl_struct.name for rm in resolved.dronecan_mappings} | {t.name for t in resolved.dronecan_types
                                                                          if t.data_type_id is not None}
    for device in resolved.spec.devices.values():
        if "dronecan" in device.protocols:
            names |= {p.type for p in [*device.dronecan_publishes, *device.dronecan_subscribes]}
    result = []
    for name in sorted(names):
        struct = catalog.get(name)
        assert isinstance(struct, V0Struct), name
        catalog.signature(name)
        result.append(struct)
    return result


# ---- tables.py -----------------------------------------------------------------------------------------------


def _type_info(struct: V0Struct) -> str:
    return (f"DroneCanTypeInfo({py_str(struct.name)}, {struct.data_type_id}, 0x{struct.signature:016X}, "
            f"{not struct.standard})")


def _type_ref(struct: V0Struct) -> str:
    return f"_DRONECAN_TYPE[{py_str(struct.name)}]"


def _port_info(struct: V0Struct, rate_hz: float, indent: int) -> str:
    one = f"DroneCanPortInfo({_type_ref(struct)}, {py_literal(float(rate_hz))})"
    if indent + len(one) + 1 <= 110:
        return one
    pad = " " * (indent + 4)
    return f"DroneCanPortInfo(\n{pad}{_type_ref(struct)},\n{pad}{py_literal(float(rate_hz))},\n{' ' * indent})"


def _frozenset(values: list[int]) -> str:
    values = sorted(set(values))
    return "frozenset({" + ", ".join(map(str, values)) + "})" if values else "frozenset()"


def tables_context(resolved: Resolved) -> dict[str, Any]:
    """The DroneCAN entries of tables.py (empty for a spec without DroneCAN) and the layouts."""
    spec = resolved.spec
    catalog = resolved.dronecan
    types = {t.name: t for t in _used_types(resolved)} if catalog is not None else {}
    devices = []
    for d in spec.devices.values():
        if "dronecan" not in d.protocols:
            continue
        devices.append({
            "name": py_str(d.name), "node_id": str(d.node_id), "description": _text(d.description, 8),
            "publishes": [_port_info(types[p.type], p.rate_hz, 12) for p in d.dronecan_publishes],
            "subscribes": [_port_info(types[p.type], p.rate_hz, 12) for p in d.dronecan_subscribes],
        })
    mappings = []
    for rm in resolved.dronecan_mappings:
        m = rm.mapping
        struct = types[rm.dsdl_struct.name]
        select = [f"({py_str(format_path(list(p)))}, {py_literal(v)})" for p, _, v in rm.select]
        elements = [py_str(f"{format_path(list(path))}[{u}]") for path, uses in rm.elements.items() for u in uses]
        mappings.append({
            "name": py_str(m.name), "direction": py_str(m.direction), "topic": py_str(m.topic),
            "data_type": _type_ref(struct), "select": _tuple(select, 8), "elements": _tuple(elements, 8),
            "source_node_ids": _frozenset(m.source_node_ids),
            "destination_node_ids": _frozenset(m.destination_node_ids),
            "frame_id": py_str(m.frame_id) if m.frame_id is not None else "None",
            "rate_hz": py_literal(float(rm.rate_hz)), "on_out_of_range": py_str(m.on_out_of_range),
            "to_ros": py_str(f"{m.name}_to_ros"), "to_uavcan": py_str(f"{m.name}_to_uavcan"),
            "exact_uavcan_fields": _tuple([py_str(s.uavcan) for s in rm.steps if s.uavcan_path and s.exact], 8),
            "linked_uavcan_fields": _tuple([py_str(s.uavcan) for s in rm.steps if s.uavcan_path], 8),
        })
    layouts = [{
        "name": py_str(layout.name), "description": _text(layout.description, 8),
        "protocols": _tuple([f"({py_str(d)}, {py_str(p)})" for d, p in layout.protocols.items()], 8),
        "cyphal_mappings": _tuple([py_str(n) for n in layout.cyphal_mappings], 8),
        "dronecan_mappings": _tuple([py_str(n) for n in layout.dronecan_mappings], 8),
    } for layout in resolved.layouts]
    return {
        "dronecan_dirs": [py_str(d) for d in emit_dsdl_v0.load_dirs(resolved)],
        "dronecan_types": [_type_info(t) for t in types.values()],
        "dronecan_devices": devices,
        "dronecan_mappings": mappings,
        "layouts": layouts,
    }


def emit(resolved: Resolved) -> dict[str, str]:
    """convert_v0.py, for a spec with DroneCAN mappings."""
    if not resolved.dronecan_mappings:
        return {}
    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    return {f"python/{package}/convert_v0.py": render("python/convert_v0.py.j2", **common,
                                                      **_convert_context(resolved))}
