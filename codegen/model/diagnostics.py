"""Spec errors with source positions, collected so that one run reports all of them."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, order=True)
class Pos:
    """A 1-based position in a source file."""

    file: str
    line: int = 0
    column: int = 0

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}" if self.line else self.file


NOWHERE = Pos("")


@dataclass(frozen=True)
class Diagnostic:
    pos: Pos
    message: str
    expected: str | None = None

    def __str__(self) -> str:
        text = f"{self.pos}: error: {self.message}"
        return f"{text} (expected {self.expected})" if self.expected else text


# The most errors shown of one spec: 5 MB of junk keys are 260,000 errors (0.5 GB of output), and past the first
# screenful nobody reads them; the rest is counted on one line.
MAX_SHOWN = 50


class SpecError(Exception):
    """The spec is invalid; carries every diagnostic of the run, sorted by position. Its text (and `lines`) shows
    at most MAX_SHOWN of them and then `... and N more errors`."""

    def __init__(self, diagnostics: list[Diagnostic]) -> None:
        # (the key in plain tuples: Pos's generated comparisons took 30 s for the 260,000 errors of 5 MB of junk)
        self.diagnostics = sorted(set(diagnostics), key=lambda d: (d.pos.file, d.pos.line, d.pos.column, d.message))
        super().__init__("\n".join(self.lines()))

    def lines(self, limit: int = MAX_SHOWN) -> list[str]:
        """The diagnostics as text, the first `limit` of them, then one line counting the rest."""
        shown = [str(d) for d in self.diagnostics[:limit]]
        rest = len(self.diagnostics) - limit
        return shown + ([f"... and {rest:,} more error{'s' if rest != 1 else ''}"] if rest > 0 else [])


@dataclass
class Diagnostics:
    """Collects errors; `check()` raises them together."""

    items: list[Diagnostic] = field(default_factory=list)

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.items.append(Diagnostic(pos, message, expected))

    def __bool__(self) -> bool:
        return bool(self.items)

    def check(self) -> None:
        if self.items:
            raise SpecError(self.items)
