"""The DroneCAN (UAVCAN v0) variant of the converters' emitter: dronecan message objects on the UAVCAN side.

V0ConvertModule says how convert_v0.py names and builds types (dronecan data types called by name through
_TYPENAMES, ROS classes called directly, arrays of composites built item by item, chosen by key: KeyedItems);
V0MappingEmitter says how a dronecan object is read (attributes, list(), the items and elements a mapping needs,
found or the message is dropped) and what MATCHES checks. The value semantics stay MappingEmitter's.
"""

from __future__ import annotations

import keyword
from typing import Any

from sam_codegen.conversion_plan import RequireItem, SetConstant
from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import py_literal, typed_literal
from sam_codegen.targets.python.mapping import MappingEmitter
from sam_codegen.targets.python.module import ConvertModule, CtorNode, FunctionDraft
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.python.statements import Assign, FindItem, RequireMinLength
from sam_codegen.validate.mapping_rules import Key, ResolvedMapping, Step, format_path

__all__ = ["TYPENAMES", "KeyedItems", "V0ConvertModule", "V0MappingEmitter", "v0_attr"]

TYPENAMES = "_TYPENAMES"


def v0_attr(name: str) -> str:
    """A dronecan field's attribute: its name (the validator refuses keywords as field names)."""
    assert not keyword.iskeyword(name), name  # the validator refuses such field names
    return name


class KeyedItems:
    """An array of composites built item by item, each chosen by a key (ArrayCommand.commands[actuator_id=3])."""

    def __init__(self) -> None:
        self.items: dict[Key, CtorNode] = {}


class V0ConvertModule(ConvertModule):
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

    def dsdl_ctor(self, struct: DsdlStruct) -> CtorNode:
        return CtorNode(f"{TYPENAMES}[{struct.name!r}]", [(f.name, f.type) for f in struct.fields], v0_attr)

    def ros_ctor(self, message: RosMessage) -> CtorNode:
        self.used_ros.add(message.full_name)
        return CtorNode(self.ros_aliases[message.full_name], [(f.name, f.type) for f in message.fields])

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType):
            if t.kind == "composite":
                return f"{TYPENAMES}[{t.composite!r}]()"
            return typed_literal(0, "float" if t.kind == "float" else t.kind)
        if not t.is_primitive:
            self.used_ros.add(t.base)
            return f"{self.ros_aliases[t.base]}()"
        return typed_literal(0, t.base)

    def insert_step(self, node: Any, name: str, index: Any, value: str | None, prefix: tuple) -> Any:
        """As ConvertModule.insert_step, and on the DroneCAN side: items chosen by key (the key field set to its
        value)."""
        if not isinstance(index, Key):
            return super().insert_step(node, name, index, value, prefix)
        t = node.types.get(name)
        assert t is not None and value is None, (prefix, name)
        items = node.kwargs.setdefault(name, KeyedItems())
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
        if isinstance(node, KeyedItems):
            lines = ["["]
            for item in node.items.values():
                part = self.format_node(item, indent + 4)
                lines.append(" " * (indent + 4) + part[0])
                lines.extend(part[1:])
                lines[-1] += ","
            lines.append(" " * indent + "]")
            return lines
        return super().format_node(node, indent)


class V0MappingEmitter(MappingEmitter):
    def __init__(self, module: V0ConvertModule, rm: ResolvedMapping) -> None:
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
                return local + "".join(f".{v0_attr(n)}" + (f"[{i}]" if i is not None else "") for n, i in path[cut:])
        return base + "".join(f".{v0_attr(n)}" + (f"[{i}]" if i is not None else "") for n, i in path)

    def bind_uavcan_arrays(self, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        """The elements of DroneCAN arrays the mapping reads: items by key (found, or the message is dropped) and
        positions (present, or dropped); then the fixed arrays read by index, one list each."""
        listed: dict[tuple, str] = {}
        for need in self.plan.required:
            source = self.uav_access("src", need.array)
            if isinstance(need, RequireItem):
                path = (*need.array[:-1], (need.array[-1][0], need.key))
                local = names.new(format_path(list(path)))
                self.items[path] = local
                fn.binds.append(FindItem(local, source, repr(need.key.field), py_literal(need.key.value),
                                         repr(f"{self.name}.{format_path(list(path))}")))
            else:
                local = names.new(format_path(list(need.array)))
                listed[need.array] = local
                fn.binds.append(Assign(local, self.uav_list(source)))
                last = f"{self.name}.{format_path(list(need.array))}[{need.length - 1}]"
                fn.binds.append(RequireMinLength(local, need.length, repr(last)))
        return super().bind_uavcan_arrays(fn, names, steps, listed)

    def matches(self) -> dict[str, Any] | None:
        """The predicate of MATCHES: the `select` values, and the elements the mapping reads are there."""
        conditions = []
        for fs in self.plan.uavcan_fields:
            if isinstance(fs.op, SetConstant) and fs.op.select:
                assert isinstance(fs.type, DsdlType)
                conditions.append(f"src.{'.'.join(v0_attr(n) for n, _ in fs.path)} == "
                                  f"{typed_literal(fs.op.value, fs.type.kind)}")
        for need in self.plan.required:
            if any(i is not None for _, i in need.array):
                continue  # inside an item: the converter checks it
            source = "src." + ".".join(v0_attr(n) for n, _ in need.array)
            if isinstance(need, RequireItem):
                conditions.append(f"_item({source}, {need.key.field!r}, {need.key.value}) is not None")
            else:
                conditions.append(f"len({source}) > {need.length - 1}")
        if not conditions:
            return None
        return {"name": f"_matches_{self.name}", "conditions": conditions}
