"""Reading YAML nodes of the spec into typed values, recording what is wrong in Diagnostics instead of raising."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, TypeVar

from sam_codegen.frontend.yaml_source import YMap, YNode, YScalar, YSeq
from sam_codegen.model.diagnostics import Diagnostics, Pos

__all__ = ["Reader", "int_list", "kind_of", "map_items", "number", "parse_type", "scalar", "seq_items", "str_list",
           "text_of", "vector3"]


T = TypeVar("T")
_MISSING = object()


def kind_of(node: YNode) -> str:
    if isinstance(node, YMap):
        return "a mapping"
    if isinstance(node, YSeq):
        return "a list"
    value = node.value
    return "null" if value is None else f"{type(value).__name__} {value!r}"


class Reader:
    """Typed access to a YAML mapping that records what is wrong instead of raising."""

    def __init__(self, node: YNode, what: str, diag: Diagnostics, allowed: tuple[str, ...]) -> None:
        self.diag = diag
        self.what = what
        self.ok = isinstance(node, YMap)
        self.map = node if isinstance(node, YMap) else YMap(node.pos)
        self.pos = node.pos
        if not self.ok:
            diag.error(node.pos, f"{what} must be a mapping, found {kind_of(node)}", "a mapping")
            return
        _report_duplicates(self.map, what, diag)
        for key, key_pos in self.map.key_pos.items():
            if key not in allowed:
                diag.error(key_pos, f"unknown field {key!r} in {what}", "one of " + ", ".join(allowed))

    def node(self, key: str) -> YNode | None:
        return self.map.entries.get(key)

    def key_pos(self, key: str) -> Pos:
        return self.map.key_pos.get(key, self.pos)

    def get(self, key: str, kind: type | tuple[type, ...], default: Any = _MISSING) -> Any:
        node = self.map.entries.get(key)
        if node is None:
            if default is _MISSING:
                if self.ok:
                    self.diag.error(self.pos, f"missing field {key!r} in {self.what}")
                return None
            return default
        return scalar(node, kind, f"{key!r} of {self.what}", self.diag)


def scalar(node: YNode, kind: type | tuple[type, ...], what: str, diag: Diagnostics) -> Any:
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if isinstance(node, YScalar) and isinstance(node.value, kinds):
        # bool is an int in Python; a spec's `true` is never a number.
        if isinstance(node.value, bool) and bool not in kinds:
            pass
        else:
            return node.value
    names = " or ".join("number" if k is float else k.__name__ for k in kinds)
    diag.error(node.pos, f"{what} must be {names}, found {kind_of(node)}", names)
    return None


def _report_duplicates(node: YMap, what: str, diag: Diagnostics) -> None:
    for key, pos, _ in node.duplicates:
        diag.error(pos, f"duplicate key {key!r} in {what} (first at line {node.key_pos[key].line})", "unique keys")


def map_items(
    node: YNode | None, what: str, diag: Diagnostics, duplicates: bool = True
) -> list[tuple[str, Pos, YNode]]:
    if node is None:
        return []
    if not isinstance(node, YMap):
        diag.error(node.pos, f"{what} must be a mapping, found {kind_of(node)}", "a mapping")
        return []
    if duplicates:
        _report_duplicates(node, what, diag)
    return [(k, node.key_pos[k], v) for k, v in node.entries.items()]


def seq_items(node: YNode | None, what: str, diag: Diagnostics) -> list[YNode]:
    if node is None:
        return []
    if not isinstance(node, YSeq):
        diag.error(node.pos, f"{what} must be a list, found {kind_of(node)}", "a list")
        return []
    return node.items


def str_list(node: YNode | None, what: str, diag: Diagnostics) -> list[tuple[str, Pos]]:
    result = []
    for item in seq_items(node, what, diag):
        value = scalar(item, str, f"an entry of {what}", diag)
        if value is not None:
            result.append((value, item.pos))
    return result


def int_list(node: YNode | None, key: str, what: str, diag: Diagnostics) -> list[int]:
    items = (scalar(i, int, f"an entry of {key} of {what}", diag) for i in seq_items(node, f"{key} of {what}", diag))
    return [n for n in items if n is not None]


def text_of(reader: Reader, key: str) -> str:
    value = reader.get(key, str, "")
    return value if isinstance(value, str) else ""


def parse_type(text: str | None, pos: Pos, parse: Callable[[str], T], diag: Diagnostics) -> T | None:
    if text is None:
        return None
    try:
        return parse(text)
    except ValueError as exc:
        diag.error(pos, str(exc))
        return None


def number(node: YNode | None, what: str, diag: Diagnostics) -> float | None:
    if node is None:
        return None
    value = scalar(node, (int, float), what, diag)
    if value is not None and not math.isfinite(value):
        diag.error(node.pos, f"{what} must be finite")
        return None
    return value


def vector3(node: YNode | None, what: str, diag: Diagnostics) -> tuple[float, float, float] | None:
    if node is None:
        return None
    items = seq_items(node, what, diag)
    values = [number(item, f"an element of {what}", diag) for item in items]
    if isinstance(node, YSeq) and len(items) != 3:
        diag.error(node.pos, f"{what} must have 3 elements, found {len(items)}", "[x, y, z]")
        return None
    if len(values) != 3 or any(v is None for v in values):
        return None
    return (float(values[0]), float(values[1]), float(values[2]))  # type: ignore[arg-type]
