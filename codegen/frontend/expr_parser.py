"""The mapping expressions' own small parser: spec text -> parse tree (model.expr), never eval or Python's ast.

Grammar (loosest first; binary operators left-associative, comparisons do not chain):

    expr    := or
    or      := and ("or" and)*
    and     := not ("and" not)*
    not     := "not" not | compare
    compare := shift (("==" | "!=" | "<" | "<=" | ">" | ">=") shift)?
    shift   := sum (("<<" | ">>") sum)*
    sum     := product (("+" | "-") product)*
    product := unary (("*" | "/") unary)*
    unary   := "-" unary | atom
    atom    := number | "true" | "false" | path | function "(" expr ("," expr)* ")" | "(" expr ")"

A path is a field path (`a.b[2].c`, `commands[actuator_id=4].command_value`); numbers are decimal (`12`, `0.5`,
`1e-3`). Invariants: every error is an ExprSyntaxError with the 0-based column it happened at; the text is at most
MAX_LENGTH characters and nests at most MAX_DEPTH levels (so no input exhausts the stack).
"""

from __future__ import annotations

import re
from collections.abc import Callable

from sam_codegen.model.expr import BINARY_OPS, FUNCTIONS, PBinary, PCall, PName, PNode, PNum, PUnary

__all__ = ["MAX_DEPTH", "MAX_LENGTH", "ExprSyntaxError", "parse_expr"]

MAX_LENGTH = 500
MAX_DEPTH = 32

_SEG = r"[A-Za-z_][A-Za-z0-9_]*(?:\[(?:[0-9]+|[A-Za-z_][A-Za-z0-9_]*=-?[0-9]+)\])?"
_TOKEN = re.compile(
    r"\s*(?:(?P<number>(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?(?![A-Za-z_0-9.]))"
    rf"|(?P<path>{_SEG}(?:\.{_SEG})*)"
    r"|(?P<op><<|>>|<=|>=|==|!=|[-+*/<>(),])"
    r"|(?P<bad>\S))"
)
_KEYWORDS = {"and", "or", "not", "true", "false"}
_HINTS = {"&": "`and`", "|": "`or`", "!": "`not`", "=": "`==`", "%": "trunc() or a shift", "^": "`*`"}


