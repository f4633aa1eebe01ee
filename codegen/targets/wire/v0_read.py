"""Straight-line Python for UAVCAN v0 (DroneCAN) payloads, generated per data type: the reader (this module) and
the writer (v0_write).

A payload is the bytes of one complete transfer, its CRC removed. The layout is dronecan's (pydronecan 1.0.27,
``dronecan/transport.py``), bit for bit:

- fields bit-packed in declaration order, no alignment, void padding included; the payload is the bit stream read
  most significant bit first in each byte (``bits_from_bytes``), the last byte zero-padded;
- a primitive of N bits is stored least significant byte first (``le_from_be_bits``): 8-bit chunks of the value
  from its low end, the last chunk holding the remaining N mod 8 high bits, each chunk written MSB first;
- a dynamic array ``T[<=N]`` has a length prefix of ``ceil(log2(N + 1))`` bits (computed as dronecan computes it),
  except under the tail array optimisation (TAO): the last field of the top-level type, recursively the last field
  of a last composite field and the last element of a last array, when it is a dynamic array whose element type has
  a minimum bit length of at least 8, has no prefix and takes every remaining whole element;
- a union starts with a tag of ``ceil(log2(number of fields))`` bits, the value of the selected field follows;
- float16 is IEEE half precision; dronecan's own float-to-half conversion rounds differently from struct's ``e``
  (the writer reproduces it), half-to-float agrees with ``e``.

These codecs frame for classic CAN, so TAO is always on, as dronecan's ``Transfer(payload=..., canfd=False)`` and
its receive path for classic frames have it (CAN FD transfers have TAO off).

What dronecan refuses, the reader refuses with ``WireError`` (a name the generated module defines), and nothing
else: a primitive field, a length prefix or a union tag that does not fit in the remaining bits (dronecan's
``ValueError: Not enough bits``), an element of a tail array cut short, a union tag beyond the union's fields
(dronecan: ``IndexError``) or no bits at all for the tag. dronecan accepts, and so does the reader: bits beyond the
type's end (ignored), void padding cut by the end of the payload, fewer than 8 bits left after a tail array, and a
length prefix larger than the array's capacity (up to what the prefix can hold; all elements are decoded) or a tail
array longer than its capacity: such arrays are given whole to the mapping, as dronecan's objects give them.

API (used by codec_v0)
---------------------------
Paths are tuples of field names, through nested (non-array) composites, to a primitive field or to an array field:
``("timestamp", "usec")``, ``("commands",)``.

- ``V0Layout(lookup)`` (v0_layout): sizes of v0 types as dronecan computes them; ``lookup(full_name) ->
  V0Struct``.
- ``v0_reader(struct, wanted, layout, consts, buf, new_name)`` -> ``(lines, path -> local)``: statements that
  check the payload in ``buf`` as dronecan would and decode the ``wanted`` paths into locals named by
  ``new_name("u_" + path)``: primitives as Python numbers and bools, arrays as lists; an element of an array of
  composites is a record, a tuple of its fields (void padding left out; nested composites as tuples, arrays as
  lists, a union as ``(tag, value)``); ``record_index`` gives a field's position in a record. Temporaries start
  with ``_``. The generated code needs ``_struct`` and ``WireError`` in its module.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.spec import V0Struct
from sam_codegen.model.types import DsdlType
from sam_codegen.targets.wire.code import Constants, prune, runs_of
from sam_codegen.targets.wire.v0_layout import (
    V0Layout,
    code_is_bytes,
    length_bits,
    merge_pads,
    record_index,
    struct_code,
    tag_bits,
)

__all__ = ["V0Layout", "WirePath", "record_index", "v0_reader"]

WirePath = tuple[str, ...]
# ---- the flattened layout ------------------------------------------------------------------------------------


@dataclass
class _Atom:
    """A primitive (or a fixed array of `count` primitives: a list) or void padding at a static position."""

    t: DsdlType  # the element type
    want: bool
    count: int = 0  # 0: a scalar
    var: str = ""

    @property
    def bits(self) -> int:
        return self.t.bits * max(self.count, 1)


@dataclass
class _Dyn:
    """A dynamic array."""

    t: DsdlType
    tao: bool  # the tao flag it is read with
    want: bool
    var: str = ""


@dataclass
class _Union:
    struct: V0Struct
    tao: bool
    want: bool
    var: str = ""


Item = _Atom | _Dyn | _Union
Val = tuple[str, Any]  # ("atom", _Atom) | ("list", [Val]) | ("tuple", [Val]) | ("dyn", _Dyn) | ("union", _Union)


def flatten(layout: V0Layout, t: DsdlType, tao: bool, want: bool, items: list[Item]) -> Val | None:
    """Append the items of a field of type `t` in wire order; return how its value is assembled (None: padding)."""
    if t.array == "fixed":
        elem = t.element
        n = t.capacity or 0
        if elem.kind != "composite":
            atom = _Atom(elem, want, n)
            items.append(atom)
            return ("atom", atom)
        return ("list", [flatten(layout, elem, tao and i == n - 1, want, items) for i in range(n)])
    if t.array:
        dyn = _Dyn(t, tao, want)
        items.append(dyn)
        return ("dyn", dyn)
    if t.kind == "composite":
        s = layout.struct(t)
        if s.union:
            u = _Union(s, tao, want)
            items.append(u)
            return ("union", u)
        fields = s.declared_fields
        vals = [flatten(layout, f.type, tao and i == len(fields) - 1, want, items)  # type: ignore[arg-type]
                for i, f in enumerate(fields)]
        return ("tuple", [v for v, f in zip(vals, fields, strict=True) if f.name])
    atom = _Atom(t, want and t.kind != "void")
    items.append(atom)
    return None if t.kind == "void" else ("atom", atom)


# ---- code generation: the cursor -------------------------------------------------------------------------------


class _Code:
    """Lines at an indent, and the offset of the next bit: `ovar` (when dynamic) + `const`; its phase (offset mod
    8) when known. Temporaries are `_`-prefixed: generated locals of the converters never are."""

    def __init__(self, consts: Constants, buf: str) -> None:
        self.consts, self.buf = consts, buf
        self.lines: list[str] = []
        self.indent = ""
        self.ovar = "_o"
        self.dyn = False  # the offset is `ovar + const`
        self.const = 0
        self.phase: int | None = 0
        self.temps = [0]  # shared with nested generators
        self.uses: set[str] = set()  # `_P` (the payload as one integer), `_L` (its bit length)

    def emit(self, line: str) -> None:
        self.lines.append(self.indent + line)

    def temp(self) -> str:
        self.temps[0] += 1
        return f"_t{self.temps[0]}"

    def at(self, rel: int = 0) -> str:
        """The bit offset `rel` bits after the cursor."""
        c = self.const + rel
        if not self.dyn:
            return str(c)
        return f"{self.ovar} + {c}" if c else self.ovar

    def fold(self) -> None:
        """Make the offset `ovar` exactly."""
        if not self.dyn:
            self.emit(f"{self.ovar} = {self.const}")
            self.dyn = True
        elif self.const:
            self.emit(f"{self.ovar} += {self.const}")
        self.const = 0

    def advance(self, bits: int) -> None:
        self.const += bits
        if self.phase is not None:
            self.phase = (self.phase + bits) % 8

    def aligned(self, rel: int) -> bool:
        return self.phase is not None and (self.phase + rel) % 8 == 0

    def byte_at(self, rel: int) -> str:
        """The byte index of an aligned offset `rel` bits after the cursor."""
        if not self.dyn:
            return str((self.const + rel) // 8)
        c = self.const + rel
        return f"({self.ovar} + {c}) >> 3" if c else f"{self.ovar} >> 3"

    def window(self, rel: int, bits: int) -> str:
        """The integer of `bits` stream bits starting `rel` bits after the cursor (MSB first): sliced from the
        payload when byte-aligned, else shifted out of `_P`. The bits must be in the payload."""
        if self.aligned(rel) and bits % 8 == 0:
            return f"int.from_bytes({self.buf}[{self.byte_at(rel)}:{self.byte_at(rel + bits)}], 'big')"
        self.uses |= {"_P", "_L"}
        return f"_P >> (_L - {_paren(self.at(rel + bits))}) & {hex((1 << bits) - 1)}"


def _paren(expr: str) -> str:
    return expr if expr.isidentifier() or expr.isdigit() else f"({expr})"


def unsigned_from_stream(w: str, shift: int, bits: int) -> str:
    """The value of an unsigned field of `bits` bits whose stream bits end `shift` bits above the low end of the
    integer `w`: chunks of 8 bits from its low end, stored first, the high remainder last.

    >>> unsigned_from_stream("w", 0, 7)
    'w & 0x7f'
    >>> unsigned_from_stream("w", 2, 11)
    '(w >> 5 & 0xff) | (w >> 2 & 0x7) << 8'
    """
    m = (bits + 7) // 8
    rem = bits - 8 * (m - 1)
    terms = []
    for i in range(m):
        width = 8 if i < m - 1 else rem
        s = shift + bits - 8 * i - width
        part = f"{w} >> {s} & {hex((1 << width) - 1)}" if s else f"{w} & {hex((1 << width) - 1)}"
        terms.append(part if i == 0 else f"({part}) << {8 * i}")
    return terms[0] if m == 1 else " | ".join(f"({t})" if i == 0 else t for i, t in enumerate(terms))


def _signed(expr: str, bits: int) -> str:
    half = 1 << (bits - 1)
    return f"(({expr}) ^ {hex(half)}) - {hex(half)}"


def scalar_from_stream(t: DsdlType, w: str, shift: int) -> str:
    """A bool or integer of a non-byte-multiple width out of the stream integer `w`.

    >>> scalar_from_stream(DsdlType("int", 5), "w", 3), scalar_from_stream(DsdlType("bool", 1), "w", 0)
    ('((w >> 3 & 0x1f) ^ 0x10) - 0x10', 'w & 1 == 1')
    """
    if t.kind == "bool":
        return f"{w} >> {shift} & 1 == 1" if shift else f"{w} & 1 == 1"
    u = unsigned_from_stream(w, shift, t.bits)
    return _signed(u, t.bits) if t.kind == "int" else u


def _int_from_bytes(expr: str, t: DsdlType) -> str:
    return f"int.from_bytes({expr}, 'little'{', signed=True' if t.kind == 'int' else ''})"


# ---- the reader ------------------------------------------------------------------------------------------------


class _Reader(_Code):
    def __init__(self, layout: V0Layout, consts: Constants, buf: str, what: str) -> None:
        super().__init__(consts, buf)
        self.layout = layout
        self.what = what  # the type's name, in error messages
        self.past_end = False  # the offset may lie beyond the payload (void padding cut by its end)
        self.checked = False  # inside an element loop whose bounds were checked for the whole array

    def fail(self, why: str) -> None:
        self.emit(f"    raise WireError({self.what + ': ' + why!r})")

    def nested(self, ovar: str, phase: int | None, checked: bool) -> _Reader:
        """A reader for the body of a loop, one indent deeper, its offset in `ovar`."""
        inner = _Reader(self.layout, self.consts, self.buf, self.what)
        inner.indent, inner.ovar, inner.dyn, inner.phase = self.indent + "    ", ovar, True, phase
        inner.checked, inner.temps, inner.uses, inner.lines = checked, self.temps, self.uses, self.lines
        return inner

    def items(self, items: list[Item]) -> None:
        for item in runs_of(items, _Atom):
            if isinstance(item, list):
                self.run(item)
            elif isinstance(item, _Dyn):
                self.dyn_array(item)
            elif isinstance(item, _Union):
                self.union(item)

    def check(self, bits: int) -> None:
        """The next `bits` bits are in the payload, or WireError."""
        if self.checked or not bits:
            return
        if not self.dyn:
            self.emit(f"if _n < {(self.const + bits + 7) // 8}:")
        else:
            self.uses.add("_L")
            self.emit(f"if _L < {self.at(bits)}:")
        self.fail("payload too short")

    # -- atoms at static offsets
    def run(self, atoms: list[_Atom]) -> None:
        pos, starts = 0, []
        for a in atoms:
            starts.append(pos)
            pos += a.bits
        req = max([s + a.bits for s, a in zip(starts, atoms, strict=True) if a.t.kind != "void"], default=0)
        self.check(req)
        # Segments of atoms read by struct (byte-multiple widths) and of atoms read with bit operations.
        segment: list[int] = []
        for i, atom in enumerate([*atoms, None]):
            by_struct = atom is not None and struct_code(atom.t) is not None
            if segment and (atom is None or by_struct != (struct_code(atoms[segment[0]].t) is not None)):
                wanted = [j for j in segment if atoms[j].want]
                if wanted:
                    span = [atoms[j] for j in range(wanted[0], wanted[-1] + 1)]
                    if struct_code(span[0].t) is not None:
                        self.struct_segment(span, starts[wanted[0]])
                    else:
                        self.bit_segment(span, starts[wanted[0]])
                segment = []
            if atom is not None:
                segment.append(i)
        self.advance(pos)
        self.past_end = pos > req if req else self.past_end or pos > 0

    def struct_segment(self, atoms: list[_Atom], rel: int) -> None:
        codes, targets = [], []
        for a in atoms:
            if not a.want:
                codes.append(f"{a.bits // 8}x")
                continue
            code = struct_code(a.t) or ""
            codes.append(f"{a.count}{code}" if a.count else code)
            targets.append(a)
        st = self.consts.struct(merge_pads("<" + "".join(codes)))
        bits = sum(a.bits for a in atoms)
        if self.aligned(rel):
            call = f"{st}.unpack_from({self.buf}, {self.byte_at(rel)})"
        else:
            call = f"{st}.unpack(({self.window(rel, bits)}).to_bytes({bits // 8}, 'big'))"
        if all(not a.count and not code_is_bytes(a.t) for a in targets):
            self.emit(f"{', '.join(a.var for a in targets)}{',' if len(targets) == 1 else ''} = {call}")
            return
        tup = self.temp()
        self.emit(f"{tup} = {call}")
        k = 0
        for a in targets:
            if a.count:
                part = f"{tup}[{k}:{k + a.count}]"
                expr = f"[{_int_from_bytes('x', a.t)} for x in {part}]" if code_is_bytes(a.t) else f"list({part})"
                k += a.count
            else:
                expr = _int_from_bytes(f"{tup}[{k}]", a.t) if code_is_bytes(a.t) else f"{tup}[{k}]"
                k += 1
            self.emit(f"{a.var} = {expr}")

    def bit_segment(self, atoms: list[_Atom], rel: int) -> None:
        bits = sum(a.bits for a in atoms)
        w = self.temp()
        self.emit(f"{w} = {self.window(rel, bits)}")
        end = bits
        for a in atoms:
            low = end - a.bits  # the shift of this atom's last bit
            if a.want and a.count:
                shifts = [low + (a.count - 1 - i) * a.t.bits for i in range(a.count)]
                self.emit(f"{a.var} = [{', '.join(scalar_from_stream(a.t, w, s) for s in shifts)}]")
            elif a.want:
                self.emit(f"{a.var} = {scalar_from_stream(a.t, w, low)}")
            end = low

    # -- dynamic arrays
    def dyn_array(self, d: _Dyn) -> None:
        layout, t = self.layout, d.t
        elem = t.element
        self.fold()
        o = self.ovar
        es = layout.static_bits(elem)
        d.var = d.var or self.temp()
        count = self.temp()
        if layout.tao_mode(t, d.tao):
            self.uses.add("_L")
            if es is None:  # dronecan: `while len(stream) >= 8`, every element read without tao
                self.element_loop(d, f"while _L - {o} >= 8:", None)
                return
            rem = f"max(_L - {o}, 0)" if self.past_end else f"_L - {o}"
            self.emit(f"{count} = ({rem} - 8) // {es} + 1 if {rem} >= 8 else 0")
            req = layout.required_bits(elem)
            if req > 8 and not self.checked:  # the last element starts with 8 bits or more left: enough?
                self.emit(f"if {count} and {rem} - ({count} - 1) * {es} < {req}:")
                self.fail("tail array element cut short")
        else:
            cw = length_bits(t.capacity or 0)
            self.check(cw)
            window = self.window(0, cw)
            self.emit(f"{count} = {window if cw <= 8 else unsigned_from_stream(_paren(window), 0, cw)}")
            self.advance(cw)
            self.fold()
            if es is None:
                if d.tao and layout.tao_sensitive(elem):  # dronecan: the last element gets the tao flag
                    self.element_loop(d, f"for _ in range({count} - 1):", count)
                else:
                    self.element_loop(d, f"for _ in range({count}):", None)
                return
            req = layout.required_bits(elem)
            if req and not self.checked:
                self.uses.add("_L")
                self.emit(f"if {count} and _L < {o} + ({count} - 1) * {es} + {req}:")
                self.fail("array beyond the payload")
        phase = self.phase if es % 8 == 0 else None
        if d.want:
            self.read_elements(d, count, es, phase)
        self.emit(f"{o} += {count} * {es}")
        self.past_end = self.past_end or es > layout.required_bits(elem)
        self.phase = phase

    def read_elements(self, d: _Dyn, count: str, es: int, phase: int | None) -> None:
        """The elements of a checked array of static element size at `ovar`: a list of values or records."""
        elem, o = d.t.element, self.ovar
        aligned = phase == 0
        if elem.kind != "composite":
            code = struct_code(elem)
            if code is None:  # bits: one window over the array
                w, nbits = self.temp(), f"{count} * {es}"
                self.uses |= {"_P", "_L"}
                self.emit(f"{w} = _P >> (_L - {o} - {nbits}) & ((1 << {nbits}) - 1)")
                self.emit(f"{d.var} = [{scalar_from_stream(elem, f'({w} >> _s)', 0)} "
                          f"for _s in range(({count} - 1) * {es}, -1, -{es})]")
            elif code == "B" and aligned:
                self.emit(f"{d.var} = list({self.buf}[{o} >> 3:({o} >> 3) + {count}])")
            elif code_is_bytes(elem):
                k = es // 8
                self.emit(f"{d.var} = [{_int_from_bytes(f'_b[_k:_k + {k}]', elem)} "
                          f"for _b in ({self.elements_bytes(count, es, aligned)},) "
                          f"for _k in range(0, {count} * {k}, {k})]")
            elif aligned:
                self.emit(f"{d.var} = list(_struct.unpack_from(f'<{{{count}}}{code}', {self.buf}, {o} >> 3))")
            else:
                self.emit(f"{d.var} = list(_struct.unpack(f'<{{{count}}}{code}', "
                          f"{self.elements_bytes(count, es, False)}))")
            return
        items: list[Item] = []
        val = flatten(self.layout, elem, False, True, items)
        codes = [struct_code(a.t) if isinstance(a, _Atom) and not a.count else None for a in items]
        flat = val is not None and val[0] == "tuple" and all(v is not None and v[0] == "atom" for v in val[1])
        if flat and all(c is not None and not c.endswith("s") for c in codes):
            # records of byte-multiple fields: struct gives them, as tuples, in one call
            st = self.consts.struct(merge_pads("<" + "".join(codes)))  # type: ignore[arg-type]
            self.emit(f"{d.var} = list({st}.iter_unpack({self.elements_bytes(count, es, aligned)}))")
            return
        self.emit(f"{d.var} = []")
        self.emit(f"for _p in range({o}, {o} + {count} * {es}, {es}):")
        inner = self.nested("_p", phase, True)
        for it in items:
            if isinstance(it, _Atom) and it.want:
                it.var = self.temp()
        inner.items(items)
        inner.emit(f"{d.var}.append({assemble(val)})")

    def elements_bytes(self, count: str, es: int, aligned: bool) -> str:
        """The bytes of `count` elements of `es` bits (a multiple of 8) at `ovar`."""
        o = self.ovar
        if aligned:
            return f"{self.buf}[{o} >> 3:({o} >> 3) + {count} * {es // 8}]"
        self.uses |= {"_P", "_L"}
        nbits = f"{count} * {es}"
        return f"(_P >> (_L - {o} - {nbits}) & ((1 << {nbits}) - 1)).to_bytes({count} * {es // 8}, 'big')"

    def element_loop(self, d: _Dyn, header: str, last: str | None) -> None:
        """Elements of variable size one after the other at `ovar`; `last`: the count, when the last element is
        read with the tao flag."""
        if d.want:
            self.emit(f"{d.var} = []")
        self.emit(header)
        self.element(d, False)
        if last is not None:
            self.emit(f"if {last}:")
            self.element(d, True)
        self.phase = None
        self.past_end = True

    def element(self, d: _Dyn, tao: bool) -> None:
        inner = self.nested(self.ovar, None, False)
        items: list[Item] = []
        val = flatten(self.layout, d.t.element, tao, d.want, items)
        for it in items:
            if isinstance(it, _Atom) and it.want:
                it.var = self.temp()
        inner.items(items)
        inner.fold()
        if d.want:
            inner.emit(f"{d.var}.append({assemble(val)})")

    # -- unions
    def union(self, u: _Union) -> None:
        fields = u.struct.declared_fields
        w = tag_bits(len(fields))
        self.fold()
        o = self.ovar
        self.uses |= {"_P", "_L"}
        if w == 0:  # dronecan reads the tag with int('', 2): a union of one field never decodes
            self.emit(f"raise WireError({self.what + ': a union of one field'!r})")
            return
        tag = self.temp()
        self.emit(f"if _L - {o} >= {w}:")
        self.emit(f"    {tag} = _P >> (_L - {o} - {w}) & {hex((1 << w) - 1)}")
        self.emit(f"    {o} += {w}")
        self.emit(f"elif _L > {o}:  # dronecan takes the bits left for the tag")
        self.emit(f"    {tag} = _P & ((1 << (_L - {o})) - 1)")
        self.emit(f"    {o} = _L")
        self.emit("else:")
        self.fail("union tag beyond the payload")
        if (1 << w) > len(fields):
            self.emit(f"if {tag} >= {len(fields)}:")
            self.fail("union tag beyond its fields")
        u.var = u.var or self.temp()
        for i, f in enumerate(fields):
            self.emit(f"{'if' if i == 0 else 'elif'} {tag} == {i}:")
            inner = self.nested(o, None, False)
            items: list[Item] = []
            val = flatten(self.layout, f.type, u.tao, u.want, items)  # type: ignore[arg-type]
            for it in items:
                if isinstance(it, _Atom) and it.want:
                    it.var = self.temp()
            size = len(self.lines)
            inner.items(items)
            inner.fold()
            if u.want:
                inner.emit(f"{u.var} = ({i}, {assemble(val)})")
            if len(self.lines) == size:
                inner.emit("pass")
        self.phase = None
        self.past_end = True


def assemble(val: Val | None) -> str:
    """The expression of a decoded value from its atoms' locals."""
    if val is None:
        return "None"
    kind, inner = val
    if kind == "atom" or kind == "dyn" or kind == "union":
        return inner.var
    parts = [assemble(v) for v in inner]
    if kind == "list":
        return "[" + ", ".join(parts) + "]"
    return "(" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")"


