"""Cross-reference and rule checks: from a parsed Spec to a Resolved interface, or every error at once."""

from __future__ import annotations

import keyword
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

from .diagnostics import Diagnostics, Pos
from .dsdl_catalog import DsdlCatalog
from .mapping_rules import (
    HEADER,
    SYNC_TIMESTAMP,
    TIME,
    ResolvedMapping,
    RuleError,
    Step,
    auto_links,
    check_arrays,
    check_scalar,
    check_string,
    derive_message,
    format_path,
    parse_path,
)
from .model import Constant, Device, DsdlStruct, Field, FieldLink, Mapping, Port, RosMessage, Scalar, Spec
from .ros_catalog import RosCatalog
from .typesys import (
    DSDL_NAMESPACE_COMPONENT,
    DSDL_SHORT_NAME,
    ROS_CONSTANT_NAME,
    ROS_FIELD_NAME,
    ROS_FLOAT_BITS,
    ROS_INT_RANGES,
    ROS_MESSAGE_NAME,
    ROS_PACKAGE_NAME,
    ROS_TOPIC_NAME,
    DsdlType,
    RosType,
    is_dsdl_identifier,
    split_composite_name,
)
from .validate_nodes import check_nodes

T = TypeVar("T", RosType, DsdlType)
CAN_NODE_IDS = range(0, 128)
SUBJECT_IDS = range(0, 8192)
_FRAME_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_PARAM_NAME = ROS_TOPIC_NAME
_CONVERTER_LOCALS = frozenset({"src", "msg", "stats", "receive_ns", "us", "stamp", "typing", "collections"})


@dataclass
class Resolved:
    """A spec that passed every check, with everything the emitters need resolved."""

    spec: Spec
    ros: RosCatalog
    dsdl: DsdlCatalog
    messages: list[RosMessage] = field(default_factory=list)  # the spec's package, sorted by name
    dsdl_types: list[DsdlStruct] = field(default_factory=list)  # the spec's root namespace, sorted by name
    mappings: list[ResolvedMapping] = field(default_factory=list)


def _indexed(leaf: T, name: str, index: int | None) -> T:
    """The element type for `name[index]`, which only a fixed-size array allows."""
    if index is None:
        return leaf
    if leaf.array != "fixed":
        raise RuleError(f"{name}[{index}]: only fixed-size arrays take an index, {name} is {leaf}")
    if index >= (leaf.capacity or 0):
        raise RuleError(f"{name}[{index}]: index out of range, {name} has {leaf.capacity} elements")
    return leaf.element


def _python_safe(name: str) -> bool:
    # Generated converters use names as Python attributes; keywords would be mangled differently per generator.
    return not keyword.iskeyword(name) and not keyword.issoftkeyword(name)


