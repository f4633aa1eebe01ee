"""Straight-line Python that writes a UAVCAN v0 (DroneCAN) payload from the values of a message: the writer half of
the v0 codecs (see v0_read for the layout; TAO on, classic CAN).

The bytes are dronecan's, bit for bit (``Transfer(payload=obj).payload`` of the object with the same values): its
cast on assignment included (a saturated float becomes +-max beyond its range, infinities included; a truncated
float beyond its range becomes infinite; a truncated integer keeps its low bits), its own float-to-half conversion
(``f16_from_f32``: not struct's rounding) and zero bits for every field left at its default (padding, a dynamic array
left empty, a union at its first field). The converters have already brought every integer into its field's range.

Runs of fields of byte-multiple widths that start on a byte boundary are packed by one ``struct`` call; the other
fields are shifted into an integer (its bits are the stream, MSB first) that becomes bytes once the stream is back
on a byte boundary, or at the end.

API (used by codec_v0)
---------------------------
- ``V0Node(fields)``: a composite's values, field name -> expression (a list expression for a whole array),
  ``V0Node`` or ``V0Items``; ``V0Items(items)``: an array's elements one by one (their number known at generation
  time), each an expression, a ``V0Node`` or None for the element's default. Fields not given are default. A
  dynamic array of composites may be a list expression of records (tuples of the element's fields, as v0_read gives
  them) when ``record_fields`` allows it (every field a scalar number of byte-multiple width: struct packs them) or
  ``record_bit_fields`` does (any scalars, void padding and composites of them, nested tuples in the record: shifted
  in as stream bits).
- ``v0_writer(struct, node, layout, consts)`` -> ``(lines, expr)``: statements and the expression of the payload.
- ``HELPERS``: the source of the helpers the generated code calls (``_f16``, ``_f16t``, ``_clamp``, ``_trunc``).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import Any

from sam_codegen.model.spec import V0Struct
from sam_codegen.model.types import DsdlType
from sam_codegen.targets.wire.code import NO_VALUE as _NO
from sam_codegen.targets.wire.code import Constants, literal_value, runs_of
from sam_codegen.targets.wire.v0_layout import V0Layout, length_bits, merge_pads, struct_code, tag_bits

__all__ = ["HELPERS", "V0Items", "V0Node", "f16_bits", "record_bit_fields", "record_fields", "v0_writer"]

FLOAT_MAX = {16: 65504.0, 32: 3.40282346638528859812e38, 64: 1.79769313486231570815e308}  # dronecan's ranges

HELPERS = '''
_F32 = _struct.Struct("<f")
_U32 = _struct.Struct("<I")


def _f16(x: float) -> int:
    """The float16 bits dronecan writes for a saturated float16 field (its cast, then its f16_from_f32)."""
    if x > 65504.0:
        x = 65504.0
    elif x < -65504.0:
        x = -65504.0
    return _half(x)


def _f16t(x: float) -> int:
    """The float16 bits dronecan writes for a truncated float16 field (beyond the range: infinite)."""
    if x > 65504.0:
        x = _INF
    elif x < -65504.0:
        x = -_INF
    return _half(x)


def _half(x: float) -> int:
    # dronecan's f16_from_f32 (libuavcan's): float32 first, the low 12 bits dropped, half an ulp added.
    u = _U32.unpack(_F32.pack(x))[0]
    sign = u >> 16 & 0x8000
    u &= 0x7FFFFFFF
    if u >= 0x7F800000:
        return (0x7FFF if u > 0x7F800000 else 0x7C00) | sign
    u &= 0xFFFFF000
    if u >= 0x38800000:  # the product by 2**-112 is a normal float32: exact
        u -= 0x37FFF000
        return (0x7C00 if u > 0x0F800000 else u >> 13) | sign
    u = _U32.unpack(_F32.pack(_F32.unpack(_U32.pack(u))[0] * 2.0**-112))[0] + 0x1000
    return u >> 13 | sign


def _clamp(x: float, m: float) -> float:
    """dronecan's saturated cast of a float: beyond +-m (infinities too) -> +-m; NaN stays."""
    return m if x > m else -m if x < -m else x


