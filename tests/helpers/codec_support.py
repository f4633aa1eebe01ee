"""What tests/test_codec_cyphal.py's worker needs beside the built classes: hypothesis strategies that fill every
field of a DSDL or ROS type over its whole range (NaN, infinities, extremes, empty and full arrays, any bytes in
utf8), plain NaN-aware comparisons of pycyphal objects and ROS messages, and the malformed variants of a payload.

Nothing here imports ROS or pycyphal at import time; the class lookups are passed in.
"""

from __future__ import annotations

import math
import struct
import sys
from collections.abc import Callable, Iterator
from typing import Any

from hypothesis import strategies as st

from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import ROS_INT_RANGES, DsdlType, RosType
from sam_codegen.targets.python.names import py_attr

DsdlLookup = Callable[[str], DsdlStruct | None]
RosLookup = Callable[[str], RosMessage | None]


# ---- values --------------------------------------------------------------------------------------------------


def same(a: Any, b: Any) -> bool:
    """Equal, NaN equal to NaN, lists element by element, dicts key by key.

    >>> same([1.0, float("nan")], [1.0, float("nan")]), same({"a": 1}, {"a": 2})
    (True, False)
    """
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(v, b[k]) for k, v in a.items())
    return type(a) is type(b) and bool(a == b)


def _plain(value: Any) -> Any:
    if hasattr(value, "tolist"):  # numpy array or scalar, array.array
        value = value.tolist()
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


# Frame prefixes of every length modulo 8 (2 to 9 characters): the CDR padding after a frame id depends on it.
FRAME_PREFIXES = ("v/", "v1/", "v12/", "v123/", "sam1/x/", "v12345/", "v123456/", "sam_two/")


def with_frame_prefix(msg: Any, prefix: str) -> Any:
    """`msg` (a ROS message; changed in place and returned) with `prefix` before the frame id of every
    std_msgs/Header in it, a sequence's elements' included, that has one: what a namespaced bridge writes."""
    if type(msg).__name__ == "Header" and type(msg).__module__.startswith("std_msgs"):
        if msg.frame_id:
            msg.frame_id = prefix + msg.frame_id
        return msg
    for name in msg.get_fields_and_field_types():
        value = getattr(msg, name)
        for item in value if isinstance(value, list) else [value]:
            if hasattr(item, "get_fields_and_field_types"):
                with_frame_prefix(item, prefix)
    return msg


