"""Utilities of the generated wire codecs' code, shared by cdr_write, cyphal_read and the DroneCAN codec: the
module-level constants generated code refers to, the literals it packs at generation time, its line wrapping,
and the pruning of assignments nothing reads."""

from __future__ import annotations

import ast
import itertools
import math
import re
import struct
from collections.abc import Iterable
from typing import Any, Protocol

from sam_codegen.render.pysource import LINE_LIMIT

__all__ = ["LINE_LIMIT", "NO_VALUE", "Constants", "FieldPath", "Names", "cdr_string", "literal_value", "prune",
           "runs_of", "wrap_line"]

# A path into a message: (field name, index or None) per level, as mapping_rules gives them.
FieldPath = tuple[tuple[str, Any], ...]


class Names(Protocol):
    def new(self, hint: str) -> str: ...


class Constants:
    """Module-level constants of a generated codec: structs and byte strings, named in order of first use.

    >>> c = Constants("_C")
    >>> c.struct("<id"), c.struct("<id"), c.data(b"ab"), c.lines()
    ('_C0', '_C0', '_C1', ["_C0 = _struct.Struct('<id')", "_C1 = b'ab'"])

    Some depend on the run's frame prefix (the vehicle's namespace, given when the bridge starts): a frame id, the
    CDR string of one, and the structs and bytes whose padding follows one (the CDR alignment after a string depends
    on its length: ``variants`` of them, by the prefix's length modulo 8). They are defined at module level for the
    empty prefix, as the spec has them, and again by the module's ``bind(frame_prefix)`` (``bind_lines``), once
    per run: per message there is no extra work.

    >>> c.bound_data([b"a", b"b"] * 4), c.lines()[-1], c.bind_lines()[-1]
    ('_C2', "_C2 = b'a'", "    _C2 = (b'a', b'b', b'a', b'b', b'a', b'b', b'a', b'b')[shift]")
    >>> s = c.bound_struct(["<d{}s"] * 8, [c.framed_string("odom")])
    >>> print(*c.lines()[-1:], *c.bind_lines()[-2:], sep="\\n")
    _C4 = _struct.Struct('<d9s')
        _C3 = _cdr_string(frame_prefix + 'odom')
        _C4 = _struct.Struct('<d{}s'.format(len(_C3)))
    """

    def __init__(self, prefix: str = "_K") -> None:
        self.prefix = prefix
        self._names: dict[str, str] = {}  # expression (a bound one's: with its bind expression) -> name
        self._exprs: dict[str, str] = {}  # name -> its module-level expression
        self._bound: dict[str, str] = {}  # name -> its expression in bind(frame_prefix)
        self._frames: dict[str, str] = {}  # frame id expression (frame_id) -> the spec's frame id
        self._frame_names: dict[str, str] = {}  # the reverse
        self.imports: set[str] = set()  # optional imports the code uses ("array"): the module imports them

    def named(self, expr: str, bound: str | None = None) -> str:
        key = expr if bound is None else f"{expr}\n{bound}"
        if key not in self._names:
            self._names[key] = name = f"{self.prefix}{len(self._names)}"
            self._exprs[name] = expr
            if bound is not None:
                self._bound[name] = bound
        return self._names[key]

    def struct(self, fmt: str) -> str:
        return self.named(f"_struct.Struct({fmt!r})")

    def data(self, value: bytes) -> str:
        return self.named(repr(value))

    # -- what depends on the frame prefix
    def frame_id(self, frame: str) -> str:
        """The expression of a frame id the spec gives (the frame prefix before it): a name the CDR writer
        recognises (frame_of: it writes the precomputed CDR string) and anything else reads as a string."""
        if frame not in self._frame_names:
            self._frame_names[frame] = name = f"{self.prefix}F{len(self._frames)}"
            self._frames[name] = frame
        return self._frame_names[frame]

    def frame_of(self, expr: str) -> str | None:
        """The frame id `expr` stands for (see frame_id), else None."""
        return self._frames.get(expr)

    def use_frames(self, exprs: Iterable[str]) -> None:
        """Define the frame ids among `exprs` (as strings: an element record holds them) in the module."""
        for expr in exprs:
            frame = self._frames.get(expr)
            if frame is not None and expr not in self._bound:
                self._names[f"{frame!r}\n{expr}"] = expr
                self._exprs[expr] = repr(frame)
                self._bound[expr] = f"frame_prefix + {frame!r}"

    def framed_string(self, frame: str) -> str:
        """The CDR string (uint32 length with the NUL, the bytes, NUL) of the frame id `frame` after the prefix."""
        return self.named(repr(cdr_string(frame)), f"_cdr_string(frame_prefix + {frame!r})")

    def bound_struct(self, fmts: list[str], frames: list[str]) -> str:
        """A struct whose format depends on the prefix: `fmts` by its length modulo 8 (the padding), each ``{}``
        in them the length of a frame id's CDR string, the bytes constants `frames` (framed_string) in order."""
        lengths = [len(ast.literal_eval(self._exprs[name])) for name in frames]
        fmt = fmts[0] if len(set(fmts)) == 1 else f"{tuple(fmts)!r}[shift]"
        return self.named(f"_struct.Struct({fmts[0].format(*lengths)!r})",
                          f"_struct.Struct({fmt if fmt != fmts[0] else repr(fmt)}.format("
                          f"{', '.join(f'len({name})' for name in frames)}))")

    def bound_data(self, values: list[bytes]) -> str:
        """Bytes that depend on the prefix's length: `values` by that length modulo 8."""
        return self.named(repr(values[0]), f"{tuple(values)!r}[shift]")

    def lines(self) -> list[str]:
        out = []
        for name, expr in self._exprs.items():
            line = f"{name} = {expr}"
            if len(line) > LINE_LIMIT and expr.startswith("b"):  # long bytes: implicitly joined chunks
                data = ast.literal_eval(expr)
                chunks = [data[i:i + 20] for i in range(0, len(data), 20)]
                out += [f"{name} = (", *(f"    {chunk!r}" for chunk in chunks), ")"]
            else:
                out.append(line)
        return out

    def bind_lines(self) -> list[str]:
        """The module's ``bind(frame_prefix)``: its frame prefix, and the constants above that depend on it."""
        names = sorted(self._bound, key=lambda n: (len(n), n))
        out = []
        if any(e.startswith("_cdr_string(") for e in self._bound.values()):
            out += ["def _cdr_string(text: str) -> bytes:",
                    "    data = text.encode()",
                    "    return _struct.pack('<I', len(data) + 1) + data + b'\\0'", "", ""]
        out += ["def bind(frame_prefix: str) -> None:",
               '    """Make this module\'s codecs write `frame_prefix` (a namespace\'s, "sam1/") before every frame '
               'id: the',
               "    constants that depend on it computed once. One module object serves one prefix: a run with "
               "another loads",
               '    a copy of the module (sam_runtime.genpkg)."""',
               *_statements("    global ", ["FRAME_PREFIX", *names])]
        if any("[shift]" in self._bound[n] for n in names):
            out.append("    shift = len(frame_prefix.encode()) % 8  # the CDR padding after a frame id depends on it")
        out.append("    FRAME_PREFIX = frame_prefix")
        for name in names:
            out.extend(wrap_line(f"    {name} = {self._bound[name]}", LINE_LIMIT))
        return out


