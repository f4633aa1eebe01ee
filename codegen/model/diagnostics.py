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


class SpecError(Exception):
    """The spec is invalid; carries every diagnostic of the run, sorted by position."""

    def __init__(self, diagnostics: list[Diagnostic]) -> None:
        self.diagnostics = sorted(set(diagnostics), key=lambda d: (d.pos, d.message))
        super().__init__("\n".join(str(d) for d in self.diagnostics))


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
