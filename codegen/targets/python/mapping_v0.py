"""The DroneCAN (UAVCAN v0) parts of the converters: dronecan message objects on the UAVCAN side.

DroneCanObjects is convert_v0.py's Construction (dronecan data types called by name through _TYPENAMES, ROS classes
called directly); V0ObjectReader reads a dronecan object (attributes, list(), the items and elements a mapping
needs, found or the message is dropped); `matches` is MATCHES' predicate. `bind_required_elements` is shared with the
wire codec of DroneCAN (targets/wire/codec_v0), which reads the same elements from bytes.
"""

from __future__ import annotations

import keyword
from dataclasses import dataclass
from typing import ClassVar, Protocol

from sam_codegen.conversion_plan import RequireItem, SetConstant
from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import py_literal, typed_literal
from sam_codegen.targets.python.mapping import MappingEmitter, UavcanReader, bind_indexed_arrays
from sam_codegen.targets.python.module import ConvertModule, CtorNode, FunctionDraft
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.python.statements import Assign, FindItem, RequireMinLength
from sam_codegen.validate.mapping_rules import Step, format_path
from sam_codegen.validate.resolve import Resolved

__all__ = ["TYPENAMES", "DroneCanObjects", "ItemReader", "Predicate", "V0ObjectReader", "bind_required_elements",
           "matches", "v0_attr"]

TYPENAMES = "_TYPENAMES"


def v0_attr(name: str) -> str:
    """A dronecan field's attribute: its name (the validator refuses keywords as field names)."""
    assert not keyword.iskeyword(name), name
    return name


class DroneCanObjects:
    """convert_v0.py's Construction: dronecan data types called by name (``_TYPENAMES[name](field=...)``), ROS
    classes called directly; records the ROS classes it calls or names (the others need no import)."""

    sized_by_use: ClassVar[bool] = True

    def __init__(self, resolved: Resolved, ros_aliases: dict[str, str]) -> None:
        self.resolved, self.ros_aliases = resolved, ros_aliases
        self.used_ros: set[str] = set()

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

    def format_return(self, module: ConvertModule, root: CtorNode, names: LocalNames) -> list[str]:
        return module.format_call(root)


class ItemReader(UavcanReader, Protocol):
    """A DroneCAN reader: it also knows the items it has bound by key, and how an item's key field is addressed."""

    items: dict[tuple, str]  # path ending in an item chosen by key -> its local

    def item_field(self, item_path: tuple, name: str) -> str:
        """The `field` argument of _item() for the key field `name` of the items at `item_path`."""
        ...


def bind_required_elements(reader: ItemReader, em: MappingEmitter, fn: FunctionDraft, names: LocalNames,
                           steps: list[Step]) -> dict[tuple, str]:
    """The elements of DroneCAN arrays the mapping reads: items by key (found, or the message is dropped) and
    positions (present, or dropped); then the fixed arrays read by index, one list each."""
    listed: dict[tuple, str] = {}
    for need in em.plan.required:
        source = reader.access(need.array)
        if isinstance(need, RequireItem):
            path = (*need.array[:-1], (need.array[-1][0], need.key))
            local = names.new(format_path(list(path)))
            reader.items[path] = local
            fn.binds.append(FindItem(local, source, reader.item_field(path, need.key.field),
                                     py_literal(need.key.value), repr(f"{em.name}.{format_path(list(path))}")))
        else:
            local = names.new(format_path(list(need.array)))
            listed[need.array] = local
            fn.binds.append(Assign(local, reader.as_list(source)))
            last = f"{em.name}.{format_path(list(need.array))}[{need.length - 1}]"
            fn.binds.append(RequireMinLength(local, need.length, repr(last)))
    return bind_indexed_arrays(reader, fn, names, steps, listed)


class V0ObjectReader:
    """A received dronecan object: attributes, arrays read with list(), items found by key. One per mapping."""

    def __init__(self) -> None:
        self.items: dict[tuple, str] = {}

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        return bind_required_elements(self, em, fn, names, steps)

    def item_field(self, item_path: tuple, name: str) -> str:
        return repr(name)

    def access(self, path: tuple) -> str:
        for cut in range(len(path), 0, -1):
            local = self.items.get(tuple(path[:cut]))
            if local is not None:
                return local + "".join(f".{v0_attr(n)}" + (f"[{i}]" if i is not None else "") for n, i in path[cut:])
        return "src" + "".join(f".{v0_attr(n)}" + (f"[{i}]" if i is not None else "") for n, i in path)

    def as_list(self, expr: str) -> str:
        return f"list({expr})"


@dataclass(frozen=True)
class Predicate:
    """A MATCHES function: `decode` lines (the wire codec's), then `return` all `conditions`."""

    name: str
    conditions: tuple[str, ...]
    decode: tuple[str, ...] = ()


def matches(em: MappingEmitter) -> Predicate | None:
    """The predicate of MATCHES: the `select` values, and the elements the mapping reads are there."""
    conditions: list[str] = []
    for fs in em.plan.uavcan_fields:
        if isinstance(fs.op, SetConstant) and fs.op.select:
            assert isinstance(fs.type, DsdlType)
            conditions.append(f"src.{'.'.join(v0_attr(n) for n, _ in fs.path)} == "
                              f"{typed_literal(fs.op.value, fs.type.kind)}")
    for need in em.plan.required:
        if any(i is not None for _, i in need.array):
            continue  # inside an item: the converter checks it
        source = "src." + ".".join(v0_attr(n) for n, _ in need.array)
        if isinstance(need, RequireItem):
            conditions.append(f"_item({source}, {need.key.field!r}, {need.key.value}) is not None")
        else:
            conditions.append(f"len({source}) > {need.length - 1}")
    if not conditions:
        return None
    return Predicate(f"_matches_{em.name}", tuple(conditions))
