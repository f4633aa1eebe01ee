"""Mapping expressions type- and range-checked: parse tree (model.expr P* nodes) -> typed tree (E* nodes).

`check_expr` resolves every name through the caller (a UAVCAN path in a UAVCAN -> ROS mapping, a ROS path in a
ROS -> UAVCAN one), gives each node its kind (bool, int, float) and each int node the range its values lie in, and
refuses what cannot be computed: arithmetic on a bool (write int(b): 0 or 1), and/or/not on a number, a comparison
of a bool with a number, a shift of a float or by anything but a constant 0..63, trunc()/round() of an int, a
division by a constant 0, integers beyond 128 bits, an expression that reads no field. `check_target` says whether
the result can be stored into the target field (a float into an integer needs trunc() or round(); a bool into a
number needs int()). Errors are ExprError(message, column) with the column of the offending node in the text.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

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
    IntRange,
    PBinary,
    PCall,
    PName,
    PNode,
    PNum,
    PUnary,
    ValueKind,
    spell,
)
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES, DsdlType, RosType
from sam_codegen.validate.mapping_rules import parse_path

__all__ = ["ExprError", "check_expr", "check_target", "value_kind"]

INT_LIMIT = 2**128  # integers an expression may reach (a float holds them; float32 saturates them)


class ExprError(ValueError):
    def __init__(self, message: str, col: int) -> None:
        super().__init__(message)
        self.message, self.col = message, col


def value_kind(t: DsdlType | RosType) -> tuple[ValueKind, IntRange | None] | None:
    """The kind and range of a scalar field an expression may read or set (None: it cannot).

    >>> value_kind(DsdlType("uint", 7)), value_kind(RosType("float32")), value_kind(RosType("string"))
    (('int', (0, 127)), ('float', None), None)
    """
    if isinstance(t, DsdlType):
        if t.array:
            return None
        if t.kind == "bool":
            return "bool", None
        if t.kind in ("int", "uint"):
            return "int", (int(t.range[0]), int(t.range[1]))
        if t.kind == "float":
            return "float", None
        return None
    if t.array or not t.is_primitive:
        return None
    if t.base == "bool":
        return "bool", None
    if t.base in ROS_INT_RANGES and t.base not in ("byte", "char"):
        lo, hi = ROS_INT_RANGES[t.base]
        return "int", (int(lo), int(hi))
    if t.base in ROS_FLOAT_BITS:
        return "float", None
    return None


def _span(values: list[int]) -> IntRange:
    return min(values), max(values)


def _col(node: PNode) -> int:
    return node.col


class _Checker:
    def __init__(self, resolve: Callable[[str], Any]) -> None:
        self.resolve = resolve
        self.fields = 0

    def number(self, node: ENode, at: PNode, what: str) -> ENode:
        if node.kind == "bool":
            raise ExprError(f"{what} is a bool, not a number (write int({spell(node)}) for 0 or 1)", _col(at))
        return node

    def boolean(self, node: ENode, at: PNode, what: str) -> ENode:
        if node.kind != "bool":
            raise ExprError(f"{what} takes a bool, {spell(node)} is {'an int' if node.kind == 'int' else 'a float'}"
                            " (compare it: x != 0)", _col(at))
        return node

    def bounded(self, rng: IntRange, at: PNode) -> IntRange:
        if rng[0] < -INT_LIMIT or rng[1] > INT_LIMIT:
            raise ExprError("the integers of this expression reach beyond 128 bits", _col(at))
        return rng

    def check(self, p: PNode) -> ENode:
        if isinstance(p, PNum):
            if isinstance(p.value, bool):
                return EConst(p.value, "bool")
            if isinstance(p.value, int):
                return EConst(p.value, "int", self.bounded((p.value, p.value), p))
            return EConst(p.value, "float")
        if isinstance(p, PName):
            try:
                t = self.resolve(p.path)
            except ValueError as exc:
                raise ExprError(str(exc), p.col) from None
            found = value_kind(t)
            if found is None:
                raise ExprError(f"{p.path} is {t}; an expression reads bool and numeric scalars", p.col)
            self.fields += 1
            return EField(tuple(parse_path(p.path)), p.path, t, found[0], found[1])
        if isinstance(p, PUnary):
            arg = self.check(p.arg)
            if p.op == "not":
                return EUnary("not", self.boolean(arg, p, "not"), "bool")
            self.number(arg, p.arg, spell(arg))
            return EUnary("neg", arg, arg.kind, None if arg.range is None else (-arg.range[1], -arg.range[0]))
        if isinstance(p, PCall):
            return self.call(p)
        assert isinstance(p, PBinary)
        return self.binary(p)

    def call(self, p: PCall) -> ENode:
        args = tuple(self.check(a) for a in p.args)
        if p.func == "int":
            if args[0].kind != "bool":
                raise ExprError(f"int() takes a bool (0 or 1); for a float write trunc() or round(), "
                                f"{spell(args[0])} is {args[0].kind}", p.col)
            return ECall("int", args, "int", (0, 1))
        for a, pa in zip(args, p.args, strict=True):
            self.number(a, pa, spell(a))
        if p.func == "float32":  # C's float arithmetic (model.expr): a float, rounded to binary32
            return ECall("float32", args, "float")
        if p.func in ("trunc", "round"):
            if args[0].kind != "float":
                raise ExprError(f"{p.func}() takes a float, {spell(args[0])} is an int already", p.col)
            return ECall(p.func, args, "int", INT64)
        if p.func == "abs":
            a = args[0]
            rng = None if a.range is None else (0 if a.range[0] <= 0 <= a.range[1] else min(abs(a.range[0]),
                                                abs(a.range[1])), max(abs(a.range[0]), abs(a.range[1])))
            return ECall("abs", args, a.kind, rng)
        kind: ValueKind = "int" if all(a.kind == "int" for a in args) else "float"
        rng = None
        if kind == "int":
            lows, highs = [a.range[0] for a in args], [a.range[1] for a in args]  # type: ignore[index]
            rng = (min(lows), min(highs)) if p.func == "min" else (max(lows), max(highs))
        return ECall(p.func, args, kind, rng)

    def binary(self, p: PBinary) -> ENode:
        left, right = self.check(p.left), self.check(p.right)
        op, sym = p.op, SPELLING[p.op]
        if op in ("and", "or"):
            self.boolean(left, p.left, f"`{sym}`")
            self.boolean(right, p.right, f"`{sym}`")
            return EBinary(op, left, right, "bool")
        if op in COMPARISONS:
            if (left.kind == "bool") != (right.kind == "bool"):
                raise ExprError(f"`{sym}` compares a bool with a number ({spell(left)} {sym} {spell(right)})", p.col)
            if left.kind == "bool" and op not in ("eq", "ne"):
                raise ExprError(f"`{sym}` orders numbers; bools compare with == and !=", p.col)
            return EBinary(op, left, right, "bool")
        self.number(left, p.left, spell(left))
        self.number(right, p.right, spell(right))
        if op in ("shl", "shr"):
            for side in (left, right):
                if side.kind != "int":
                    raise ExprError(f"`{sym}` shifts integers, {spell(side)} is a float (write trunc() or round() "
                                    "first)", p.col)
            if not isinstance(right, EConst) or not 0 <= int(right.value) <= 63:
                raise ExprError(f"the shift amount must be a constant 0..63, not {spell(right)}", _col(p.right))
            n = int(right.value)
            lo, hi = left.range or INT64
            rng = (lo << n, hi << n) if op == "shl" else (lo >> n, hi >> n)
            return EBinary(op, left, right, "int", self.bounded(rng, p))
        if op == "div":
            if isinstance(right, EConst) and right.value == 0:
                raise ExprError(f"division by zero ({spell(left)} / {spell(right)})", p.col)
            may_be_zero = right.kind == "float" or right.range is None or right.range[0] <= 0 <= right.range[1]
            return EBinary("div", left, right, "float", None, may_be_zero and not isinstance(right, EConst))
        if left.kind == "int" and right.kind == "int":
            (a, b), (c, d) = left.range or INT64, right.range or INT64
            if op == "add":
                rng = (a + c, b + d)
            elif op == "sub":
                rng = (a - d, b - c)
            else:
                rng = _span([a * c, a * d, b * c, b * d])
            return EBinary(op, left, right, "int", self.bounded(rng, p))
        return EBinary(op, left, right, "float")


def check_expr(tree: PNode, resolve: Callable[[str], Any]) -> ENode:
    """The typed tree of a parse tree; `resolve(path text)` gives a field's type or raises ValueError (the
    message). Raises ExprError."""
    checker = _Checker(resolve)
    typed = checker.check(tree)
    if checker.fields == 0:
        raise ExprError("the expression reads no field (a constant is a `value`, or an entry of uavcan_values)", 0)
    return typed


def check_target(node: ENode, target: DsdlType | RosType, name: str) -> None:
    """Whether the expression's value can be stored into `target` (field `name`); raises ExprError at column 0."""
    found = value_kind(target)
    if found is None:
        raise ExprError(f"an expression sets a bool or numeric scalar, {name} is {target}", 0)
    kind = found[0]
    if kind == "bool" and node.kind != "bool":
        raise ExprError(f"{name} is a bool: the expression must give a bool (a comparison), it gives "
                        f"{'an int' if node.kind == 'int' else 'a float'}", 0)
    if kind != "bool" and node.kind == "bool":
        raise ExprError(f"{name} is {target}, the expression gives a bool (write int(...) for 0 or 1)", 0)
    if kind == "int" and node.kind == "float":
        raise ExprError(f"{name} is {target}, the expression gives a float (write trunc(...) or round(...))", 0)
