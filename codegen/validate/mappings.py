"""Bridge mappings: each `ros_field: uavcan_field` line resolved against both types and the conversion rules,
and the check that every UAVCAN field of a mapping is mapped, ignored or given a value. Mapping expressions
(`{expr: ...}` lines, `uavcan_exprs`) are type-checked by validate.expressions against the paths resolved here;
in a UAVCAN -> ROS mapping every ROS field is written (a link, a value, an expression, the bridge's header) or
listed in `ros_defaults`.

MappingValidator is put together from parts by job: the type lookups along a line's paths and the state of the
mapping being resolved (validate.mapping_paths), the expression lines (validate.mapping_expressions) and the
coverage checks (validate.mapping_coverage); here the mappings' ports and node ids, and each line of a mapping."""

from __future__ import annotations

import re
from typing import Any

from sam_codegen.catalogs.cyphal import DsdlCatalog
from sam_codegen.catalogs.ros import RosCatalog
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.expr import names_of
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.spec import (
    ROS_TO_UAVCAN,
    UAVCAN_TO_ROS,
    Device,
    DsdlStruct,
    FieldLink,
    Mapping,
    Port,
    RosMessage,
    Scalar,
    Spec,
    Topic,
    V0Struct,
)
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES, DsdlType, RosType
from sam_codegen.validate.element_mappings import resolve_elements
from sam_codegen.validate.mapping_coverage import MappingCoverage
from sam_codegen.validate.mapping_expressions import MappingExpressions
from sam_codegen.validate.mapping_paths import Reported
from sam_codegen.validate.mapping_rules import (
    HEADER,
    TIME,
    TIMESTAMPS,
    PathSeg,
    ResolvedMapping,
    RuleError,
    Step,
    auto_links,
    check_arrays,
    check_scalar,
    check_string,
    format_path,
    missing_table_keys,
    parse_path,
    wrap_problem,
)
from sam_codegen.validate.values import CAN_NODE_IDS, SUBJECT_IDS, check_dsdl_value, check_ros_value, python_safe


