"""The layout of a ROS 2 message in CDR as cdr_write's writer (cdr_write.py) and reader (cdr_read.py) walk it:
the primitives' struct codes and sizes, the message flattened into leaves in wire order, and what is known of the
alignment at each point (XCDR1, little endian; offsets relative to the first byte after the header).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.spec import Field, RosMessage, Scalar
from sam_codegen.model.types import ROS_FLOAT_BITS, RosType
from sam_codegen.targets.wire.code import FieldPath

__all__ = ["ARRAY_CODE", "HEADER", "MODULE_PRELUDE", "PRIM", "Leaf", "Phase", "elem_path", "flatten", "nested_message",
           "ros_default", "strip_pads", "typed"]

HEADER = b"\x00\x01\x00\x00"
MODULE_PRELUDE = ['_ZEROS = bytes(64)']

# ROS primitive -> (struct code, size); `byte` is a 1-byte bytes object in rclpy (struct 'c').
PRIM: dict[str, tuple[str, int]] = {
    "bool": ("?", 1), "byte": ("c", 1), "char": ("B", 1), "int8": ("b", 1), "uint8": ("B", 1),
    "int16": ("h", 2), "uint16": ("H", 2), "int32": ("i", 4), "uint32": ("I", 4),
    "int64": ("q", 8), "uint64": ("Q", 8), "float32": ("f", 4), "float64": ("d", 8),
}
# array.array typecodes of fixed width (an element of a sequence written in one call).
ARRAY_CODE = {"int8": "b", "int16": "h", "uint16": "H", "int32": "i", "uint32": "I", "int64": "q",
               "uint64": "Q", "float32": "f", "float64": "d"}


def ros_default(f: Field) -> Scalar:
    """A primitive field's default as the ROS message class has it (what convert.py's `_new_*` factories use):
    the .msg default, else zero / False / ''.

    >>> ros_default(Field("w", RosType("float64"), default=1.0)), ros_default(Field("s", RosType("string")))
    (1.0, '')
    """
    t = f.type
    assert isinstance(t, RosType)
    return typed(f.default if f.default is not None else ("" if t.base in ("string", "wstring") else 0), t.base)


def typed(value: Any, base: str) -> Any:
    if base in ROS_FLOAT_BITS:
        return float(value)
    if base == "bool":
        return bool(value)
    if base == "byte":
        return value if isinstance(value, bytes) else bytes((int(value),))
    if base in ("string", "wstring"):
        return str(value)
    return int(value)


# ---- the flattened layout ------------------------------------------------------------------------------------


@dataclass
class Leaf:
    """One item of a message's layout in wire order."""

    kind: str  # prim | block (fixed array of primitives) | string | seq | msgseq
    path: FieldPath
    base: str = ""
    count: int = 1  # block: elements
    bound: int | None = None  # string / sequence bound
    default: Any = None  # prim: the field's default
    message: RosMessage | None = None  # msgseq: the element type
    array: str = ""  # block: the ROS array kind, for the element paths


def flatten(message: RosMessage, lookup: Callable[[str], RosMessage | None], prefix: FieldPath = ()) -> list[Leaf]:
    if not message.fields:  # rosidl gives an empty message one uint8 member
        return [Leaf("prim", (*prefix, ("structure_needs_at_least_one_member", None)), "uint8", default=0)]
    out: list[Leaf] = []
    for f in message.fields:
        t = f.type
        assert isinstance(t, RosType), f
        path = (*prefix, (f.name, None))
        if t.base == "wstring":
            raise NotImplementedError(f"{message.full_name}.{f.name}: wstring has no wire codec")
        if not t.array:
            if t.base == "string":
                out.append(Leaf("string", path, bound=t.string_bound, default=ros_default(f)))
            elif t.is_primitive:
                out.append(Leaf("prim", path, t.base, default=ros_default(f)))
            else:
                out.extend(flatten(nested_message(lookup, t.base), lookup, path))
        elif t.array == "fixed":
            if t.base == "string":
                for i in range(t.capacity or 0):
                    out.append(Leaf("string", (*prefix, (f.name, i)), bound=t.string_bound, default=""))
            elif t.is_primitive:
                out.append(Leaf("block", path, t.base, count=t.capacity or 0, default=typed(0, t.base)))
            else:
                nested = nested_message(lookup, t.base)
                for i in range(t.capacity or 0):
                    out.extend(flatten(nested, lookup, (*prefix, (f.name, i))))
        elif t.is_primitive and t.base != "string":
            out.append(Leaf("seq", path, t.base, bound=t.capacity if t.array == "bounded" else None))
        else:
            element = None if t.base == "string" else nested_message(lookup, t.base)
            out.append(Leaf("msgseq", path, t.base, bound=t.capacity if t.array == "bounded" else None,
                             message=element))
    return out


def nested_message(lookup: Callable[[str], RosMessage | None], name: str) -> RosMessage:
    message = lookup(name)
    if message is None:
        raise ValueError(f"unknown ROS message {name}")
    return message


def elem_path(path: FieldPath, i: int) -> FieldPath:
    return (*path[:-1], (path[-1][0], i))


# ---- alignment state -----------------------------------------------------------------------------------------


@dataclass
class Phase:
    """What is known of the current offset (relative to the first byte after the header): offset % mod == rem."""

    mod: int = 8
    rem: int = 0

    def pad(self, align: int) -> int | None:
        """Static padding before an item of alignment `align`, or None when only run time knows it."""
        if align <= self.mod:
            return -self.rem % align
        return None

    def advance(self, size: int) -> None:
        self.rem = (self.rem + size) % self.mod

    def unknown(self, mod: int = 1) -> None:
        self.mod, self.rem = mod, 0


def strip_pads(fmt: str) -> str:
    """Merge repeated pad codes of a struct format: 'xxxd' -> '3xd'.

    >>> strip_pads("<xxxdxBB")
    '<3xdxBB'
    """
    out, i = [], 0
    while i < len(fmt):
        j = i
        while j < len(fmt) and fmt[j] == fmt[i] == "x":
            j += 1
        if j - i > 1:
            out.append(f"{j - i}x")
            i = j
        else:
            out.append(fmt[i])
            i += 1
    return "".join(out)
