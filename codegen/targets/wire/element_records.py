"""Element mappings (arrays of composites converted element by element, targets.python.elements) in the wire
codecs, DroneCAN's first: the element functions read and return records instead of objects.

The element functions are targets.python.elements' (the same MappingEmitter, plan, checks and stats keys), emitted
in an `element_scope` of DroneCanWire that gives them these readers and signatures:

- UAVCAN -> ROS: `src` is a record of the element type as v0_read decodes an array of composites (a tuple of its
  fields, void padding left out: record_index); the result is a tuple of the ROS element's leaves in cdr_layout's
  `flatten` order (every leaf, defaults included), which cdr_write writes as one element of the sequence;
- ROS -> UAVCAN: `src` is such a tuple, as cdr_read reads a sequence of messages; the result is a record of the
  element type (its fields in record order, defaults included), which v0_write writes as one array element.

The Cyphal codec's element functions share the CDR side, the signatures, the records and `record_scope` with these
(targets.wire.cyphal_elements). What a v0 record cannot hold, `unsupported` names (the mapping stays on the object
converters, OBJECT_ONLY says why): an element type holding arrays or a union (v0_write packs records of byte-multiple
numbers with struct, and shifts other scalar fields, and nested composites of them, in as stream bits), a ROS element
message holding arrays (its leaves are numbers, bools and strings only).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType
from sam_codegen.render.pysource import typed_literal
from sam_codegen.targets.python.mapping import MappingEmitter, RosReads
from sam_codegen.targets.python.mapping_v0 import bind_required_elements
from sam_codegen.targets.python.module import FunctionDraft
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.wire.cdr_layout import flatten
from sam_codegen.targets.wire.v0_layout import V0Layout, record_index
from sam_codegen.targets.wire.v0_write import record_bit_fields, record_fields
from sam_codegen.validate.mapping_rules import ResolvedMapping, Step

__all__ = ["ElementSignatures", "RecordCdrReader", "RecordUavcanReader", "default_literal", "element_record",
           "record_scope", "unsupported"]


def unsupported(rm: ResolvedMapping, layout: V0Layout, lookup: Any) -> str | None:
    """Why the element mappings of `rm` have no wire codec (None: they have one)."""
    for s in rm.steps:
        if s.kind != "elements":
            continue
        assert s.elements is not None and s.uavcan_type is not None
        element = s.uavcan_type.element
        if record_fields(layout, element) is None and record_bit_fields(layout, element) is None:
            return (f"arrays of composites converted element by element: {s.uavcan}'s element type holds arrays "
                    "or a union")
        if any(leaf.kind not in ("prim", "string") for leaf in flatten(s.elements.ros_message, lookup)):
            return f"arrays of composites converted element by element: {s.ros}'s element message holds arrays"
    return None


@contextmanager
def record_scope(build: Any, uavcan: Any, ros_lookup: Any, base: str) -> Iterator[tuple[Any, Any, Any]]:
    """A wire codec's `element_scope` (targets.python.elements): `build.records` set while the element functions
    are emitted (their results are records), with `uavcan` as the UAVCAN reader of a record."""
    build.records = True
    try:
        yield uavcan, RecordCdrReader(ros_lookup), ElementSignatures(base)
    finally:
        build.records = False


class ElementSignatures:
    """`_<mapping>_<ros array>_item_to_ros(src, receive_ns, stats)` and `..._item_to_uavcan(src, stats)`: records."""

    def __init__(self, base: str) -> None:
        self.base = base

    def to_ros(self, em: MappingEmitter) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(f"{self.base}_to_ros", ["src: tuple", "receive_ns: int", "stats: Any"], "tuple | None",
                             [f"One element of {rm.mapping.name}, UAVCAN -> ROS (records; receive_ns: the "
                              "message's stamp).", "", f"{rm.dsdl_struct.name} -> {rm.ros_message.full_name}"])

    def to_uavcan(self, em: MappingEmitter) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(f"{self.base}_to_uavcan", ["src: tuple", "stats: Any"], "tuple | None",
                             [f"One element of {rm.mapping.name}, ROS -> UAVCAN (records).", "",
                              f"{rm.ros_message.full_name} -> {rm.dsdl_struct.name}"])


class RecordUavcanReader:
    """The UAVCAN side of an element (both codecs): `src`, a record of the element type (its fields by position, a
    nested composite a tuple of its own); `struct_of` gives a nested composite's type."""

    def __init__(self, rm: ResolvedMapping, struct_of: Any) -> None:
        self.rm, self.struct_of = rm, struct_of
        self.items: dict[tuple, str] = {}

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        return bind_required_elements(self, em, fn, names, steps)

    def access(self, path: tuple) -> str:
        struct, text = self.rm.dsdl_struct, "src"
        for name, index in path:
            assert index is None, path  # the element's fields are scalars and composites of them (unsupported)
            text += f"[{record_index(struct, name)}]"
            f = struct.field(name)
            assert f is not None and isinstance(f.type, DsdlType)
            if f.type.kind == "composite":
                struct = self.struct_of(f.type)
        return text

    def as_list(self, expr: str) -> str:
        return f"list({expr})"

    def item_field(self, item_path: tuple, name: str) -> str:
        raise AssertionError("an element of scalars has no items (unsupported)")


