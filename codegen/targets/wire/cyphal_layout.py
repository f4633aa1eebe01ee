"""The Cyphal v1 layout facts cyphal_read's reader and writer share (pydsdl's rules): struct codes of the standard
primitives, length prefix and union tag widths, largest sizes, and what makes a composite's size vary."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import DsdlType
from sam_codegen.targets.wire.code import FieldPath

__all__ = ["CYPHAL_PRELUDE", "Lookup", "max_bits", "prefix_bits"]

Lookup = Callable[[str], DsdlStruct | None]

CYPHAL_PRELUDE = [
    "",
    "",
    "def _extend(data: Any, size: int) -> Any:",
    '    """`data` zero-extended to `size` bytes (the implicit zero extension), as it is when long enough."""',
    "    return data if len(data) >= size else bytes(data) + bytes(size - len(data))",
]

# (kind, bits) of the primitives a struct code reads and writes in place, when byte-aligned.
STD_FORMATS = {("uint", 8): "B", ("uint", 16): "H", ("uint", 32): "I", ("uint", 64): "Q", ("int", 8): "b",
        ("int", 16): "h", ("int", 32): "i", ("int", 64): "q", ("float", 16): "e", ("float", 32): "f",
        ("float", 64): "d", ("byte", 8): "B", ("utf8", 8): "B"}
UNSIGNED_FORMATS = {8: "B", 16: "H", 32: "I", 64: "Q"}
FLOAT_FORMATS = {16: "e", 32: "f", 64: "d"}


def prefix_bits(capacity: int) -> int:
    """The length prefix of a variable-length array (pydsdl's rule).

    >>> [prefix_bits(c) for c in (1, 255, 256, 65536)]
    [8, 8, 16, 32]
    """
    return 2 ** math.ceil(math.log2(max(8, capacity.bit_length())))


def union_tag_bits(variants: int) -> int:
    """The tag of a union (pydsdl's rule; the variants' alignment is at most 8 in DSDL v1)."""
    return 2 ** math.ceil(math.log2(max(8, (variants - 1).bit_length())))


def ceil8(bits: int) -> int:
    return -(-bits // 8) * 8


def struct_of(lookup: Lookup, name: str | None) -> DsdlStruct:
    struct_ = lookup(name or "")
    if struct_ is None:
        raise ValueError(f"unknown DSDL type {name}")
    return struct_


def _field_bits(t: DsdlType, lookup: Lookup) -> int:
    """Largest size of a field in bits, composites padded (their start is aligned by the caller)."""
    if t.kind == "composite":
        nested = struct_of(lookup, t.composite)
        one = max_bits(nested, lookup) if nested.sealed else 32 + 8 * (nested.extent or 0)
    else:
        one = t.bits
    if t.array == "fixed":
        return one * (t.capacity or 0)
    if t.array == "bounded":
        return prefix_bits(t.capacity or 0) + one * (t.capacity or 0)
    return one


def max_bits(struct_: DsdlStruct, lookup: Lookup) -> int:
    """The largest serialized size of a composite, in bits (a delimited nested one counts its extent)."""
    fields = [f.type for f in struct_.declared_fields]
    if struct_.union:
        return ceil8(union_tag_bits(len(fields)) + max(_field_bits(t, lookup) for t in fields))  # type: ignore[arg-type]
    bits = 0
    for t in fields:
        assert isinstance(t, DsdlType)
        if t.kind == "composite":
            bits = ceil8(bits)
        bits += _field_bits(t, lookup)
    return ceil8(bits)


def is_fixed_size(struct_: DsdlStruct, lookup: Lookup) -> bool:
    """No variable-length part anywhere (a sealed type of fixed size: its delimiter header is a constant)."""
    if struct_.union:
        return False
    for f in struct_.declared_fields:
        t = f.type
        assert isinstance(t, DsdlType)
        if t.array == "bounded":
            return False
        if t.kind == "composite":
            nested = struct_of(lookup, t.composite)
            if not nested.sealed or not is_fixed_size(nested, lookup):
                return False
    return True


def has_delimited(struct_: DsdlStruct, lookup: Lookup) -> bool:
    """Whether a delimited composite is read as part of this one (directly or inside sealed ones)."""
    for f in struct_.declared_fields:
        t = f.type
        assert isinstance(t, DsdlType)
        if t.kind == "composite":
            nested = struct_of(lookup, t.composite)
            if not nested.sealed or has_delimited(nested, lookup):
                return True
    return False


def signed_expr(raw: str, bits: int) -> str:
    half = 1 << (bits - 1)
    return f"(({raw} ^ {half}) - {half})"


def piece_sizes(nbytes: int) -> list[int]:
    """Struct-sized pieces covering nbytes, largest first.

    >>> piece_sizes(7), piece_sizes(3), piece_sizes(8)
    ([4, 2, 1], [2, 1], [8])
    """
    out = []
    for size in (8, 4, 2, 1):
        while nbytes >= size:
            out.append(size)
            nbytes -= size
    return out


def elem_path(path: FieldPath, i: int) -> FieldPath:
    return (*path[:-1], (path[-1][0], i))


def touches(paths: Iterable[FieldPath], path: FieldPath | None) -> bool:
    """Whether a path goes into the field at `path`, whatever its index."""
    if path is None:
        return False
    n = len(path)
    return any(len(p) >= n and p[:n - 1] == path[:-1] and p[n - 1][0] == path[-1][0] for p in paths)
