"""Mapping expressions (model.expr's typed tree, a conversion plan's Evaluate) said in Python, for the object
converters and the wire codecs alike: the reader gives each field's expression, this module the rest.

Invariants: every field read is converted to the plain Python value of its kind (int(), float(), bool()) so that a
library's numpy scalar can never wrap or round differently from the codec's plain values; int arithmetic is Python's
(exact), float arithmetic binary64; a division whose divisor may be zero goes through conversion_support's
`divide` (+-inf, NaN for 0 / 0, as IEEE 754); trunc() and round() are hoisted into statements before the
expression (a NaN drops the message, beyond int64 saturates or rejects under the link's key and policy), so every
trunc()/round() of an expression is evaluated, whichever way `and` / `or` go.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable

from sam_codegen.model.expr import (
    COMPARISONS,
    INT64,
    SPELLING,
    EBinary,
    ECall,
    EConst,
    EField,
    ENode,
    EUnary,
    precedence,
)
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import py_literal
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.python.statements import Assign, Bound, NanReject, Statement

__all__ = ["ExpressionWriter"]


def f32(x: float) -> float:
    """`x` rounded to binary32 (to nearest, ties to even; beyond its range +-inf), as conversion_support.f32."""
    try:
        return float(_F32.unpack(_F32.pack(x))[0])
    except OverflowError:
        return math.copysign(math.inf, x)


def _binary32_exact(t: object) -> bool:
    """Whether a float field of type `t` holds binary32 values already (float16, float32): no rounding needed."""
    if isinstance(t, DsdlType):
        return t.kind == "float" and t.bits <= 32
    return isinstance(t, RosType) and t.base == "float32"

_F32 = struct.Struct("<f")
_INT64_EDGE = py_literal(float(2**63))  # the first float beyond int64 (and -it the last one in it)
LINE_BUDGET = 60  # an operator's operands together (the statement's target and indentation fit beside them)
HOIST_OVER = 20  # an operand longer than this is bound to a local when they do not fit


class ExpressionWriter:
    """Writes one expression: `read(path)` is the reader's expression of a source field."""

    def __init__(self, read: Callable[[tuple], str], names: LocalNames, key: str, reject: bool) -> None:
        self.read, self.names, self.key, self.reject = read, names, key, reject
        self.statements: list[Statement] = []
        self.in_float32 = 0  # inside float32(...): float values are binary32 (model.expr)

    def write(self, node: ENode, parent: int = 0) -> str:
        if self.in_float32 and node.kind == "float":
            return self.binary32(node)
        if isinstance(node, EConst):
            return py_literal(node.value)
        if isinstance(node, EField):
            return f"{node.kind}({self.read(node.path)})"
        if isinstance(node, ECall):
            return self.call(node)
        if isinstance(node, EUnary):
            mine = precedence(node.op)
            text = ("not " if node.op == "not" else "-") + self.write(node.arg, mine)
            return f"({text})" if mine < parent else text
        assert isinstance(node, EBinary)
        if node.op == "div" and node.divisor_may_be_zero:
            return "_support.divide(" + ", ".join(self.fit([self.write(node.left), self.write(node.right)])) + ")"
        mine = precedence(node.op)
        left = mine + 1 if node.op in ("eq", "ne", "lt", "le", "gt", "ge") else mine  # Python chains comparisons
        right = mine + 1
        if node.op == "or":  # `a and b` inside `or` in parentheses (ruff's RUF021: the precedence made clear)
            left = right = precedence("and") + 1
        if self.in_float32 and node.op in COMPARISONS and "float" in (node.left.kind, node.right.kind):
            a, b = self.fit([self.as_binary32(node.left), self.as_binary32(node.right)])  # C compares as float
        else:
            a, b = self.fit([self.write(node.left, left), self.write(node.right, right)])
        text = f"{a} {SPELLING[node.op]} {b}"
        return f"({text})" if mine < parent else text

    def fit(self, parts: list[str]) -> list[str]:
        """Operands whose text together passes LINE_BUDGET: the longer ones bound to locals first (expressions have
        no side effects and raise nothing, so evaluating an operand early changes no result), so that every
        generated line stays within the line limit."""
        if sum(len(p) for p in parts) <= LINE_BUDGET:
            return parts
        out = []
        for part in parts:
            if len(part) > HOIST_OVER:
                var = self.names.new("e")
                self.statements.append(Assign(var, part))
                part = var
            out.append(part)
        return out

    def as_binary32(self, node: ENode) -> str:
        """An operand of a float operation inside float32(): a float one is binary32 already, an int one is
        converted (exactly rounded, as C converts an int to float)."""
        if isinstance(node, EConst) and node.kind == "int" and abs(int(node.value)) <= 2**53:
            return py_literal(f32(float(node.value)))  # exact as a double: rounded once, here
        text = self.write(node)
        return text if node.kind == "float" else f"_support.f32({text})"

    def binary32(self, node: ENode) -> str:
        """A float node inside float32(): its value rounded to binary32 after every operation, as C computes
        with `float` (the double result of one operation on binary32 operands rounds to the same binary32)."""
        if isinstance(node, EConst):
            return py_literal(f32(float(node.value)))  # rounded once, here
        if isinstance(node, EField):
            read = f"float({self.read(node.path)})"
            return read if _binary32_exact(node.source) else f"_support.f32({read})"
        if isinstance(node, EUnary):  # neg: exact in binary32
            return f"(-{self.write(node.arg)})"
        if isinstance(node, ECall):
            if node.func == "float32":
                return self.as_binary32(node.args[0])
            # abs, min, max: exact on binary32 operands
            return f"{node.func}(" + ", ".join(self.fit([self.as_binary32(a) for a in node.args])) + ")"
        assert isinstance(node, EBinary)
        a, b = self.fit([self.as_binary32(node.left), self.as_binary32(node.right)])
        if node.op == "div" and node.divisor_may_be_zero:
            return f"_support.f32_divide({a}, {b})"  # IEEE 754 as C: x / -0.0 is -inf
        return f"_support.f32({a} {SPELLING[node.op]} {b})"

    def call(self, node: ECall) -> str:
        if node.func == "float32":
            self.in_float32 += 1
            try:
                return self.as_binary32(node.args[0])
            finally:
                self.in_float32 -= 1
        if node.func in ("trunc", "round"):
            var = self.names.new(node.func)
            self.statements.append(Assign(var, self.fit([self.write(node.args[0])])[0]))
            self.statements.append(NanReject(var, self.key))
            edge = _INT64_EDGE
            checks = ((f"{var} >= {edge}", str(INT64[1])), (f"{var} < -{edge}", str(INT64[0])))
            convert = "int" if node.func == "trunc" else "round"  # int() truncates toward zero
            self.statements.append(Bound(var, checks, self.key, self.reject, f"{var} = {convert}({var})"))
            return var
        func = node.func
        if func in ("max", "min") and any(a.kind == "float" for a in node.args):
            # IEEE 754-2019 maximum/minimum: a NaN argument gives NaN whichever its place (Python's max() and min()
            # keep their first argument against a NaN), and the NaN result is then rejected and counted.
            func = "_support.maximum" if func == "max" else "_support.minimum"
        return f"{func}(" + ", ".join(self.fit([self.write(a) for a in node.args])) + ")"