def _statements(head: str, names: list[str]) -> list[str]:
    """`head` (``global``) with `names`, as many statements as the line limit needs.

    >>> _statements("global ", ["a" * 70, "b" * 70, "c"])[1:] == ["global " + "b" * 70 + ", c"]
    True
    """
    out: list[str] = []
    for name in names:
        if out and len(out[-1]) + 2 + len(name) <= LINE_LIMIT:
            out[-1] += f", {name}"
        else:
            out.append(head + name)
    return out


def cdr_string(text: str) -> bytes:
    """A CDR string: uint32 length including the NUL, the UTF-8 bytes, NUL (what the module's _cdr_string gives).

    >>> cdr_string("ab")
    b'\\x03\\x00\\x00\\x00ab\\x00'
    """
    data = text.encode()
    return struct.pack("<I", len(data) + 1) + data + b"\0"


_SPECIAL = {"_NAN": math.nan, "_INF": math.inf, "-_INF": -math.inf}
NO_VALUE = object()


def runs_of(items: Iterable[Any], atom: type) -> Iterable[Any]:
    """The items in order, each run of consecutive `atom` instances gathered into one list (code for a run of
    fixed-size fields is one struct call).

    >>> list(runs_of([1, 2, "x", 3, "y", "z"], int))
    [[1, 2], 'x', [3], 'y', 'z']
    """
    run: list[Any] = []
    for item in items:
        if isinstance(item, atom):
            run.append(item)
            continue
        if run:
            yield run
            run = []
        yield item
    if run:
        yield run