class ExprSyntaxError(ValueError):
    def __init__(self, message: str, col: int) -> None:
        super().__init__(message)
        self.message, self.col = message, col


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.tokens: list[tuple[str, str, int]] = []  # (kind, text, column)
        pos = 0
        while text[pos:].strip():
            match = _TOKEN.match(text, pos)
            assert match is not None and match.lastgroup is not None  # `bad` takes any other character
            kind = match.lastgroup
            value = match[kind]
            col = match.start(kind)
            if kind == "bad":
                hint = _HINTS.get(value)
                raise ExprSyntaxError(f"unexpected {value!r}" + (f" (write {hint})" if hint else ""), col)
            if kind == "path" and value in _KEYWORDS:
                kind = "op"
            self.tokens.append((kind, value, col))
            pos = match.end()
        self.i = 0
        self.depth = 0

    def peek(self) -> tuple[str, str, int]:
        return self.tokens[self.i] if self.i < len(self.tokens) else ("end", "", len(self.text.rstrip()))

    def take(self, *ops: str) -> tuple[str, str, int] | None:
        tok = self.peek()
        if tok[0] == "op" and tok[1] in ops:
            self.i += 1
            return tok
        return None

    def expect(self, op: str, what: str) -> None:
        if self.take(op) is None:
            tok = self.peek()
            found = "the end" if tok[0] == "end" else repr(tok[1])
            raise ExprSyntaxError(f"expected {what}, found {found}", tok[2])

    def nested(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExprSyntaxError(f"the expression nests deeper than {MAX_DEPTH} levels", self.peek()[2])

    def parse(self) -> PNode:
        if not self.tokens:
            raise ExprSyntaxError("the expression is empty", 0)
        node = self.or_()
        tok = self.peek()
        if tok[0] != "end":
            raise ExprSyntaxError(f"unexpected {tok[1]!r} after a complete expression", tok[2])
        return node

    def left_assoc(self, ops: tuple[str, ...], operand: Callable[[], PNode]) -> PNode:
        node = operand()
        while (tok := self.take(*ops)) is not None:
            node = PBinary(BINARY_OPS[tok[1]], node, operand(), tok[2])
        return node

    def or_(self) -> PNode:
        return self.left_assoc(("or",), self.and_)

    def and_(self) -> PNode:
        return self.left_assoc(("and",), self.not_)

    def not_(self) -> PNode:
        tok = self.take("not")
        if tok is not None:
            self.nested()
            node = PUnary("not", self.not_(), tok[2])
            self.depth -= 1
            return node
        return self.compare()

    def compare(self) -> PNode:
        node = self.shift()
        tok = self.take("==", "!=", "<", "<=", ">", ">=")
        if tok is None:
            return node
        node = PBinary(BINARY_OPS[tok[1]], node, self.shift(), tok[2])
        again = self.peek()
        if again[0] == "op" and again[1] in ("==", "!=", "<", "<=", ">", ">="):
            raise ExprSyntaxError("comparisons do not chain (write `a < b and b < c`)", again[2])
        return node

    def shift(self) -> PNode:
        return self.left_assoc(("<<", ">>"), self.sum)

    def sum(self) -> PNode:
        return self.left_assoc(("+", "-"), self.product)

    def product(self) -> PNode:
        return self.left_assoc(("*", "/"), self.unary)

    def unary(self) -> PNode:
        tok = self.take("-")
        if tok is not None:
            self.nested()
            node = PUnary("neg", self.unary(), tok[2])
            self.depth -= 1
            return node
        return self.atom()

    def atom(self) -> PNode:
        kind, value, col = self.peek()
        if kind == "number":
            self.i += 1
            number = float(value) if any(c in value for c in ".eE") else int(value)
            if number in (float("inf"), float("-inf")):
                raise ExprSyntaxError(f"the number {value} is beyond a float64", col)
            return PNum(number, col)
        if kind == "op" and value in ("true", "false"):
            self.i += 1
            return PNum(value == "true", col)
        if kind == "op" and value == "(":
            self.i += 1
            self.nested()
            node = self.or_()
            self.depth -= 1
            self.expect(")", "')'")
            return node
        if kind == "path":
            self.i += 1
            if self.take("(") is None:
                return PName(value, col)
            if value not in FUNCTIONS:
                raise ExprSyntaxError(f"unknown function {value!r} (expected one of "
                                      + ", ".join(sorted(FUNCTIONS)) + ")", col)
            self.nested()
            args = [self.or_()]
            while self.take(",") is not None:
                args.append(self.or_())
            self.depth -= 1
            self.expect(")", "')' or ','")
            if len(args) != FUNCTIONS[value]:
                raise ExprSyntaxError(f"{value}() takes {FUNCTIONS[value]} argument"
                                      f"{'s' if FUNCTIONS[value] > 1 else ''}, not {len(args)}", col)
            return PCall(value, tuple(args), col)
        found = "the end" if kind == "end" else repr(value)
        raise ExprSyntaxError(f"expected a field, a number or '(', found {found}", col)


def parse_expr(text: str) -> PNode:
    """Parse an expression; raises ExprSyntaxError(message, column).

    >>> parse_expr("position == 100")
    PBinary(op='eq', left=PName(path='position', col=0), right=PNum(value=100, col=12), col=9)
    >>> parse_expr("(alpha * r) >> 3").op, parse_expr("int(data)").func
    ('shr', 'int')
    """
    if len(text) > MAX_LENGTH:
        raise ExprSyntaxError(f"the expression is longer than {MAX_LENGTH} characters", MAX_LENGTH)
    if "\n" in text.strip():
        raise ExprSyntaxError("an expression is one line", text.index("\n"))
    return _Parser(text).parse()
