"""Straight-line Python for Cyphal v1 DSDL serialized representations: a writer and a reader per type.

The layout is DSDL v1's, as pycyphal (nunavut 2.3's Python serializer) reads and writes it:

- bit-level little-endian packing, least significant bit first; every composite starts and ends on a byte
  boundary (zero padding); void fields are zero bits;
- a variable-length array is a length prefix (the smallest of uint8/16/32/64 that holds the capacity, as pydsdl
  sizes it) then the elements; a fixed array is its elements only; utf8 and byte arrays are arrays of bytes;
- a nested non-sealed (delimited) composite is a uint32 header with its byte length, then its bytes; a sealed one is
  inline; a union is its tag (uint8 or wider) then the selected field;
- reading applies the implicit zero extension (bits beyond the payload read as zero), ignores what follows the
  data (implicit truncation: a newer minor version's extra fields, up to and beyond the extent), and refuses
  (``WireError``) exactly where pycyphal's deserialize does not give an object: an array length prefix beyond the
  capacity, a delimiter header beyond the remaining bytes, a union tag beyond the variants, and the bit length
  check at the end of each composite (its assertion) that a delimited field longer than its extent can break.

API (the codecs build on it)
----------------------------
Paths are tuples of ``(DSDL field name, index or None)`` (names as in the DSDL, not pycyphal's mangled ones).

- ``cyphal_reader(struct, wanted, lookup, names, consts, payload)`` -> ``(lines, locals)``: statements decoding the
  payload (bytes, bytearray or memoryview) into locals for the ``wanted`` leaves: ints, floats, bools; lists for
  whole arrays (bytes as ints); a memoryview for utf8 arrays (``.tobytes()``, as pycyphal's numpy arrays).
- ``cyphal_writer(struct, values, lookup, names, consts)`` -> ``(lines, expr)``: statements and the expression of
  the payload bytes; ``values`` maps leaf paths to expressions (whole arrays: a list, or bytes for utf8/uint8
  arrays), unset leaves are zero, unset variable-length arrays empty, an unset union its first field. Values are
  assumed in range (the converters' checks ran before).
- ``max_bits(struct, lookup)``: the largest serialized size in bits (pydsdl's bit length set maximum).
- ``lookup(full name with version) -> DsdlStruct`` (``Resolved.dsdl.get``); ``names``/``consts`` as in cdr_write.

The generated code needs ``_struct``, ``WireError`` and ``_extend`` (``CYPHAL_PRELUDE``) in its module. This module
holds the reader; the writer is in cyphal_write, the layout rules both follow in cyphal_layout.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import partial

from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import DsdlType
from sam_codegen.targets.wire.code import Constants, FieldPath, Names, prune
from sam_codegen.targets.wire.cyphal_layout import (
    CYPHAL_PRELUDE,
    FLOAT_FORMATS,
    STD_FORMATS,
    UNSIGNED_FORMATS,
    Lookup,
    ceil8,
    elem_path,
    has_delimited,
    max_bits,
    piece_sizes,
    prefix_bits,
    signed_expr,
    struct_of,
    union_tag_bits,
)
from sam_codegen.targets.wire.cyphal_write import cyphal_writer

__all__ = ["CYPHAL_PRELUDE", "cyphal_reader", "cyphal_writer", "max_bits", "prefix_bits"]


# ---- reader --------------------------------------------------------------------------------------------------


@dataclass
class _Shared:
    lookup: Lookup
    names: Names
    consts: Constants
    wanted: set[FieldPath]
    found: dict[FieldPath, str] = field(default_factory=dict)
    keep: set[str] = field(default_factory=set)  # locals read by generated lines (records' fields), kept by prune

    def want(self, path: FieldPath | None, hint: str | None = None) -> str | None:
        if path is None or path not in self.wanted:
            return None
        name = self.names.new(hint or "_".join(str(p) for seg in path for p in seg if p is not None))
        self.found[path] = name
        return name

    def wants_inside(self, path: FieldPath | None) -> bool:
        return path is not None and any(p[:len(path)] == path for p in self.wanted)


class _Reader:
    """Reads one buffer. Position: byte mode (`var` a byte offset local or None, plus `bits`) or bit mode (`var` a
    bit offset local, plus `bits`); in byte mode, aligned primitives go into struct runs and other fields into
    groups read as one word; in bit mode every field comes out of the buffer as one big integer."""

    def __init__(self, shared: _Shared, buf: str, size: str) -> None:
        self.s = shared
        self.buf, self.size = buf, size
        self.lines: list[str] = []
        self.var: str | None = None
        self.bits = 0
        self.bitmode = False
        self.big: str | None = None
        self.run: list[tuple[str, str | None]] = []
        self.run_bits = 0
        self.after: list[str] = []  # after the run's unpack: values out of group words
        self.post: list[str] = []  # after those: whole arrays made of read elements
        self.group: list[tuple[int, DsdlType, str | None]] | None = None
        self.group_start = 0

    # -- positions
    def byte_at(self, bits: int) -> str:
        assert not self.bitmode and bits % 8 == 0
        if self.var:
            return f"{self.var} + {bits // 8}" if bits else self.var
        return str(bits // 8)

    def bit_at(self, bits: int) -> str:
        assert self.bitmode
        return f"{self.var} + {bits}" if self.var and bits else (self.var or str(bits))

    def fold(self) -> str:
        """Make the position a local (a byte offset in byte mode, which must be aligned); returns it."""
        self.flush()
        if self.bitmode:
            if self.var is None:
                self.var = self.s.names.new("bit")
                self.lines.append(f"{self.var} = {self.bits}")
            elif self.bits:
                self.lines.append(f"{self.var} += {self.bits}")
        else:
            assert self.bits % 8 == 0
            if self.var is None:
                self.var = self.s.names.new("offset")
                self.lines.append(f"{self.var} = {self.bits // 8}")
            elif self.bits:
                self.lines.append(f"{self.var} += {self.bits // 8}")
        self.bits = 0
        return self.var

    def to_bitmode(self) -> None:
        self.flush()
        if self.bitmode:
            return
        start = f"{self.var} * 8 + {self.bits}" if self.var else str(self.bits)
        self.var = self.s.names.new("bit")
        self.lines.append(f"{self.var} = {start}")
        self.bits, self.bitmode = 0, True

    def bigint(self) -> str:
        if self.big is None:
            self.big = self.s.names.new("word")
            self.lines.append(f"{self.big} = int.from_bytes({self.buf}, 'little')")
        return self.big

    def align(self) -> None:
        if self.bitmode:
            start = f"{self.var} + {self.bits} + 7" if self.bits else f"{self.var} + 7"
            self.var = self.s.names.new("offset")
            self.lines.append(f"{self.var} = ({start}) >> 3")
            self.bits, self.bitmode = 0, False
            return
        self.close_group()
        self.bits = ceil8(self.bits)

    # -- runs and groups (byte mode)
    def item(self, code: str, nbits: int, target: str | None) -> None:
        if not self.run:
            self.run_bits = self.bits
        self.run.append((code if target else "x" * (nbits // 8), target))
        self.bits += nbits

    def close_group(self) -> None:
        group, self.group = self.group, None
        if group is None:
            return
        nbytes = -(-(self.bits - self.group_start) // 8)
        if not any(target for _, _, target in group):
            if not self.run:
                self.run_bits = self.group_start
            self.run.append(("x" * nbytes, None))
            return
        if not self.run:
            self.run_bits = self.group_start
        pieces, shift = [], 0
        for size in piece_sizes(nbytes):
            piece = self.s.names.new("bits")
            self.run.append((UNSIGNED_FORMATS[size * 8], piece))
            pieces.append(piece if not shift else f"{piece} << {shift}")
            shift += size * 8
        word = pieces[0]
        if len(pieces) > 1:
            word = self.s.names.new("bits")
            self.after.append(f"{word} = {' | '.join(pieces)}")
        for offset, t, target in group:
            if target:
                self.after.append(f"{target} = {self.convert(word, offset, t)}")

    def flush(self) -> None:
        self.close_group()
        run, self.run = self.run, []
        targets = [t for _, t in run if t]
        if targets:
            fmt = "<" + "".join(code for code, _ in run)
            lhs = ", ".join(targets) + ("," if len(targets) == 1 else "")
            self.lines.append(f"{lhs} = {self.s.consts.struct(fmt)}.unpack_from({self.buf}, "
                              f"{self.byte_at(self.run_bits)})")
        self.lines.extend(self.after + self.post)
        self.after, self.post = [], []

    def convert(self, word: str, offset: str | int, t: DsdlType) -> str:
        """The value of a primitive at bit `offset` of the integer `word`."""
        raw = f"{word} >> {offset} & {(1 << t.bits) - 1}" if offset != 0 else f"{word} & {(1 << t.bits) - 1}"
        if t.kind == "bool":
            return f"({raw}) == 1"
        if t.kind == "int":
            return signed_expr(f"({raw})", t.bits)
        if t.kind == "float":
            unpack = self.s.consts.struct("<" + FLOAT_FORMATS[t.bits])
            pack = self.s.consts.struct("<" + UNSIGNED_FORMATS[t.bits])
            return f"{unpack}.unpack({pack}.pack({raw}))[0]"
        return f"({raw})"

    # -- fields
    def prim(self, t: DsdlType, target: str | None) -> None:
        """One primitive (or void) at the current position."""
        if self.bitmode:
            if target:
                self.lines.append(f"{target} = {self.convert(self.bigint(), self.bit_at(self.bits), t)}")
            self.bits += t.bits
            return
        code = STD_FORMATS.get((t.kind, t.bits))
        if code and self.bits % 8 == 0:
            self.close_group()  # a group ends where an aligned standard primitive starts
            self.item(code, t.bits, target)
            return
        if self.group is None:
            self.group, self.group_start = [], self.bits
        self.group.append((self.bits - self.group_start, t, target))
        self.bits += t.bits
        if self.bits % 8 == 0 and not any(tg for _, _, tg in self.group):
            self.close_group()  # a byte boundary: skipped bits become pad bytes

    def read_struct(self, struct_: DsdlStruct, prefix: FieldPath | None) -> None:
        """The fields of a composite, from an aligned position; ends aligned (with the bit length check)."""
        check = has_delimited(struct_, self.s.lookup)
        start = None
        if check:  # where it starts, for the bit length check at its end
            start = self.s.names.new("start")
            self.lines.append(f"{start} = {self.fold()}")
        if struct_.union:
            self.read_union(struct_, prefix)
        else:
            for f in struct_.declared_fields:
                t = f.type
                assert isinstance(t, DsdlType)
                path = None if prefix is None or not f.name else (*prefix, (f.name, None))
                self.read_field(t, path)
        self.align()
        if check and start is not None:
            end = self.fold()
            limit = max_bits(struct_, self.s.lookup) // 8
            self.lines += [f"if {end} - {start} > {limit}:",
                           f"    raise WireError('{struct_.name}: longer than its largest size')"]

    def read_field(self, t: DsdlType, path: FieldPath | None) -> None:
        if t.kind == "composite":
            nested = struct_of(self.s.lookup, t.composite)
            if not t.array:
                self.read_composite(nested, path)
            elif t.array == "fixed":
                records = self.s.want(path, path[-1][0] if path else None)
                if records is not None:
                    self.lines.append(f"{records} = []")
                for i in range(t.capacity or 0):
                    if records is not None:
                        self.read_record(nested, records, path)  # type: ignore[arg-type]
                    else:
                        self.read_composite(nested, None if path is None else elem_path(path, i))
            else:
                self.read_composite_array(nested, t.capacity or 0, path)
        elif t.array == "fixed":
            self.read_fixed(t, path)
        elif t.array == "bounded":
            self.read_var(t, path)
        else:
            self.prim(t, None if t.kind == "void" else self.s.want(path))

    def read_fixed(self, t: DsdlType, path: FieldPath | None) -> None:
        e, n = t.element, t.capacity or 0
        whole = self.s.want(path, path[-1][0] if path else None)
        targets = [self.s.want(elem_path(path, i)) if path else None for i in range(n)]
        if whole:
            targets = [tg or self.s.names.new(f"{path[-1][0]}_{i}") for i, tg in enumerate(targets)]  # type: ignore[index]
        code = STD_FORMATS.get((e.kind, e.bits))
        if code and not self.bitmode and self.bits % 8 == 0 and not any(targets):
            self.close_group()
            self.item(code, e.bits * n, None)  # skipped in one
        else:
            for target in targets:
                self.prim(e, target)
        if whole:
            value = f"[{', '.join(targets)}]"  # type: ignore[arg-type]
            if e.kind == "utf8":
                value = f"memoryview(bytes({value}))"
            (self.lines if self.bitmode else self.post).append(f"{whole} = {value}")

    def read_var(self, t: DsdlType, path: FieldPath | None) -> None:
        e, cap = t.element, t.capacity or 0
        pb = prefix_bits(cap)
        count = self.s.names.new("count")
        target = self.s.want(path, path[-1][0] if path else None)
        fast = not self.bitmode and self.bits % 8 == 0 and (e.kind, e.bits) in STD_FORMATS
        if fast:
            self.close_group()
            self.item(UNSIGNED_FORMATS[pb], pb, count)
            off = self.fold()
            self.check_count(count, cap, t)
            buf = self.buf
            if target is not None:
                if e.kind == "utf8":
                    self.lines.append(f"{target} = memoryview({buf}[{off}:{off} + {count}])")
                elif e.bits == 8 and e.kind in ("uint", "byte"):
                    self.lines.append(f"{target} = list({buf}[{off}:{off} + {count}])")
                else:
                    code = STD_FORMATS[(e.kind, e.bits)]
                    self.lines.append(f"{target} = list(_struct.unpack_from(f'<{{{count}}}{code}', {buf}, {off}))")
            self.lines.append(f"{off} += {count}" + (f" * {e.bits // 8}" if e.bits > 8 else ""))
            return
        self.to_bitmode()
        big = self.bigint()
        self.lines.append(f"{count} = {self.convert(big, self.bit_at(self.bits), DsdlType('uint', pb))}")
        self.check_count(count, cap, t)
        self.bits += pb
        q = self.fold()
        if target is not None:
            if e.kind == "utf8":
                self.lines.append(f"{target} = memoryview(({big} >> {q} & ((1 << 8 * {count}) - 1))"
                                  f".to_bytes({count}, 'little'))")
            else:
                element = self.convert(big, f"({q} + {e.bits} * i)", e)
                self.lines.append(f"{target} = [{element} for i in range({count})]")
        self.lines.append(f"{q} += {count} * {e.bits}" if e.bits > 1 else f"{q} += {count}")

    def check_count(self, count: str, cap: int, t: DsdlType) -> None:
        self.lines += [f"if {count} > {cap}:", f"    raise WireError('array length prefix beyond {t}')"]

    def read_composite(self, nested: DsdlStruct, path: FieldPath | None) -> None:
        self.align()
        if nested.sealed:
            self.read_struct(nested, path)
            return
        self.close_group()
        header = self.s.names.new("length")
        self.item("I", 32, header)
        off = self.fold()
        self.lines += [f"if {header} > {self.size} - {off}:",
                       f"    raise WireError('{nested.name}: delimiter header beyond the payload')"]
        sub = self.s.names.new("nested")
        room = max_bits(nested, self.s.lookup) // 8 + 8
        room_expr = f"{header} + {room}" if has_delimited(nested, self.s.lookup) else str(room)
        self.lines.append(f"{sub} = _extend({self.buf}[{off}:{off} + {header}], {room_expr})")
        inner = _Reader(self.s, sub, header)
        inner.read_struct(nested, path)
        inner.flush()
        self.lines.extend(inner.lines)
        self.lines.append(f"{off} += {header}")

    def read_composite_array(self, nested: DsdlStruct, cap: int, path: FieldPath | None) -> None:
        records = self.s.want(path, path[-1][0] if path else None)
        if records is None and self.s.wants_inside(path):
            raise NotImplementedError(f"{path}: reading into a variable-length array of composites")
        self.align()
        self.close_group()
        count = self.s.names.new("count")
        self.item(UNSIGNED_FORMATS[prefix_bits(cap)], prefix_bits(cap), count)
        off = self.fold()
        self.check_count(count, cap, DsdlType("composite", composite=nested.name, array="bounded", capacity=cap))
        if records is None:
            self.loop(f"for _ in range({count}):", off, lambda r: r.read_composite(nested, None))
            return
        assert path is not None
        self.lines.append(f"{records} = []")
        self.loop(f"for _ in range({count}):", off, lambda r: r.read_record(nested, records, path))

    def read_record(self, nested: DsdlStruct, records: str, path: FieldPath) -> None:
        """One composite of scalar fields appended to the list local `records` as a record: a tuple of its fields
        in declaration order, void padding left out (what the element functions take: targets.wire.element_records)."""
        at = (*path[:-1], (path[-1][0], -1))  # the element being read (no index of a real element is negative)
        fields = self.record_paths(nested, at)
        self.s.wanted.update(fields)
        self.read_composite(nested, at)
        self.flush()  # the fields' struct runs unpacked before they are gathered
        values = {f: self.s.found.pop(f) for f in fields}
        self.s.wanted.difference_update(fields)
        self.s.keep.update(values.values())
        self.lines.append(f"{records}.append({self.record_expr(nested, at, values)})")

    def record_paths(self, struct_: DsdlStruct, at: FieldPath) -> list[FieldPath]:
        """The scalar leaves of a record of `struct_` read at `at` (nested composites: their leaves)."""
        out: list[FieldPath] = []
        for f in struct_.fields:
            t = f.type
            assert isinstance(t, DsdlType)
            if t.array or (t.kind == "composite" and struct_of(self.s.lookup, t.composite).union):
                raise NotImplementedError(f"{struct_.name}: records of composites holding arrays or unions")
            path = (*at, (f.name, None))
            out += self.record_paths(struct_of(self.s.lookup, t.composite), path) if t.kind == "composite" else [path]
        return out

    def record_expr(self, struct_: DsdlStruct, at: FieldPath, values: dict[FieldPath, str]) -> str:
        """The tuple of a record from its leaves' locals (a nested composite a tuple of its own)."""
        items = []
        for f in struct_.fields:
            t, path = f.type, (*at, (f.name, None))
            assert isinstance(t, DsdlType)
            items.append(self.record_expr(struct_of(self.s.lookup, t.composite), path, values)
                         if t.kind == "composite" else values[path])
        return f"({', '.join(items)}{',' if len(items) == 1 else ''})"

    def loop(self, head: str, off: str, body: Callable[[_Reader], None]) -> None:
        """A block read with its own state from the byte offset local `off`, which it leaves advanced."""
        inner = _Reader(self.s, self.buf, self.size)
        inner.var = off
        body(inner)
        inner.align()
        inner.flush()
        end = inner.fold()
        if end != off:
            inner.lines.append(f"{off} = {end}")
        self.lines.append(head)
        self.lines.extend("    " + line for line in inner.lines or ["pass"])

    def read_union(self, union: DsdlStruct, path: FieldPath | None) -> None:
        if self.s.wants_inside(path):
            raise NotImplementedError(f"{path}: reading into a union")
        tag_bits = union_tag_bits(len(union.declared_fields))
        tag = self.s.names.new("tag")
        self.close_group()
        self.item(UNSIGNED_FORMATS[tag_bits], tag_bits, tag)
        off = self.fold()
        variants = union.declared_fields
        self.lines += [f"if {tag} >= {len(variants)}:", f"    raise WireError('{union.name}: bad union tag')"]
        for i, f in enumerate(variants):
            assert isinstance(f.type, DsdlType)
            self.loop(f"{'if' if i == 0 else 'elif'} {tag} == {i}:", off, partial(_read_variant, t=f.type))


def cyphal_reader(struct_: DsdlStruct, wanted: Iterable[FieldPath], lookup: Lookup, names: Names, consts: Constants,
                  payload: str) -> tuple[list[str], dict[FieldPath, str]]:
    """Statements that decode `payload` (a serialized `struct_`) into locals for the `wanted` leaves."""
    shared = _Shared(lookup, names, consts, set(wanted))
    buf, size = names.new("buf"), names.new("size")
    room = max_bits(struct_, lookup) // 8 + 8
    room_expr = f"{size} + {room}" if has_delimited(struct_, lookup) else str(room)
    r = _Reader(shared, buf, size)
    r.lines += [f"{size} = len({payload})", f"{buf} = _extend({payload}, {room_expr})"]
    r.read_struct(struct_, ())
    r.flush()
    missing = shared.wanted - set(shared.found)
    if missing:
        raise ValueError(f"{struct_.name}: no field at {sorted(map(str, missing))}")
    return prune(r.lines, {*shared.found.values(), *shared.keep}), shared.found


def _read_variant(r: _Reader, t: DsdlType) -> None:
    r.read_field(t, None)