def literal_value(expr: str) -> Any:
    """The value of a literal expression (as py_literal writes them), else a marker that it is not one.

    >>> literal_value("-1.0"), literal_value("'a'"), literal_value("_NAN") != literal_value("_NAN")
    (-1.0, 'a', True)
    >>> literal_value("x") is NO_VALUE, literal_value("receive_ns // 1") is NO_VALUE
    (True, True)
    """
    if expr in _SPECIAL:
        return _SPECIAL[expr]
    try:
        return ast.literal_eval(expr)
    except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
        return NO_VALUE


def _scan(text: str) -> list[tuple[int, str, int]]:
    """The brackets, commas and operators (|, +) of code outside string literals: (position, what, depth), the
    depth of a closing bracket being that after it."""
    out, depth, i, quote = [], 0, 0, ""
    while i < len(text):
        c = text[i]
        if quote:
            if c == "\\":
                i += 1
            elif c == quote:
                quote = ""
        elif c in "'\"":
            quote = c
        elif c in "([{":
            out.append((i, c, depth))
            depth += 1
        elif c in ")]}":
            depth -= 1
            out.append((i, c, depth))
        elif c == ",":
            out.append((i, c, depth))
        elif text[i:i + 3] in (" | ", " + "):
            out.append((i, text[i + 1], depth))
        i += 1
    return out


def _split(text: str, what: str) -> list[str]:
    """`text` cut at its top-level `what` (',' drops it; '|' and '+' stay at the start of the next part).

    >>> _split("a, f(b, c), 'd, e'", ","), _split("a | f(b | c) + 'x | y'", "|+")
    (['a', 'f(b, c)', "'d, e'"], ['a', '| f(b | c)', "+ 'x | y'"])
    """
    cuts = [pos for pos, c, depth in _scan(text) if c in what and depth == 0]
    if what == ",":
        bounds = [-1, *cuts, len(text)]
        parts = [text[a + 1:b] for a, b in itertools.pairwise(bounds)]
    else:  # cut at the space before the operator, which starts the next part
        bounds = [0, *[c + 1 for c in cuts], len(text)]
        parts = [text[a:b] for a, b in itertools.pairwise(bounds)]
    return [p.strip() for p in parts if p.strip()]