def _names_of(path: WirePath) -> str:
    return "_".join(path)


def v0_reader(struct: V0Struct, wanted: Iterable[WirePath], layout: V0Layout, consts: Constants, buf: str,
              new_name: Callable[[str], str]) -> tuple[list[str], dict[WirePath, str]]:
    """Statements that check the payload in `buf` as dronecan does and decode the `wanted` paths into locals named
    by `new_name(hint)`; (lines, path -> local)."""
    wanted = set(wanted)
    if struct.union:
        raise ValueError(f"{struct.name} is a union: unions cannot be mapped")
    items: list[Item] = []
    vals: dict[WirePath, Val] = {}
    _flatten_top(layout, struct, (), True, wanted, items, vals)
    missing = wanted - set(vals)
    if missing:
        raise ValueError(f"{struct.name}: no field at {sorted(missing)}")
    for path, val in vals.items():
        if val[0] in ("atom", "dyn"):
            val[1].var = new_name("u_" + _names_of(path))
    reader = _Reader(layout, consts, buf, struct.name)
    for item in items:  # the atoms inside records of wanted fixed arrays of composites
        if isinstance(item, _Atom) and item.want and not item.var:
            item.var = reader.temp()
    reader.items(items)
    found: dict[WirePath, str] = {}
    for path, val in vals.items():
        if val[0] in ("atom", "dyn"):
            found[path] = val[1].var
        else:
            local = new_name("u_" + _names_of(path))
            reader.emit(f"{local} = {assemble(val)}")
            found[path] = local
    lines = prune(reader.lines, found.values())  # (the offset after the last field, ...)
    text = "\n".join(lines)
    prologue = [f"_n = len({buf})"]
    if re.search(r"\b_L\b", text):
        prologue.append("_L = _n << 3")
    if re.search(r"\b_P\b", text):
        prologue.append(f"_P = int.from_bytes({buf}, 'big')")
    return prologue + lines, found


def _flatten_top(layout: V0Layout, struct: V0Struct, prefix: WirePath, tao: bool, wanted: set[WirePath],
                 items: list[Item], vals: dict[WirePath, Val]) -> None:
    """The top level: nested composites that hold wanted paths are flattened into paths of their own."""
    fields = struct.declared_fields
    for i, f in enumerate(fields):
        t: DsdlType = f.type  # type: ignore[assignment]
        last = tao and i == len(fields) - 1
        path = (*prefix, f.name)
        if f.name and t.kind == "composite" and not t.array and path not in wanted and any(
                w[:len(path)] == path for w in wanted) and not layout.struct(t).union:
            _flatten_top(layout, layout.struct(t), path, last, wanted, items, vals)
            continue
        want = bool(f.name) and path in wanted
        val = flatten(layout, t, last, want, items)
        if want and val is not None:
            vals[path] = val
