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

from collections.abc import Callable

from sam_codegen.model.expr import (
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
from sam_codegen.render.pysource import py_literal
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.python.statements import Assign, Bound, NanReject, Statement

__all__ = ["ExpressionWriter"]

_INT64_EDGE = py_literal(float(2**63))  # the first float beyond int64 (and -it the last one in it)
LINE_BUDGET = 60  # an operator's operands together (the statement's target and indentation fit beside them)
HOIST_OVER = 20  # an operand longer than this is bound to a local when they do not fit


class ExpressionWriter:
    """Writes one expression: `read(path)` is the reader's expression of a source field."""

    def __init__(self, read: Callable[[tuple], str], names: LocalNames, key: str, reject: bool) -> None:
        self.read, self.names, self.key, self.reject = read, names, key, reject
        self.statements: list[Statement] = []

    def write(self, node: ENode, parent: int = 0) -> str:
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

    def call(self, node: ECall) -> str:
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
