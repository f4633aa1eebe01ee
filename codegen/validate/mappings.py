"""Bridge mappings: each `ros_field: uavcan_field` line resolved against both types and the conversion rules,
and the check that every UAVCAN field of a mapping is mapped, ignored or given a value. Mapping expressions
(`{expr: ...}` lines, `uavcan_exprs`) are type-checked by validate.expressions against the paths resolved here;
in a UAVCAN -> ROS mapping every ROS field is written (a link, a value, an expression, the bridge's header) or
listed in `ros_defaults`."""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any, TypeVar

from sam_codegen.catalogs.cyphal import DsdlCatalog
from sam_codegen.catalogs.ros import RosCatalog
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.expr import ExprSource, fields_of, names_of
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
from sam_codegen.validate.expressions import ExprError, check_expr, check_target
from sam_codegen.validate.mapping_rules import (
    HEADER,
    TIME,
    TIMESTAMPS,
    Key,
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
)
from sam_codegen.validate.values import CAN_NODE_IDS, SUBJECT_IDS, check_dsdl_value, check_ros_value, python_safe

T = TypeVar("T", RosType, DsdlType)


class _Reported(RuleError):
    """The path runs into a type that is reported broken already: the link adds no error of its own."""


def _indexed(leaf: T, name: str, index: int | Key | None, v0: bool = False) -> T:
    """The element type for `name[index]`, which only a fixed-size array allows; in a DroneCAN message also a
    bounded one (the element of a broadcast array, e.g. rpm[1] of esc.RPMCommand), and `name[key=value]` (checked
    by the caller) an array of composites."""
    if index is None:
        return leaf
    if isinstance(index, Key):
        if not v0 or isinstance(leaf, RosType):
            raise RuleError(f"{name}[{index}]: an item is chosen by key only in the arrays of a DroneCAN message")
        if not leaf.array or leaf.kind != "composite":
            raise RuleError(f"{name}[{index}]: an item is chosen by key in an array of composites, {name} is {leaf}")
        return leaf.element
    if leaf.array != "fixed" and not (v0 and leaf.array == "bounded" and isinstance(leaf, DsdlType)):
        allowed = "fixed-size and DroneCAN arrays" if v0 else "fixed-size arrays"
        raise RuleError(f"{name}[{index}]: only {allowed} take an index, {name} is {leaf}")
    if index >= (leaf.capacity or 0):
        raise RuleError(f"{name}[{index}]: index out of range, {name} has {leaf.capacity} elements"
                        if leaf.array == "fixed" else f"{name}[{index}]: index out of range, {name} holds at most "
                        f"{leaf.capacity} elements")
    return leaf.element


