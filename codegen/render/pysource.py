"""Python source literals shared by every target that writes Python (the bridge's tables and converters, the wire
codecs, the nodes): numbers, typed field values, long strings and tuples wrapped within the line limit.

Invariants: every function is pure and deterministic; text from the spec only ever reaches the output through
`py_str` (repr: inert), so a quote, newline or template marker in a description cannot change the code around it.
A literal that must wrap is told the column it starts at (`indent`): where it stands is the caller's (the
template's) decision, how it wraps is this module's.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.spec import Scalar
from sam_codegen.model.types import ROS_FLOAT_BITS
from sam_codegen.render.filters import py_str

__all__ = ["LINE_LIMIT", "PY_FILTERS", "Call", "call_literal", "float_literal", "frozenset_literal", "py_literal",
           "text_literal", "tuple_literal", "typed_literal"]

LINE_LIMIT = 110  # of every generated Python file (ruff's line-length for generated/)


def py_literal(value: Scalar | None) -> str:
    """A Python literal; non-finite floats refer to the module constants _NAN and _INF of the generated module.

    >>> py_literal(1.0), py_literal(float("nan")), py_literal(-float("inf")), py_literal("a'b"), py_literal(2)
    ('1.0', '_NAN', '-_INF', '"a\\'b"', '2')
    """
    if isinstance(value, float):
        if math.isnan(value):
            return "_NAN"
        if math.isinf(value):
            return "_INF" if value > 0 else "-_INF"
    return repr(value)


def typed_literal(value: Scalar, base: str) -> str:
    """A literal of the Python type rclpy / pycyphal keep for a field of primitive type `base`.

    >>> typed_literal(0, "float32"), typed_literal(1, "bool"), typed_literal(7, "byte"), typed_literal(3.0, "int8")
    ('0.0', 'True', "b'\\\\x07'", '3')
    """
    if base in ROS_FLOAT_BITS or base.startswith("float"):
        return py_literal(float(value))
    if base == "bool":
        return py_literal(bool(value))
    if base == "byte":
        return repr(bytes((int(value),)))
    if base in ("string", "wstring"):
        return py_literal(str(value))
    return py_literal(int(value))


def float_literal(value: float) -> str:
    """A float literal; -0.0 written as 0.0 (a rotation of 0 rad gives it).

    >>> float_literal(-0.0), float_literal(2)
    ('0.0', '2.0')
    """
    return repr(float(value) + 0.0)


def text_literal(text: str, indent: int) -> str:
    """A string literal (py_str: repr, inert) starting at column `indent`; long text becomes implicitly
    concatenated chunks in parentheses, one per line.

    >>> text_literal("short", 8)
    "'short'"
    >>> text_literal("word " * 30, 80).splitlines()[:2]
    ['(', "                                                                                    'word word word word '"]
    """
    literal = py_str(text)
    if indent + len(literal) <= LINE_LIMIT - 10:
        return literal
    chunks: list[str] = []
    for word in re.findall(r"\S*\s*", text):
        if chunks and len(py_str(chunks[-1] + word)) + indent + 4 <= LINE_LIMIT - 2:
            chunks[-1] += word
        elif word:
            chunks.append(word)
    pad = " " * (indent + 4)
    return "(\n" + "".join(f"{pad}{py_str(c)}\n" for c in chunks) + " " * indent + ")"


def tuple_literal(items: list[str], indent: int) -> str:
    """A tuple literal of rendered items at column `indent`, on one line if it fits, else one item per line.

    >>> tuple_literal([], 8), tuple_literal(["1"], 8), tuple_literal(["1", "2"], 8)
    ('()', '(1,)', '(1, 2)')
    """
    if not items:
        return "()"
    one = "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"
    if indent + len(one) <= LINE_LIMIT - 30:
        return one
    pad = " " * (indent + 4)
    return "(\n" + "".join(f"{pad}{item},\n" for item in items) + " " * indent + ")"


def frozenset_literal(values: Iterable[int]) -> str:
    """A frozenset of integers, sorted (the output must not depend on set order).

    >>> frozenset_literal([3, 1, 3]), frozenset_literal([])
    ('frozenset({1, 3})', 'frozenset()')
    """
    ordered = sorted(set(values))
    return "frozenset({" + ", ".join(map(str, ordered)) + "})" if ordered else "frozenset()"


@dataclass(frozen=True)
class Call:
    """A call of rendered arguments, `func(arg, ...)`; `keywords` name the arguments when the call wraps."""

    func: str
    args: tuple[str, ...]
    keywords: tuple[str, ...] = ()


def call_literal(call: Call, indent: int, prefix: int = 0) -> str:
    """`call` at column `indent`, after `prefix` characters on its line and before a comma: on one line if it fits,
    else one argument per line.

    >>> call_literal(Call("P", ("1", "2")), 8)
    'P(1, 2)'
    >>> print(call_literal(Call("P", ("1" * 60, "2" * 60), ("a", "b")), 0))
    P(
        a=111111111111111111111111111111111111111111111111111111111111,
        b=222222222222222222222222222222222222222222222222222222222222,
    )
    """
    one = f"{call.func}(" + ", ".join(call.args) + ")"
    if indent + prefix + len(one) + 1 <= LINE_LIMIT:
        return one
    pad = " " * (indent + 4)
    keywords = call.keywords or ("",) * len(call.args)
    lines = "".join(f"{pad}{k + '=' if k else ''}{v},\n" for k, v in zip(keywords, call.args, strict=True))
    return f"{call.func}(\n" + lines + " " * indent + ")"


# The Jinja filters of this module: a template says where a literal starts (`{{ text | text_literal(8) }}`).
PY_FILTERS: dict[str, Callable[..., Any]] = {"text_literal": text_literal, "tuple_literal": tuple_literal,
                                             "call_literal": call_literal}
