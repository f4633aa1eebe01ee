"""Cross-reference and rule checks: from a parsed Spec to a Resolved interface, or every error at once.

Invariants: validation never changes the spec; what it derives (the messages of `derive_from`, the resolved mappings
and layouts) it returns, in a frozen Resolved whose `ros` catalog overlays the derived messages on the spec's. The
messages are derived before any check looks a ROS type up, so every check sees the same catalog.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from sam_codegen.catalogs.cyphal import DsdlCatalog
from sam_codegen.catalogs.dronecan import V0Catalog
from sam_codegen.catalogs.ros import RosCatalog
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.ros_names import NAME_RULES, ros_name_problem
from sam_codegen.model.spec import Constant, DsdlService, DsdlStruct, Field, RosMessage, RosService, Spec, V0Struct
from sam_codegen.model.types import (
    DSDL_NAMESPACE_COMPONENT,
    DSDL_SHORT_NAME,
    ROS_CONSTANT_NAME,
    ROS_FIELD_NAME,
    ROS_MESSAGE_NAME,
    ROS_PACKAGE_NAME,
    DsdlType,
    RosType,
    is_dsdl_identifier,
    split_composite_name,
)
from sam_codegen.validate.bus_budget import check_bus_budgets
from sam_codegen.validate.dronecan import DronecanValidator, ResolvedLayout
from sam_codegen.validate.mapping_options import check_mapping_options
from sam_codegen.validate.mapping_rules import ResolvedMapping, RuleError, derive_message
from sam_codegen.validate.mappings import MappingValidator
from sam_codegen.validate.node_services import resolve_node_services
from sam_codegen.validate.nodes import check_nodes
from sam_codegen.validate.panic_duty import check_panic_duty
from sam_codegen.validate.routing import check_routing
from sam_codegen.validate.services import ResolvedServiceMapping, ServiceValidator
from sam_codegen.validate.topics_message import topics_message
from sam_codegen.validate.type_graph import check_type_sizes, ros_children, type_graph
from sam_codegen.validate.values import CAN_NODE_IDS, SUBJECT_IDS, check_dsdl_value, check_ros_value, python_safe

_FRAME_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_CONVERTER_LOCALS = frozenset({"src", "msg", "stats", "receive_ns", "us", "stamp", "typing", "collections"})
# Types inside types: the cycle check, the layouts and the codecs walk them recursively, a few frames a level, and
# a spec whose YAML is flat can still chain thousands. ROS's own messages nest at most ~6 levels.
_MAX_NESTING = 32


@dataclass(frozen=True)
class Resolved:
    """A spec that passed every check, with everything the emitters need resolved."""

    spec: Spec
    ros: RosCatalog  # the derived messages over the spec's, then the external and installed ones
    dsdl: DsdlCatalog
    messages: list[RosMessage]  # the spec's package (as derived), sorted by name
    dsdl_types: list[DsdlStruct]  # the spec's root namespace, sorted by name
    mappings: list[ResolvedMapping]  # Cyphal
    dronecan: V0Catalog | None
    dronecan_types: list[V0Struct]  # the spec's own, sorted by name
    dronecan_mappings: list[ResolvedMapping]
    layouts: list[ResolvedLayout]  # the implicit "default" first
    services: list[RosService] = field(default_factory=list)  # the package's .srv types, sorted by name
    service_mappings: list[ResolvedServiceMapping] = field(default_factory=list)
    dsdl_services: list[DsdlService] = field(default_factory=list)  # the spec's Cyphal service types, by name


def derive_messages(spec: Spec, dsdl: DsdlCatalog, diag: Diagnostics) -> tuple[dict[str, RosMessage], set[str]]:
    """The messages of the spec that `derive_from` a DSDL type, derived, by full name; and the full names of those
    that could not be derived (reported into diag)."""
    derived: dict[str, RosMessage] = {}
    failed: set[str] = set()
    for message in spec.messages.values():
        if message.derived_from is None:
            continue
        struct = dsdl.get(message.derived_from)
        if struct is None:
            diag.error(message.pos, f"message {message.full_name} derives from unknown DSDL type "
                       f"{message.derived_from!r}")
            failed.add(message.full_name)
            continue
        try:
            derived[message.full_name] = derive_message(struct, message.package, message.name, message.description,
                                                        message.pos)
        except RuleError as exc:
            diag.error(message.pos, str(exc))
            failed.add(message.full_name)
    return derived, failed


class _Validator:
    def __init__(self, spec: Spec, ros: RosCatalog, dsdl: DsdlCatalog, diag: Diagnostics,
                 failed_messages: set[str]) -> None:
        self.spec, self.ros, self.dsdl = spec, ros, dsdl
        self.diag = diag
        # What is reported broken already, so that the checks which use it add no follow-on errors:
        self.bad_dsdl_fields: set[tuple[str, str]] = set()  # (DSDL type, field)
        self.failed_messages = failed_messages  # derived ROS messages that could not be derived

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
            if not ROS_FIELD_NAME.fullmatch(f.name) or not python_safe(f.name):
                self.error(f.pos, f"{f.name!r} is not a valid ROS field name in {what}",
                           "lower_case with single underscores, not a Python keyword")
            if f.name in seen:
                self.error(f.pos, f"field {f.name!r} appears twice in {what}")
            seen.add(f.name)
            assert isinstance(f.type, RosType)
            self.ros_type_exists(f.type, f.pos, what)
            if f.default is not None:
                check_ros_value(self.diag, f.type, f.default, f.pos, f"default of {f.name!r}")
        for c in message.constants:
            if not ROS_CONSTANT_NAME.fullmatch(c.name):
                self.error(c.pos, f"{c.name!r} is not a valid ROS constant name in {what}", "UPPER_CASE")
            assert isinstance(c.type, RosType)
            if not c.type.is_primitive or c.type.array:
                self.error(c.pos, f"constant {c.name} of {what} must have a primitive type, not {c.type}")
            else:
                check_ros_value(self.diag, c.type, c.value, c.pos, f"constant {c.name}")
            if c.name in seen:
                self.error(c.pos, f"{c.name!r} is both a field and a constant in {what}")
            seen.add(c.name)

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
        fields = {id(f) for f in struct.fields}
        members: list[Field | Constant] = [*struct.fields, *struct.constants]
        for f in members:
            bad = False
            if not is_dsdl_identifier(f.name) or not python_safe(f.name):
                self.error(f.pos, f"{f.name!r} is not a valid DSDL identifier in {what}",
                           "letters, digits and underscores, not reserved (e.g. uint8, bool, saturated) "
                           "nor a Python keyword")
                bad = True
            if f.name in seen:
                self.error(f.pos, f"{f.name!r} appears twice in {what}")
                bad = True
            seen.add(f.name)
            if bad and id(f) in fields:
                self.bad_dsdl_fields.add((struct.name, f.name))
        for f in struct.fields:  # void padding is not among them: it is only emitted
            assert isinstance(f.type, DsdlType)
            if f.type.kind == "composite" and f.type.composite and self.dsdl.get(f.type.composite) is None:
                self.error(f.pos, f"unknown DSDL type {f.type.composite!r} in {what}",
                           "a type of this spec or of CYPHAL_PATH (uavcan.*, reg.*)")
                self.bad_dsdl_fields.add((struct.name, f.name))
        for c in struct.constants:
            assert isinstance(c.type, DsdlType)
            check_dsdl_value(self.diag, c.type, c.value, c.pos, f"constant {c.name} of {what}")

    # ---- interface ------------------------------------------------------------------------------------
    def check_messages(self) -> list[RosMessage]:
        """Checks the external and the spec's own messages (as derived); returns the latter sorted by name."""
        messages = self.ros.messages
        for message in self.spec.external_messages.values():
            self.check_ros_message(message)
        for message in messages.values():
            self.check_ros_message(message)
        self.check_message_cycles(messages)
        return sorted(messages.values(), key=lambda m: m.name)

    def check_message_cycles(self, messages: dict[str, RosMessage]) -> None:
        """Messages inside messages: no cycle, at most _MAX_NESTING levels; one pass over them (validate.type_graph:
        a walk of every path was exponential)."""
        graph = type_graph(messages, lambda name: ros_children(messages.get(name)))
        for component in graph.cycles:
            name = component[0]
            self.error(messages[name].pos, f"message {name} contains itself: {' -> '.join(graph.cycle_from(name))}")
        deep = next((name for name in messages if graph.height[name] > _MAX_NESTING), None)
        if deep is not None:  # one error is enough: a chain of N messages would give N - 32
            chain = graph.chain(deep, _MAX_NESTING + 1)
            self.error(messages[deep].pos, f"message {deep} nests messages more than {_MAX_NESTING} levels deep "
                       f"({deep} -> {chain[1]} -> ... -> {chain[-1]})",
                       f"at most {_MAX_NESTING} levels of messages inside messages")

    def check_frames_and_parameters(self) -> None:
        s = self.spec
        for frame in s.frames.values():
            if not _FRAME_NAME.fullmatch(frame.name):
                self.error(frame.pos, f"frame {frame.name!r} is not a valid TF frame id", "an identifier")
            if frame.parent is not None and frame.parent not in s.frames:
                self.error(frame.pos, f"frame {frame.name!r} has unknown parent {frame.parent!r}")
        # Each frame is walked up once: a frame whose ancestry reaches a loop (or one known to) is in error, one
        # that reaches a root (or a frame known to) is not; a chain of N frames costs N steps, not N^2 / 2.
        loops: dict[str, bool] = {}
        for frame in s.frames.values():
            path: list[str] = []
            on_path: set[str] = set()
            cur: str | None = frame.name
            while cur is not None and cur in s.frames and cur not in loops and cur not in on_path:
                path.append(cur)
                on_path.add(cur)
                cur = s.frames[cur].parent
            looped = cur in on_path or (cur is not None and loops.get(cur, False))
            for name in path:
                loops[name] = looped
        for frame in s.frames.values():
            if loops[frame.name]:
                self.error(frame.pos, f"frame {frame.name!r} is its own ancestor")
        for t in s.transforms:
            for name in (t.parent, t.child):
                if name not in s.frames:
                    self.error(t.pos, f"transform {t.parent}->{t.child} names unknown frame {name!r}")
            if t.publisher not in s.nodes:
                self.error(t.pos, f"transform {t.parent}->{t.child} is published by unknown node {t.publisher!r}")
        for p in s.parameters.values():
            if (why := ros_name_problem(p.name)) is not None:
                self.error(p.pos, f"parameter name {p.name!r} is not a valid ROS name: {why}", NAME_RULES)
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
            if any(isinstance(p.default, float) and math.isnan(p.default) for p in (left, right)):
                continue  # a NaN default (`allow_nan: true`: e.g. "no limit") is ordered against nothing
            ok = {"<": lambda a, b: a < b, "<=": lambda a, b: a <= b,
                  ">": lambda a, b: a > b, ">=": lambda a, b: a >= b}[rule.op](left.default, right.default)
            if not ok:
                self.error(rule.pos, f"inconsistent parameter limits: {rule.left} = {left.default} must be "
                           f"{rule.op} {rule.right} = {right.default}" + (f" ({rule.description})"
                                                                          if rule.description else ""))

    def check_topics_and_nodes(self) -> None:
        s = self.spec
        for topic in s.topics.values():
            if (why := ros_name_problem(topic.name)) is not None:
                self.error(topic.pos, f"topic name {topic.name!r} is not a valid ROS name: {why}", NAME_RULES)
            if "/" not in topic.type:
                self.error(topic.pos, f"topic {topic.name} type {topic.type!r} needs its package", "pkg/Name")
            elif self.ros.get(topic.type) is None:
                self.error(topic.pos, f"unknown ROS type {topic.type!r} of topic {topic.name}",
                           "a message of this spec, an external_messages entry or an installed ROS message")

    def check_devices(self) -> dict[int, str]:
        """Checks the devices' Cyphal side; returns who publishes each subject id (the devices)."""
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
            if device.node_id not in CAN_NODE_IDS and CYPHAL.name in device.protocols:
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
        return publishers

    def mapping_validator(self, v0: V0Catalog, publishers: dict[int, str]) -> MappingValidator:
        return MappingValidator(self.spec, self.ros, self.dsdl, self.diag, publishers,
                                self.bad_dsdl_fields, self.failed_messages, v0)


