"""The writer half of cyphal_read: straight-line Python serializing a Cyphal v1 composite as pycyphal does (see
cyphal_read for the layout and the API; ``cyphal_writer`` is re-exported there)."""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import DsdlType
from sam_codegen.targets.wire.code import NO_VALUE, Constants, FieldPath, Names, literal_value
from sam_codegen.targets.wire.cyphal_layout import (
    FLOAT_FORMATS,
    STD_FORMATS,
    UNSIGNED_FORMATS,
    Lookup,
    ceil8,
    elem_path,
    is_fixed_size,
    max_bits,
    piece_sizes,
    prefix_bits,
    struct_of,
    touches,
    union_tag_bits,
)

__all__ = ["cyphal_writer"]


@dataclass
class _Term:
    """One primitive of a bit group being written: its offset in the group, type, expression, literal value."""

    offset: int
    type: DsdlType
    expr: str
    value: Any


class _Writer:
    """Writes one composite. Byte mode: parts (whole bytes) from struct runs, with fields that are not aligned
    standard primitives gathered in groups packed as one word; bit mode (after a variable-length array that
    leaves the position unaligned): one integer accumulated with shifts, flushed as bytes at the next alignment."""

    def __init__(self, lookup: Lookup, names: Names, consts: Constants, values: dict[FieldPath, str]) -> None:
        self.lookup, self.names, self.consts, self.values = lookup, names, consts, values
        self.used: set[FieldPath] = set()
        self.lines: list[str] = []
        self.parts: list[str] = []
        self.run: list[tuple[str, str | None, Any]] = []  # (code, expression or None for pad, literal value)
        self.group: list[_Term] | None = None
        self.group_start = 0
        self.bits = 0  # byte mode: static bits since the last flushed part; bit mode: beyond `var`
        self.bitmode = False
        self.acc: str | None = None
        self.var: str | None = None  # bit mode: the bit offset local (None: 0)

    def value(self, path: FieldPath | None) -> tuple[str | None, Any]:
        if path is None or path not in self.values:
            return None, NO_VALUE
        self.used.add(path)
        expr = self.values[path]
        return expr, literal_value(expr)

    # -- byte mode
    def flush_run(self) -> None:
        self.close_group()
        run, self.run = self.run, []
        if not run:
            return
        if all(expr is None or value is not NO_VALUE for _, expr, value in run):
            fmt = "<" + "".join(code for code, _, _ in run)
            data = struct.pack(fmt, *[v for _, e, v in run if e is not None])
            self.parts.append(self.consts.data(data))
            return
        fmt = "<" + "".join(code for code, _, _ in run)
        args = [expr for _, expr, _ in run if expr is not None]
        self.parts.append(f"{self.consts.struct(fmt)}.pack({', '.join(args)})")

    def term_bits(self, term: _Term) -> tuple[str | None, int]:
        """(expression of the term's bits, or None) and the literal bits, both unshifted."""
        t = term.type
        mask = (1 << t.bits) - 1
        if term.value is not NO_VALUE:
            if t.kind == "float":
                packed = struct.pack("<" + FLOAT_FORMATS[t.bits], term.value)
                raw = struct.unpack("<" + UNSIGNED_FORMATS[t.bits], packed)[0]
                return None, raw
            return None, int(term.value) & mask
        if t.kind == "bool":
            return f"{term.expr}", 0
        if t.kind == "float":
            unpack = self.consts.struct("<" + UNSIGNED_FORMATS[t.bits])
            pack = self.consts.struct("<" + FLOAT_FORMATS[t.bits])
            return f"{unpack}.unpack({pack}.pack({term.expr}))[0]", 0
        if t.kind == "int":
            return f"({term.expr} & {mask})", 0
        return term.expr, 0

    def close_group(self) -> None:
        group, self.group = self.group, None
        if group is None:
            return
        nbytes = -(-(self.bits - self.group_start) // 8)
        constant, terms = 0, []
        for term in group:
            expr, bits = self.term_bits(term)
            constant |= bits << term.offset
            if expr is not None:
                terms.append(f"{expr} << {term.offset}" if term.offset else expr)
        if not terms:
            for size in piece_sizes(nbytes):
                self.run.append((UNSIGNED_FORMATS[size * 8], repr(constant & ((1 << size * 8) - 1)),
                                 constant & ((1 << size * 8) - 1)))
                constant >>= size * 8
            return
        if constant:
            terms.append(str(constant))
        word = " | ".join(terms)
        sizes = piece_sizes(nbytes)
        if len(sizes) == 1:
            self.run.append((UNSIGNED_FORMATS[sizes[0] * 8], word, NO_VALUE))
            return
        local = self.names.new("bits")
        self.lines.append(f"{local} = {word}")
        shift = 0
        for size in sizes:
            mask = (1 << size * 8) - 1
            piece = f"{local} >> {shift} & {mask}" if shift else f"{local} & {mask}"
            self.run.append((UNSIGNED_FORMATS[size * 8], piece, NO_VALUE))
            shift += size * 8

    def prim(self, t: DsdlType, expr: str | None, value: Any) -> None:
        if expr is None:
            expr, value = ("False" if t.kind == "bool" else "0"), (False if t.kind == "bool" else 0)
            if t.kind == "float":
                expr, value = "0.0", 0.0
        if self.bitmode:
            term = _Term(0, t, expr, value)
            bits_expr, constant = self.term_bits(term)
            at = f"{self.var} + {self.bits}" if self.var else str(self.bits)
            if bits_expr is not None:
                self.lines.append(f"{self.acc} |= {bits_expr} << ({at})")
            elif constant:
                self.lines.append(f"{self.acc} |= {constant} << ({at})")
            self.bits += t.bits
            return
        code = STD_FORMATS.get((t.kind, t.bits))
        if code and self.bits % 8 == 0 and t.kind != "utf8":
            self.close_group()
            self.run.append((code, expr, value))
            self.bits += t.bits
            return
        if self.group is None:
            self.group, self.group_start = [], self.bits
        self.group.append(_Term(self.bits - self.group_start, t, expr, value))
        self.bits += t.bits

    def to_bitmode(self) -> None:
        """Continue in one accumulated integer from the start of the open group (or the current byte)."""
        group, origin = self.group, (self.group_start if self.group is not None else self.bits)
        assert origin % 8 == 0
        self.group = None
        self.flush_run()
        now = self.bits
        self.acc = self.names.new("acc")
        self.lines.append(f"{self.acc} = 0")
        self.bitmode, self.var = True, None
        for term in group or []:
            self.bits = term.offset
            self.prim(term.type, term.expr, term.value)
        self.bits = now - origin

    def align(self) -> None:
        if self.bitmode:
            at = f"{self.var} + {self.bits}" if self.var else str(self.bits)
            self.parts.append(f"{self.acc}.to_bytes(({at} + 7) >> 3, 'little')")
            self.bitmode, self.acc, self.var, self.bits = False, None, None, 0
            return
        if self.group is not None:
            self.bits = ceil8(self.bits)
            self.close_group()
        self.bits = ceil8(self.bits)

    def fold(self) -> str:
        assert self.bitmode
        if self.var is None:
            self.var = self.names.new("bit")
            self.lines.append(f"{self.var} = {self.bits}")
        elif self.bits:
            self.lines.append(f"{self.var} += {self.bits}")
        self.bits = 0
        return self.var

    # -- fields
    def write_struct(self, struct_: DsdlStruct, prefix: FieldPath | None) -> None:
        if struct_.union:
            if prefix is not None and any(p[:len(prefix)] == prefix for p in self.values):
                raise NotImplementedError(f"{prefix}: writing into a union")
            variants = struct_.declared_fields
            tag_bits = union_tag_bits(len(variants))
            self.prim(DsdlType("uint", tag_bits), "0", 0)
            first = variants[0].type
            assert isinstance(first, DsdlType)
            self.write_field(first, None)
        else:
            for f in struct_.declared_fields:
                t = f.type
                assert isinstance(t, DsdlType)
                self.write_field(t, (*prefix, (f.name, None)) if f.name and prefix is not None else None)
        self.align()

    def write_field(self, t: DsdlType, path: FieldPath | None) -> None:
        if t.kind == "composite":
            nested = struct_of(self.lookup, t.composite)
            expr, _ = self.value(path)
            if not t.array:
                self.write_composite(nested, path)
            elif expr is not None and not touches(set(self.values) - {path}, path):
                self.write_records(nested, t, expr)
            elif t.array == "fixed":
                for i in range(t.capacity or 0):
                    self.write_composite(nested, None if path is None else elem_path(path, i))
            else:
                if expr is not None or touches(self.values, path):
                    raise NotImplementedError(f"{path}: writing a variable-length array of composites")
                self.align()
                pb = prefix_bits(t.capacity or 0)
                self.prim(DsdlType("uint", pb), "0", 0)  # empty
        elif t.array == "fixed":
            self.write_fixed(t, path)
        elif t.array == "bounded":
            self.write_var(t, path)
        elif t.kind == "void":
            self.prim(DsdlType("uint", t.bits), "0", 0)
        else:
            expr, value = self.value(path)
            self.prim(t, expr, value)

    def write_fixed(self, t: DsdlType, path: FieldPath | None) -> None:
        e, n = t.element, t.capacity or 0
        whole, _ = self.value(path)
        code = STD_FORMATS.get((e.kind, e.bits))
        if whole is not None:
            if code and not self.bitmode and self.bits % 8 == 0:
                self.close_group()
                if e.bits == 8 and e.kind in ("uint", "byte", "utf8"):
                    self.run.append((f"{n}s", f"bytes({whole})", NO_VALUE))
                else:
                    self.run.append((f"{n}{code}", f"*{whole}", NO_VALUE))
                self.bits += e.bits * n
                return
            local = self.names.new(path[-1][0] if path else "array")
            self.lines.append(f"{local} = {whole}")
            for i in range(n):
                self.prim(e, f"{local}[{i}]", NO_VALUE)
            return
        for i in range(n):
            expr, value = self.value(None if path is None else elem_path(path, i))
            self.prim(e, expr, value)

    def write_var(self, t: DsdlType, path: FieldPath | None) -> None:
        e, cap = t.element, t.capacity or 0
        pb = prefix_bits(cap)
        expr, _ = self.value(path)
        if expr is None:
            self.prim(DsdlType("uint", pb), "0", 0)
            return
        local = self.names.new(path[-1][0] if path else "array")
        byte_like = e.bits == 8 and e.kind in ("uint", "byte", "utf8")
        self.lines.append(f"{local} = bytes({expr})" if byte_like else f"{local} = {expr}")
        fast = not self.bitmode and self.bits % 8 == 0 and (e.kind, e.bits) in STD_FORMATS
        if fast:
            self.flush_run()
            prefix = self.consts.struct("<" + UNSIGNED_FORMATS[pb])
            if byte_like:
                self.parts.append(f"{prefix}.pack(len({local})) + {local}")
            else:
                code = STD_FORMATS[(e.kind, e.bits)]
                count = UNSIGNED_FORMATS[pb]
                self.parts.append(f"_struct.pack(f'<{count}{{len({local})}}{code}', len({local}), *{local})")
            return
        if not self.bitmode:
            self.to_bitmode()
        self.prim(DsdlType("uint", pb), f"len({local})", NO_VALUE)
        q = self.fold()
        if byte_like:
            self.lines += [f"{self.acc} |= int.from_bytes({local}, 'little') << {q}", f"{q} += 8 * len({local})"]
            return
        term_expr, _ = self.term_bits(_Term(0, e, "x", NO_VALUE))
        self.lines += [f"for x in {local}:", f"    {self.acc} |= {term_expr} << {q}", f"    {q} += {e.bits}"]

    def write_records(self, nested: DsdlStruct, t: DsdlType, records: str) -> None:
        """An array of composites from a list of records (tuples of their fields in declaration order, void padding
        left out: what the element functions return, targets.wire.element_records); a fixed array's list has its
        size, a variable-length one's is within the capacity (the converters cut it before)."""
        local = self.names.new("records")
        self.lines.append(f"{local} = {records}")
        self.align()
        if t.array == "bounded":
            self.prim(DsdlType("uint", prefix_bits(t.capacity or 0)), f"len({local})", NO_VALUE)
        self.flush_run()
        record, chunks = self.names.new("record"), self.names.new("chunks")
        inner = _Writer(self.lookup, self.names, self.consts, self.record_values(nested, (), record))
        inner.write_composite(nested, ())
        inner.flush_run()
        one = " + ".join(inner.parts) if inner.parts else repr(b"")
        self.lines += [f"{chunks} = []", f"for {record} in {local}:",
                       *(f"    {line}" for line in inner.lines), f"    {chunks}.append({one})"]
        self.parts.append(f"b''.join({chunks})")

    def record_values(self, struct_: DsdlStruct, at: FieldPath, record: str) -> dict[FieldPath, str]:
        """The writer's values of a record of `struct_` (its scalar leaves; a nested composite a tuple of its own)."""
        out: dict[FieldPath, str] = {}
        for i, f in enumerate(struct_.fields):
            t = f.type
            assert isinstance(t, DsdlType)
            if t.array or (t.kind == "composite" and struct_of(self.lookup, t.composite).union):
                raise NotImplementedError(f"{struct_.name}: records of composites holding arrays or unions")
            if t.kind == "composite":
                out.update(self.record_values(struct_of(self.lookup, t.composite), (*at, (f.name, None)),
                                              f"{record}[{i}]"))
            else:
                out[(*at, (f.name, None))] = f"{record}[{i}]"
        return out

    def write_composite(self, nested: DsdlStruct, path: FieldPath | None) -> None:
        self.align()
        if nested.sealed:
            self.write_struct(nested, path)
            return
        if is_fixed_size(nested, self.lookup):
            size = max_bits(nested, self.lookup) // 8
            self.prim(DsdlType("uint", 32), str(size), size)
            self.write_struct(nested, path)
            return
        self.flush_run()
        inner = _Writer(self.lookup, self.names, self.consts, self.values)
        inner.write_struct(nested, path)
        inner.flush_run()
        self.used |= inner.used
        self.lines.extend(inner.lines)
        local = self.names.new("nested")
        self.lines.append(f"{local} = {' + '.join(inner.parts) if inner.parts else repr(b'')}")
        self.parts.append(f"{self.consts.struct('<I')}.pack(len({local})) + {local}")


def cyphal_writer(struct_: DsdlStruct, values: dict[FieldPath, str], lookup: Lookup, names: Names, consts: Constants
                  ) -> tuple[list[str], str]:
    """Statements and the expression of the serialized `struct_` with `values` (unset: zero / empty)."""
    w = _Writer(lookup, names, consts, values)
    w.write_struct(struct_, ())
    w.flush_run()
    unused = set(values) - w.used
    if unused:
        raise ValueError(f"{struct_.name}: no field at {sorted(map(str, unused))}")
    return w.lines, " + ".join(w.parts) if w.parts else repr(b"")