def ros_plain(msg: Any) -> Any:
    """A ROS message as nested dicts and lists of plain values."""
    if hasattr(msg, "get_fields_and_field_types"):
        return {name: ros_plain(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    if hasattr(msg, "tolist"):
        msg = msg.tolist()
    if isinstance(msg, (list, tuple)):
        return [ros_plain(v) for v in msg]
    return msg


def dsdl_plain(obj: Any, struct: DsdlStruct, lookup: DsdlLookup) -> dict[str, Any]:
    """A pycyphal object of `struct` as nested dicts and lists (utf8 arrays as bytes; unions left out)."""
    out: dict[str, Any] = {}
    for f in struct.fields:
        t = f.type
        assert isinstance(t, DsdlType)
        value = getattr(obj, py_attr(f.name))
        if t.kind == "composite":
            nested = lookup(t.composite or "")
            assert nested is not None
            if nested.union:
                continue
            out[f.name] = [dsdl_plain(v, nested, lookup) for v in value] if t.array else \
                dsdl_plain(value, nested, lookup)
        elif t.kind == "utf8":
            out[f.name] = bytes(value.tobytes())
        else:
            out[f.name] = _plain(value)
    return out


# ---- strategies ----------------------------------------------------------------------------------------------

_FLOAT_FORMS = {16: ("<e", 65504.0), 32: ("<f", 3.4028234663852886e38), 64: ("<d", sys.float_info.max)}


def any_float(bits: int) -> st.SearchStrategy[float]:
    """Every float of a width: finite ones, and every bit pattern (infinities, NaNs with payloads, subnormals).
    Not st.floats(width=16): it rejects each draw that overflows the width, and with a few dozen float16 fields
    in one message Hypothesis gives up on the filtering (FailedHealthCheck)."""
    form, biggest = _FLOAT_FORMS[bits]
    patterns = st.integers(0, (1 << bits) - 1).map(
        lambda n: float(struct.unpack(form, n.to_bytes(bits // 8, "little"))[0]))
    return st.one_of(st.floats(-biggest, biggest, width=bits), patterns)  # type: ignore[arg-type]


def _dsdl_scalar(t: DsdlType) -> st.SearchStrategy[Any]:
    if t.kind == "bool":
        return st.booleans()
    if t.kind in ("int", "uint", "byte", "utf8"):
        lo, hi = (0, 255) if t.kind in ("byte", "utf8") else t.range
        return st.integers(lo, hi)
    assert t.kind == "float", t
    return any_float(t.bits)


def dsdl_strategy(struct: DsdlStruct, lookup: DsdlLookup, cls_of: Callable[[DsdlStruct], type],
                  special: dict[str, st.SearchStrategy[Any]] | None = None, prefix: str = ""
                  ) -> st.SearchStrategy[Any]:
    """pycyphal objects of `struct` with every field drawn over its whole range (`special`: by field path)."""
    special = special or {}
    fields: dict[str, st.SearchStrategy[Any]] = {}
    for f in struct.fields:
        t = f.type
        assert isinstance(t, DsdlType)
        path = prefix + f.name
        if path in special:
            fields[py_attr(f.name)] = special[path]
            continue
        if t.kind == "composite":
            nested = lookup(t.composite or "")
            assert nested is not None
            if nested.union:
                continue  # its default
            one = dsdl_strategy(nested, lookup, cls_of, special, path + ".")
            if t.array:
                low = t.capacity if t.array == "fixed" else 0
                fields[py_attr(f.name)] = st.lists(one, min_size=low or 0, max_size=min(t.capacity or 0, 4)
                                                   if t.array == "bounded" else t.capacity)
            else:
                fields[py_attr(f.name)] = one
        elif t.kind == "utf8":
            fields[py_attr(f.name)] = st.binary(max_size=t.capacity or 0)  # any bytes: invalid UTF-8 too
        elif t.array:
            low = t.capacity if t.array == "fixed" else 0
            fields[py_attr(f.name)] = st.lists(_dsdl_scalar(t.element), min_size=low or 0, max_size=t.capacity)
        else:
            fields[py_attr(f.name)] = _dsdl_scalar(t)
    return st.fixed_dictionaries(fields).map(lambda kwargs: cls_of(struct)(**kwargs))


def _ros_scalar(base: str, string_bound: int | None) -> st.SearchStrategy[Any]:
    if base == "bool":
        return st.booleans()
    if base == "byte":
        return st.binary(min_size=1, max_size=1)
    if base in ROS_INT_RANGES:
        return st.integers(*ROS_INT_RANGES[base])
    if base == "float32":
        return any_float(32)
    if base == "float64":
        return any_float(64)
    assert base == "string", base
    if string_bound is not None:
        return st.text(st.characters(max_codepoint=127), max_size=string_bound)
    return st.text(max_size=12)  # NUL, surrogates excluded by hypothesis' default alphabet only where invalid


def ros_strategy(message: RosMessage, lookup: RosLookup, cls_of: Callable[[str], type]) -> st.SearchStrategy[Any]:
    """ROS messages of `message` with every field drawn over its whole range."""
    fields: dict[str, st.SearchStrategy[Any]] = {}
    for f in message.fields:
        t = f.type
        assert isinstance(t, RosType)
        if t.is_primitive:
            one = _ros_scalar(t.base, t.string_bound)
        else:
            nested = lookup(t.base)
            assert nested is not None
            one = ros_strategy(nested, lookup, cls_of)
        if t.array == "fixed":
            fields[f.name] = st.lists(one, min_size=t.capacity or 0, max_size=t.capacity)
        elif t.array:
            fields[f.name] = st.lists(one, max_size=t.capacity if t.array == "bounded" else 8)
        else:
            fields[f.name] = one

    def build(values: dict[str, Any]) -> Any:
        msg = cls_of(message.full_name)()
        for name, value in values.items():
            setattr(msg, name, value)
        return msg

    return st.fixed_dictionaries(fields).map(build)


# ---- malformed payloads --------------------------------------------------------------------------------------


def _prefix_bits(capacity: int) -> int:
    return 2 ** math.ceil(math.log2(max(8, capacity.bit_length())))


def length_fields(struct: DsdlStruct, obj: Any, lookup: DsdlLookup, start: int = 0
                  ) -> tuple[int, list[tuple[int, int, int]]]:
    """Where the length fields of a serialized object are, worked out from the DSDL layout and the object's
    array lengths (independently of wire_cyphal): (end bit, [(bit offset, width, the value that is one too
    many)]) - a length prefix's capacity + 1, a delimiter header's (its bytes + 1: checked against the payload
    by the caller)."""
    bits, out = start, []
    for f in struct.declared_fields:
        t = f.type
        assert isinstance(t, DsdlType)
        value = getattr(obj, py_attr(f.name)) if f.name else None
        if t.kind != "composite":
            if t.array == "bounded":
                width = _prefix_bits(t.capacity or 0)
                out.append((bits, width, (t.capacity or 0) + 1))
                bits += width + len(value) * t.bits
            else:
                bits += t.bits * (t.capacity or 1 if t.array else 1)
            continue
        nested = lookup(t.composite or "")
        assert nested is not None and not nested.union
        items = [value] if not t.array else list(value)
        bits = -(-bits // 8) * 8
        if t.array == "bounded":
            width = _prefix_bits(t.capacity or 0)
            out.append((bits, width, (t.capacity or 0) + 1))
            bits += width
        for item in items:
            bits = -(-bits // 8) * 8
            if nested.sealed:
                bits, inner = length_fields(nested, item, lookup, bits)
                out += inner
            else:
                header = bits
                end, inner = length_fields(nested, item, lookup, bits + 32)
                end = -(-end // 8) * 8
                out.append((header, 32, (end - header - 32) // 8 + 1))
                out += inner
                bits = end
    return -(-bits // 8) * 8, out


def with_bits(payload: bytes, offset: int, width: int, value: int) -> bytes:
    """`payload` with `width` bits at bit `offset` set to `value` (little-endian, LSB first).

    >>> with_bits(bytes(2), 4, 8, 0xFF).hex()
    'f00f'
    """
    word = int.from_bytes(payload, "little")
    mask = ((1 << width) - 1) << offset
    word = (word & ~mask) | ((value << offset) & mask)
    return word.to_bytes(len(payload), "little")


def corruptions(payload: bytes, noise: bytes) -> Iterator[bytes]:
    """Every truncation, each byte set to 0xFF and to a byte of `noise` (length prefixes and delimiter headers
    among them), the payload extended by `noise` (a newer minor version), and `noise` alone."""
    for cut in range(len(payload)):
        yield payload[:cut]
    for i in range(len(payload)):
        for value in (0xFF, noise[i % len(noise)] if noise else 0x7F):
            if payload[i] != value:
                yield payload[:i] + bytes((value,)) + payload[i + 1:]
    yield payload + noise
    yield noise


def bad_lengths(payload: bytes, struct: DsdlStruct, obj: Any, lookup: DsdlLookup) -> Iterator[bytes]:
    """The payload of `obj` with each length prefix one beyond its capacity and at its largest value, and each
    delimiter header one byte longer than what follows it and than the nested bytes."""
    _, fields = length_fields(struct, obj, lookup)
    for offset, width, too_many in fields:
        if offset + width > 8 * len(payload):
            continue
        if width == 32:  # a delimiter header
            rest = len(payload) - (offset + 32) // 8
            for value in (rest + 1, too_many, rest):
                yield with_bits(payload, offset, width, value)
        else:
            for value in (too_many, (1 << width) - 1):
                yield with_bits(payload, offset, width, value)