class MappingValidator:
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

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.diag.error(pos, message, expected)

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
        s = self.spec
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
        if mapping.frame_id is not None and mapping.frame_id not in s.frames:
            self.error(mapping.pos, f"frame_id {mapping.frame_id!r} of {what} is not a declared frame",
                       "one of " + ", ".join(s.frames))
        if mapping.direction == UAVCAN_TO_ROS and has_header and mapping.frame_id is None:
            self.error(mapping.pos, f"{what} publishes {ros_message.full_name}, which has a header: it needs "
                       "a frame_id")
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
        steps: list[Step] = []
        select: list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]] = []
        uavcan_values: list[tuple[tuple[PathSeg, ...], DsdlType, Scalar]] = []
        ros_targets: dict[str, Pos] = {}
        self.failed_paths: set[str] = set()
        self.failed_ros: set[str] = set()  # ROS fields of failed links
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
        for path_text, value in mapping.select.items():
            try:
                path = parse_path(path_text)
                if any(index is not None for _, index in path):
                    raise RuleError(f"{path_text} names an array element; a selection compares a field")
                leaf = self.dsdl_leaf(struct, path)
                if leaf.array or leaf.kind not in ("bool", "int", "uint"):
                    raise RuleError(f"{path_text} is {leaf}; a selection compares an integer or bool field")
            except _Reported:
                continue
            except RuleError as exc:
                self.error(mapping.select_pos, f"select of {what}: {exc}")
                continue
            check_dsdl_value(self.diag, leaf, value, mapping.select_pos, f"select value {path_text!r} of {what}")
            select.append((tuple(path), leaf, value))
        for path_text, value in mapping.uavcan_values.items():
            try:
                path = parse_path(path_text)
                leaf = self.dsdl_leaf(struct, path)
            except _Reported:
                self.failed_paths.add(path_text.split("[")[0].split(".")[0])
                continue
            except RuleError as exc:
                self.error(mapping.pos, f"uavcan_values of {what}: {exc}")
                continue
            check_dsdl_value(self.diag, leaf, value, mapping.pos, f"uavcan value {path_text!r} of {what}")
            uavcan_values.append((tuple(path), leaf, value))
        self.ignored: set[str] = set()
        for ignored in mapping.ignore:
            try:
                path = parse_path(ignored)
                self.dsdl_leaf(struct, path, allow_composite=True, record=False)
            except _Reported:
                self.ignored.add(ignored.split("[")[0].split(".")[0])
            except RuleError as exc:
                self.error(mapping.pos, f"ignore of {what}: {exc}")
            else:
                self.ignored.add(format_path(path))
        steps += self.resolve_uavcan_exprs(mapping, ros_message, struct, what, steps)
        elements, elements_ok = self.check_elements(mapping, what)
        resolved = ResolvedMapping(mapping, ros_message, struct, steps, uavcan_values, has_header, rate_hz, select,
                                   elements)
        if elements_ok:  # (else coverage would only repeat the confusion)
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
            nested = not (leaf.is_primitive or leaf.array or leaf.base == TIME)
            current = self.ros.get(leaf.base) if nested else None
            if nested and (current is None or current.full_name in self.failed_messages):
                raise _Reported(f"{leaf.base} is unknown or could not be derived")  # reported with the type
        assert leaf is not None
        return leaf

    def dsdl_leaf(self, struct: DsdlStruct, path: list, allow_composite: bool = False, record: bool = True
                  ) -> DsdlType:
        """The type at `path`; with `record`, the DroneCAN array elements it names are noted (self.elements)."""
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
            array = leaf
            leaf = _indexed(leaf, name, index, self.v0)
            current = self.types.get(leaf.composite) if leaf.kind == "composite" and not leaf.array else None
            if current is None and leaf.kind == "composite" and not leaf.array:
                raise _Reported(f"unknown DSDL type {leaf.composite}")  # reported with the field's declaration
            if current is not None and current.union:
                raise RuleError(f"{name} is a union ({current.name}); unions cannot be mapped")
            if isinstance(index, Key) and current is not None:
                self.check_key(current, name, index)
            if record and ((index is not None and self.v0 and array.array == "bounded") or isinstance(index, Key)):
                uses = self.elements.setdefault((*path[:i], (name, None)), {"index": {}, "key": {}})
                uses["key" if isinstance(index, Key) else "index"][index] = None
        assert leaf is not None
        if leaf.kind == "composite" and not leaf.array and not allow_composite and leaf.composite not in TIMESTAMPS:
            raise RuleError(f"{format_path(path)} is a composite ({leaf.composite}); map its fields one by one")
        return leaf

    def check_key(self, item: DsdlStruct, name: str, key: Key) -> None:
        """`name[field=value]`: `field` an integer of the item type, `value` one of its values."""
        f = item.field(key.field)
        t = f.type if f is not None else None
        if not isinstance(t, DsdlType) or t.array or t.kind not in ("int", "uint"):
            raise RuleError(f"{name}[{key}]: the key must be an integer field of {item.name}"
                            + (f", {key.field} is {t}" if t is not None else f", which has no field {key.field!r}"))
        lo, hi = t.range
        if not lo <= key.value <= hi:
            raise RuleError(f"{name}[{key}]: {key.value} is outside the range of {key.field} ({t}) [{lo}, {hi}]")

    def resolve_link(self, link: FieldLink, ros_message: RosMessage, struct: DsdlStruct, mapping: Mapping,
                     what: str) -> Step | None:
        try:
            ros_path = parse_path(link.ros_path)
            ros_type = self.ros_leaf(ros_message, ros_path)
            if link.expr is not None:
                return self.resolve_expr_link(link, link.expr, ros_path, ros_type, struct, mapping, what)
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
                exact = check_string(ros_type, uav_type, link, mapping.protocol == "dronecan")
                kind = "string"
            elif uav_type.array or ros_type.array:
                exact = check_arrays(ros_type, uav_type, link)
                kind = "array"
            else:
                kind, exact = check_scalar(ros_type, uav_type, link)
            if kind == "table" and mapping.direction == UAVCAN_TO_ROS and link.table_default is None:
                self.check_table_covers(uav_type, link, what)
            return Step(kind, tuple(ros_path), ros_type, tuple(uav_path), uav_type, link.scale, link.offset,
                        tuple(sorted((link.table or {}).items())), link.table_default, None, link.limits, exact,
                        link.pos)
        except _Reported:
            return None
        except RuleError as exc:
            self.error(link.pos, f"{what}, field {link.ros_path!r}: {exc}")
            return None

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

    def uncovered(self, struct: DsdlStruct, prefix: str, pool: set[str], skip: str | None = None
                  ) -> list[tuple[str, DsdlType]]:
        """The fields of `struct` (paths under `prefix`) that `pool` leaves without a value, each as large as
        possible: a field or array element under which the pool has no path is one entry, whole."""
        result: list[tuple[str, DsdlType]] = []
        for f in struct.fields:
            assert isinstance(f.type, DsdlType)
            if (struct.name, f.name) not in self.bad_dsdl_fields and f.name != skip:  # reported with its declaration
                result.extend(self.uncovered_at(prefix + f.name, f.type, pool))
        return result

    def uncovered_at(self, path: str, t: DsdlType, pool: set[str]) -> list[tuple[str, DsdlType]]:
        if path in pool:
            return []
        uses = self.element_uses.get(path)
        if uses is not None:  # a DroneCAN array of which the mapping names elements
            if self.direction == UAVCAN_TO_ROS:
                return []  # it reads its elements; the others are other mappings' (or nobody's)
            if uses["index"]:  # the message is built with exactly the elements up to the last one named
                return [u for i in range(max(uses["index"]) + 1)
                        for u in self.uncovered_at(f"{path}[{i}]", t.element, pool)]
            item = self.types.get(t.composite) if t.composite else None
            return [u for key in uses["key"] for u in self.uncovered(item, f"{path}[{key}].", pool, key.field)
                    ] if item is not None else []
        if not any(p.startswith((path + ".", path + "[")) for p in pool):
            return [(path, t)]
        if t.array == "fixed":  # some elements (or their fields) are covered: look at each
            return [u for i in range(t.capacity or 0) for u in self.uncovered_at(f"{path}[{i}]", t.element, pool)]
        nested = self.types.get(t.composite) if t.kind == "composite" and not t.array and t.composite else None
        if nested is not None:
            return self.uncovered(nested, path + ".", pool)
        return [(path, t)]

    def check_elements(self, mapping: Mapping, what: str) -> tuple[dict[tuple[PathSeg, ...], list], bool]:
        """A DroneCAN array's elements are named by position or by one key field, not both. Returns the arrays
        named one way (path -> positions or items, in order) and whether every array is."""
        ok = True
        elements: dict[tuple[PathSeg, ...], list] = {}
        for path, uses in self.elements.items():
            text = format_path(list(path))
            fields = {key.field for key in uses["key"]}
            if uses["index"] and uses["key"]:
                self.error(mapping.pos, f"{what} names elements of {text} both by position and by key",
                           "one way for one array")
                ok = False
            elif len(fields) > 1:
                self.error(mapping.pos, f"{what} chooses items of {text} by more than one key field ("
                           + ", ".join(sorted(fields)) + ")", "one key field per array")
                ok = False
            else:
                elements[path] = list(uses["index"] or uses["key"])
        self.element_uses = {format_path(list(path)): uses for path, uses in self.elements.items()}
        return elements, ok

    def check_coverage(self, resolved: ResolvedMapping, what: str) -> None:
        mapping = resolved.mapping
        self.direction = mapping.direction
        linked = {s.uavcan for s in resolved.steps if s.uavcan_path} | self.failed_paths
        linked |= {f.text for s in resolved.steps if s.expr is not None and not s.uavcan_path
                   for f in fields_of(s.expr)}  # what UAVCAN -> ROS expressions read
        valued = {format_path(list(p)) for p, _, _ in resolved.uavcan_values}
        selected = {format_path(list(p)) for p, _, _ in resolved.select}
        # UAVCAN->ROS may also publish a select field (esc_index routed on and reported); ROS->UAVCAN sets it once
        for path in sorted(selected & (linked | valued) if mapping.direction == ROS_TO_UAVCAN else selected & valued):
            self.error(mapping.pos, f"UAVCAN field {path!r} is set by `select` in {what}; it cannot also be mapped",
                       "the field in select only")
        linked |= selected
        struct = resolved.dsdl_struct
        if mapping.direction == UAVCAN_TO_ROS:
            if not mapping.name.endswith("[]"):  # an element mapping's (`<mapping>.<array>[]`): element_mappings
                self.check_ros_written(resolved, what)  # checks its fields, with advice that fits `fields`
            for path, t in self.uncovered(struct, "", linked | self.ignored):
                self.error(mapping.pos, f"required field left unmapped: UAVCAN field {path!r} ({t}) of "
                           f"{struct.name} is neither mapped nor ignored in {what}",
                           f"a `ros_field: {path}` line or `{path}` in ignore")
        else:
            if mapping.ros_defaults:
                self.error(mapping.pos, f"{what} goes ROS->UAVCAN: ros_defaults name ROS fields a UAVCAN->ROS "
                           "mapping leaves unwritten")
            for path, t in self.uncovered(struct, "", linked | valued):
                self.error(mapping.pos, f"required field left unmapped: UAVCAN field {path!r} ({t}) of "
                           f"{struct.name} gets no value in {what}",
                           f"a `ros_field: {path}` line or an entry in uavcan_values")
            for path in sorted(linked & valued):
                self.error(mapping.pos, f"UAVCAN field {path!r} is both mapped and in uavcan_values in {what}")

    # ---- mapping expressions (model.expr) and the ROS fields a UAVCAN -> ROS mapping writes -----------------------

    def check_expression(self, source: ExprSource, resolve: Callable[[list], DsdlType | RosType],
                         target: DsdlType | RosType, target_name: str, what: str) -> Step | None:
        """The typed tree of an expression whose names `resolve` finds, checked against its target; None when
        reported (at the column of the offending node)."""
        def field_type(path_text: str) -> DsdlType | RosType:
            try:
                return resolve(parse_path(path_text))
            except _Reported:
                raise
            except RuleError as exc:
                raise ValueError(f"unknown field: {exc}") from None

        try:
            tree = check_expr(source.tree, field_type)
            check_target(tree, target, target_name)
        except _Reported:
            return None
        except ExprError as exc:
            self.error(source.at(exc.col), f"{what}: {exc.message}")
            return None
        return Step("expr", (), RosType("float64"), pos=source.pos, exact=False, expr=tree)

    def resolve_expr_link(self, link: FieldLink, source: ExprSource, ros_path: list, ros_type: RosType,
                          struct: DsdlStruct, mapping: Mapping, what: str) -> Step | None:
        """`ros_field: {expr: "..."}` in a UAVCAN -> ROS mapping: the ROS field computed from UAVCAN fields."""
        if mapping.direction == ROS_TO_UAVCAN:
            raise RuleError("an `expr` line computes a ROS field from UAVCAN fields; a ROS->UAVCAN mapping "
                            "computes UAVCAN fields from ROS fields in uavcan_exprs")
        step = self.check_expression(source, lambda path: self.dsdl_leaf(struct, path), ros_type, link.ros_path,
                                     f"{what}, field {link.ros_path!r}")
        if step is None:
            return None
        return Step("expr", tuple(ros_path), ros_type, pos=link.pos, exact=False, expr=step.expr)

    def resolve_uavcan_exprs(self, mapping: Mapping, ros_message: RosMessage, struct: DsdlStruct, what: str,
                             linked: list[Step]) -> list[Step]:
        """`uavcan_exprs: {uavcan_field: "..."}` of a ROS -> UAVCAN mapping: UAVCAN fields computed from ROS
        fields."""
        steps: list[Step] = []
        if mapping.uavcan_exprs and mapping.direction == UAVCAN_TO_ROS:
            self.error(mapping.uavcan_exprs[0].pos, f"{what} goes UAVCAN->ROS: uavcan_exprs compute UAVCAN fields "
                       "of a ROS->UAVCAN mapping", "`ros_field: {expr: ...}` lines in fields")
            return steps
        for entry in mapping.uavcan_exprs:
            try:
                path = parse_path(entry.uavcan_path)
                target = self.dsdl_leaf(struct, path)
            except _Reported:
                self.failed_paths.add(entry.uavcan_path.split("[")[0].split(".")[0])
                continue
            except RuleError as exc:
                self.error(entry.pos, f"uavcan_exprs of {what}: {exc}")
                continue
            step = self.check_expression(entry.expr, lambda p: self.ros_leaf(ros_message, p), target,
                                         entry.uavcan_path, f"{what}, UAVCAN field {entry.uavcan_path!r}")
            if step is None:
                self.failed_paths.add(entry.uavcan_path.split("[")[0].split(".")[0])
            else:
                if any(s.uavcan == format_path(path) for s in [*linked, *steps]):
                    self.error(entry.pos, f"UAVCAN field {entry.uavcan_path!r} is both mapped and in uavcan_exprs "
                               f"in {what}", "one of them")
                    continue
                steps.append(Step("expr", (), RosType("float64"), tuple(path), target, pos=entry.pos, exact=False,
                                  expr=step.expr))
        return steps

    def check_ros_written(self, resolved: ResolvedMapping, what: str) -> None:
        """UAVCAN -> ROS: every ROS field gets a value (a link, a `value`, an `expr`; header.stamp and frame_id
        from the bridge) or is listed in ros_defaults: a field nothing writes would always read 0 / false."""
        m = resolved.mapping
        message = resolved.ros_message
        written = {s.ros for s in resolved.steps if s.ros_path} | self.failed_ros
        if "" in written:
            return  # a link names a ROS field that does not resolve: reported already, coverage would only guess
        if resolved.has_header:
            written.add("header")  # stamp: the source's or the receive time; frame_id: the mapping's
        defaults: set[str] = set()
        for text in m.ros_defaults:
            try:
                segments = parse_path(text)
                self.ros_leaf(message, segments)
            except _Reported:
                continue
            except RuleError as exc:
                self.error(m.pos, f"ros_defaults of {what}: {exc}")
                continue
            name = format_path(segments)
            if name in written:
                self.error(m.pos, f"ROS field {name!r} is in ros_defaults of {what} but the mapping writes it",
                           "ros_defaults lists only fields nothing writes")
            defaults.add(name)
        for path, t, elements in self.ros_unwritten(message, "", written, defaults):
            self.error(m.pos, f"ROS field {path!r} ({t}) of {message.full_name} is written by nothing in {what}"
                       + (f" (elements {elements})" if elements else "") + ": it would always keep its default",
                       f"a `{path}: <uavcan field>` line, `{path}: {{value: ...}}`, `{path}: {{expr: ...}}` or "
                       f"`{path}` in ros_defaults")

    def ros_unwritten(self, message: RosMessage, prefix: str, written: set[str], defaults: set[str]
                      ) -> list[tuple[str, RosType, str]]:
        """The fields of `message` (paths under `prefix`) that nothing writes and no default names, each as large
        as possible; a fixed array written in part is one entry with the elements left (a default naming a
        field covers everything under it that nothing writes)."""
        out: list[tuple[str, RosType, str]] = []
        for f in message.fields:
            assert isinstance(f.type, RosType)
            path, t = prefix + f.name, f.type
            if path in written or path in defaults:
                continue
            if not t.is_primitive and self.ros.get(t.base) is None and t.base != TIME:
                continue  # an unknown type: reported with its declaration
            if not any(p.startswith((path + ".", path + "[")) for p in written):
                out.append((path, t, ""))
            elif t.array == "fixed":
                element = t.element
                nested = self.ros.get(element.base) if not element.is_primitive else None
                left = []
                for i in range(t.capacity or 0):
                    item = f"{path}[{i}]"
                    if item in written or item in defaults:
                        continue
                    if nested is not None and any(p.startswith(item + ".") for p in written):
                        out += self.ros_unwritten(nested, item + ".", written, defaults)
                    else:
                        left.append(str(i))
                if left:
                    out.append((path, t, ", ".join(left)))
            elif not t.array and not t.is_primitive and self.ros.get(t.base) is not None:
                out += self.ros_unwritten(self.ros.get(t.base), path + ".", written, defaults)  # type: ignore[arg-type]
            else:
                out.append((path, t, ""))
        return out