def validate(spec: Spec, *, ros_share_dirs: list[Path] | None = None, dsdl_roots: list[Path] | None = None,
             dronecan_roots: list[Path] | None = None) -> Resolved:
    """Check a parsed spec; raises SpecError with every problem, or returns the resolved interface."""
    dsdl, v0 = DsdlCatalog(spec, dsdl_roots), V0Catalog(spec, dronecan_roots)
    diag = Diagnostics()
    derived, failed_messages = derive_messages(spec, dsdl, diag)
    ros = RosCatalog(spec, ros_share_dirs, derived)
    v = _Validator(spec, ros, dsdl, diag, failed_messages)
    v.check_header()
    # Before anything expands a type (the checks below, the converters, pydsdl): a type of 2^30 fields is fatal.
    if not check_type_sizes(spec, ros, dsdl, v0, diag):
        diag.check()
    for struct in spec.dsdl_types.values():
        v.check_dsdl_struct(struct)
    for service in spec.dsdl_services.values():  # each half as a struct (an error of the name is reported once)
        v.check_dsdl_struct(service.request)
        v.check_dsdl_struct(service.response)
    messages = v.check_messages()
    topics_msg = topics_message(spec, v.diag)  # ros.topics_message (validate.topics_message)
    messages = sorted([*messages, topics_msg], key=lambda m: m.name) if topics_msg is not None else messages
    v.check_frames_and_parameters()
    v.check_topics_and_nodes()
    check_nodes(spec, ros, v.diag)  # nodes, QoS, TF topics, external packages (validate.nodes)
    publishers = v.check_devices()
    dronecan = DronecanValidator(spec, v0, v.diag, v.mapping_validator(v0, publishers))
    dronecan.check_types()
    services = ServiceValidator(spec, ros, v0, v.diag, dsdl)
    srv_types = services.check_srv_types()
    services.check_v0_service_types()
    dronecan.check_devices()
    mappings = dronecan.mappings.resolve_mappings()
    dronecan_mappings = dronecan.resolve_mappings()
    check_panic_duty(spec, v.diag)
    layouts = dronecan.resolve_layouts(mappings, dronecan_mappings)
    # options that would act on nothing (validate.mapping_options)
    check_mapping_options([*mappings, *dronecan_mappings], v.diag, {d.pos for d in v.diag.items})
    service_mappings = services.resolve_mappings()
    service_mappings += resolve_node_services(spec, v.diag, v0.signed, ros.get)  # the duties (validate.node_services)
    check_routing(spec, v.diag)  # `any` node ids, `shares_data_type` (validate.routing)
    for error in v0.errors:
        v.error(Pos(spec.file), f"a DroneCAN standard definition cannot be read: {error}")
    v.diag.check()
    # The bus budget judges the resolved spec: a layout its CAN bus cannot carry is an error too.
    check_bus_budgets(spec, layouts, {"cyphal": mappings, "dronecan": dronecan_mappings}, dsdl.get, v0.get)
    # Every type of the spec passed its checks, so each has its signature (computed in check_types).
    dronecan_types = [v0.signed(t.name) for t in sorted(spec.dronecan_types.values(), key=lambda t: t.name)]
    return Resolved(spec, ros, dsdl, messages, sorted(spec.dsdl_types.values(), key=lambda t: t.name), mappings,
                    v0, [t for t in dronecan_types if t is not None], dronecan_mappings, layouts, srv_types,
                    service_mappings, sorted(spec.dsdl_services.values(), key=lambda t: t.name))


__all__ = ["CAN_NODE_IDS", "SUBJECT_IDS", "Constant", "Field", "Resolved", "validate"]
