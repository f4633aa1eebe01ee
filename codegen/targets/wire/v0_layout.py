"""The UAVCAN v0 (DroneCAN) layout rules the wire codecs follow, as dronecan (pydronecan 1.0.27,
``dronecan/transport.py`` and ``dronecan/dsdl/parser.py``) computes them: bit lengths (``get_min_bitlen``), the
length prefix of a dynamic array, the tag of a union, when a dynamic array is a tail array (TAO), and which
primitives struct reads byte for byte. See v0_read for the layout itself.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable

from sam_codegen.model.spec import DsdlStruct, V0Struct
from sam_codegen.model.types import DsdlType

__all__ = ["V0Layout", "code_is_bytes", "length_bits", "merge_pads", "record_index", "struct_code", "tag_bits"]

# struct codes of the byte-multiple primitives (24 to 56-bit integers are read as bytes).
_INT_CODES = {8: "B", 16: "H", 32: "I", 64: "Q"}
_FLOAT_CODES = {16: "e", 32: "f", 64: "d"}


def length_bits(capacity: int) -> int:
    """The length prefix of a dynamic array, as dronecan computes it (``array_len_bits_from_max_size``).

    >>> length_bits(20), length_bits(15), length_bits(16), length_bits(255)
    (5, 4, 5, 8)
    """
    return math.ceil(math.log(capacity + 1, 2))


def tag_bits(fields: int) -> int:
    """The tag of a union of `fields` fields, as dronecan computes it (``union_tag_bits_from_num_elements``).

    >>> tag_bits(2), tag_bits(3), tag_bits(5), tag_bits(1)
    (1, 2, 3, 0)
    """
    return math.ceil(math.log(fields, 2))


def struct_code(t: DsdlType) -> str | None:
    """The struct code that reads a primitive byte for byte (little-endian), or None when it needs bit operations.

    >>> [struct_code(DsdlType(k, b)) for k, b in (("uint", 8), ("int", 16), ("int", 24), ("float", 16), ("bool", 1),
    ...                                              ("uint", 11), ("void", 16))]
    ['B', 'h', '3s', 'e', None, None, '2x']
    """
    if t.bits % 8:
        return None
    if t.kind == "float":
        return _FLOAT_CODES[t.bits]
    if t.kind in ("int", "uint"):
        code = _INT_CODES.get(t.bits, f"{t.bits // 8}s")
        return code.lower() if t.kind == "int" and code != f"{t.bits // 8}s" else code
    if t.kind == "void":
        return f"{t.bits // 8}x"
    return None


def record_index(struct: DsdlStruct, name: str) -> int:
    """A field's position in the records of `struct` (its fields without void padding)."""
    return [f.name for f in struct.fields].index(name)


class V0Layout:
    """Bit lengths of v0 types as dronecan's parser computes them."""

    def __init__(self, lookup: Callable[[str], V0Struct | None]) -> None:
        self._lookup = lookup

    def struct(self, t: DsdlType | str) -> V0Struct:
        name = t if isinstance(t, str) else t.composite
        struct = self._lookup(name or "")
        if struct is None:
            raise ValueError(f"unknown UAVCAN v0 type {name}")
        return struct

    def min_bits(self, t: DsdlType) -> int:
        """dronecan's ``get_min_bitlen``: dynamic arrays count 0 ("considering TAO"), a union its shortest field
        and its tag (``max(n - 1, 1).bit_length()``), void padding its bits."""
        if t.array == "fixed":
            return (t.capacity or 0) * self.min_bits(t.element)
        if t.array:
            return 0
        if t.kind != "composite":
            return t.bits
        s = self.struct(t)
        lens = [self.min_bits(f.type) for f in s.declared_fields]  # type: ignore[arg-type]
        if not lens:
            return 0
        return min(lens) + max(len(lens) - 1, 1).bit_length() if s.union else sum(lens)

    def static_bits(self, t: DsdlType) -> int | None:
        """The bit length of a type of fixed size; None for one with dynamic arrays or unions."""
        if t.array == "fixed":
            inner = self.static_bits(t.element)
            return None if inner is None else inner * (t.capacity or 0)
        if t.array:
            return None
        if t.kind != "composite":
            return t.bits
        s = self.struct(t)
        if s.union:
            return None
        total = 0
        for f in s.declared_fields:
            inner = self.static_bits(f.type)  # type: ignore[arg-type]
            if inner is None:
                return None
            total += inner
        return total

    def required_bits(self, t: DsdlType) -> int:
        """For a type of fixed size: where its last non-void bit ends (what must fit for dronecan to read it)."""
        if t.array == "fixed":
            n = t.capacity or 0
            return 0 if not n else (n - 1) * (self.static_bits(t.element) or 0) + self.required_bits(t.element)
        if t.kind == "void":
            return 0
        if t.kind != "composite":
            return t.bits
        end = pos = 0
        for f in self.struct(t).declared_fields:
            ft: DsdlType = f.type  # type: ignore[assignment]
            if self.required_bits(ft):
                end = pos + self.required_bits(ft)
            pos += self.static_bits(ft) or 0
        return end

    def tao_mode(self, t: DsdlType, tao: bool) -> bool:
        """Whether a dynamic array given the tao flag is a tail array (no prefix)."""
        return tao and self.min_bits(t.element) >= 8

    def tao_sensitive(self, t: DsdlType) -> bool:
        """Whether the tao flag changes how a type is laid out (a tail array can be reached through it)."""
        if t.array == "fixed":
            return self.tao_sensitive(t.element)
        if t.array:
            return self.min_bits(t.element) >= 8 or self.tao_sensitive(t.element)
        if t.kind != "composite":
            return False
        s = self.struct(t)
        fields = s.declared_fields
        if s.union:
            return any(self.tao_sensitive(f.type) for f in fields)  # type: ignore[arg-type]
        return bool(fields) and self.tao_sensitive(fields[-1].type)  # type: ignore[arg-type]


def code_is_bytes(t: DsdlType) -> bool:
    code = struct_code(t)
    return code is not None and code.endswith("s")


def merge_pads(fmt: str) -> str:
    """Merge consecutive pad codes of a struct format.

    >>> merge_pads("<2x1xB3xe")
    '<3xB3xe'
    """
    out: list[str] = []
    for count, code in re.findall(r"(\d*)(\D)", fmt):
        if code == "x" and out and out[-1].endswith("x"):
            out[-1] = f"{int(out[-1][:-1] or 1) + int(count or 1)}x"
        else:
            out.append(count + code)
    return "".join(out)
