"""Dataclass fields that are also command-line options: a field's metadata holds its flags and help, so the options
are defined once (their type, default and meaning) and the argparse options, the values read back from them and the
argv another process is given are derived from that definition.

>>> from dataclasses import dataclass, field
>>> @dataclass(frozen=True)
... class Options:
...     rate: float = field(default=5.0, metadata=cli_field(
...         Flag("--rate", "samples per second (default 5)", type=float), value=lambda a: a.rate))
>>> p = argparse.ArgumentParser()
>>> add_flags(p, Options)
>>> args = p.parse_args(["--rate", "2"])
>>> options_from(Options, args), forwarded_argv(Options, args)
({'rate': 2.0}, ['--rate', '2.0'])
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterator
from dataclasses import MISSING, Field, dataclass, fields
from typing import Any

__all__ = ["CliField", "Flag", "add_flags", "cli_field", "float_list", "forwarded_argv", "options_from"]

METADATA_KEY = "cli"


def _same(value: Any) -> Any:
    return value


@dataclass(frozen=True)
class Flag:
    """One option of a field (a field may take several: the sea floor's depth or profile and its axis)."""

    name: str  # e.g. "--battery-start"
    help: str
    metavar: str | None = None
    type: Callable[[str], Any] | None = None  # argparse's; None: the text as given
    default: Callable[[Any], Any] = _same  # the field's default -> the option's (e.g. a tuple -> "0,0,0,0")
    main_job: bool = True  # also an option of the main job (`sam-codegen run`), which passes it on to its sim
    forwarded: bool = True  # the main job passes it on

    @property
    def dest(self) -> str:
        return self.name.lstrip("-").replace("-", "_")


@dataclass(frozen=True)
class CliField:
    flags: tuple[Flag, ...]
    value: Callable[[argparse.Namespace], Any]  # the field's value from the parsed options (ValueError: one line)


def cli_field(*flags: Flag, value: Callable[[argparse.Namespace], Any]) -> dict[str, CliField]:
    """A field's metadata: ``field(default=..., metadata=cli_field(Flag(...), value=...))``."""
    return {METADATA_KEY: CliField(flags, value)}


def _cli_fields(cls: type) -> Iterator[tuple[Field[Any], CliField]]:
    for f in fields(cls):
        if METADATA_KEY in f.metadata:
            yield f, f.metadata[METADATA_KEY]


def _default(f: Field[Any]) -> Any:
    if f.default is not MISSING:
        return f.default
    assert f.default_factory is not MISSING, f"{f.name} has no default"
    return f.default_factory()


def add_flags(group: Any, cls: type, *, main_job: bool = False) -> None:
    """The options of ``cls``'s fields, in field order, into an argparse parser or group."""
    for f, cli in _cli_fields(cls):
        for flag in cli.flags:
            if main_job and not flag.main_job:
                continue
            extra: dict[str, Any] = {"metavar": flag.metavar} if flag.metavar is not None else {}
            if flag.type is not None:
                extra["type"] = flag.type
            group.add_argument(flag.name, default=flag.default(_default(f)), help=flag.help, **extra)


def options_from(cls: type, args: argparse.Namespace) -> dict[str, Any]:
    """The fields' values from parsed options (a field whose options the parser lacks keeps its default)."""
    return {f.name: cli.value(args) for f, cli in _cli_fields(cls)
            if all(hasattr(args, flag.dest) for flag in cli.flags)}


def forwarded_argv(cls: type, args: argparse.Namespace) -> list[str]:
    """The forwarded options as another process's argv (each as given: text as is, numbers by repr)."""
    out = []
    for _, cli in _cli_fields(cls):
        for flag in cli.flags:
            if flag.forwarded and hasattr(args, flag.dest):
                value = getattr(args, flag.dest)
                out += [flag.name, value if isinstance(value, str) else repr(value)]
    return out


def float_list(text: str, n: int, what: str) -> tuple[float, ...]:
    """``n`` comma-separated numbers (ValueError: one line naming the option)."""
    try:
        values = tuple(float(x) for x in text.split(","))
    except ValueError:
        values = ()
    if len(values) != n:
        raise ValueError(f"{what}: expected {n} comma-separated numbers, got {text!r}")
    return values
