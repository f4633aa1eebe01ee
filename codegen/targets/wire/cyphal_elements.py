"""Element mappings (arrays of composites converted element by element, targets.python.elements) in the Cyphal
wire codec: the element functions read and return records instead of objects, as the DroneCAN codec's do.

The element functions are targets.python.elements' (the same MappingEmitter, plan, checks and stats keys), emitted
in CyphalWire's `element_scope` with element_records' record readers and signatures:

- UAVCAN -> ROS: `src` is a record of the element type as cyphal_read decodes a wanted array of composites (a tuple
  of its fields in declaration order, void padding left out, a nested composite a tuple of its own); the result is
  a tuple of the ROS element's leaves in cdr_layout's `flatten` order, which cdr_write writes as one element of the
  sequence;
- ROS -> UAVCAN: `src` is such a tuple, as cdr_read reads a sequence of messages; the result is a record of the
  element type, which cyphal_write writes as one array element (with its delimiter header when not sealed).

Cyphal's bit-level layout puts any scalar in a record (bools, bit-width integers, float16) and composites of them
(sealed or delimited); what a record cannot hold, `unsupported` names (the mapping stays on the object converters,
OBJECT_ONLY says why): an element type holding arrays or a union, a ROS element message holding arrays.
"""

from __future__ import annotations

from typing import Any

from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import DsdlType
from sam_codegen.targets.wire.cdr_layout import flatten
from sam_codegen.targets.wire.element_records import element_record
from sam_codegen.validate.mapping_rules import ResolvedMapping

__all__ = ["unsupported", "zero_record"]

WHY = "arrays of composites converted element by element"


def unsupported(rm: ResolvedMapping, dsdl: Any, ros: Any) -> str | None:
    """Why the element mappings of `rm` have no Cyphal wire codec (None: they have one)."""
    for s in rm.steps:
        if s.kind != "elements":
            continue
        assert s.elements is not None
        if not _scalars(s.elements.dsdl_struct, dsdl):
            return f"{WHY}: {s.uavcan}'s element type holds arrays or a union"
        if any(leaf.kind not in ("prim", "string") for leaf in flatten(s.elements.ros_message, ros)):
            return f"{WHY}: {s.ros}'s element message holds arrays"
    return None


def _scalars(struct: DsdlStruct, dsdl: Any) -> bool:
    """Whether a record holds `struct`: scalar fields and composites of them (no arrays, no unions)."""
    if struct.union:
        return False
    for f in struct.fields:
        t = f.type
        if not isinstance(t, DsdlType) or t.array:
            return False
        if t.kind == "composite" and not _scalars(dsdl(t.composite), dsdl):
            return False
    return True


def zero_record(struct: DsdlStruct, dsdl: Any) -> str:
    """The record of an element nobody sets: every field zero (a fixed array's padding)."""
    return element_record(struct, {}, lambda t: dsdl(t.composite))
