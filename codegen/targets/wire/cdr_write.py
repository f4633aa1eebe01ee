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
  (It lives in code.py with ``literal_value``, ``NO_VALUE``, ``wrap_line`` and ``prune``; all re-exported here.)
- ``cdr_writer(message, values, lookup, names, consts)`` -> ``(lines, expr)``: statements and the final expression
  of the CDR bytes (header included). ``values`` maps leaf paths to Python expressions; a whole-array path takes a
  list expression (``byte`` arrays: a list of 1-byte ``bytes``, as rclpy keeps them), a string path a ``str``
  expression; a sequence of messages a list of records, tuples of the element's leaves in ``flatten`` order (prim and
  string leaves only; cdr_reader reads a sequence of messages wanted at its own path into the same records).
  A leaf without a value gets the field's default, as the ROS message class has it (``ros_default``).
  Literal expressions (``py_literal``: numbers, strings, True/False, ``_NAN``, ``_INF``) are packed at generation
  time. A frame id (``consts.frame_id(frame)``: the spec's, after the run's frame prefix) is the CDR string the
  module's ``bind(frame_prefix)`` makes, packed in the struct around it; that struct's format (its length) and the
  padding after it, which depends on the prefix's length modulo 8, are made by ``bind`` too: per message the code
  is the same as for a literal.
- ``cdr_reader(message, wanted, lookup, names, consts, buf)`` -> ``(lines, locals)``: statements that check the CDR
  in ``buf`` (bytes or memoryview, header included) and decode the leaves in ``wanted`` into locals: numbers,
  bools, 1-byte ``bytes`` for a ``byte`` scalar, ``str`` for strings, lists for whole arrays (``byte`` arrays as
  ints). They raise ``WireError`` (a name the generated module defines) on a wrong header, truncated data, a
  string without its NUL, a length beyond the buffer or a bound exceeded: never another exception.
- ``lookup(full_name) -> RosMessage`` resolves nested types (``Resolved.ros.get``, external ones included);
  ``names.new(hint)`` gives a fresh local (targets.python.names.LocalNames).

The generated code needs, in its module, ``import struct as _struct``, ``from array import array as _array``, the
``WireError`` class and ``_ZEROS`` (zero bytes, at least 8: ``MODULE_PRELUDE``).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from sam_codegen.model.spec import Field, RosMessage  # noqa: F401  (Field, RosType: for the doctests, which run in this namespace)
from sam_codegen.model.types import RosType  # noqa: F401
from sam_codegen.targets.wire.cdr_layout import (
    ARRAY_CODE,
    HEADER,
    MODULE_PRELUDE,
    PRIM,
    Leaf,
    Phase,
    elem_path,
    flatten,
    ros_default,
    strip_pads,
)
from sam_codegen.targets.wire.cdr_read import cdr_reader
from sam_codegen.targets.wire.code import (
    LINE_LIMIT,
    NO_VALUE,
    Constants,
    FieldPath,
    Names,
    literal_value,
    prune,
    wrap_line,
)

# Constants, literal_value, NO_VALUE, Names, FieldPath, wrap_line and prune live in code.py, ros_default and
# MODULE_PRELUDE in cdr_layout, cdr_reader in cdr_read; re-exported here (API).
__all__ = [
    "LINE_LIMIT",
    "MODULE_PRELUDE",
    "NO_VALUE",
    "Constants",
    "FieldPath",
    "Names",
    "cdr_reader",
    "cdr_writer",
    "literal_value",
    "prune",
    "ros_default",
    "wrap_line",
]


# The frame prefix's length modulo 8: what the CDR padding after a frame id depends on.
VARIANTS = 8
_PADS = "pads"  # a _Run item: padding by variant
_FRAME = "{}s"  # a _Run item: a frame id's CDR string, its length given when the struct is made


# ---- writer --------------------------------------------------------------------------------------------------


