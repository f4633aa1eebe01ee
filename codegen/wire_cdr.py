"""Straight-line Python for ROS 2 CDR bytes, generated per message type: a writer and a reader.

The wire codecs (codec.py, codec_v0.py) publish and receive ROS messages as CDR bytes (rclpy's raw publish and raw
subscriptions) instead of message objects. This module writes the code that produces and decodes those bytes for
one RosMessage of the model, the way rclpy / Fast CDR lay them out (XCDR1, little endian):

- a 4-byte encapsulation header ``00 01 00 00`` (CDR_LE) before the data;
- each primitive aligned to its size (at most 8) relative to the first byte after the header; bool, byte, char,
  int8 and uint8 take 1 byte;
- string: uint32 length including the terminating NUL, the UTF-8 bytes, NUL (rclpy ends a string at its first NUL);
- sequences (unbounded and bounded): uint32 count, then the elements; fixed arrays: the elements only;
- nested messages inline, field by field.

API (stable: codec.py and codec_v0.py are built on it)
------------------------------------------------------
Paths are tuples of ``(field name, index or None)``, as mapping_rules gives them: ``(("header", None), ("stamp",
None), ("sec", None))``, ``(("orientation_covariance", 0),)`` for one element of a fixed array,
``(("cell_voltage", None),)`` for a whole array.

- ``Constants``: the module-level constants generated code refers to (one ``struct.Struct`` per run of fixed-layout
  fields, precomputed bytes), deduplicated by content and named deterministically; ``lines()`` renders them.
  (It lives in wire_code with ``literal_value``, ``NO_VALUE``, ``wrap_line`` and ``prune``; all re-exported here.)
- ``cdr_writer(message, values, lookup, names, consts)`` -> ``(lines, expr)``: statements and the final expression
  of the CDR bytes (header included). ``values`` maps leaf paths to Python expressions; a whole-array path takes a
  list expression (``byte`` arrays: a list of 1-byte ``bytes``, as rclpy keeps them), a string path a ``str``
  expression. A leaf without a value gets the field's default, as the ROS message class has it (``ros_default``).
  Literal expressions (``py_literal``: numbers, strings, True/False, ``_NAN``, ``_INF``) are packed at generation
  time.
- ``cdr_reader(message, wanted, lookup, names, consts, buf)`` -> ``(lines, locals)``: statements that check the CDR
  in ``buf`` (bytes or memoryview, header included) and decode the leaves in ``wanted`` into locals: numbers,
  bools, 1-byte ``bytes`` for a ``byte`` scalar, ``str`` for strings, lists for whole arrays (``byte`` arrays as
  ints). They raise ``WireError`` (a name the generated module defines) on a wrong header, truncated data, a
  string without its NUL, a length beyond the buffer or a bound exceeded: never another exception.
- ``lookup(full_name) -> RosMessage`` resolves nested types (``Resolved.ros.get``, external ones included);
  ``names.new(hint)`` gives a fresh local (emit_python's ``_Names``).

The generated code needs, in its module, ``import struct as _struct``, ``from array import array as _array``, the
``WireError`` class and ``_ZEROS`` (zero bytes, at least 8: ``MODULE_PRELUDE``).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from .model import Field, RosMessage, Scalar
from .typesys import ROS_FLOAT_BITS, RosType
from .wire_code import LINE_LIMIT, NO_VALUE, Constants, Names, Path, literal_value, prune, wrap_line

# Constants, literal_value, NO_VALUE, Names, Path, wrap_line and prune live in wire_code; re-exported here (API).
__all__ = ["LINE_LIMIT", "MODULE_PRELUDE", "NO_VALUE", "Constants", "Names", "Path", "cdr_reader", "cdr_writer",
           "literal_value", "prune", "ros_default", "wrap_line"]

HEADER = b"\x00\x01\x00\x00"
MODULE_PRELUDE = ['_ZEROS = bytes(64)']

# ROS primitive -> (struct code, size); `byte` is a 1-byte bytes object in rclpy (struct 'c').
_PRIM: dict[str, tuple[str, int]] = {
    "bool": ("?", 1), "byte": ("c", 1), "char": ("B", 1), "int8": ("b", 1), "uint8": ("B", 1),
    "int16": ("h", 2), "uint16": ("H", 2), "int32": ("i", 4), "uint32": ("I", 4),
    "int64": ("q", 8), "uint64": ("Q", 8), "float32": ("f", 4), "float64": ("d", 8),
}
# array.array typecodes of fixed width (an element of a sequence written in one call).
_ARRAY_CODE = {"int8": "b", "int16": "h", "uint16": "H", "int32": "i", "uint32": "I", "int64": "q",
               "uint64": "Q", "float32": "f", "float64": "d"}


def ros_default(f: Field) -> Scalar:
    """A primitive field's default as the ROS message class has it (what emit_python's `_new_*` factories use):
    the .msg default, else zero / False / ''.

    >>> ros_default(Field("w", RosType("float64"), default=1.0)), ros_default(Field("s", RosType("string")))
    (1.0, '')
    """
    t = f.type
    assert isinstance(t, RosType)
    return _typed(f.default if f.default is not None else ("" if t.base in ("string", "wstring") else 0), t.base)


def _typed(value: Any, base: str) -> Any:
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
class _Leaf:
    """One item of a message's layout in wire order."""

    kind: str  # prim | block (fixed array of primitives) | string | seq | msgseq
    path: Path
    base: str = ""
    count: int = 1  # block: elements
    bound: int | None = None  # string / sequence bound
    default: Any = None  # prim: the field's default
    message: RosMessage | None = None  # msgseq: the element type
    array: str = ""  # block: the ROS array kind, for the element paths


