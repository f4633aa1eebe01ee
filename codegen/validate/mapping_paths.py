"""The paths of a mapping's lines (`header.stamp`, `cells[2].volts`, `esc[index=3].rpm`) resolved to the ROS or
UAVCAN type they name: MappingPaths, the base of MappingValidator (validate.mappings), which holds the state of the
mapping being resolved. A path that runs into a type reported broken already raises Reported: the line adds no
error of its own."""

from __future__ import annotations

from typing import Any, TypeVar

from sam_codegen.catalogs.ros import RosCatalog
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.validate.mapping_rules import TIME, TIMESTAMPS, Key, RuleError, format_path

__all__ = ["MappingPaths", "Reported", "indexed_type"]

T = TypeVar("T", RosType, DsdlType)


class Reported(RuleError):
    """The path runs into a type that is reported broken already: the link adds no error of its own."""


def indexed_type(leaf: T, name: str, index: int | Key | None, v0: bool = False) -> T:
    """The element type for `name[index]`, which only a fixed-size array allows; in a DroneCAN message also a
    bounded one (the element of a broadcast array, e.g. rpm[1] of esc.RPMCommand), and `name[key=value]` (checked
    by the caller) an array of composites."""
    if index is None:
        return leaf
    if isinstance(index, Key):
        if not v0 or isinstance(leaf, RosType):
            raise RuleError(f"{name}[{index}]: an item is chosen by key only in the arrays of a DroneCAN message")
        if not leaf.array or leaf.kind != "composite":
            raise RuleError(f"{name}[{index}]: an item is chosen by key in an array of composites, {name} is {leaf}")
        return leaf.element
    if leaf.array != "fixed" and not (v0 and leaf.array == "bounded" and isinstance(leaf, DsdlType)):
        allowed = "fixed-size and DroneCAN arrays" if v0 else "fixed-size arrays"
        raise RuleError(f"{name}[{index}]: only {allowed} take an index, {name} is {leaf}")
    if index >= (leaf.capacity or 0):
        raise RuleError(f"{name}[{index}]: index out of range, {name} has {leaf.capacity} elements"
                        if leaf.array == "fixed" else f"{name}[{index}]: index out of range, {name} holds at most "
                        f"{leaf.capacity} elements")
    return leaf.element



class MappingPaths:
    """Type lookups along a mapping's paths. The state is MappingValidator's (set per mapping by its resolve_body;
    element_mappings saves and restores it around an element mapping): declared here, assigned there."""

    diag: Diagnostics
    ros: RosCatalog
    types: Any  # where the mapping's composite types are looked up (the DSDL or the DroneCAN catalog)
    v0: bool  # the mapping being resolved is a DroneCAN one
    # DroneCAN arrays whose elements the mapping names: array path -> {"index": {i: None}, "key": {Key: None}}
    elements: dict[tuple, dict[str, dict]]
    failed_messages: set[str]  # ROS messages whose derive_from failed
    bad_dsdl_fields: set[tuple[str, str]]  # (DSDL type, field) reported with their declarations
    failed_paths: set[str]  # UAVCAN fields of lines reported already: not reported again as unmapped
    failed_ros: set[str]  # ROS fields of failed links ("" when a ROS path did not resolve)
    ignored: set[str]  # the mapping's `ignore` entries that resolve
    element_uses: dict[str, dict[str, dict]]  # `elements` by path text (check_elements)
    direction: str  # the direction of the mapping whose coverage is checked

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.diag.error(pos, message, expected)

    def ros_leaf(self, message: RosMessage, path: list) -> RosType:
        current: RosMessage | None = message
        leaf: RosType | None = None
        for i, (name, index) in enumerate(path):
            if current is None:
                raise RuleError(f"{format_path(path[:i])} is a {leaf}, it has no field {name!r}")
            f = current.field(name)
            if f is None:
                raise RuleError(f"{current.full_name} has no field {name!r}")
            assert isinstance(f.type, RosType)
            leaf = f.type
            leaf = indexed_type(leaf, name, index)
            nested = not (leaf.is_primitive or leaf.array or leaf.base == TIME)
            current = self.ros.get(leaf.base) if nested else None
            if nested and (current is None or current.full_name in self.failed_messages):
                raise Reported(f"{leaf.base} is unknown or could not be derived")  # reported with the type
        assert leaf is not None
        return leaf

    def dsdl_leaf(self, struct: DsdlStruct, path: list, allow_composite: bool = False, record: bool = True
                  ) -> DsdlType:
        """The type at `path`; with `record`, the DroneCAN array elements it names are noted (self.elements)."""
        current: DsdlStruct | None = struct
        leaf: DsdlType | None = None
        for i, (name, index) in enumerate(path):
            if current is None:
                raise RuleError(f"{format_path(path[:i])} is a {leaf}, it has no field {name!r}")
            f = current.field(name)
            if f is None:
                raise RuleError(f"{current.name} has no field {name!r}")
            assert isinstance(f.type, DsdlType)
            leaf = f.type
            array = leaf
            leaf = indexed_type(leaf, name, index, self.v0)
            current = self.types.get(leaf.composite) if leaf.kind == "composite" and not leaf.array else None
            if current is None and leaf.kind == "composite" and not leaf.array:
                raise Reported(f"unknown DSDL type {leaf.composite}")  # reported with the field's declaration
            if current is not None and current.union:
                raise RuleError(f"{name} is a union ({current.name}); unions cannot be mapped")
            if isinstance(index, Key) and current is not None:
                self.check_key(current, name, index)
            if record and ((index is not None and self.v0 and array.array == "bounded") or isinstance(index, Key)):
                uses = self.elements.setdefault((*path[:i], (name, None)), {"index": {}, "key": {}})
                uses["key" if isinstance(index, Key) else "index"][index] = None
        assert leaf is not None
        if leaf.kind == "composite" and not leaf.array and not allow_composite and leaf.composite not in TIMESTAMPS:
            raise RuleError(f"{format_path(path)} is a composite ({leaf.composite}); map its fields one by one")
        return leaf

    def check_key(self, item: DsdlStruct, name: str, key: Key) -> None:
        """`name[field=value]`: `field` an integer of the item type, `value` one of its values."""
        f = item.field(key.field)
        t = f.type if f is not None else None
        if not isinstance(t, DsdlType) or t.array or t.kind not in ("int", "uint"):
            raise RuleError(f"{name}[{key}]: the key must be an integer field of {item.name}"
                            + (f", {key.field} is {t}" if t is not None else f", which has no field {key.field!r}"))
        lo, hi = t.range
        if not lo <= key.value <= hi:
            raise RuleError(f"{name}[{key}]: {key.value} is outside the range of {key.field} ({t}) [{lo}, {hi}]")