@dataclass
class _Run:
    """A run of fixed-layout items packed by one struct: (code, expression or None for pad, literal value)."""

    items: list[tuple[str, str | None, Any]] = field(default_factory=list)

    def add(self, code: str, expr: str, value: Any = NO_VALUE) -> None:
        self.items.append((code, expr, value))

    def pad(self, n: int) -> None:
        self.items.append(("x" * n, None, NO_VALUE))

    def pads(self, by_variant: tuple[int, ...]) -> None:
        """Padding that depends on the frame prefix's length: `by_variant[len % 8]` bytes."""
        self.items.append((_PADS, None, by_variant))

    def frame(self, name: str) -> None:
        """A frame id's CDR string (the bound bytes constant `name`): its length is known once bound."""
        self.items.append((_FRAME, name, NO_VALUE))

    @property
    def bound(self) -> bool:
        """Whether the struct depends on the frame prefix (a frame id in it, or padding after one)."""
        return any(code in (_PADS, _FRAME) for code, _, _ in self.items)

    def packed(self, consts: Constants, variant: int = 0) -> tuple[str, list[str], bytes | None]:
        """(struct format, arguments, or the bytes when every value is a literal); consecutive literals are
        packed here, at generation time, into one `Ns` argument (zeros into pad bytes). Padding that depends on the
        frame prefix is that of `variant` (the prefix's length % 8); it ends a literal chunk, so the arguments are
        the same for every variant and only the format differs."""
        if all(expr is None or value is not NO_VALUE for _, expr, value in self.items):  # literals only
            items = [("x" * value[variant], NO_VALUE) if code == _PADS else (code, value)
                     for code, _, value in self.items]
            fmt = "<" + "".join(code for code, _ in items)
            return fmt, [], struct.pack(fmt, *[v for _, v in items if v is not NO_VALUE])
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
            if code == _PADS:
                close()
                codes.append("x" * value[variant])
                continue
            if expr is None or value is not NO_VALUE:
                chunk.append((code, value))
                continue
            close()
            codes.append(code)
            args.append(expr)
        close()
        return strip_pads("<" + "".join(codes)), args, None