def _flatten(message: RosMessage, lookup: Callable[[str], RosMessage | None], prefix: Path = ()) -> list[_Leaf]:
    if not message.fields:  # rosidl gives an empty message one uint8 member
        return [_Leaf("prim", (*prefix, ("structure_needs_at_least_one_member", None)), "uint8", default=0)]
    out: list[_Leaf] = []
    for f in message.fields:
        t = f.type
        assert isinstance(t, RosType), f
        path = (*prefix, (f.name, None))
        if t.base == "wstring":
            raise NotImplementedError(f"{message.full_name}.{f.name}: wstring has no wire codec")
        if not t.array:
            if t.base == "string":
                out.append(_Leaf("string", path, bound=t.string_bound, default=ros_default(f)))
            elif t.is_primitive:
                out.append(_Leaf("prim", path, t.base, default=ros_default(f)))
            else:
                out.extend(_flatten(_nested(lookup, t.base), lookup, path))
        elif t.array == "fixed":
            if t.base == "string":
                for i in range(t.capacity or 0):
                    out.append(_Leaf("string", (*prefix, (f.name, i)), bound=t.string_bound, default=""))
            elif t.is_primitive:
                out.append(_Leaf("block", path, t.base, count=t.capacity or 0, default=_typed(0, t.base)))
            else:
                nested = _nested(lookup, t.base)
                for i in range(t.capacity or 0):
                    out.extend(_flatten(nested, lookup, (*prefix, (f.name, i))))
        elif t.is_primitive and t.base != "string":
            out.append(_Leaf("seq", path, t.base, bound=t.capacity if t.array == "bounded" else None))
        else:
            nested = None if t.base == "string" else _nested(lookup, t.base)
            out.append(_Leaf("msgseq", path, t.base, bound=t.capacity if t.array == "bounded" else None,
                             message=nested))
    return out


def _nested(lookup: Callable[[str], RosMessage | None], name: str) -> RosMessage:
    message = lookup(name)
    if message is None:
        raise ValueError(f"unknown ROS message {name}")
    return message


def _elem_path(path: Path, i: int) -> Path:
    return (*path[:-1], (path[-1][0], i))


# ---- alignment state -----------------------------------------------------------------------------------------


@dataclass
class _Phase:
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


