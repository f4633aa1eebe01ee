"""YAML read with the safe loader into nodes that remember where they came from.

PyYAML's plain loaders drop positions and silently keep the last of two equal keys; a spec needs both
reported, so the composed node graph is converted by hand.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import yaml

from sam_codegen.model.diagnostics import Diagnostic, Pos, SpecError


@dataclass
class YScalar:
    pos: Pos
    value: Any


@dataclass
class YSeq:
    pos: Pos
    items: list[YNode]


@dataclass
class YMap:
    pos: Pos
    entries: dict[str, YNode] = field(default_factory=dict)
    key_pos: dict[str, Pos] = field(default_factory=dict)
    # Repeated keys, kept so that the reader can say what a repetition means where it happens.
    duplicates: list[tuple[str, Pos, YNode]] = field(default_factory=list)


YNode = YScalar | YSeq | YMap


# libyaml's composer when PyYAML was built with it (3x faster on large specs), else the pure-Python one.
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_COLLECTION_TAGS = ("tag:yaml.org,2002:map", "tag:yaml.org,2002:seq")


def _pos(file: str, node: yaml.Node) -> Pos:
    return Pos(file, node.start_mark.line + 1, node.start_mark.column + 1)


class _Converter:
    def __init__(self, file: str) -> None:
        self.file = file
        self.errors: list[Diagnostic] = []
        self.constructor = yaml.constructor.SafeConstructor()

    def convert(self, node: yaml.Node) -> YNode:
        pos = _pos(self.file, node)
        if not isinstance(node, yaml.ScalarNode) and node.tag not in _COLLECTION_TAGS:
            self.errors.append(Diagnostic(pos, f"YAML tag {node.tag!r} is not allowed in a spec"))
        if isinstance(node, yaml.ScalarNode):
            try:
                return YScalar(pos, self.constructor.construct_object(node, deep=True))
            except yaml.YAMLError as exc:
                self.errors.append(Diagnostic(pos, f"bad scalar: {exc}"))
                return YScalar(pos, None)
        if isinstance(node, yaml.SequenceNode):
            return YSeq(pos, [self.convert(item) for item in node.value])
        if isinstance(node, yaml.MappingNode):
            result = YMap(pos)
            for key_node, value_node in node.value:
                key_pos = _pos(self.file, key_node)
                if not isinstance(key_node, yaml.ScalarNode):
                    self.errors.append(Diagnostic(key_pos, "a mapping key must be a plain scalar"))
                    continue
                key = self.constructor.construct_object(key_node)
                key = str(key) if not isinstance(key, str) else key
                if key in result.entries:
                    result.duplicates.append((key, key_pos, self.convert(value_node)))
                    continue
                result.entries[key] = self.convert(value_node)
                result.key_pos[key] = key_pos
            return result
        raise AssertionError(f"unknown YAML node {node!r}")  # pragma: no cover - PyYAML has only three kinds


def load_yaml(text: str, file: str) -> YNode:
    """Parse YAML text (safe loader semantics: no tags beyond the standard ones, nothing evaluated)."""
    try:
        root = yaml.compose(text, Loader=_LOADER)
    except yaml.YAMLError:
        # Re-read with the pure-Python composer: its messages are the same on every machine.
        root = _compose_for_errors(text, file)
    if root is None:
        return YMap(Pos(file, 1, 1))
    converter = _Converter(file)
    result = converter.convert(root)
    if converter.errors:
        raise SpecError(converter.errors)
    return result


def _compose_for_errors(text: str, file: str) -> yaml.Node | None:
    try:
        return yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        pos = Pos(file, mark.line + 1, mark.column + 1) if mark else Pos(file)
        problem = exc.problem or "invalid YAML"
        context = f" {exc.context}" if exc.context else ""
        raise SpecError([Diagnostic(pos, f"YAML syntax error: {problem}{context}")]) from None
    except yaml.YAMLError as exc:
        raise SpecError([Diagnostic(Pos(file), f"YAML error: {exc}")]) from None