class _Writer:
    def __init__(self, lookup: Callable[[str], RosMessage | None], names: Names, consts: Constants,
                 values: dict[FieldPath, str]) -> None:
        self.lookup, self.names, self.consts, self.values = lookup, names, consts, values
        self.used: set[FieldPath] = set()
        # what is known of the offset, for each length of the frame prefix modulo 8 (VARIANTS): the same until a
        # frame id is written, then shifted by that length (static padding becomes padding by variant)
        self.phases = [Phase() for _ in range(VARIANTS)]
        self.run = _Run()
        self.lines: list[str] = []
        self.parts: list[str] = []  # expressions appended to the output so far (before `buf` exists)
        self.buf: str | None = None  # the bytearray local, once something needs the length so far

    # -- values
    def value(self, path: FieldPath, default: Any) -> tuple[str, Any]:
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
        if run.bound:  # a frame id or padding after one: the struct (or bytes) bind(frame_prefix) makes
            variants = [run.packed(self.consts, v) for v in range(VARIANTS)]
            fmt, args, data = variants[0]
            assert all(a == args for _, a, _ in variants)
            if data is not None:
                self.emit(self.consts.bound_data([d for _, _, d in variants if d is not None]))
            else:
                frames = [expr for code, expr, _ in run.items if code == _FRAME and expr is not None]
                name = self.consts.bound_struct([f for f, _, _ in variants], frames)
                self.emit(f"{name}.pack({', '.join(args)})")
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
        """Padding before an item of `size` bytes: static when the phase allows (by variant after a frame id),
        else computed at run time."""
        align = min(size, 8)
        pads = [phase.pad(align) for phase in self.phases]
        if pads[0] is None:  # (the variants differ in `rem` only: all None or none)
            buf = self.need_buffer()
            self.lines.append(f"{buf} += _ZEROS[:(4 - len({buf})) & {align - 1}]")
            self.unknown(align)
            return
        if len(set(pads)) > 1:
            self.run.pads(tuple(p or 0 for p in pads))
        elif pads[0]:
            self.run.pad(pads[0])
        for phase, pad in zip(self.phases, pads, strict=True):
            phase.advance(pad or 0)

    def advance(self, size: int) -> None:
        for phase in self.phases:
            phase.advance(size)

    def unknown(self, mod: int = 1) -> None:
        for phase in self.phases:
            phase.unknown(mod)

    def static_pad(self, align: int) -> int | None:
        """The padding before an item of alignment `align` when it is the same for every variant, else None."""
        pads = {phase.pad(align) for phase in self.phases}
        return pads.pop() if len(pads) == 1 else None

    # -- layout
    def write(self, leaves: list[Leaf]) -> None:
        for leaf in leaves:
            getattr(self, f"write_{leaf.kind}")(leaf)

    def write_prim(self, leaf: Leaf) -> None:
        code, size = PRIM[leaf.base]
        self.align(size)
        expr, value = self.value(leaf.path, leaf.default)
        self.run.add(code, expr, value)
        self.advance(size)

    def write_block(self, leaf: Leaf) -> None:
        code, size = PRIM[leaf.base]
        self.align(size)
        whole = self.values.get(leaf.path)
        if whole is not None:
            self.used.add(leaf.path)
            self.run.add(f"{leaf.count}{code}", f"*{whole}")
        else:
            for i in range(leaf.count):
                expr, value = self.value(elem_path(leaf.path, i), leaf.default)
                self.run.add(code, expr, value)
        self.advance(size * leaf.count)

    def write_string(self, leaf: Leaf) -> None:
        self.align(4)
        expr, value = self.value(leaf.path, leaf.default)
        if value is not NO_VALUE:
            data = str(value).encode().partition(b"\0")[0] + b"\0"  # rclpy ends a string at its first NUL
            self.run.add("I", str(len(data)), len(data))
            self.run.add(f"{len(data)}s", repr(data), data)
            self.advance(4 + len(data))
            return
        frame = self.consts.frame_of(expr)
        if frame is not None:  # the frame prefix, then the spec's frame id: bytes bind(frame_prefix) computes,
            self.run.frame(self.consts.framed_string(frame))  # packed with what is around it as one struct
            size = 4 + len(frame.encode()) + 1
            for variant, phase in enumerate(self.phases):
                phase.advance(size + variant)
            return
        self.flush()
        text = self.names.new("text")
        self.lines.append(f"{text} = {expr}.encode().partition(b'\\0')[0]")
        self.emit(f"{self.consts.struct('<I')}.pack(len({text}) + 1) + {text} + b'\\0'")
        self.unknown()

    def write_seq(self, leaf: Leaf) -> None:
        self.align(4)
        expr = self.values.get(leaf.path)
        if expr is None:
            self.run.add("I", "0", 0)
            self.advance(4)
            return
        self.used.add(leaf.path)
        self.flush()
        seq = self.names.new(leaf.path[-1][0])
        self.lines.append(f"{seq} = {expr}")
        self.emit(f"{self.consts.struct('<I')}.pack(len({seq}))")
        self.advance(4)
        size = PRIM[leaf.base][1]
        pad = self.static_pad(size)
        if pad != 0:  # 8-byte elements after the count; Fast CDR aligns them only when there are some
            buf = self.need_buffer()
            fill = f"_ZEROS[:{pad}]" if pad is not None else f"_ZEROS[:(4 - len({buf})) & {size - 1}]"
            self.lines += [f"if {seq}:", f"    {buf} += {fill}"]
        if leaf.base == "byte":
            self.emit(f"b''.join({seq})")
        elif leaf.base in ("bool", "uint8", "char"):
            self.emit(f"bytes({seq})")
        else:
            self.consts.imports.add("array")
            self.emit(f"_array({ARRAY_CODE[leaf.base]!r}, {seq}).tobytes()")
        self.unknown(min(size, 4))

    def write_msgseq(self, leaf: Leaf) -> None:
        """Empty, or from a list of records (tuples of the element's leaves in `flatten` order, prim and string
        leaves only), each element written as a message at the offset the one before it ends."""
        expr = self.values.get(leaf.path)
        self.align(4)
        if expr is None:
            self.run.add("I", "0", 0)
            self.advance(4)
            return
        if leaf.message is None:
            raise NotImplementedError(f"{leaf.path}: a sequence of strings is written empty only")
        leaves = flatten(leaf.message, self.lookup)
        if any(x.kind not in ("prim", "string") for x in leaves):
            raise NotImplementedError(f"{leaf.path}: a sequence of messages that hold arrays is written empty only")
        self.used.add(leaf.path)
        self.flush()
        seq, record = self.names.new(leaf.path[-1][0]), self.names.new("record")
        self.lines.append(f"{seq} = {expr}")
        self.emit(f"{self.consts.struct('<I')}.pack(len({seq}))")
        buf = self.need_buffer()
        inner = _Writer(self.lookup, self.names, self.consts,
                        {x.path: f"{record}[{i}]" for i, x in enumerate(leaves)})
        inner.buf = buf
        inner.unknown()  # an element starts wherever the one before ended
        inner.write(leaves)
        inner.flush()
        self.lines.append(f"for {record} in {seq}:")
        self.lines.extend("    " + line for line in inner.lines)
        self.unknown()


def _lit(value: float) -> str:
    return "_NAN" if math.isnan(value) else "_INF" if value > 0 else "-_INF"


def cdr_writer(message: RosMessage, values: dict[FieldPath, str], lookup: Callable[[str], RosMessage | None],
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
    leaves = flatten(message, lookup)
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
