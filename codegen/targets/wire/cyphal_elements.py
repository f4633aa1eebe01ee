"""Element mappings (arrays of composites converted element by element, targets.python.elements) in the Cyphal
wire codec: the element functions read and return records instead of objects, as the DroneCAN codec's do.

The element functions are targets.python.elements' (the same MappingEmitter, plan, checks and stats keys), emitted
in CyphalWire's `element_scope` with these readers and v0_elements' signatures and CDR reader:

- UAVCAN -> ROS: `src` is a record of the element type as cyphal_read decodes a wanted array of composites (a tuple
  of its fields in declaration order, void padding left out); the result is a tuple of the ROS element's leaves in
  cdr_layout's `flatten` order, which cdr_write writes as one element of the sequence;
- ROS -> UAVCAN: `src` is such a tuple, as cdr_read reads a sequence of messages; the result is a record of the
  element type, which cyphal_write writes as one array element (with its delimiter header when not sealed).

Cyphal's bit-level layout puts any scalar in a record (bools, bit-width integers, float16); what a record cannot
hold, `unsupported` names (the mapping stays on the object converters, OBJECT_ONLY says why): an element type
holding arrays, composites or a union, a ROS element message holding arrays.
"""

from __future__ import annotations

from typing import Any

from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import DsdlType
from sam_codegen.targets.python.mapping import MappingEmitter
from sam_codegen.targets.python.module import FunctionDraft
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.wire.cdr_layout import flatten
from sam_codegen.targets.wire.v0_elements import element_record
from sam_codegen.targets.wire.v0_layout import record_index
from sam_codegen.validate.mapping_rules import ResolvedMapping, Step

__all__ = ["RecordCyphalReader", "unsupported", "zero_record"]

WHY = "arrays of composites converted element by element"


def unsupported(rm: ResolvedMapping, dsdl: Any, ros: Any) -> str | None:
    """Why the element mappings of `rm` have no Cyphal wire codec (None: they have one)."""
    for s in rm.steps:
        if s.kind != "elements":
            continue
        assert s.elements is not None
        struct = s.elements.dsdl_struct
        if struct.union or any(isinstance(f.type, DsdlType) and (f.type.array or f.type.kind == "composite")
                               for f in struct.fields):
            return f"{WHY}: {s.uavcan}'s element type holds arrays, composites or a union"
        if any(leaf.kind not in ("prim", "string") for leaf in flatten(s.elements.ros_message, ros)):
            return f"{WHY}: {s.ros}'s element message holds arrays"
    return None


def zero_record(struct: DsdlStruct) -> str:
    """The record of an element nobody sets: every field zero (a fixed array's padding)."""
    return element_record(struct, {}, None)


class RecordCyphalReader:
    """The UAVCAN side of an element: `src`, a record of the element type (its fields by position)."""

    def __init__(self, rm: ResolvedMapping) -> None:
        self.rm = rm

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        return {}

    def access(self, path: tuple) -> str:
        assert len(path) == 1 and path[0][1] is None, path  # the element's fields are scalars (unsupported)
        return f"src[{record_index(self.rm.dsdl_struct, path[0][0])}]"

    def as_list(self, expr: str) -> str:
        return f"list({expr})"
