"""The CDR reader of cdr_write (its API and the layout rules are in cdr_write.py's docstring): statements that check
CDR bytes and decode the leaves a codec wants, raising WireError on anything that is not a message of the type.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from sam_codegen.model.spec import RosMessage
from sam_codegen.targets.wire.cdr_layout import PRIM, Leaf, Phase, elem_path, flatten, strip_pads
from sam_codegen.targets.wire.code import Constants, FieldPath, Names, prune

__all__ = ["cdr_reader"]


# ---- reader --------------------------------------------------------------------------------------------------


class _Reader:
    def __init__(self, lookup: Callable[[str], RosMessage | None], names: Names, consts: Constants, buf: str,
                 wanted: set[FieldPath], size: str, var: str | None = None) -> None:
        self.lookup, self.names, self.consts, self.buf = lookup, names, consts, buf
        self.wanted = wanted
        self.found: dict[FieldPath, str] = {}
        self.lines: list[str] = []
        self.phase = Phase()
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
        st = self.consts.struct(strip_pads("<" + "".join(code for code, _ in run)))
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

    def want(self, path: FieldPath, hint: str | None = None) -> str | None:
        if path not in self.wanted:
            return None
        name = self.names.new(hint or "_".join(str(p) for seg in path for p in seg if p is not None))
        self.found[path] = name
        return name

    # -- layout
    def read(self, leaves: list[Leaf]) -> None:
        for leaf in leaves:
            getattr(self, f"read_{leaf.kind}")(leaf)

    def read_prim(self, leaf: Leaf) -> None:
        code, size = PRIM[leaf.base]
        self.align(size)
        self.item(code, size, self.want(leaf.path))

    def read_block(self, leaf: Leaf) -> None:
        code, size = PRIM[leaf.base]
        self.align(size)
        whole = self.want(leaf.path, leaf.path[-1][0])
        if whole is None:
            for i in range(leaf.count):
                self.item(code, size, self.want(elem_path(leaf.path, i)))
            return
        elements = []
        for i in range(leaf.count):
            element = self.found.get(elem_path(leaf.path, i)) or self.want(elem_path(leaf.path, i)) \
                or self.names.new(f"{leaf.path[-1][0]}_{i}")
            elements.append(element)
            self.item("B" if leaf.base == "byte" else code, size, element)  # whole byte arrays: ints
        self.after.append(f"{whole} = [{', '.join(elements)}]")
        if leaf.base == "byte":  # an element read alone is a 1-byte bytes object, as rclpy gives it
            for i in range(leaf.count):
                path = elem_path(leaf.path, i)
                if path in self.found:
                    self.after.append(f"{self.found[path]} = bytes(({self.found[path]},))")

    def count(self, leaf: Leaf, hint: str) -> str:
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

    def read_string(self, leaf: Leaf) -> None:
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

    def read_seq(self, leaf: Leaf) -> None:
        count = self.count(leaf, "count")
        code, size = PRIM[leaf.base]
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

    def read_msgseq(self, leaf: Leaf) -> None:
        """A sequence of messages (or strings) is checked element by element: skipped, or read whole (wanted at its
        own path) into a list of records, each a tuple of the element's leaves in `flatten` order (prim and string
        leaves only: an element message with arrays is not read into one)."""
        whole = leaf.path in self.wanted and leaf.message is not None
        if not whole and any(p[:len(leaf.path)] == leaf.path for p in self.wanted):
            raise NotImplementedError(f"{leaf.path}: reading into a sequence of messages")
        count = self.count(leaf, "count")
        off = self.dynamic()
        leaves = flatten(leaf.message, self.lookup) if leaf.message is not None else [Leaf("string", leaf.path)]
        if whole and any(x.kind not in ("prim", "string") for x in leaves):
            raise NotImplementedError(f"{leaf.path}: reading a sequence of messages that hold arrays")
        wanted = {x.path for x in leaves} if whole else set()
        inner = _Reader(self.lookup, self.names, self.consts, self.buf, wanted, self.size, off)
        inner.phase = Phase(1, 0)  # an element starts wherever the one before ended
        inner.open_segment()
        inner.read(leaves)
        inner.close_segment()
        inner.dynamic()
        target = self.want(leaf.path, leaf.path[-1][0])
        if target is not None:
            record = ", ".join(inner.found[x.path] for x in leaves) + ("," if len(leaves) == 1 else "")
            self.lines.append(f"{target} = []")
            inner.lines.append(f"{target}.append(({record}))")
        self.lines.append(f"for _ in range({count}):")
        self.lines.extend("    " + line for line in inner.lines or ["pass"])
        self.phase.unknown()
        self.open_segment()


def cdr_reader(message: RosMessage, wanted: Iterable[FieldPath], lookup: Callable[[str], RosMessage | None],
               names: Names, consts: Constants, buf: str) -> tuple[list[str], dict[FieldPath, str]]:
    """Statements that check the CDR bytes in `buf` and decode the `wanted` leaves; (lines, path -> local)."""
    wanted = set(wanted)
    r = _Reader(lookup, names, consts, buf, wanted, names.new("size"))
    r.lines += [f"{r.size} = len({buf})",
                f"if {r.size} < 4 or {buf}[0] != 0 or {buf}[1] != 1:",
                "    raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')"]
    r.open_segment()
    r.read(flatten(message, lookup))
    r.close_segment()
    missing = wanted - set(r.found)
    if missing:
        raise ValueError(f"{message.full_name}: no field at {sorted(map(str, missing))}")
    return prune(r.lines, r.found.values()), r.found