def _strip(fmt: str) -> str:
    """Merge repeated pad codes of a struct format: 'xxxd' -> '3xd'.

    >>> _strip("<xxxdxBB")
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


# ---- writer --------------------------------------------------------------------------------------------------


@dataclass
class _Run:
    """A run of fixed-layout items packed by one struct: (code, expression or None for pad, literal value)."""

    items: list[tuple[str, str | None, Any]] = field(default_factory=list)

    def add(self, code: str, expr: str, value: Any = NO_VALUE) -> None:
        self.items.append((code, expr, value))

    def pad(self, n: int) -> None:
        self.items.append(("x" * n, None, NO_VALUE))

    def packed(self, consts: Constants) -> tuple[str, list[str], bytes | None]:
        """(struct format, arguments, or the bytes when every value is a literal); consecutive literals are
        packed here, at generation time, into one `Ns` argument (zeros into pad bytes)."""
        codes: list[str] = []
        args: list[str] = []
        chunk: list[tuple[str, Any]] = []  # literal items (and pads) not yet emitted

        def close() -> None:
            if not chunk:
                return
            fmt = "<" + "".join(code for code, _ in chunk)
            data = struct.pack(fmt, *[v for _, v in chunk if v is not NO_VALUE])
            if any(data):
                codes.append(f"{len(data)}s")
                args.append(consts.data(data))
            else:
                codes.append("x" * len(data))
            chunk.clear()

        for code, expr, value in self.items:
            if expr is None or value is not NO_VALUE:
                chunk.append((code, value))
                continue
            close()
            codes.append(code)
            args.append(expr)
        if not args:
            fmt = "<" + "".join(code for code, _ in chunk)
            return fmt, [], struct.pack(fmt, *[v for _, v in chunk if v is not NO_VALUE])
        close()
        return _strip("<" + "".join(codes)), args, None


class _Writer:
    def __init__(self, lookup: Callable[[str], RosMessage | None], names: Names, consts: Constants,
                 values: dict[Path, str]) -> None:
        self.lookup, self.names, self.consts, self.values = lookup, names, consts, values
        self.used: set[Path] = set()
        self.phase = _Phase()
        self.run = _Run()
        self.lines: list[str] = []
        self.parts: list[str] = []  # expressions appended to the output so far (before `buf` exists)
        self.buf: str | None = None  # the bytearray local, once something needs the length so far

    # -- values
    def value(self, path: Path, default: Any) -> tuple[str, Any]:
        """(expression, literal value or NO_VALUE) of a leaf."""
        expr = self.values.get(path)
        if expr is None:
            return repr(default) if not isinstance(default, float) or math.isfinite(default) else _lit(default), \
                default
        self.used.add(path)
        return expr, literal_value(expr)

    # -- output
    def flush(self) -> None:
        run, self.run = self.run, _Run()
        if not run.items:
            return
        fmt, args, data = run.packed(self.consts)
        if data is not None:
            self.emit(self.consts.data(data))
        else:
            self.emit(f"{self.consts.struct(fmt)}.pack({', '.join(args)})")

    def emit(self, expr: str) -> None:
        if self.buf is None:
            self.parts.append(expr)
        else:
            self.lines.append(f"{self.buf} += {expr}")

    def need_buffer(self) -> str:
        """The bytearray written so far (its length gives the run-time alignment)."""
        self.flush()
        if self.buf is None:
            self.buf = self.names.new("cdr")
            first = " + ".join(self.parts) if self.parts else "b''"
            self.lines.append(f"{self.buf} = bytearray({first})")
            self.parts = []
        return self.buf

    def align(self, size: int) -> None:
        """Padding before an item of `size` bytes: static when the phase allows, else computed at run time."""
        align = min(size, 8)
        pad = self.phase.pad(align)
        if pad is None:
            buf = self.need_buffer()
            self.lines.append(f"{buf} += _ZEROS[:(4 - len({buf})) & {align - 1}]")
            self.phase.unknown(align)
        elif pad:
            self.run.pad(pad)
            self.phase.advance(pad)

    # -- layout
    def write(self, leaves: list[_Leaf]) -> None:
        for leaf in leaves:
            getattr(self, f"write_{leaf.kind}")(leaf)

    def write_prim(self, leaf: _Leaf) -> None:
        code, size = _PRIM[leaf.base]
        self.align(size)
        expr, value = self.value(leaf.path, leaf.default)
        self.run.add(code, expr, value)
        self.phase.advance(size)

    def write_block(self, leaf: _Leaf) -> None:
        code, size = _PRIM[leaf.base]
        self.align(size)
        whole = self.values.get(leaf.path)
        if whole is not None:
            self.used.add(leaf.path)
            self.run.add(f"{leaf.count}{code}", f"*{whole}")
        else:
            for i in range(leaf.count):
                expr, value = self.value(_elem_path(leaf.path, i), leaf.default)
                self.run.add(code, expr, value)
        self.phase.advance(size * leaf.count)

    def write_string(self, leaf: _Leaf) -> None:
        self.align(4)
        expr, value = self.value(leaf.path, leaf.default)
        if value is not NO_VALUE:
            data = str(value).encode().partition(b"\0")[0] + b"\0"  # rclpy ends a string at its first NUL
            self.run.add("I", str(len(data)), len(data))
            self.run.add(f"{len(data)}s", repr(data), data)
            self.phase.advance(4 + len(data))
            return
        self.flush()
        data = self.names.new("text")
        self.lines.append(f"{data} = {expr}.encode().partition(b'\\0')[0]")
        self.emit(f"{self.consts.struct('<I')}.pack(len({data}) + 1) + {data} + b'\\0'")
        self.phase.unknown()

    def write_seq(self, leaf: _Leaf) -> None:
        self.align(4)
        expr = self.values.get(leaf.path)
        if expr is None:
            self.run.add("I", "0", 0)
            self.phase.advance(4)
            return
        self.used.add(leaf.path)
        self.flush()
        seq = self.names.new(leaf.path[-1][0])
        self.lines.append(f"{seq} = {expr}")
        self.emit(f"{self.consts.struct('<I')}.pack(len({seq}))")
        self.phase.advance(4)
        size = _PRIM[leaf.base][1]
        pad = self.phase.pad(size)
        if pad != 0:  # 8-byte elements after the count; Fast CDR aligns them only when there are some
            buf = self.need_buffer()
            fill = f"_ZEROS[:{pad}]" if pad is not None else f"_ZEROS[:(4 - len({buf})) & {size - 1}]"
            self.lines += [f"if {seq}:", f"    {buf} += {fill}"]
        if leaf.base == "byte":
            self.emit(f"b''.join({seq})")
        elif leaf.base in ("bool", "uint8", "char"):
            self.emit(f"bytes({seq})")
        else:
            self.emit(f"_array({_ARRAY_CODE[leaf.base]!r}, {seq}).tobytes()")
        self.phase.unknown(min(size, 4))

    def write_msgseq(self, leaf: _Leaf) -> None:
        if leaf.path in self.values:
            raise NotImplementedError(f"{leaf.path}: a sequence of messages is written empty only")
        self.align(4)
        self.run.add("I", "0", 0)
        self.phase.advance(4)


def _lit(value: float) -> str:
    return "_NAN" if math.isnan(value) else "_INF" if value > 0 else "-_INF"


def cdr_writer(message: RosMessage, values: dict[Path, str], lookup: Callable[[str], RosMessage | None],
               names: Names, consts: Constants) -> tuple[list[str], str]:
    """Statements and the final expression of the CDR bytes (header included) of `message` with `values`.

    >>> m = RosMessage("p", "M", [Field("a", RosType("uint8")), Field("b", RosType("float64")),
    ...                           Field("s", RosType("string"))])
    >>> class N:
    ...     def new(self, hint): return hint
    >>> c = Constants()
    >>> cdr_writer(m, {(("b", None),): "x"}, {}.get, N(), c)  # header, a, padding; b; s = '' (length 1, NUL)
    ([], '_K2.pack(_K0, x, _K1)')
    >>> c.lines()[2], len(eval(c.lines()[0].split(" = ")[1]))
    ("_K2 = _struct.Struct('<12sd5s')", 12)
    """
    w = _Writer(lookup, names, consts, values)
    w.run.add("4s", repr(HEADER), HEADER)
    leaves = _flatten(message, lookup)
    w.write(leaves)
    if all(leaf.kind in ("prim", "block") for leaf in leaves):
        w.align(4)  # as rclpy: the data of a type without strings and sequences fills whole 4-byte words
    unused = set(values) - w.used
    if unused:
        raise ValueError(f"{message.full_name}: no field at {sorted(map(str, unused))}")
    w.flush()
    if w.buf is None:
        return w.lines, " + ".join(w.parts) if w.parts else repr(HEADER)
    return w.lines, f"bytes({w.buf})"


# ---- reader --------------------------------------------------------------------------------------------------


class _Reader:
    def __init__(self, lookup: Callable[[str], RosMessage | None], names: Names, consts: Constants, buf: str,
                 wanted: set[Path], size: str, var: str | None = None) -> None:
        self.lookup, self.names, self.consts, self.buf = lookup, names, consts, buf
        self.wanted = wanted
        self.found: dict[Path, str] = {}
        self.lines: list[str] = []
        self.phase = _Phase()
        self.var = var  # the local holding the dynamic part of the offset (None: 0)
        self.delta = 0  # static part of the offset (after the header)
        self.size = size  # the local holding len(buf)
        self.segment: tuple[int, int] | None = None  # (index in lines for its bounds check, delta at its start)
        self.run: list[tuple[str, str | None]] = []  # (struct code, target or None: skipped)
        self.run_delta = 0
        self.after: list[str] = []  # statements after the run's unpack (whole arrays)

    def at(self, delta: int) -> str:
        """The buffer index (header included) of a static offset in the current segment."""
        return f"{self.var} + {4 + delta}" if self.var else str(4 + delta)

    # Bounds: each segment of static offsets (between two dynamic items) is checked once, before its reads.
    def open_segment(self) -> None:
        self.segment = (len(self.lines), self.delta)

    def close_segment(self) -> None:
        self.flush()
        if self.segment is None:
            return
        index, start = self.segment
        if self.delta > start:
            self.lines[index:index] = [f"if {self.size} < {self.at(self.delta)}:",
                                       "    raise WireError('CDR: truncated')"]
        self.segment = None

    def flush(self) -> None:
        run, self.run = self.run, []
        targets = [t for _, t in run if t]
        if not targets:
            return
        st = self.consts.struct(_strip("<" + "".join(code for code, _ in run)))
        lhs = ", ".join(targets) + ("," if len(targets) == 1 else "")
        self.lines.append(f"{lhs} = {st}.unpack_from({self.buf}, {self.at(self.run_delta)})")
        self.lines.extend(self.after)
        self.after = []

    def dynamic(self) -> str:
        """Fold the static offset into the offset local (created on first use); returns the local."""
        if self.var is None:
            self.var = self.names.new("offset")
            self.lines.append(f"{self.var} = {self.delta}")
        elif self.delta:
            self.lines.append(f"{self.var} += {self.delta}")
        self.delta = 0
        return self.var

    def align(self, size: int) -> None:
        align = min(size, 8)
        pad = self.phase.pad(align)
        if pad is None:
            self.close_segment()
            off = self.dynamic()
            self.lines.append(f"{off} += -{off} & {align - 1}")
            self.phase.unknown(align)
            self.open_segment()
        elif pad:
            if self.run:
                self.run.append(("x" * pad, None))
            self.delta += pad
            self.phase.advance(pad)

    def item(self, code: str, size: int, target: str | None) -> None:
        if not self.run:
            self.run_delta = self.delta
        self.run.append((code if target else "x" * size, target))
        self.delta += size
        self.phase.advance(size)

    def want(self, path: Path, hint: str | None = None) -> str | None:
        if path not in self.wanted:
            return None
        name = self.names.new(hint or "_".join(str(p) for seg in path for p in seg if p is not None))
        self.found[path] = name
        return name

    # -- layout
    def read(self, leaves: list[_Leaf]) -> None:
        for leaf in leaves:
            getattr(self, f"read_{leaf.kind}")(leaf)

    def read_prim(self, leaf: _Leaf) -> None:
        code, size = _PRIM[leaf.base]
        self.align(size)
        self.item(code, size, self.want(leaf.path))

    def read_block(self, leaf: _Leaf) -> None:
        code, size = _PRIM[leaf.base]
        self.align(size)
        whole = self.want(leaf.path, leaf.path[-1][0])
        if whole is None:
            for i in range(leaf.count):
                self.item(code, size, self.want(_elem_path(leaf.path, i)))
            return
        elements = []
        for i in range(leaf.count):
            element = self.found.get(_elem_path(leaf.path, i)) or self.want(_elem_path(leaf.path, i)) \
                or self.names.new(f"{leaf.path[-1][0]}_{i}")
            elements.append(element)
            self.item("B" if leaf.base == "byte" else code, size, element)  # whole byte arrays: ints
        self.after.append(f"{whole} = [{', '.join(elements)}]")
        if leaf.base == "byte":  # an element read alone is a 1-byte bytes object, as rclpy gives it
            for i in range(leaf.count):
                path = _elem_path(leaf.path, i)
                if path in self.found:
                    self.after.append(f"{self.found[path]} = bytes(({self.found[path]},))")

    def count(self, leaf: _Leaf, hint: str) -> str:
        """Read a uint32 length/count, end the segment there; returns the local (the offset is past it)."""
        self.align(4)
        local = self.names.new(hint)
        self.item("I", 4, local)
        self.close_segment()
        if leaf.bound is not None:
            limit = leaf.bound + 1 if leaf.kind == "string" else leaf.bound
            self.lines += [f"if {local} > {limit}:", f"    raise WireError('CDR: {leaf.kind} bound exceeded')"]
        self.dynamic()
        return local

    def read_string(self, leaf: _Leaf) -> None:
        length = self.count(leaf, "length")
        off, buf = self.dynamic(), self.buf
        target = self.want(leaf.path, leaf.path[-1][0] if leaf.path[-1][1] is None else None)
        self.lines += [
            f"if {length} and ({self.size} < {off} + 4 + {length} or {buf}[{off} + 3 + {length}] != 0):",
            "    raise WireError('CDR: string beyond the buffer or without its NUL')",
        ]
        if target is not None:  # rclpy ends a string at its first NUL
            text = f"bytes({buf}[{off} + 4:{off} + 3 + {length}]).partition(b'\\0')[0]"
            self.lines.append(f"{target} = str({text}, 'utf-8', 'replace') if {length} else ''")
        self.lines.append(f"{off} += {length}")
        self.phase.unknown()
        self.open_segment()

    def read_seq(self, leaf: _Leaf) -> None:
        count = self.count(leaf, "count")
        code, size = _PRIM[leaf.base]
        off, buf = self.dynamic(), self.buf
        pad = self.phase.pad(size)  # 8-byte elements: aligned only when there are some (Fast CDR)
        if pad is None:
            self.lines.append(f"if {count}:")
            self.lines.append(f"    {off} += -{off} & {size - 1}")
        elif pad:
            self.lines.append(f"if {count}:")
            self.lines.append(f"    {off} += {pad}")
        nbytes = f"{count} * {size}" if size > 1 else count
        self.lines += [f"if {self.size} < {off} + 4 + {nbytes}:",
                       "    raise WireError('CDR: sequence beyond the buffer')"]
        target = self.want(leaf.path, leaf.path[-1][0])
        if target is not None:
            start, end = f"{off} + 4", f"{off} + 4 + {nbytes}"
            if leaf.base in ("uint8", "char", "byte"):
                self.lines.append(f"{target} = list({buf}[{start}:{end}])")
            elif leaf.base == "bool":
                self.lines.append(f"{target} = [x != 0 for x in {buf}[{start}:{end}]]")
            else:
                self.lines.append(f"{target} = list(_struct.unpack_from(f'<{{{count}}}{code}', {buf}, {start}))")
        self.lines.append(f"{off} += {nbytes}")
        self.phase.unknown(min(size, 4))
        self.open_segment()

    def read_msgseq(self, leaf: _Leaf) -> None:
        """A sequence of messages (or strings) is checked and skipped element by element: nothing reads into one."""
        if any(p[:len(leaf.path)] == leaf.path for p in self.wanted):
            raise NotImplementedError(f"{leaf.path}: reading into a sequence of messages")
        count = self.count(leaf, "count")
        off = self.dynamic()
        inner = _Reader(self.lookup, self.names, self.consts, self.buf, set(), self.size, off)
        inner.phase = _Phase(1, 0)  # an element starts wherever the one before ended
        inner.open_segment()
        if leaf.message is None:
            inner.read_string(_Leaf("string", leaf.path))
        else:
            inner.read(_flatten(leaf.message, self.lookup))
        inner.close_segment()
        inner.dynamic()
        self.lines.append(f"for _ in range({count}):")
        self.lines.extend("    " + line for line in inner.lines or ["pass"])
        self.phase.unknown()
        self.open_segment()


def cdr_reader(message: RosMessage, wanted: Iterable[Path], lookup: Callable[[str], RosMessage | None],
               names: Names, consts: Constants, buf: str) -> tuple[list[str], dict[Path, str]]:
    """Statements that check the CDR bytes in `buf` and decode the `wanted` leaves; (lines, path -> local)."""
    wanted = set(wanted)
    r = _Reader(lookup, names, consts, buf, wanted, names.new("size"))
    r.lines += [f"{r.size} = len({buf})",
                f"if {r.size} < 4 or {buf}[0] != 0 or {buf}[1] != 1:",
                "    raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')"]
    r.open_segment()
    r.read(_flatten(message, lookup))
    r.close_segment()
    missing = wanted - set(r.found)
    if missing:
        raise ValueError(f"{message.full_name}: no field at {sorted(map(str, missing))}")
    return prune(r.lines, r.found.values()), r.found
