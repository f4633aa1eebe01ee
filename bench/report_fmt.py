"""How bench/run.py's reports write figures: numbers, ranges, verdicts, markdown tables."""

from __future__ import annotations

import math
from typing import Any


def num(x: Any, digits: int = 2) -> str:
    """A figure with thousands separators; ``-`` for none.

    >>> num(1234.5), num(1234), num(None), num(float("nan"))
    ('1,234.50', '1,234', '-', '-')
    """
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, float):
        return f"{x:,.{digits}f}"
    if isinstance(x, int):
        return f"{x:,}"
    return str(x)


def spread(runs: list[float] | None) -> str:
    """` (0.74-0.93)`: the range of the repetitions' ratios, where there are several.

    >>> spread([0.93, 0.74]), spread([1.0])
    (' (0.74-0.93)', '')
    """
    return f" ({min(runs):.2f}-{max(runs):.2f})" if runs and len(runs) > 1 else ""


def span(xs: list[float]) -> str:
    """`87` or `87-98`.

    >>> span([87.2, 97.9]), span([87.0])
    ('87-98', '87')
    """
    lo, hi = f"{min(xs):.0f}", f"{max(xs):.0f}"
    return lo if lo == hi else f"{lo}-{hi}"


def ok(flag: bool | None) -> str:
    """The verdict of a target.

    >>> ok(True), ok(False), ok(None)
    ('met', '**missed**', '-')
    """
    return "-" if flag is None else ("met" if flag else "**missed**")


def table(header: list[str], rows: list[list[str]]) -> str:
    """A markdown table.

    >>> print(table(["a", "b"], [["1", "2"]]))
    | a | b |
    |---|---|
    | 1 | 2 |
    """
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)
