"""Mapping expressions (`{expr: "..."}` links and `uavcan_exprs`): the parse tree of the spec's text and the typed
tree that validation builds from it and the conversion plan carries to every renderer.

Invariants:
- the parse tree (P* nodes) is what frontend.expr_parser read, with the column of each node inside the text; it names
  fields by their path text and knows no types;
- the typed tree (E* nodes) is what validate.expressions checked: every node has a `kind` (bool, int or float) and,
  for an int, the range its values lie in (None: the int64 range or unknown); a field is a resolved path with its
  source type. Nothing here is Python: renderers word the tree (targets.python.expressions, targets.docs).
- int arithmetic is exact (no wrap); float arithmetic is IEEE binary64; `/` always gives a float (x / 0 is +-inf,
  0 / 0 NaN); `>>` is an arithmetic shift (floor); trunc() and round() (half to even) take a float into an int64, a
  NaN dropping the message and what lies beyond int64 (infinities too) following the mapping's on_out_of_range.
- float32(x) computes x as C does with `float` operands (issue 27): every float field and constant in x is rounded to
  binary32, every float operation's result too (+ - * / and what mixes an int into a float: the int converted to
  binary32 first); integer sub-expressions stay exact. Its value is a float (a binary32 one).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

from sam_codegen.model.diagnostics import Pos

ValueKind = Literal["bool", "int", "float"]
IntRange = tuple[int, int]
INT64: IntRange = (-(2**63), 2**63 - 1)

# Operators by their spelling in the spec, and the functions it may call with their arity.
BINARY_OPS = {"+": "add", "-": "sub", "*": "mul", "/": "div", "<<": "shl", ">>": "shr",
              "==": "eq", "!=": "ne", "<": "lt", "<=": "le", ">": "gt", ">=": "ge", "and": "and", "or": "or"}
SPELLING = {name: text for text, name in BINARY_OPS.items()}
COMPARISONS = ("eq", "ne", "lt", "le", "gt", "ge")
FUNCTIONS = {"min": 2, "max": 2, "trunc": 1, "round": 1, "int": 1, "abs": 1, "float32": 1}


# ---- parse tree ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PNum:
    value: int | float | bool
    col: int  # 0-based column of the node's first character in the text


@dataclass(frozen=True)
class PName:
    path: str  # a field path, as parse_path reads it
    col: int


@dataclass(frozen=True)
class PUnary:
    op: str  # neg | not
    arg: PNode
    col: int


@dataclass(frozen=True)
class PBinary:
    op: str  # a BINARY_OPS value
    left: PNode
    right: PNode
    col: int  # the operator's column


@dataclass(frozen=True)
class PCall:
    func: str
    args: tuple[PNode, ...]
    col: int


PNode = PNum | PName | PUnary | PBinary | PCall


@dataclass(frozen=True)
class ExprSource:
    """An expression as the spec wrote it: its text, its parse tree, where its first character is."""

    text: str
    tree: PNode
    pos: Pos

    def at(self, col: int) -> Pos:
        """The position of column `col` of the text (a single-line text: the same line)."""
        return Pos(self.pos.file, self.pos.line, self.pos.column + col) if self.pos.line else self.pos


@dataclass(frozen=True)
class UavcanExpr:
    """One `uavcan_exprs` entry of a ROS -> UAVCAN mapping: a UAVCAN field computed from ROS fields."""

    uavcan_path: str
    expr: ExprSource
    pos: Pos
    wrap: bool = False  # `{expr: ..., on_out_of_range: wrap}`: stored modulo 2**bits (FieldLink.wrap)


def names_of(node: PNode) -> list[str]:
    """The field paths a parse tree names (a failed expression's fields are not reported as unmapped again)."""
    if isinstance(node, PName):
        return [node.path]
    if isinstance(node, PUnary):
        return names_of(node.arg)
    if isinstance(node, PBinary):
        return names_of(node.left) + names_of(node.right)
    if isinstance(node, PCall):
        return [n for a in node.args for n in names_of(a)]
    return []


# ---- typed tree --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class EConst:
    value: int | float | bool
    kind: ValueKind
    range: IntRange | None = None


@dataclass(frozen=True)
class EField:
    """A source field: `path` is a tuple of (name, index | Key | None) segments, `source` its DSDL or ROS type."""

    path: tuple[Any, ...]
    text: str
    source: Any
    kind: ValueKind
    range: IntRange | None = None


@dataclass(frozen=True)
class EUnary:
    op: str  # neg | not
    arg: ENode
    kind: ValueKind
    range: IntRange | None = None


@dataclass(frozen=True)
class EBinary:
    op: str
    left: ENode
    right: ENode
    kind: ValueKind
    range: IntRange | None = None
    divisor_may_be_zero: bool = False  # div only: the renderers guard it


@dataclass(frozen=True)
class ECall:
    """min, max, abs; trunc and round (float -> int64, checked at run time); int (bool -> 0 or 1)."""

    func: str
    args: tuple[ENode, ...]
    kind: ValueKind
    range: IntRange | None = None


ENode = EConst | EField | EUnary | EBinary | ECall


def uses_function(node: ENode, func: str) -> bool:
    """Whether the typed tree calls `func` anywhere (float32: the generated support module then defines f32)."""
    stack = [node]
    while stack:
        n = stack.pop()
        if isinstance(n, ECall):
            if n.func == func:
                return True
            stack += n.args
        elif isinstance(n, EUnary):
            stack.append(n.arg)
        elif isinstance(n, EBinary):
            stack += [n.left, n.right]
    return False


def fields_of(node: ENode) -> list[EField]:
    """The fields an expression reads, each path once, in reading order."""
    out: dict[tuple[Any, ...], EField] = {}
    stack = [node]
    while stack:
        n = stack.pop()
        if isinstance(n, EField):
            out.setdefault(n.path, n)
        elif isinstance(n, EUnary):
            stack.append(n.arg)
        elif isinstance(n, EBinary):
            stack += [n.right, n.left]
        elif isinstance(n, ECall):
            stack += reversed(n.args)
    return list(out.values())


_PRECEDENCE = {"or": 1, "and": 2, "not": 3, **dict.fromkeys(COMPARISONS, 4), "shl": 5, "shr": 5, "add": 6,
               "sub": 6, "mul": 7, "div": 7, "neg": 8}


def precedence(op: str) -> int:
    """The binding strength of an operator (higher binds tighter), as the parser reads them."""
    return _PRECEDENCE[op]


def spell(node: ENode, parent: int = 0) -> str:
    """The expression as text in the spec's own syntax (for the docs and messages), minimal parentheses.

    >>> spell(EBinary("shr", EBinary("mul", EConst(2, "int"), EConst(3, "int"), "int"), EConst(1, "int"), "int"))
    '2 * 3 >> 1'
    >>> spell(EBinary("mul", EBinary("add", EConst(2, "int"), EConst(3, "int"), "int"), EConst(1.5, "float"), "float"))
    '(2 + 3) * 1.5'
    """
    if isinstance(node, EConst):
        return ("true" if node.value else "false") if node.kind == "bool" else repr(node.value)
    if isinstance(node, EField):
        return node.text
    if isinstance(node, ECall):
        return f"{node.func}(" + ", ".join(spell(a) for a in node.args) + ")"
    if isinstance(node, EUnary):
        mine = precedence(node.op)
        text = ("not " if node.op == "not" else "-") + spell(node.arg, mine)
    else:
        mine = precedence(node.op)
        # left-associative: the right operand needs parentheses at the same level
        left = mine + 1 if node.op in COMPARISONS else mine  # comparisons do not chain
        text = f"{spell(node.left, left)} {SPELLING[node.op]} {spell(node.right, mine + 1)}"
    return f"({text})" if mine < parent else text