class RecordCdrReader:
    """The ROS side of an element: `src`, a tuple of the element message's leaves in flatten order."""

    def __init__(self, lookup: Any) -> None:
        self.lookup = lookup

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> RosReads:
        index = {leaf.path: i for i, leaf in enumerate(flatten(em.rm.ros_message, self.lookup))}
        return RosReads(lambda path: f"src[{index[tuple(path)]}]",
                        lambda path: (f"src[{index[(*path, ('sec', None))]}]",
                                      f"src[{index[(*path, ('nanosec', None))]}]"))

    def array_read(self, expr: str, ros_type: Any) -> str:
        raise AssertionError("an element message with arrays has no wire codec (unsupported)")


def element_record(of: Any, values: dict[tuple, str], lookup: Any, default_of: Any = None, prefix: tuple = ()) -> str:
    """The record an element function returns: a ROS element's leaves (flatten order) or a v0 or Cyphal element's
    fields (record order; a nested composite a tuple of its own, its type from `lookup`), each the value given or the
    field's default (`default_of(leaf)` for a ROS leaf)."""
    if isinstance(of, RosMessage):
        items = []
        for leaf in flatten(of, lookup):
            if leaf.path in values:
                items.append(values[leaf.path])
            else:
                items.append(default_of(leaf))
    else:
        assert isinstance(of, DsdlStruct)
        items = [element_record(lookup(f.type), values, lookup, default_of, (*prefix, (f.name, None)))
                 if f.type.kind == "composite" else values.get((*prefix, (f.name, None)), _zero(f.type))
                 for f in of.declared_fields if f.name and isinstance(f.type, DsdlType)]
    return f"({', '.join(items)}{',' if len(items) == 1 else ''})"


def _zero(t: DsdlType) -> str:
    """A scalar field's zero as a record holds it (a number or a bool; bytes and utf8 as ints).

    >>> _zero(DsdlType("float", 16)), _zero(DsdlType("bool", 1)), _zero(DsdlType("byte", 8))
    ('0.0', 'False', '0')
    """
    return typed_literal(0, t.kind if t.kind in ("float", "bool") else "int")


def default_literal(leaf: Any) -> str:
    """A ROS leaf's default as an expression (an element record's leaf nothing sets)."""
    value = leaf.default if leaf.kind == "prim" else leaf.default or ""
    if isinstance(value, float) and not math.isfinite(value):
        return "_NAN" if math.isnan(value) else "_INF" if value > 0 else "-_INF"
    return repr(value)