def _trunc(x: float, m: float) -> float:
    """dronecan's truncated cast of a float: beyond +-m -> +-inf; NaN stays."""
    return _INF if x > m else -_INF if x < -m else x
'''


def f16_bits(x: float, truncated: bool = False) -> int:
    """The float16 bits dronecan writes for `x` (generation time: literals); the same as HELPERS' _f16 / _f16t.

    >>> hex(f16_bits(1.0)), hex(f16_bits(math.inf)), hex(f16_bits(math.inf, True)), hex(f16_bits(-0.0))
    ('0x3c00', '0x7bff', '0x7c00', '0x8000')
    """
    namespace: dict[str, Any] = {"_struct": struct, "_INF": math.inf}
    exec(HELPERS, namespace)  # the generated helpers themselves
    return int(namespace["_f16t" if truncated else "_f16"](float(x)))


@dataclass
class V0Node:
    fields: dict[str, Any] = field(default_factory=dict)


@dataclass
class V0Items:
    items: list[Any] = field(default_factory=list)


@dataclass
class _Atom:
    t: DsdlType  # element type (primitive or void)
    expr: str | None  # None: zero (default, padding)
    count: int = 0  # > 0: a fixed array of `count` from the list expression `expr` (or zeros)

    @property
    def bits(self) -> int:
        return self.t.bits * max(self.count, 1)


@dataclass
class _List:
    """A dynamic array of primitives from a list expression, its length known at run time only."""

    t: DsdlType  # element type
    expr: str
    prefix: int  # length prefix bits (0: tail array)
    record: tuple[DsdlType, ...] = ()  # composite elements: records, the types of their fields (see record_fields)
    # composite elements of bit fields: every scalar's type and where the record holds it (see record_bit_fields)
    bit_record: tuple[tuple[DsdlType, str | None], ...] = ()

    @property
    def bits(self) -> int:
        if self.bit_record:
            return sum(t.bits for t, _ in self.bit_record)
        return sum(t.bits for t in self.record) if self.record else self.t.bits


def record_fields(layout: V0Layout, t: DsdlType) -> tuple[DsdlType, ...] | None:
    """The field types of a composite element written from a record (a tuple of its fields, as v0_read gives them):
    when every field is a scalar number of byte-multiple width (one struct code per field), else None."""
    if t.kind != "composite":
        return None
    s = layout.struct(t)
    types = tuple(f.type for f in s.declared_fields)
    if s.union or not types or any(
            not isinstance(x, DsdlType) or x.array or x.kind not in ("int", "uint", "float") or struct_code(x) is None
            or not f.name for x, f in zip(types, s.declared_fields, strict=True)):
        return None
    return types  # type: ignore[return-value]


def record_bit_fields(layout: V0Layout, t: DsdlType, at: str = "") -> tuple[tuple[DsdlType, str | None], ...] | None:
    """The scalar fields of a composite element written from a record as stream bits, in wire order: when every field
    is a scalar (a bool, an integer of any width, a float), void padding or a composite of such fields (no arrays, no
    unions), each scalar's type and where the record holds it (`[2][0]`: a nested composite is a tuple in its
    record; None: padding, not in the record); else None."""
    if t.kind != "composite":
        return None
    s = layout.struct(t)
    if s.union:
        return None
    out: list[tuple[DsdlType, str | None]] = []
    position = 0
    for f in s.declared_fields:
        x = f.type
        if not isinstance(x, DsdlType) or x.array or x.kind not in ("bool", "int", "uint", "float", "void",
                                                                    "composite"):
            return None
        if x.kind == "composite":
            nested = record_bit_fields(layout, x, f"{at}[{position}]")
            if nested is None:
                return None
            out.extend(nested)
        else:
            out.append((x, f"{at}[{position}]" if f.name else None))
        position += bool(f.name)
    return tuple(out) if out else None


def _flatten(layout: V0Layout, t: DsdlType, value: Any, tao: bool, out: list[_Atom | _List]) -> None:
    if t.array == "fixed":
        elem, n = t.element, t.capacity or 0
        if elem.kind != "composite" and not isinstance(value, V0Items):
            out.append(_Atom(elem, value, n))
            return
        items = value.items if isinstance(value, V0Items) else [None] * n
        for i in range(n):
            _flatten(layout, elem, items[i] if i < len(items) else None, tao and i == n - 1, out)
        return
    if t.array:
        tao_mode = layout.tao_mode(t, tao)
        prefix = 0 if tao_mode else length_bits(t.capacity or 0)
        if isinstance(value, str):
            record: tuple[DsdlType, ...] = ()
            bit_record: tuple[tuple[DsdlType, str | None], ...] = ()
            if t.element.kind == "composite":
                found = record_fields(layout, t.element)
                bits_found = record_bit_fields(layout, t.element) if found is None else None
                if found is None and bits_found is None:
                    raise NotImplementedError(f"{t}: an array of composites of other than scalar fields")
                record, bit_record = found or (), bits_found or ()
            out.append(_List(t.element, value, prefix, record, bit_record))
            return
        items = value.items if isinstance(value, V0Items) else []
        if prefix:
            out.append(_Atom(DsdlType("uint", prefix), str(len(items)) if items else None))
        for i, item in enumerate(items):
            _flatten(layout, t.element, item, not tao_mode and tao and i == len(items) - 1, out)
        return
    if t.kind == "composite":
        s = layout.struct(t)
        fields = s.declared_fields
        if s.union:  # unions cannot be mapped: the first field, at its default
            if value is not None:
                raise NotImplementedError(f"{s.name}: writing a union")
            out.append(_Atom(DsdlType("uint", max(tag_bits(len(fields)), 1)), None))
            if fields:
                _flatten(layout, fields[0].type, None, tao, out)  # type: ignore[arg-type]
            return
        given = value.fields if isinstance(value, V0Node) else {}
        for i, f in enumerate(fields):
            _flatten(layout, f.type, given.get(f.name) if f.name else None,  # type: ignore[arg-type]
                     tao and i == len(fields) - 1, out)
        return
    out.append(_Atom(t, value if t.kind != "void" else None))


def _is_name(expr: str) -> bool:
    return expr.isidentifier()


class _Writer:
    def __init__(self, consts: Constants) -> None:
        self.consts = consts
        self.lines: list[str] = []
        self.parts: list[str | bytes] = []  # bytes expressions (or bytes known now), in order
        self.acc = False  # bits are pending in `_a` (then `nb` counts them)
        self.nb_dyn = False  # the count is `_nb + nb`
        self.nb = 0
        self.temps = 0

    def temp(self) -> str:
        self.temps += 1
        return f"_v{self.temps}"

    def name(self, expr: str) -> str:
        """The expression as a name or literal (bound to a temporary when it is more than that)."""
        if _is_name(expr) or literal_value(expr) is not _NO:
            return expr
        local = self.temp()
        self.lines.append(f"{local} = {expr}")
        return local

    # -- values
    def cast_float(self, t: DsdlType, x: str) -> str:
        """dronecan's cast of a float32/64 value (struct packs it next)."""
        m = FLOAT_MAX[t.bits]
        value = literal_value(x)
        if value is not _NO:
            v = float(value)
            if t.truncated:
                v = math.inf if v > m else -math.inf if v < -m else v
            else:
                v = m if v > m else -m if v < -m else v
            return repr(v) if math.isfinite(v) else ("_INF" if v > 0 else "-_INF" if v < 0 else "_NAN")
        if t.truncated:
            return f"_trunc({x}, {m!r})"
        x = self.name(x)
        return f"({x} if {-m!r} <= {x} <= {m!r} else _clamp({x}, {m!r}))"

    def struct_arg(self, t: DsdlType, x: str) -> str:
        """The struct argument of a scalar of byte-multiple width (its code from struct_write_code)."""
        if t.kind == "float":
            if t.bits == 16:
                value = literal_value(x)
                if value is not _NO:
                    return hex(f16_bits(value, t.truncated))
                return f"{'_f16t' if t.truncated else '_f16'}({x})"
            return self.cast_float(t, x)
        mask = (1 << t.bits) - 1
        value = literal_value(x)
        if value is not _NO and struct_code(t) and struct_code(t).endswith("s"):  # type: ignore[union-attr]
            return repr((int(value) & mask).to_bytes(t.bits // 8, "little"))
        if struct_code(t).endswith("s"):  # type: ignore[union-attr]
            return f"({x} & {hex(mask)}).to_bytes({t.bits // 8}, 'little')"
        if t.truncated and t.kind == "uint":
            return f"{x} & {hex(mask)}"
        return x

    def unsigned(self, t: DsdlType, x: str) -> str:
        """The bits of a scalar (bool, integer, float16) as an unsigned integer of t.bits bits."""
        if t.kind == "bool":
            value = literal_value(x)
            return ("1" if value else "0") if value is not _NO else f"(1 if {x} else 0)"
        if t.kind == "float":
            return self.struct_arg(t, x)
        value = literal_value(x)
        if value is not _NO:
            return hex(int(value) & ((1 << t.bits) - 1))
        return f"{x} & {hex((1 << t.bits) - 1)}"

    def stream_bits(self, t: DsdlType, x: str) -> str:
        """The stream bits (MSB first) of a bool, integer or float16 scalar: its bytes from the low end."""
        v = self.unsigned(t, x)
        if t.bits <= 8:
            return v
        value = literal_value(v)
        if value is not _NO:
            n = int(value)
            return hex(_reorder(n, t.bits))
        v = self.name(v) if not _is_name(v) else v
        m = (t.bits + 7) // 8
        terms = []
        for i in range(m):
            if i < m - 1:
                part = f"{v} >> {8 * i} & 0xff" if i else f"{v} & 0xff"
                terms.append(f"({part}) << {t.bits - 8 * (i + 1)}")
            else:
                terms.append(f"{v} >> {8 * i}")
        bits = self.temp()  # (a name: the terms that hold it stay flat)
        self.lines.append(f"{bits} = {' | '.join(terms)}")
        return bits

    # -- static runs
    def pieces(self, atoms: list[_Atom]) -> list[tuple[str, Any, int]]:
        """("struct", (codes, args), bits) for runs of byte-multiple fields, ("bits", expr or None, bits) else."""
        out: list[tuple[str, Any, int]] = []
        for a in atoms:
            code = struct_code(a.t)
            if code is not None and a.t.kind != "bool":
                if a.expr is None:
                    codes, args = [f"{a.bits // 8}x"], []
                elif a.count:
                    write_code = "H" if a.t.kind == "float" and a.t.bits == 16 else code
                    codes, args = [f"{a.count}{write_code}"], [self.list_arg(a.t, a.expr)]
                else:
                    codes = ["H" if a.t.kind == "float" and a.t.bits == 16 else code]
                    args = [self.struct_arg(a.t, a.expr)]
                if out and out[-1][0] == "struct":
                    prev = out[-1]
                    out[-1] = ("struct", (prev[1][0] + codes, prev[1][1] + args), prev[2] + a.bits)
                else:
                    out.append(("struct", (codes, args), a.bits))
            elif a.expr is None:
                out.append(("bits", None, a.bits))
            elif a.count:
                items = self.name(a.expr)
                for i in range(a.count):
                    out.append(("bits", self.stream_bits(a.t, f"{items}[{i}]"), a.t.bits))
            else:
                out.append(("bits", self.stream_bits(a.t, a.expr), a.bits))
        return out

    def list_arg(self, t: DsdlType, expr: str) -> str:
        """A struct argument list (starred) for the elements of a list expression."""
        if t.kind == "float" and t.bits == 16:
            return f"*[{'_f16t' if t.truncated else '_f16'}(x) for x in {expr}]"
        if t.kind == "float":
            return f"*[{self.cast_float(t, 'x')} for x in {expr}]"
        if struct_code(t).endswith("s"):  # type: ignore[union-attr]
            mask = hex((1 << t.bits) - 1)
            return f"*[(x & {mask}).to_bytes({t.bits // 8}, 'little') for x in {expr}]"
        if t.truncated and t.kind == "uint":
            return f"*[x & {hex((1 << t.bits) - 1)} for x in {expr}]"
        return f"*{expr}"

    def packed(self, codes: list[str], args: list[str]) -> str | bytes:
        """The struct call of a run of byte-multiple fields (its bytes when every value is known now)."""
        fmt = merge_pads("<" + "".join(codes))
        values = [literal_value(a) for a in args]
        if all(v is not _NO for v in values):
            return struct.pack(fmt, *values)
        args = [a[1:-1] if a.startswith("(") and a.endswith(")") and _balanced(a[1:-1]) else a for a in args]
        return f"{self.consts.struct(fmt)}.pack({', '.join(args)})"

    def as_expr(self, part: str | bytes) -> str:
        return self.consts.data(part) if isinstance(part, bytes) else part

    def run(self, atoms: list[_Atom]) -> None:
        pieces = self.pieces(atoms)
        if self.acc:
            self.shift_in(pieces)
            return
        phase = 0
        group: list[tuple[str, Any, int]] = []  # bits (and misaligned structs) since the last byte boundary
        for kind, value, bits in pieces:
            if kind == "struct" and phase == 0 and not group:
                self.parts.append(self.packed(*value))
            else:
                group.append((kind, value, bits))
            phase = (phase + bits) % 8
            if phase == 0 and group:
                total = sum(b for _, _, b in group)
                expr = self.combine(group)
                value = literal_value(expr)
                if value is _NO:
                    local = expr if expr.isidentifier() else self.temp()
                    if local != expr:
                        self.lines.append(f"{local} = {expr}")
                    self.parts.append(f"{local}.to_bytes({total // 8}, 'big')")
                else:
                    self.parts.append(int(value).to_bytes(total // 8, "big"))
                group = []
        if group:  # the run ends off a byte boundary: on in bits
            self.acc = True
            self.lines.append(f"_a = {self.combine(group)}")
            self.nb = sum(b for _, _, b in group)

    def combine(self, pieces: list[tuple[str, Any, int]]) -> str:
        """One integer of the pieces' stream bits."""
        total = sum(b for _, _, b in pieces)
        terms, end, constant = [], total, 0
        for kind, value, bits in pieces:
            end -= bits
            if kind == "struct":
                data = self.packed(*value)
                term = hex(int.from_bytes(data, "big")) if isinstance(data, bytes) else \
                    f"int.from_bytes({data}, 'big')"
            elif value is None:
                continue
            else:
                term = value
            value = literal_value(term)
            if value is not _NO:
                constant |= int(value) << end
                continue
            simple = term.isidentifier() or (term.startswith("(") and term.endswith(")") and _balanced(term[1:-1]))
            terms.append(term if not end else f"{term} << {end}" if simple else f"({term}) << {end}")
        if constant:
            terms.append(hex(constant))
        return " | ".join(terms) if terms else "0"

    def shift_in(self, pieces: list[tuple[str, Any, int]]) -> None:
        bits = sum(b for _, _, b in pieces)
        expr = self.combine(pieces)
        self.lines.append(f"_a = _a << {bits} | {expr}" if expr != "0" else f"_a <<= {bits}")
        self.nb += bits

    # -- dynamic arrays
    def dyn_list(self, d: _List) -> None:
        t = d.t
        items = self.name(d.expr)
        code = struct_code(t) if t.kind != "bool" else None
        if d.record:  # records of byte-multiple numbers: their bytes are their stream bits
            code = "record"
            codes = "".join("H" if x.kind == "float" and x.bits == 16 else str(struct_code(x)) for x in d.record)
            args = [f"_clamp(_r[{i}], {FLOAT_MAX[x.bits]!r})" if x.kind == "float" and x.bits > 16 and not x.truncated
                    else self.struct_arg(x, f"_r[{i}]") for i, x in enumerate(d.record)]  # (no statement: in a list)
            data = f"b''.join([{self.consts.struct('<' + codes)}.pack({', '.join(args)}) for _r in {items}])"
            if not self.acc and not d.prefix:
                self.parts.append(data)
                return
        elif code is not None:
            if t.kind == "uint" and t.bits == 8 and not t.truncated:
                data = f"bytes({items})"
            else:
                write_code = "H" if t.kind == "float" and t.bits == 16 else code
                data = f"_struct.pack(f'<{{len({items})}}{write_code}', {self.list_arg(t, items)})"
            if not self.acc and not d.prefix:
                self.parts.append(data)
                return
        self.start_acc()
        if d.prefix:
            prefix = self.stream_bits(DsdlType("uint", d.prefix), f"len({items})")
            self.lines.append(f"_a = _a << {d.prefix} | {prefix}")
        if code is not None:
            chunk = self.temp()
            self.lines.append(f"{chunk} = {data}")
            self.lines.append(f"_a = _a << (len({chunk}) << 3) | int.from_bytes({chunk}, 'big')")
        elif d.bit_record:  # records of bit fields: each element's stream bits as one integer
            outer, self.lines = self.lines, []
            bits = self.combine(self.pieces([_Atom(x, None if at is None else f"_r{at}") for x, at in d.bit_record]))
            # (their temporaries are bound in the loop)
            body, self.lines = self.lines, outer
            self.lines.append(f"for _r in {items}:")
            self.lines.extend(f"    {line}" for line in [*body, f"_a = _a << {d.bits} | {bits}"])
        else:
            outer, self.lines = self.lines, []
            bits = self.stream_bits(t, "x")  # (its temporaries are bound in the loop)
            body, self.lines = self.lines, outer
            self.lines.append(f"for x in {items}:")
            self.lines.extend(f"    {line}" for line in [*body, f"_a = _a << {t.bits} | {bits}"])
        if not self.nb_dyn:
            self.lines.append(f"_nb = {self.nb} + {d.prefix} + len({items}) * {d.bits}")
            self.nb_dyn, self.nb = True, 0
        else:
            self.lines.append(f"_nb += {self.nb + d.prefix} + len({items}) * {d.bits}")
            self.nb = 0

    def start_acc(self) -> None:
        if not self.acc:
            self.acc = True
            self.lines.append("_a = 0")
            self.nb = 0

    def finish(self) -> str:
        if self.acc:
            if self.nb_dyn:
                if self.nb:
                    self.lines.append(f"_nb += {self.nb}")
                self.parts.append("(_a << (-_nb & 7)).to_bytes((_nb + 7) >> 3, 'big')")
            elif self.nb:
                pad = -self.nb % 8
                shifted = f"(_a << {pad})" if pad else "_a"
                self.parts.append(f"{shifted}.to_bytes({(self.nb + pad) // 8}, 'big')")
        parts: list[str | bytes] = []
        for part in self.parts:  # bytes known now: one constant
            if isinstance(part, bytes) and parts and isinstance(parts[-1], bytes):
                parts[-1] += part
            else:
                parts.append(part)
        if not parts:
            return "b''"
        return " + ".join(self.as_expr(p) for p in parts)


def _reorder(n: int, bits: int) -> int:
    """The stream bits of an unsigned value: its bytes from the low end, the high remainder last.

    >>> hex(_reorder(0x123, 11)), hex(_reorder(0x1234, 16))
    ('0x119', '0x3412')
    """
    m = (bits + 7) // 8
    out = 0
    for i in range(m):
        if i < m - 1:
            out |= (n >> 8 * i & 0xFF) << (bits - 8 * (i + 1))
        else:
            out |= n >> 8 * i
    return out


def _balanced(text: str) -> bool:
    """Whether the parentheses of `text` balance without closing below its level (so "(text)" is one group).

    >>> _balanced("1 if x else 0"), _balanced("a) | (b")
    (True, False)
    """
    depth = 0
    for c in text:
        depth += {"(": 1, ")": -1}.get(c, 0)
        if depth < 0:
            return False
    return depth == 0


def v0_writer(struct_: V0Struct, node: V0Node | None, layout: V0Layout, consts: Constants
              ) -> tuple[list[str], str]:
    """Statements and the expression of the payload of `struct_` with the values of `node`."""
    if struct_.union:
        raise ValueError(f"{struct_.name} is a union: unions cannot be mapped")
    items: list[_Atom | _List] = []
    fields = struct_.declared_fields
    given = node.fields if node is not None else {}
    for i, f in enumerate(fields):
        _flatten(layout, f.type, given.get(f.name) if f.name else None, i == len(fields) - 1,  # type: ignore[arg-type]
                 items)
    w = _Writer(consts)
    for item in runs_of(items, _Atom):
        if isinstance(item, list):
            w.run(item)
        elif isinstance(item, _List):
            w.dyn_list(item)
    return w.lines, w.finish()