class _Validator:
    def __init__(self, spec: Spec, ros: RosCatalog, dsdl: DsdlCatalog) -> None:
        self.spec, self.ros, self.dsdl = spec, ros, dsdl
        self.diag = Diagnostics()

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.diag.error(pos, message, expected)

    # ---- names and types -------------------------------------------------------------------------------
    def check_header(self) -> None:
        s = self.spec
        if not ROS_PACKAGE_NAME.fullmatch(s.ros.name):
            self.error(Pos(s.file, 1, 1), f"ROS package name {s.ros.name!r} is not valid",
                       "lower case letters, digits and single underscores, starting with a letter")
        if not DSDL_NAMESPACE_COMPONENT.fullmatch(s.dsdl_root) or not is_dsdl_identifier(s.dsdl_root):
            self.error(Pos(s.file, 1, 1), f"DSDL root namespace {s.dsdl_root!r} is not valid",
                       "a lower case DSDL identifier")
        if s.dsdl_root in ("uavcan", "reg"):
            self.error(Pos(s.file, 1, 1), f"root namespace {s.dsdl_root!r} is reserved for the standard types")
        if s.dsdl_root in _CONVERTER_LOCALS or s.dsdl_root == s.ros.name:
            # The generated converters import the root namespace as a Python module beside these names.
            self.error(Pos(s.file, 1, 1), f"root namespace {s.dsdl_root!r} would shadow a name of the generated "
                       "converters", "another name")
        if not re.fullmatch(r"[a-z][a-z0-9_]*", s.vehicle):
            self.error(Pos(s.file, 1, 1), f"vehicle name {s.vehicle!r} is not valid", "a lower case identifier")

    def ros_type_exists(self, t: RosType, pos: Pos, what: str) -> bool:
        if t.is_primitive:
            return True
        if self.ros.get(t.base) is None:
            self.error(pos, f"unknown ROS type {t.base!r} in {what}",
                       "a primitive, a message of this spec or an installed ROS message")
            return False
        return True

    def check_ros_message(self, message: RosMessage) -> None:
        what = f"message {message.full_name}"
        if not ROS_MESSAGE_NAME.fullmatch(message.name):
            self.error(message.pos, f"{message.name!r} is not a valid ROS message name", "CamelCase, e.g. ThrusterRPMs")
        seen: set[str] = set()
        for f in message.fields:
            if not ROS_FIELD_NAME.fullmatch(f.name) or not _python_safe(f.name):
                self.error(f.pos, f"{f.name!r} is not a valid ROS field name in {what}",
                           "lower_case with single underscores, not a Python keyword")
            if f.name in seen:
                self.error(f.pos, f"field {f.name!r} appears twice in {what}")
            seen.add(f.name)
            assert isinstance(f.type, RosType)
            self.ros_type_exists(f.type, f.pos, what)
            if f.default is not None:
                self.check_ros_value(f.type, f.default, f.pos, f"default of {f.name!r}")
        for c in message.constants:
            if not ROS_CONSTANT_NAME.fullmatch(c.name):
                self.error(c.pos, f"{c.name!r} is not a valid ROS constant name in {what}", "UPPER_CASE")
            assert isinstance(c.type, RosType)
            if not c.type.is_primitive or c.type.array:
                self.error(c.pos, f"constant {c.name} of {what} must have a primitive type, not {c.type}")
            else:
                self.check_ros_value(c.type, c.value, c.pos, f"constant {c.name}")
            if c.name in seen:
                self.error(c.pos, f"{c.name!r} is both a field and a constant in {what}")
            seen.add(c.name)

    def check_ros_value(self, t: RosType, value: Scalar, pos: Pos, what: str) -> None:
        base = t.base
        if base in ROS_INT_RANGES:
            lo, hi = ROS_INT_RANGES[base]
            if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
                self.error(pos, f"{what} = {value!r} does not fit {base}", f"an integer in [{lo}, {hi}]")
        elif base in ROS_FLOAT_BITS:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                self.error(pos, f"{what} = {value!r} is not a number", f"a {base}")
        elif base == "bool":
            if not isinstance(value, bool):
                self.error(pos, f"{what} = {value!r} is not a bool", "true or false")
        elif base in ("string", "wstring"):
            if not isinstance(value, str):
                self.error(pos, f"{what} = {value!r} is not a string")
            elif t.string_bound is not None and len(value) > t.string_bound:
                self.error(pos, f"{what} is longer than its bound {t.string_bound}")

    def check_dsdl_value(self, t: DsdlType, value: Scalar, pos: Pos, what: str) -> None:
        if t.array or t.kind in ("composite", "void", "utf8"):
            self.error(pos, f"{what} must have a primitive scalar type, not {t}")
        elif t.kind in ("int", "uint", "byte"):
            lo, hi = t.range
            if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
                self.error(pos, f"{what} = {value!r} does not fit {t}", f"an integer in [{lo}, {hi}]")
        elif t.kind == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                self.error(pos, f"{what} = {value!r} is not a finite number", f"a {t}")
        elif t.kind == "bool" and not isinstance(value, bool):
            self.error(pos, f"{what} = {value!r} is not a bool", "true or false")

    def check_dsdl_struct(self, struct: DsdlStruct) -> None:
        what = f"DSDL type {struct.name}"
        try:
            full, major, minor = split_composite_name(struct.name)
        except ValueError as exc:
            self.error(struct.pos, str(exc), "root.namespace.Name.MAJOR.MINOR")
            return
        parts = full.split(".")
        if parts[0] != self.spec.dsdl_root:
            self.error(struct.pos, f"{what} is outside the spec's root namespace {self.spec.dsdl_root!r}",
                       f"{self.spec.dsdl_root}.<namespace>.Name.MAJOR.MINOR")
        for part in parts[:-1]:
            if not DSDL_NAMESPACE_COMPONENT.fullmatch(part) or not is_dsdl_identifier(part):
                self.error(struct.pos, f"namespace {part!r} of {what} is not a valid DSDL identifier")
        if not DSDL_SHORT_NAME.fullmatch(parts[-1]) or not is_dsdl_identifier(parts[-1]) or not parts[-1][0].isupper():
            self.error(struct.pos, f"{parts[-1]!r} is not a valid DSDL type name", "CamelCase identifier")
        if not (0 <= major <= 255 and 0 <= minor <= 255) or (major, minor) == (0, 0):
            self.error(struct.pos, f"version {major}.{minor} of {what} is not valid", "MAJOR.MINOR in 0..255, not 0.0")
        if struct.extent is not None and not 0 < struct.extent <= 65535:
            self.error(struct.pos, f"extent of {what} must be 1..65535 bytes")
        seen: set[str] = set()
        for f in [*struct.fields, *struct.constants]:
            if not is_dsdl_identifier(f.name) or not _python_safe(f.name):
                self.error(f.pos, f"{f.name!r} is not a valid DSDL identifier in {what}",
                           "letters, digits and underscores, not reserved (e.g. uint8, bool, saturated) "
                           "nor a Python keyword")
            if f.name in seen:
                self.error(f.pos, f"{f.name!r} appears twice in {what}")
            seen.add(f.name)
        for f in struct.fields:
            assert isinstance(f.type, DsdlType)
            if f.type.kind == "void":
                self.error(f.pos, f"field {f.name!r} of {what}: void padding is not supported",
                           "a named field; sealed types are bit-packed")
            if f.type.kind == "composite" and f.type.composite and self.dsdl.get(f.type.composite) is None:
                self.error(f.pos, f"unknown DSDL type {f.type.composite!r} in {what}",
                           "a type of this spec or of CYPHAL_PATH (uavcan.*, reg.*)")
        for c in struct.constants:
            assert isinstance(c.type, DsdlType)
            self.check_dsdl_value(c.type, c.value, c.pos, f"constant {c.name} of {what}")

    # ---- interface ------------------------------------------------------------------------------------
    def resolve_messages(self) -> list[RosMessage]:
        for message in list(self.spec.messages.values()):
            if message.derived_from is None:
                continue
            struct = self.dsdl.get(message.derived_from)
            if struct is None:
                self.error(message.pos, f"message {message.full_name} derives from unknown DSDL type "
                           f"{message.derived_from!r}")
                continue
            try:
                derived = derive_message(struct, message.package, message.name, message.description, message.pos)
            except RuleError as exc:
                self.error(message.pos, str(exc))
                continue
            self.spec.messages[message.full_name] = derived
        for message in self.spec.external_messages.values():
            self.check_ros_message(message)
        for message in self.spec.messages.values():
            self.check_ros_message(message)
        self.check_message_cycles()
        return sorted(self.spec.messages.values(), key=lambda m: m.name)

    def check_message_cycles(self) -> None:
        def visit(name: str, stack: tuple[str, ...]) -> None:
            message = self.spec.messages.get(name)
            if message is None:
                return
            if name in stack:
                self.error(message.pos, f"message {name} contains itself: {' -> '.join((*stack, name))}")
                return
            for f in message.fields:
                assert isinstance(f.type, RosType)
                if not f.type.is_primitive:
                    visit(f.type.base, (*stack, name))

        for name in self.spec.messages:
            visit(name, ())

    def check_frames_and_parameters(self) -> None:
        s = self.spec
        for frame in s.frames.values():
            if not _FRAME_NAME.fullmatch(frame.name):
                self.error(frame.pos, f"frame {frame.name!r} is not a valid TF frame id", "an identifier")
            if frame.parent is not None and frame.parent not in s.frames:
                self.error(frame.pos, f"frame {frame.name!r} has unknown parent {frame.parent!r}")
        for frame in s.frames.values():
            seen, cur = {frame.name}, frame.parent
            while cur is not None and cur in s.frames:
                if cur in seen:
                    self.error(frame.pos, f"frame {frame.name!r} is its own ancestor")
                    break
                seen.add(cur)
                cur = s.frames[cur].parent
        for t in s.transforms:
            for name in (t.parent, t.child):
                if name not in s.frames:
                    self.error(t.pos, f"transform {t.parent}->{t.child} names unknown frame {name!r}")
            if t.publisher not in s.nodes:
                self.error(t.pos, f"transform {t.parent}->{t.child} is published by unknown node {t.publisher!r}")
        for p in s.parameters.values():
            if not _PARAM_NAME.fullmatch(p.name):
                self.error(p.pos, f"parameter name {p.name!r} is not a valid ROS name", "/name")
        for rule in s.parameter_rules:
            left, right = s.parameters.get(rule.left), s.parameters.get(rule.right)
            for name, param in ((rule.left, left), (rule.right, right)):
                if param is None:
                    self.error(rule.pos, f"parameter rule names unknown parameter {name!r}")
                elif param.type not in ("double", "integer"):
                    self.error(rule.pos, f"parameter rule compares non-numeric parameter {name!r}")
            if left is None or right is None or left.type not in ("double", "integer") \
                    or right.type not in ("double", "integer"):
                continue
            ok = {"<": lambda a, b: a < b, "<=": lambda a, b: a <= b,
                  ">": lambda a, b: a > b, ">=": lambda a, b: a >= b}[rule.op](left.default, right.default)
            if not ok:
                self.error(rule.pos, f"inconsistent parameter limits: {rule.left} = {left.default} must be "
                           f"{rule.op} {rule.right} = {right.default}" + (f" ({rule.description})"
                                                                          if rule.description else ""))

    def check_topics_and_nodes(self) -> None:
        s = self.spec
        for topic in s.topics.values():
            if not ROS_TOPIC_NAME.fullmatch(topic.name):
                self.error(topic.pos, f"topic name {topic.name!r} is not a valid ROS name",
                           "/segment[/segment...], each a letter or underscore then letters, digits, underscores")
            if "/" not in topic.type:
                self.error(topic.pos, f"topic {topic.name} type {topic.type!r} needs its package", "pkg/Name")
            elif self.ros.get(topic.type) is None:
                self.error(topic.pos, f"unknown ROS type {topic.type!r} of topic {topic.name}",
                           "a message of this spec, an external_messages entry or an installed ROS message")

    def check_devices(self) -> None:
        s = self.spec
        owners: dict[int, str] = {}
        if s.bridge is not None:
            if s.bridge.node_id not in CAN_NODE_IDS:
                self.error(s.bridge.pos, f"bridge node id {s.bridge.node_id} is out of range for Cyphal/CAN",
                           "0..127")
            owners[s.bridge.node_id] = f"bridge {s.bridge.name}"
        subject_types: dict[int, tuple[str, Pos]] = {}
        publishers: dict[int, str] = {}
        for device in s.devices.values():
            if not re.fullmatch(r"[a-z][a-z0-9_]*", device.name):
                self.error(device.pos, f"device name {device.name!r} is not valid", "lower_case")
            if device.node_id not in CAN_NODE_IDS:
                self.error(device.pos, f"node id {device.node_id} of device {device.name} is out of range for "
                           "Cyphal/CAN", "0..127")
            elif device.node_id in owners:
                self.error(device.pos, f"node id {device.node_id} of device {device.name} is already used by "
                           f"{owners[device.node_id]}", "a unique node id")
            else:
                owners[device.node_id] = f"device {device.name}"
            for port, publishing in [(p, True) for p in device.publishes] + [(p, False) for p in device.subscribes]:
                if port.subject_id not in SUBJECT_IDS:
                    self.error(port.pos, f"subject id {port.subject_id} of device {device.name} is out of range",
                               "0..8191")
                if self.dsdl.get(port.type) is None:
                    self.error(port.pos, f"unknown DSDL type {port.type!r} of device {device.name}",
                               "a type of this spec or of CYPHAL_PATH")
                known = subject_types.get(port.subject_id)
                if known is not None and known[0] != port.type:
                    self.error(port.pos, f"subject id {port.subject_id} carries {known[0]} elsewhere "
                               f"(line {known[1].line}), not {port.type}", "one type per subject")
                subject_types.setdefault(port.subject_id, (port.type, port.pos))
                if publishing:
                    if port.subject_id in publishers:
                        self.error(port.pos, f"duplicate subject id {port.subject_id}: already published by "
                                   f"{publishers[port.subject_id]}", "one publisher per subject")
                    publishers[port.subject_id] = f"device {device.name}"
        self.publishers = publishers

    def resolve_mappings(self) -> list[ResolvedMapping]:
        s = self.spec
        if s.bridge is None:
            return []
        devices_by_id = s.devices_by_node_id()
        self.ports_by_subject: dict[int, list[tuple[Device, Port, bool]]] = {}
        for d in s.devices.values():
            for p, publishing in [(p, True) for p in d.publishes] + [(p, False) for p in d.subscribes]:
                self.ports_by_subject.setdefault(p.subject_id, []).append((d, p, publishing))
        result = []
        for mapping in s.bridge.mappings:
            resolved = self.resolve_mapping(mapping, devices_by_id)
            if resolved is not None:
                result.append(resolved)
        return result

    def resolve_mapping(self, mapping: Mapping, devices_by_id: dict) -> ResolvedMapping | None:
        s, what = self.spec, f"mapping {mapping.name!r}"
        if not re.fullmatch(r"[a-z][a-z0-9_]*", mapping.name) or not _python_safe(mapping.name):
            self.error(mapping.pos, f"mapping name {mapping.name!r} is not valid", "lower_case identifier")
        topic = s.topics.get(mapping.topic)
        if topic is None:
            self.error(mapping.pos, f"{what} uses undeclared topic {mapping.topic!r}", "a topic of `topics`")
        if mapping.subject_id not in SUBJECT_IDS:
            self.error(mapping.pos, f"subject id {mapping.subject_id} of {what} is out of range", "0..8191")
        ports = self.ports_by_subject.get(mapping.subject_id, [])
        if not ports:
            self.error(mapping.pos, f"subject id {mapping.subject_id} of {what} is used by no device",
                       "a subject a device publishes or subscribes")
            return None
        port = ports[0][1]
        if mapping.direction == "uavcan_to_ros":
            publishers = {d.node_id for d, _, pub in ports if pub}
            for node_id in mapping.source_node_ids:
                if node_id not in CAN_NODE_IDS:
                    self.error(mapping.pos, f"source node id {node_id} of {what} is out of range", "0..127")
                elif node_id not in publishers:
                    owner = devices_by_id.get(node_id)
                    self.error(mapping.pos, f"source node id {node_id} of {what} does not publish subject "
                               f"{mapping.subject_id}" + (f" (it is device {owner.name})" if owner else ""),
                               "the node id of a device that publishes it: " + ", ".join(map(str, sorted(publishers)))
                               if publishers else "a publishing device")
        else:
            dest = mapping.destination_node_id
            subscribers = {d.node_id for d, _, pub in ports if not pub}
            if dest is not None and dest not in CAN_NODE_IDS:
                self.error(mapping.pos, f"destination node id {dest} of {what} is out of range", "0..127")
            elif dest is not None and dest not in subscribers:
                self.error(mapping.pos, f"destination node id {dest} of {what} does not subscribe to subject "
                           f"{mapping.subject_id}", "the node id of a device that subscribes to it")
            owner = self.publishers.get(mapping.subject_id)
            if owner is not None:
                self.error(mapping.pos, f"duplicate subject id {mapping.subject_id}: {what} publishes it but "
                           f"{owner} does too", "one publisher per subject")
            self.publishers[mapping.subject_id] = what
        struct = self.dsdl.get(port.type)
        ros_message = self.ros.get(topic.type) if topic is not None else None
        if struct is None or ros_message is None:
            return None
        if struct.union:
            self.error(mapping.pos, f"{what}: union types ({struct.name}) cannot be mapped")
            return None
        has_header = any(f.name == "header" and isinstance(f.type, RosType) and f.type.base == HEADER
                         for f in ros_message.fields)
        if mapping.frame_id is not None and mapping.frame_id not in s.frames:
            self.error(mapping.pos, f"frame_id {mapping.frame_id!r} of {what} is not a declared frame",
                       "one of " + ", ".join(s.frames))
        if mapping.direction == "uavcan_to_ros" and has_header and mapping.frame_id is None:
            self.error(mapping.pos, f"{what} publishes {ros_message.full_name}, which has a header: it needs "
                       "a frame_id")
        links = auto_links(struct, mapping.pos) if mapping.auto else mapping.links
        if mapping.auto and ros_message.derived_from != struct.name:
            self.error(mapping.pos, f"{what} uses `fields: auto`, which needs a ROS message derived from "
                       f"{struct.name} (topic type is {ros_message.full_name})")
            return None
        resolved = ResolvedMapping(mapping, ros_message, struct, has_header=has_header, rate_hz=port.rate_hz)
        ros_targets: dict[str, Pos] = {}
        self.failed_paths: set[str] = set()
        for link in links:
            step = self.resolve_link(link, ros_message, struct, mapping, what)
            if step is None:
                # Its UAVCAN side is reported already; do not report it again as unmapped.
                if link.uavcan_path:
                    self.failed_paths.add(link.uavcan_path.split("[")[0].split(".")[0])
                continue
            if step.ros in ros_targets:
                self.error(link.pos, f"ROS field {step.ros!r} is set twice in {what}")
            ros_targets[step.ros] = link.pos
            resolved.steps.append(step)
        for path_text, value in mapping.uavcan_values.items():
            try:
                path = parse_path(path_text)
                leaf = self.dsdl_leaf(struct, path)
            except RuleError as exc:
                self.error(mapping.pos, f"uavcan_values of {what}: {exc}")
                continue
            self.check_dsdl_value(leaf, value, mapping.pos, f"uavcan value {path_text!r} of {what}")
            resolved.uavcan_values.append((tuple(path), leaf, value))
        for ignored in mapping.ignore:
            try:
                self.dsdl_leaf(struct, parse_path(ignored), allow_composite=True)
            except RuleError as exc:
                self.error(mapping.pos, f"ignore of {what}: {exc}")
        self.check_coverage(resolved, what)
        return resolved

    def ros_leaf(self, message: RosMessage, path: list) -> RosType:
        current: RosMessage | None = message
        leaf: RosType | None = None
        for i, (name, index) in enumerate(path):
            if current is None:
                raise RuleError(f"{format_path(path[:i])} is a {leaf}, it has no field {name!r}")
            f = current.field(name)
            if f is None:
                raise RuleError(f"{current.full_name} has no field {name!r}")
            assert isinstance(f.type, RosType)
            leaf = f.type
            leaf = _indexed(leaf, name, index)
            current = None if leaf.is_primitive or leaf.array or leaf.base == TIME else self.ros.get(leaf.base)
        assert leaf is not None
        return leaf

    def dsdl_leaf(self, struct: DsdlStruct, path: list, allow_composite: bool = False) -> DsdlType:
        current: DsdlStruct | None = struct
        leaf: DsdlType | None = None
        for i, (name, index) in enumerate(path):
            if current is None:
                raise RuleError(f"{format_path(path[:i])} is a {leaf}, it has no field {name!r}")
            f = current.field(name)
            if f is None:
                raise RuleError(f"{current.name} has no field {name!r}")
            assert isinstance(f.type, DsdlType)
            leaf = f.type
            leaf = _indexed(leaf, name, index)
            current = self.dsdl.get(leaf.composite) if leaf.kind == "composite" and not leaf.array else None
            if current is not None and current.union:
                raise RuleError(f"{name} is a union ({current.name}); unions cannot be mapped")
        assert leaf is not None
        if leaf.kind == "composite" and not leaf.array and not allow_composite and leaf.composite != SYNC_TIMESTAMP:
            raise RuleError(f"{format_path(path)} is a composite ({leaf.composite}); map its fields one by one")
        return leaf

    def resolve_link(self, link: FieldLink, ros_message: RosMessage, struct: DsdlStruct, mapping: Mapping,
                     what: str) -> Step | None:
        try:
            ros_path = parse_path(link.ros_path)
            ros_type = self.ros_leaf(ros_message, ros_path)
            if link.value is not None:
                if mapping.direction == "ros_to_uavcan":
                    raise RuleError("a `value` sets a ROS field; a ROS->UAVCAN mapping sets UAVCAN fields with "
                                    "uavcan_values")
                if ros_type.array or not ros_type.is_primitive:
                    raise RuleError(f"a `value` sets a primitive field, {link.ros_path} is {ros_type}")
                self.check_ros_value(ros_type, link.value, link.pos, f"value of {link.ros_path!r}")
                return Step("value", tuple(ros_path), ros_type, value=link.value, pos=link.pos)
            assert link.uavcan_path is not None
            uav_path = parse_path(link.uavcan_path)
            uav_type = self.dsdl_leaf(struct, uav_path)
            if uav_type.kind == "composite" and uav_type.composite == SYNC_TIMESTAMP:
                uav_path.append(("microsecond", None))
                uav_type = DsdlType("uint", 56, truncated=True)
            if not ros_type.is_primitive and ros_type.base == TIME and not ros_type.array:
                if uav_type.kind not in ("uint", "int") or uav_type.array or link.scale or link.table:
                    raise RuleError(f"builtin_interfaces/Time receives a microsecond integer, not {uav_type}")
                return Step("time", tuple(ros_path), ros_type, tuple(uav_path), uav_type, pos=link.pos)
            if not ros_type.is_primitive:
                raise RuleError(f"{link.ros_path} is a {ros_type.base}; map its fields one by one")
            if link.limits is not None and (ros_type.array or ros_type.base not in {*ROS_INT_RANGES, *ROS_FLOAT_BITS}):
                raise RuleError("limits apply to numeric scalar fields")
            if uav_type.kind == "utf8" or ros_type.base == "string":
                exact = check_string(ros_type, uav_type, link)
                kind = "string"
            elif uav_type.array or ros_type.array:
                exact = check_arrays(ros_type, uav_type, link)
                kind = "array"
            else:
                kind, exact = check_scalar(ros_type, uav_type, link)
            return Step(kind, tuple(ros_path), ros_type, tuple(uav_path), uav_type, link.scale, link.offset,
                        tuple(sorted((link.table or {}).items())), None, link.limits, exact, link.pos)
        except RuleError as exc:
            self.error(link.pos, f"{what}, field {link.ros_path!r}: {exc}")
            return None

    def dsdl_leaves(self, struct: DsdlStruct, prefix: str = "") -> list[tuple[str, DsdlType]]:
        leaves: list[tuple[str, DsdlType]] = []
        for f in struct.fields:
            assert isinstance(f.type, DsdlType)
            path = f"{prefix}{f.name}"
            nested = self.dsdl.get(f.type.composite) if f.type.kind == "composite" and not f.type.array \
                and f.type.composite else None
            if nested is not None and not nested.union:
                leaves.extend(self.dsdl_leaves(nested, path + "."))
            else:
                leaves.append((path, f.type))
        return leaves

    def check_coverage(self, resolved: ResolvedMapping, what: str) -> None:
        mapping = resolved.mapping
        linked = {s.uavcan for s in resolved.steps if s.uavcan_path} | self.failed_paths
        valued = {format_path(list(p)) for p, _, _ in resolved.uavcan_values}
        ignored = set(mapping.ignore)

        def covered(path: str, t: DsdlType, pool: set[str]) -> bool:
            if path in pool or any(path.startswith(p + ".") for p in pool):
                return True
            return t.array == "fixed" and all(f"{path}[{i}]" in pool for i in range(t.capacity or 0))

        for path, t in self.dsdl_leaves(resolved.dsdl_struct):
            if mapping.direction == "uavcan_to_ros":
                if not covered(path, t, linked | ignored):
                    self.error(mapping.pos, f"required field left unmapped: UAVCAN field {path!r} ({t}) of "
                               f"{resolved.dsdl_struct.name} is neither mapped nor ignored in {what}",
                               f"a `ros_field: {path}` line or `{path}` in ignore")
            elif not covered(path, t, linked | valued):
                self.error(mapping.pos, f"required field left unmapped: UAVCAN field {path!r} ({t}) of "
                           f"{resolved.dsdl_struct.name} gets no value in {what}",
                           f"a `ros_field: {path}` line or an entry in uavcan_values")
        if mapping.direction == "ros_to_uavcan":
            for path in linked & valued:
                self.error(mapping.pos, f"UAVCAN field {path!r} is both mapped and in uavcan_values in {what}")


def validate(spec: Spec, *, ros_share_dirs: list[Path] | None = None, dsdl_roots: list[Path] | None = None
             ) -> Resolved:
    """Check a parsed spec; raises SpecError with every problem, or returns the resolved interface."""
    ros, dsdl = RosCatalog(spec, ros_share_dirs), DsdlCatalog(spec, dsdl_roots)
    v = _Validator(spec, ros, dsdl)
    v.check_header()
    for struct in spec.dsdl_types.values():
        v.check_dsdl_struct(struct)
    messages = v.resolve_messages()
    v.check_frames_and_parameters()
    v.check_topics_and_nodes()
    check_nodes(spec, ros, v.diag)  # nodes, QoS, TF topics, external packages (validate_nodes)
    v.check_devices()
    mappings = v.resolve_mappings()
    v.diag.check()
    return Resolved(spec, ros, dsdl, messages, sorted(spec.dsdl_types.values(), key=lambda t: t.name), mappings)


__all__ = ["Constant", "Field", "Resolved", "validate"]