class MappingValidator(MappingExpressions, MappingCoverage):
    """Resolves the bridge's mappings; reports into the run's Diagnostics."""

    def __init__(self, spec: Spec, ros: RosCatalog, dsdl: DsdlCatalog, diag: Diagnostics,
                 publishers: dict[int, str], bad_dsdl_fields: set[tuple[str, str]] | None = None,
                 failed_messages: set[str] | None = None, v0_types: Any = None) -> None:
        self.spec, self.ros, self.dsdl, self.diag = spec, ros, dsdl, diag
        self.v0_types = v0_types  # the DroneCAN catalog (dronecan_catalog.V0Catalog), for DroneCAN mappings
        self.v0 = False  # the mapping being resolved is a DroneCAN one
        self.types: Any = dsdl  # where its composite types are looked up
        self.elements: dict[tuple, dict[str, dict]] = {}
        self.publishers = publishers  # subject id -> who publishes it (devices; mappings are added)
        # Reported already (with their declarations): no follow-on errors about them.
        self.bad_dsdl_fields = bad_dsdl_fields or set()  # (DSDL type, field)
        self.failed_messages = failed_messages or set()  # ROS messages whose derive_from failed

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
        if not re.fullmatch(r"[a-z][a-z0-9_]*", mapping.name) or not python_safe(mapping.name):
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
        if mapping.direction == UAVCAN_TO_ROS:
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
        return self.resolve_body(mapping, what, topic, self.dsdl.get(port.type), port.rate_hz)

    def resolve_body(self, mapping: Mapping, what: str, topic: Topic | None, struct: DsdlStruct | None,
                     rate_hz: float) -> ResolvedMapping | None:
        """The protocol-independent part: the links, values and ignores against both types, and coverage."""
        self.v0 = isinstance(struct, V0Struct)
        self.types = self.v0_types if self.v0 else self.dsdl
        # DroneCAN arrays whose elements the mapping names: array path -> {"index": {i: None}, "key": {Key: None}}
        self.elements = {}
        ros_message = self.ros.get(topic.type) if topic is not None else None
        if struct is None or ros_message is None:
            return None
        if ros_message.full_name in self.failed_messages:
            return None  # its fields are unknown: every line would be a follow-on error
        if struct.union:
            self.error(mapping.pos, f"{what}: union types ({struct.name}) cannot be mapped")
            return None
        has_header = any(f.name == "header" and isinstance(f.type, RosType) and f.type.base == HEADER
                         for f in ros_message.fields)
        if has_header and self.header_left_default(mapping, what):
            has_header = False  # the bridge writes no stamp and no frame id: the C++'s untouched header
        links = self.mapped_links(mapping, what, struct, ros_message, has_header)
        if links is None:
            return None
        steps = self.resolve_links(links, ros_message, struct, mapping, what)
        select = self.resolve_select(mapping, struct, what)
        uavcan_values = self.resolve_uavcan_values(mapping, struct, what)
        self.resolve_ignores(mapping, struct, what)
        steps += self.resolve_uavcan_exprs(mapping, ros_message, struct, what, steps)
        elements, elements_ok = self.check_elements(mapping, what)
        resolved = ResolvedMapping(mapping, ros_message, struct, steps, uavcan_values, has_header, rate_hz, select,
                                   elements)
        if elements_ok:  # (else coverage would only repeat the confusion)
            self.check_coverage(resolved, what)
        return resolved

    def header_left_default(self, mapping: Mapping, what: str) -> bool:
        """Whether a UAVCAN -> ROS mapping leaves its message's header at its default (`ros_defaults: [header]`:
        zero stamp, empty frame id, as a C++ bridge that never touches it); a frame_id beside it is an error."""
        if mapping.direction != UAVCAN_TO_ROS or "header" not in mapping.ros_defaults:
            return False
        if mapping.frame_id is not None:
            self.error(mapping.pos, f"{what} leaves its header at its default (ros_defaults: [header]) but gives "
                       f"frame_id {mapping.frame_id!r}", "either the frame_id or header in ros_defaults")
        for link in mapping.links:
            if link.ros_path == "header" or link.ros_path.startswith("header."):
                self.error(link.pos, f"{what} leaves its header at its default (ros_defaults: [header]) but "
                           f"writes {link.ros_path!r}", "either the line or header in ros_defaults")
        return True

    def mapped_links(self, mapping: Mapping, what: str, struct: DsdlStruct, ros_message: RosMessage,
                     has_header: bool) -> list[FieldLink] | None:
        """The mapping's field lines (`fields: auto` spelled out), after checking its frame_id; None (reported)
        when `fields: auto` does not fit the types."""
        s = self.spec
        # '' is the explicit empty frame id (a bridge that never sets one): written as nothing, never prefixed
        if mapping.frame_id and mapping.frame_id not in s.frames:
            self.error(mapping.pos, f"frame_id {mapping.frame_id!r} of {what} is not a declared frame",
                       "one of " + ", ".join(s.frames) + ", or '' for an empty frame id")
        if mapping.direction == UAVCAN_TO_ROS and has_header and mapping.frame_id is None:
            self.error(mapping.pos, f"{what} publishes {ros_message.full_name}, which has a header: it needs "
                       "a frame_id", "a declared frame, `frame_id: ''` for an empty one, or `ros_defaults: "
                       "[header]` to leave the header at its default")
        links = auto_links(struct, mapping.pos) if mapping.auto else mapping.links
        if mapping.auto and not self.v0 and ros_message.derived_from != struct.name:
            self.error(mapping.pos, f"{what} uses `fields: auto`, which needs a ROS message derived from "
                       f"{struct.name} (topic type is {ros_message.full_name})")
            return None
        if mapping.auto and self.v0:  # by name: every field of the DroneCAN type into the ROS field of its name
            missing = [link.ros_path for link in links if link.ros_path != "header.stamp"
                       and ros_message.field(link.ros_path) is None]
            if missing:
                self.error(mapping.pos, f"{what} uses `fields: auto`, but {ros_message.full_name} has no field "
                           + ", ".join(repr(m) for m in missing), f"a ROS message with the fields of {struct.name}")
                return None
        return links

    def resolve_links(self, links: list[FieldLink], ros_message: RosMessage, struct: DsdlStruct, mapping: Mapping,
                      what: str) -> list[Step]:
        """A step per field line that resolves; a failed line's fields go to failed_paths and failed_ros."""
        steps: list[Step] = []
        ros_targets: dict[str, Pos] = {}
        self.failed_paths = set()
        self.failed_ros = set()  # ROS fields of failed links
        for link in links:
            step = self.resolve_link(link, ros_message, struct, mapping, what)
            if step is None:
                # Its UAVCAN side is reported already; do not report it again as unmapped.
                if link.uavcan_path:
                    self.failed_paths.add(link.uavcan_path.split("[")[0].split(".")[0])
                if link.expr is not None:  # its fields are reported already
                    self.failed_paths |= {n.split("[")[0].split(".")[0] for n in names_of(link.expr.tree)}
                self.failed_ros.add(link.ros_path)  # and its target
                try:
                    self.ros_leaf(ros_message, parse_path(link.ros_path))
                except RuleError:  # a ROS path that does not resolve: which fields are written is unclear
                    self.failed_ros.add("")
                continue
            if step.ros in ros_targets:
                self.error(link.pos, f"ROS field {step.ros!r} is set twice in {what}")
            ros_targets[step.ros] = link.pos
            steps.append(step)
        return steps

    def resolve_select(self, mapping: Mapping, struct: DsdlStruct,
                       what: str) -> list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]]:
        """`select`: the integer or bool fields a message must carry these values in."""
        select: list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]] = []
        for path_text, value in mapping.select.items():
            try:
                path = parse_path(path_text)
                if any(index is not None for _, index in path):
                    raise RuleError(f"{path_text} names an array element; a selection compares a field")
                leaf = self.dsdl_leaf(struct, path)
                if leaf.array or leaf.kind not in ("bool", "int", "uint"):
                    raise RuleError(f"{path_text} is {leaf}; a selection compares an integer or bool field")
            except Reported:
                continue
            except RuleError as exc:
                self.error(mapping.select_pos, f"select of {what}: {exc}")
                continue
            check_dsdl_value(self.diag, leaf, value, mapping.select_pos, f"select value {path_text!r} of {what}")
            select.append((tuple(path), leaf, value))
        return select

    def resolve_uavcan_values(self, mapping: Mapping, struct: DsdlStruct,
                              what: str) -> list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]]:
        """`uavcan_values`: UAVCAN fields given a fixed value."""
        uavcan_values: list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]] = []
        for path_text, value in mapping.uavcan_values.items():
            try:
                path = parse_path(path_text)
                leaf = self.dsdl_leaf(struct, path)
            except Reported:
                self.failed_paths.add(path_text.split("[")[0].split(".")[0])
                continue
            except RuleError as exc:
                self.error(mapping.pos, f"uavcan_values of {what}: {exc}")
                continue
            check_dsdl_value(self.diag, leaf, value, mapping.pos, f"uavcan value {path_text!r} of {what}")
            uavcan_values.append((tuple(path), leaf, value))
        return uavcan_values

    def resolve_ignores(self, mapping: Mapping, struct: DsdlStruct, what: str) -> None:
        """`ignore`: the UAVCAN fields (or whole composites) no line maps, into self.ignored."""
        self.ignored = set()
        for ignored in mapping.ignore:
            try:
                path = parse_path(ignored)
                self.dsdl_leaf(struct, path, allow_composite=True, record=False)
            except Reported:
                self.ignored.add(ignored.split("[")[0].split(".")[0])
            except RuleError as exc:
                self.error(mapping.pos, f"ignore of {what}: {exc}")
            else:
                self.ignored.add(format_path(path))

    def resolve_link(self, link: FieldLink, ros_message: RosMessage, struct: DsdlStruct, mapping: Mapping,
                     what: str) -> Step | None:
        try:
            ros_path = parse_path(link.ros_path)
            ros_type = self.ros_leaf(ros_message, ros_path)
            if link.expr is not None:
                step = self.resolve_expr_link(link, link.expr, ros_path, ros_type, struct, mapping, what)
                return self.checked_wrap(step, mapping)
            if link.each is not None:  # an array of composites, element by element
                return resolve_elements(self, link, ros_path, ros_type, struct, mapping, what)
            if link.value is not None:
                if mapping.direction == ROS_TO_UAVCAN:
                    raise RuleError("a `value` sets a ROS field; a ROS->UAVCAN mapping sets UAVCAN fields with "
                                    "uavcan_values")
                if ros_type.array or not ros_type.is_primitive:
                    raise RuleError(f"a `value` sets a primitive field, {link.ros_path} is {ros_type}")
                check_ros_value(self.diag, ros_type, link.value, link.pos, f"value of {link.ros_path!r}")
                return Step("value", tuple(ros_path), ros_type, value=link.value, pos=link.pos)
            assert link.uavcan_path is not None
            uav_path = parse_path(link.uavcan_path)
            uav_type = self.dsdl_leaf(struct, uav_path)
            if uav_type.kind == "composite" and uav_type.composite in TIMESTAMPS:
                uav_path.append((TIMESTAMPS[uav_type.composite], None))
                uav_type = DsdlType("uint", 56, truncated=True)
            if not ros_type.is_primitive and ros_type.base == TIME and not ros_type.array:
                if uav_type.kind not in ("uint", "int") or uav_type.array or link.scale or link.table:
                    raise RuleError(f"builtin_interfaces/Time receives a microsecond integer, not {uav_type}")
                return Step("time", tuple(ros_path), ros_type, tuple(uav_path), uav_type, pos=link.pos)
            if not ros_type.is_primitive:
                raise RuleError(f"{link.ros_path} is a {ros_type.base}; map its fields one by one" if not ros_type.array
                                else f"{link.ros_path} is {ros_type}: map it element by element with "
                                "`{each: <UAVCAN array>, fields: {...}}`")
            if link.limits is not None and (ros_type.array or ros_type.base not in {*ROS_INT_RANGES, *ROS_FLOAT_BITS}):
                raise RuleError("limits apply to numeric scalar fields")
            if link.limits is not None and mapping.direction == UAVCAN_TO_ROS:  # the converters apply none there
                raise RuleError("limits bound the values a ROS -> UAVCAN mapping commands; a UAVCAN -> ROS mapping "
                                "passes on what the device measured")
            if uav_type.kind == "utf8" or ros_type.base == "string":
                exact = check_string(ros_type, uav_type, link, protocol_of(mapping.protocol).v0)
                kind = "string"
            elif uav_type.array or ros_type.array:
                exact = check_arrays(ros_type, uav_type, link)
                kind = "array"
            else:
                kind, exact = check_scalar(ros_type, uav_type, link)
            if kind == "table" and mapping.direction == UAVCAN_TO_ROS and link.table_default is None:
                self.check_table_covers(uav_type, link, what)
            return self.checked_wrap(
                Step(kind, tuple(ros_path), ros_type, tuple(uav_path), uav_type, link.scale, link.offset,
                     tuple(sorted((link.table or {}).items())), link.table_default, None, link.limits, exact,
                     link.pos, wrap=link.wrap), mapping)
        except Reported:
            return None
        except RuleError as exc:
            self.error(link.pos, f"{what}, field {link.ros_path!r}: {exc}")
            return None

    @staticmethod
    def checked_wrap(step: Step | None, mapping: Mapping) -> Step | None:
        """`step`, unless its line's `on_out_of_range: wrap` cannot apply (raised: reported with the line)."""
        if step is not None:
            problem = wrap_problem(step, to_ros=mapping.direction == UAVCAN_TO_ROS)
            if problem is not None:
                raise RuleError(problem)
        return step

    def check_table_covers(self, uav: DsdlType, link: FieldLink, what: str) -> None:
        """A UAVCAN -> ROS table must say what every value the device may send becomes; a value it misses
        would drop the whole message at run time."""
        count, first = missing_table_keys(uav, set(link.table or {}))
        if count:
            listed = ", ".join(map(str, first)) + (", ..." if count > len(first) else "")
            total = uav.range[1] - uav.range[0] + 1
            self.error(link.pos, f"{what}, field {link.ros_path!r}: the table has no entry for {count} of the "
                       f"{total} values of {uav} ({listed}); a message carrying one would be dropped",
                       "an entry for each value, or `default: <ROS value>` for the values it does not list")
