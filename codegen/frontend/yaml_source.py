"""YAML read with the safe loader into nodes that remember where they came from.

PyYAML's plain loaders drop positions and silently keep the last of two equal keys; a spec needs both
reported, so the tree is composed here from the parser's events. Composing from events (not converting
PyYAML's composed node graph) is what lets one pass also see where each alias is written, refuse aliases
that expand without bound ("billion laughs") and refuse nesting too deep to walk, all without recursion:
a spec arrives in pull requests, and no input may hang CI or end in a RecursionError traceback.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import yaml
from yaml.events import (
    AliasEvent,
    CollectionStartEvent,
    Event,
    MappingEndEvent,
    MappingStartEvent,
    NodeEvent,
    ScalarEvent,
    SequenceEndEvent,
    StreamEndEvent,
)

from sam_codegen.model.diagnostics import Diagnostic, Pos, SpecError

__all__ = ["MAX_ALIAS_NODES_FLOOR", "MAX_ALIAS_NODES_PER_NODE", "MAX_DEPTH", "YMap", "YNode", "YScalar", "YSeq",
           "load_yaml"]


@dataclass
class YScalar:
    pos: Pos
    value: Any
    quoted: bool = False  # written in quotes: its text starts one column after pos (mapping expressions' columns)


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

# Lists and mappings inside each other, the top-level mapping being level 1. The real spec and the test specs nest
# at most 7 levels and no sensible spec needs 15; 100 is far above that and far below what recursive walks of the
# tree can take (Python stops at 1000 frames, and the reader and validators spend a few frames per level).
MAX_DEPTH = 100
# Nodes that aliases may add to the tree, in total: the larger of a floor and a multiple of the nodes written in
# the file so far. An alias copies its anchor's whole subtree, so aliases of aliases grow exponentially with the
# file's length (nine levels of ten aliases are 10^9 nodes from ~100 written: minutes of CPU and gigabytes before
# any check could run). Bounding the copies by 10 per node written keeps the tree, and every later pass over it,
# linear in the file's size whatever the anchors. The real spec writes ~2,700 nodes (keys included); a 5-node
# `<<: *defaults` on each of its 28 topics and parameters would copy 140. So the floor of 10,000 copies (several
# times the whole real spec's 1,500 nodes) and the 27,000 its size allows are met only by a hostile or runaway
# file, and at the floor the copies cost a few MB and a few milliseconds.
MAX_ALIAS_NODES_FLOOR = 10_000
MAX_ALIAS_NODES_PER_NODE = 10

# libyaml's parser when PyYAML was built with it (3x faster on large specs), else the pure-Python one.
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_MAP_TAG = "tag:yaml.org,2002:map"
_SEQ_TAG = "tag:yaml.org,2002:seq"
_MERGE_TAG = "tag:yaml.org,2002:merge"
_COLLECTION_TAGS = (_MAP_TAG, _SEQ_TAG)


def _pos(file: str, event: Event) -> Pos:
    return Pos(file, event.start_mark.line + 1, event.start_mark.column + 1)


class _TooDeep(Exception):
    """Composition stops at the first node nested too deep: the rest of such a document is not worth reading."""


@dataclass
class _Anchored:
    node: YNode
    size: int  # nodes in the subtree, aliases expanded
    height: int  # collection levels in the subtree; 0 for a scalar


_SKIP = ("", Pos(""))  # the key was refused: its value is composed (to keep the event stream) and dropped


@dataclass
class _Open:
    """A list or mapping whose end event has not come yet."""

    node: YSeq | YMap
    anchor: str | None
    made_before: int
    height: int = 1
    # Mappings alternate key and value: the key read, waiting for its value; None while waiting for a key.
    key: tuple[str, Pos] | None = None
    merge_at: Pos | None = None  # the value to come is the value of a merge key `<<`
    merges: list[YMap] = field(default_factory=list)  # later ones win


class _Composer:
    def __init__(self, file: str, parser: Any) -> None:
        self.file = file
        self.parser = parser
        self.errors: list[Diagnostic] = []
        self.resolver = yaml.resolver.Resolver()
        self.constructor = yaml.constructor.SafeConstructor()
        self.anchors: dict[str, _Anchored] = {}
        self.anchor_pos: dict[str, Pos] = {}
        self.open_anchors: set[str] = set()
        self.written = 0  # node events in the file
        self.made = 0  # nodes built, copies included
        self.copied = 0  # nodes built by expanding aliases
        self.over_budget = False

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.errors.append(Diagnostic(pos, message, expected))

    def document(self) -> YNode | None:
        parser = self.parser
        parser.get_event()  # StreamStart
        if parser.check_event(StreamEndEvent):
            return None
        parser.get_event()  # DocumentStart
        root = self.node()
        parser.get_event()  # DocumentEnd
        if not parser.check_event(StreamEndEvent):
            self.error(_pos(self.file, parser.peek_event()), "a second YAML document in the spec file",
                       "a single document")
        return root

    def node(self) -> YNode:
        """One node and everything in it, with an explicit stack instead of recursion."""
        stack: list[_Open] = []
        while True:
            event = self.parser.get_event()
            parent = stack[-1] if stack else None
            if isinstance(event, CollectionStartEvent):
                self.written += 1
                stack.append(self.open(event, len(stack) + 1))
                continue
            if isinstance(event, (SequenceEndEvent, MappingEndEvent)):
                frame = stack.pop()
                parent = stack[-1] if stack else None
                done, height = self.close(frame), frame.height
            elif isinstance(event, AliasEvent):
                self.written += 1
                done, height = self.alias(event, len(stack))
            elif parent is not None and isinstance(parent.node, YMap) and parent.key is None:
                self.written += 1
                self.key(parent, event)
                continue
            else:
                self.written += 1
                done, height = self.scalar(event), 0
                self.register(event, done, 1, 0)
            if parent is None:
                return done
            parent.height = max(parent.height, height + 1)
            self.attach(parent, done)

    def open(self, event: CollectionStartEvent, depth: int) -> _Open:
        pos = _pos(self.file, event)
        if depth > MAX_DEPTH:
            self.error(pos, f"the YAML nests deeper than {MAX_DEPTH} levels",
                       f"at most {MAX_DEPTH} lists and mappings inside each other")
            raise _TooDeep
        is_map = isinstance(event, MappingStartEvent)
        tag = event.tag
        if tag is None or tag == "!":
            tag = _MAP_TAG if is_map else _SEQ_TAG
        if tag not in _COLLECTION_TAGS:
            self.error(pos, f"YAML tag {tag!r} is not allowed in a spec")
        self.check_anchor(event, pos)
        if event.anchor is not None:
            self.open_anchors.add(event.anchor)
        self.made += 1
        return _Open(YMap(pos) if is_map else YSeq(pos, []), event.anchor, self.made - 1)

    def close(self, frame: _Open) -> YNode:
        node = frame.node
        if isinstance(node, YMap) and frame.merges:
            # YAML 1.1 merge keys as PyYAML's SafeConstructor has them: merged keys first, in the order they
            # first come, later sources over earlier ones, and the mapping's own keys over all of them.
            entries: dict[str, YNode] = {}
            key_pos: dict[str, Pos] = {}
            duplicates: list[tuple[str, Pos, YNode]] = []
            for source in [*frame.merges, node]:
                entries.update(source.entries)
                key_pos.update(source.key_pos)
                duplicates += source.duplicates
            node.entries, node.key_pos, node.duplicates = entries, key_pos, duplicates
        if frame.anchor is not None:
            self.open_anchors.discard(frame.anchor)
            self.anchors[frame.anchor] = _Anchored(node, self.made - frame.made_before, frame.height)
        return node

    def key(self, frame: _Open, event: Event) -> None:
        pos = _pos(self.file, event)
        if isinstance(event, ScalarEvent):
            tag = event.tag
            if tag is None or tag == "!":
                tag = self.resolver.resolve(yaml.ScalarNode, event.value, event.implicit)
            if tag == _MERGE_TAG:
                self.check_anchor(event, pos)
                frame.key, frame.merge_at = _SKIP, pos
                self.register(event, YScalar(pos, event.value), 1, 0)
                return
            value = self.scalar(event)
            self.register(event, value, 1, 0)
            frame.key = (value.value if isinstance(value.value, str) else str(value.value), pos)
            return
        raise AssertionError(f"unexpected YAML event {event!r}")  # pragma: no cover - keys of other kinds attach

    def attach(self, frame: _Open, done: YNode) -> None:
        node = frame.node
        if isinstance(node, YSeq):
            node.items.append(done)
            return
        if frame.key is None:
            # A key that is a list, a mapping or an alias: only aliases of scalars are keys.
            if isinstance(done, YScalar):
                value = done.value
                frame.key = (value if isinstance(value, str) else str(value), done.pos)
            else:
                self.error(done.pos, "a mapping key must be a plain scalar")
                frame.key = _SKIP
            return
        skipped = frame.key is _SKIP
        key, key_pos = frame.key
        frame.key = None
        if frame.merge_at is not None:
            self.merge(frame, done)
        elif skipped:
            pass
        elif key in node.entries:
            node.duplicates.append((key, key_pos, done))
        else:
            node.entries[key] = done
            node.key_pos[key] = key_pos

    def merge(self, frame: _Open, value: YNode) -> None:
        frame.merge_at = None
        if isinstance(value, YMap):
            frame.merges.append(value)
        elif isinstance(value, YSeq) and all(isinstance(item, YMap) for item in value.items):
            # In `<<: [*a, *b]` the first mapping wins, so it is applied last.
            frame.merges += [item for item in reversed(value.items) if isinstance(item, YMap)]
        else:
            bad = next((item for item in value.items if not isinstance(item, YMap)), value) \
                if isinstance(value, YSeq) else value
            self.error(bad.pos, "a merge key '<<' takes a mapping or a list of mappings",
                       "an alias of a mapping, or a list of such aliases")

    def scalar(self, event: ScalarEvent) -> YScalar:
        pos = _pos(self.file, event)
        self.check_anchor(event, pos)
        tag = event.tag
        if tag is None or tag == "!":
            tag = self.resolver.resolve(yaml.ScalarNode, event.value, event.implicit)
        node = yaml.ScalarNode(tag, event.value, event.start_mark, event.end_mark, style=event.style)
        self.made += 1
        try:
            return YScalar(pos, self.constructor.construct_object(node, deep=True), event.style in ("'", '"'))
        except yaml.YAMLError as exc:
            self.error(pos, f"bad scalar: {exc}")
            return YScalar(pos, None)
        finally:
            self.constructor.constructed_objects.clear()

    def register(self, event: NodeEvent, node: YNode, size: int, height: int) -> None:
        if event.anchor is not None:
            self.anchors[event.anchor] = _Anchored(node, size, height)

    def check_anchor(self, event: NodeEvent, pos: Pos) -> None:
        name = event.anchor
        if name is None:
            return
        if name in self.anchor_pos:
            self.error(pos, f"anchor &{name} is defined twice (first at line {self.anchor_pos[name].line})",
                       "a new name for each anchor")
        self.anchor_pos[name] = pos

    def alias(self, event: AliasEvent, depth: int) -> tuple[YNode, int]:
        pos = _pos(self.file, event)
        name = event.anchor
        anchored = self.anchors.get(name)
        if name in self.open_anchors:
            self.error(pos, f"alias *{name} is inside the node it names: a spec is a tree, not a loop",
                       "an alias after the end of its anchor's node")
            return YScalar(pos, None), 0
        if anchored is None:
            self.error(pos, f"alias *{name} names no anchor", f"&{name} on a node before it")
            return YScalar(pos, None), 0
        if depth + anchored.height > MAX_DEPTH:
            self.error(pos, f"alias *{name} nests the YAML deeper than {MAX_DEPTH} levels",
                       f"at most {MAX_DEPTH} lists and mappings inside each other")
            raise _TooDeep
        budget = max(MAX_ALIAS_NODES_FLOOR, MAX_ALIAS_NODES_PER_NODE * self.written)
        if self.copied + anchored.size > budget:
            if not self.over_budget:
                self.over_budget = True
                self.error(pos, f"alias *{name} would copy {anchored.size} more nodes, past the {budget} that "
                           f"aliases may add to this spec ({self.copied} so far)",
                           f"aliases that copy at most {MAX_ALIAS_NODES_FLOOR} nodes in all, or "
                           f"{MAX_ALIAS_NODES_PER_NODE} per node written in a larger spec")
            return YScalar(pos, None), 0
        self.copied += anchored.size
        self.made += anchored.size
        return _copy(anchored.node), anchored.height


def _copy(node: YNode) -> YNode:
    # Recursion is bounded: the depth check in `alias` has passed, so the subtree is at most MAX_DEPTH deep.
    if isinstance(node, YScalar):
        return YScalar(node.pos, node.value)
    if isinstance(node, YSeq):
        return YSeq(node.pos, [_copy(item) for item in node.items])
    return YMap(node.pos, {key: _copy(value) for key, value in node.entries.items()}, dict(node.key_pos),
                [(key, pos, _copy(value)) for key, pos, value in node.duplicates])


def load_yaml(text: str, file: str) -> YNode:
    """Parse YAML text (safe loader semantics: no tags beyond the standard ones, nothing evaluated)."""
    try:
        return _load(text, file, _LOADER)
    except yaml.YAMLError as exc:
        if _LOADER is yaml.SafeLoader:
            raise SpecError([_syntax_error(file, exc)]) from None
        # Re-read with the pure-Python parser: its messages are the same on every machine, and it has no nesting
        # limit of its own (libyaml stops at 1000 levels while scanning ahead), so the depth check speaks first.
        try:
            _load(text, file, yaml.SafeLoader)
        except yaml.YAMLError as again:
            raise SpecError([_syntax_error(file, again)]) from None
        raise SpecError([_syntax_error(file, exc)]) from None


def _load(text: str, file: str, loader: type) -> YNode:
    parser = loader(text)
    composer = _Composer(file, parser)
    try:
        root = composer.document()
    except _TooDeep:
        raise SpecError(composer.errors) from None
    finally:
        parser.dispose()
    if composer.errors:
        raise SpecError(composer.errors)
    return YMap(Pos(file, 1, 1)) if root is None else root


def _syntax_error(file: str, exc: yaml.YAMLError) -> Diagnostic:
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        pos = Pos(file, mark.line + 1, mark.column + 1) if mark else Pos(file)
        problem = exc.problem or "invalid YAML"
        context = f" {exc.context}" if exc.context else ""
        return Diagnostic(pos, f"YAML syntax error: {problem}{context}")
    return Diagnostic(Pos(file), f"YAML error: {exc}")