def wrap_line(line: str, width: int = LINE_LIMIT) -> list[str]:
    """A generated statement in lines of at most `width`, as a formatter would break it: a tuple of targets, then
    the top-level items of its expression, its operands (| and +), or the arguments of its first call, in a
    block indented by 4; as it is when it fits or cannot be broken.

    >>> wrap_line("a, b, c = f(x)", 10)
    ['(', '    a, b,', '    c,', ') = f(x)']
    >>> wrap_line("return g(aaaa, 'b, c)', d) + h", 16)
    ['return (', '    g(', '        aaaa,', "        'b, c)',", '        d,', '    )', '    + h', ')']
    """
    if len(line) <= width:
        return [line]
    pad = line[:len(line) - len(line.lstrip())]
    inner = pad + "    "
    body = line.strip()
    head, expr = "", body
    if body.startswith("return "):
        head, expr = "return ", body[7:]
    else:
        assign = next((pos for pos, c, depth in _scan(body) if depth == 0 and c in "([{"), len(body))
        eq = body.find(" = ", 0, assign)
        if eq > 0 and "," in body[:eq]:  # tuple targets
            targets = [t.strip() for t in body[:eq].split(",") if t.strip()]
            return [f"{pad}(", *_pack(targets, inner, width), *wrap_line(f"{pad}) = {body[eq + 3:]}", width)]
        for op in (" += ", " = "):
            at = body.find(op, 0, assign)
            if at > 0:
                head, expr = body[:at + len(op)], body[at + len(op):]
                break
    items = _split(expr, ",")
    if len(items) > 1:
        return [f"{pad}{head}(", *_pack(items, inner, width), f"{pad})"]
    operands = _split(expr, "|+")
    if len(operands) > 1:
        out = [f"{pad}{head}("]
        for operand in operands:
            out.extend(wrap_line(inner + operand, width))
        return [*out, f"{pad})"]
    marks = _scan(expr)
    opening = next((pos for pos, c, depth in marks if c in "([" and depth == 0), None)
    if opening is None:
        return [line]
    end = next((pos for pos, c, depth in marks if pos > opening and c in ")]" and depth == 0), None)
    if end is None:
        return [line]
    args = _split(expr[opening + 1:end], ",")
    packed = _pack(args, inner, width)
    call = expr[opening] == "(" and opening > 0 and (expr[opening - 1].isalnum() or expr[opening - 1] in "_)]")
    if len(args) == 1 and not call:  # a group, subscript or display of one item: a comma would make a tuple
        packed[-1] = packed[-1].removesuffix(",")
    return [f"{pad}{head}{expr[:opening + 1]}", *packed, *wrap_line(pad + expr[end:], width)]


def _pack(items: list[str], indent: str, width: int) -> list[str]:
    """Items with their commas, as many per line as fit; an item too long alone is broken itself."""
    lines: list[str] = []
    line = ""
    for item in items:
        if line and len(indent) + len(line) + 1 + len(item) + 1 > width:
            lines.append(indent + line)
            line = ""
        line = f"{line} {item}," if line else f"{item},"
    if line:
        lines.append(indent + line)
    out: list[str] = []
    for one in lines:
        if len(one) <= width:
            out.append(one)
            continue
        item = one.strip()[:-1]
        operands = _split(item, "|+")
        if len(operands) > 1:  # an expression alone: in brackets of its own, an operand a line
            out.append(indent + "(")
            for operand in operands:
                out.extend(wrap_line(indent + "    " + operand, width))
            out.append(indent + "),")
            continue
        wrapped = wrap_line(indent + item, width)
        out.extend([*wrapped[:-1], wrapped[-1] + ","])
    return out


_ASSIGN = re.compile(r"^(\s*)([A-Za-z_][A-Za-z0-9_]*) (?:\+)?= ")


def prune(lines: list[str], keep: Iterable[str]) -> list[str]:
    """Drop the assignments of a reader's locals that nothing reads (a last offset update, a buffer of a nested
    composite nothing is read from); `keep` are the locals the caller reads.

    >>> prune(["o = 4", "x, = f(b, o)", "o += 2", "n = g(b)", "for _ in range(x):", "    o += 1", "    m = 0"], ["x"])
    ['o = 4', 'x, = f(b, o)', 'o += 2', 'for _ in range(x):', '    o += 1']
    """
    keep = set(keep)
    out = list(lines)
    changed = True
    while changed:
        changed = False
        for i in range(len(out) - 1, -1, -1):
            match = _ASSIGN.match(out[i])
            if not match or match[2] in keep:
                continue
            word = re.compile(rf"\b{match[2]}\b")
            elsewhere = any(word.search(line) for j, line in enumerate(out) if j != i)
            later = any(word.search(line) for line in out[i + 1:])
            if not elsewhere or (not match[1] and not later):
                del out[i]
                changed = True
    return out
