"""The spec's service types and service mappings: ROS `.srv` types (`services`), the DroneCAN service types of
`dronecan_types` (`request`/`response`, a data type id in the vendor service range) and `bridge.service_mappings`
(a ROS service answered by a UAVCAN request to one device).

Invariants: every error is reported with its position and nothing follows from a reported one (a mapping whose srv
or UAVCAN type is broken gets no field errors). A resolved service mapping writes every UAVCAN request field (a
link or a `uavcan_values` constant): the device never gets a half-filled request. Response fields the mapping does
not link keep the srv's defaults. A link is scalar (a number or bool into a number or bool) or a string <-> a
UAVCAN uint8 array (text).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field

from sam_codegen.catalogs.cyphal import DsdlCatalog
from sam_codegen.catalogs.dronecan import SERVICE_ID_MAX, VENDOR_SERVICE_IDS, V0Catalog
from sam_codegen.catalogs.ros import RosCatalog
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.ros_names import NAME_RULES, ros_name_problem
from sam_codegen.model.spec import DsdlStruct, Field, FieldLink, RosService, Scalar, ServiceMapping, Spec, V0Struct
from sam_codegen.model.types import (
    ROS_CONSTANT_NAME,
    ROS_FIELD_NAME,
    ROS_FLOAT_BITS,
    ROS_INT_RANGES,
    ROS_MESSAGE_NAME,
    DsdlType,
    RosType,
)
from sam_codegen.validate.cyphal_services import resolve_cyphal_mapping
from sam_codegen.validate.service_coverage import check_response_written, response_leaf
from sam_codegen.validate.values import check_dsdl_value, check_ros_value, python_safe

__all__ = ["ResolvedServiceMapping", "ServiceLink", "ServiceValidator", "bridge_written"]

_F32_MAX = 3.4028234663852886e38
_V0_FIELD_NAME = re.compile(r"^[a-zA-Z][a-zA-Z0-9_]*$")


@dataclass(frozen=True)
class ServiceLink:
    """One field a service mapping writes: `target` from `source` (None: the constant `value`), as
    target = (source - offset) / scale going to UAVCAN and target = source * scale + offset coming back (a mapping
    line's rule). `kind`: "int" (rounded half to even, saturated to [lo, hi]), "float", "bool" or "text" (a ROS
    string <-> a UAVCAN uint8 array of at most `hi` bytes, cut there)."""

    target: str
    source: str | None
    kind: str
    value: Scalar | None = None
    scale: float | None = None
    offset: float | None = None
    lo: float = -math.inf
    hi: float = math.inf


@dataclass(frozen=True)
class ResolvedServiceMapping:
    mapping: ServiceMapping
    srv: RosService
    struct: V0Struct | None  # DroneCAN: signed, its data type id and signature; None on Cyphal
    request: list[ServiceLink] = field(default_factory=list)  # every UAVCAN request field
    response: list[ServiceLink] = field(default_factory=list)  # the ROS response fields it sets
    data_type: str = ""  # the UAVCAN service type's full name (Cyphal: with its version)
    service_id: int = 0  # DroneCAN: the data type id; Cyphal: the service id


def _ros_kind(t: RosType) -> str | None:
    if t.array:
        return None
    if t.base in ROS_INT_RANGES:
        return "int"
    if t.base in ROS_FLOAT_BITS:
        return "float"
    if t.base == "bool":
        return "bool"
    if t.base == "string":
        return "text"
    return None


def _v0_kind(t: DsdlType) -> str | None:
    if t.array:
        return "text" if t.kind in ("uint", "byte", "utf8") and t.bits == 8 else None
    return {"int": "int", "uint": "int", "float": "float", "bool": "bool"}.get(t.kind)


def bridge_written(srv: RosService, duty: bool = False) -> set[str]:
    """The response fields the bridge writes itself: a bool `success` (a duty's `ok` too) and a string `message`,
    its answer to a call that failed (sam_codegen.targets.python.services)."""
    types = {f.name: str(f.type) for f in srv.response}
    out = {name for name in ("success", *(("ok",) if duty else ())) if types.get(name) == "bool"}
    return out | ({"message"} if types.get("message") == "string" else set())


class ServiceValidator:
    def __init__(self, spec: Spec, ros: RosCatalog, catalog: V0Catalog, diag: Diagnostics,
                 dsdl: DsdlCatalog | None = None) -> None:
        self.spec, self.ros, self.catalog, self.diag = spec, ros, catalog, diag
        self.dsdl = dsdl if dsdl is not None else DsdlCatalog(spec)  # Cyphal service mappings' types
        self.nested: Callable[[str], DsdlStruct | None] = catalog.get  # a nested type by name: the mapping's protocol's
        self.bad: set[str] = set()  # srv and v0 service types reported broken
        self.srv: RosService | None = None  # the srv of the mapping being resolved (nested response paths)

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.diag.error(pos, message, expected)

    # ---- types -------------------------------------------------------------------------------------------
    def check_srv_types(self) -> list[RosService]:
        """The spec's .srv types checked; returned sorted by name."""
        messages = {m.name for m in self.spec.messages.values()}
        for srv in self.spec.services.values():
            what = f"service type {srv.full_name}"
            if not ROS_MESSAGE_NAME.fullmatch(srv.name):
                self.error(srv.pos, f"{srv.name!r} is not a valid ROS service name", "CamelCase, e.g. UpdateBattery")
                self.bad.add(srv.full_name)
            if not srv.external and (srv.name in messages or any(
                    srv.name == f"{m}Request" or srv.name == f"{m}Response" for m in messages)):
                self.error(srv.pos, f"{what} has the name of a message of the package", "a name of its own")
                self.bad.add(srv.full_name)
            for part, fields in (("request", srv.request), ("response", srv.response)):
                seen: set[str] = set()
                for f in fields:
                    assert isinstance(f.type, RosType)
                    if not ROS_FIELD_NAME.fullmatch(f.name) or not python_safe(f.name):
                        self.error(f.pos, f"{f.name!r} is not a valid ROS field name in the {part} of {what}",
                                   "lower_case with single underscores, not a Python keyword")
                        self.bad.add(srv.full_name)
                    if f.name in seen:
                        self.error(f.pos, f"field {f.name!r} appears twice in the {part} of {what}")
                        self.bad.add(srv.full_name)
                    seen.add(f.name)
                    if not f.type.is_primitive and self.ros.get(f.type.base) is None:
                        self.error(f.pos, f"unknown ROS type {f.type.base!r} in the {part} of {what}",
                                   "a primitive, a message of this spec or an installed ROS message")
                        self.bad.add(srv.full_name)
            self.check_srv_constants(srv, what, {f.name for f in srv.request})
        return sorted(self.spec.services.values(), key=lambda s: s.name)

    def check_srv_constants(self, srv: RosService, what: str, request_names: set[str]) -> None:
        """A srv's constants (emitted in its request, as rosidl reads them): as a message's."""
        seen: set[str] = set()
        for c in srv.constants:
            assert isinstance(c.type, RosType)
            if not ROS_CONSTANT_NAME.fullmatch(c.name):
                self.error(c.pos, f"{c.name!r} is not a valid ROS constant name in {what}", "UPPER_CASE")
                self.bad.add(srv.full_name)
            elif c.name in seen or c.name in request_names:
                self.error(c.pos, f"{c.name!r} is declared twice in {what} (constants and request share one "
                           "namespace)", "a name of its own")
                self.bad.add(srv.full_name)
            seen.add(c.name)
            if not c.type.is_primitive or c.type.array:
                self.error(c.pos, f"constant {c.name} of {what} must have a primitive type, not {c.type}")
                self.bad.add(srv.full_name)
            else:
                check_ros_value(self.diag, c.type, c.value, c.pos, f"constant {c.name}")

    def check_v0_service_types(self) -> None:
        """The id and the response of the spec's DroneCAN service types (the request is checked with the
        messages' fields by validate.dronecan)."""
        ids: dict[int, str] = {}
        standard = self.catalog.standard_ids() if self.catalog.roots else {}
        for struct in self.spec.dronecan_types.values():
            if not struct.service:
                continue
            what = f"DroneCAN service type {struct.name}"
            dtid = struct.data_type_id
            if dtid is None:
                self.error(struct.pos, f"{what} needs its data type id (`id`)",
                           f"a vendor-specific service id, {VENDOR_SERVICE_IDS.start}..{VENDOR_SERVICE_IDS.stop - 1}")
                self.bad.add(struct.name)
            elif not 0 <= dtid <= SERVICE_ID_MAX or dtid not in VENDOR_SERVICE_IDS:
                self.error(struct.pos, f"data type id {dtid} of {what} is outside the vendor-specific service range",
                           f"{VENDOR_SERVICE_IDS.start}..{VENDOR_SERVICE_IDS.stop - 1}")
                self.bad.add(struct.name)
            elif (True, dtid) in standard:
                self.error(struct.pos, f"data type id {dtid} of {what} is taken by the standard service "
                           f"{standard[(True, dtid)]}", "a free vendor-specific service id")
                self.bad.add(struct.name)
            elif dtid in ids:
                self.error(struct.pos, f"data type id {dtid} of {what} is taken by {ids[dtid]}",
                           "a unique service data type id")
                self.bad.add(struct.name)
            else:
                ids[dtid] = struct.name
            seen: set[str] = set()
            for f in struct.response:
                t = f.type
                assert isinstance(t, DsdlType)
                if not _V0_FIELD_NAME.fullmatch(f.name) or not python_safe(f.name):
                    self.error(f.pos, f"{f.name!r} is not a valid DroneCAN field name in the response of {what}",
                               "a letter, then letters, digits and underscores; not a Python keyword")
                    self.bad.add(struct.name)
                if f.name in seen:
                    self.error(f.pos, f"{f.name!r} appears twice in the response of {what}")
                    self.bad.add(struct.name)
                seen.add(f.name)
                if t.kind == "composite" and t.composite:
                    nested = self.catalog.get(t.composite)
                    if nested is None or nested.service:
                        self.error(f.pos, f"{t.composite!r} in the response of {what} is not a DroneCAN message type",
                                   "a type of dronecan_types or a standard one, by its full name")
                        self.bad.add(struct.name)

    # ---- mappings ------------------------------------------------------------------------------------------
    def resolve_mappings(self) -> list[ResolvedServiceMapping]:
        s = self.spec
        if s.bridge is None:
            return []
        result = []
        names: dict[str, str] = {}
        for m in s.bridge.service_mappings:
            what = f"service mapping {m.name!r}"
            if not re.fullmatch(r"[a-z][a-z0-9_]*", m.name) or not python_safe(m.name):
                self.error(m.pos, f"service mapping name {m.name!r} is not valid", "lower_case identifier")
            # One name rule for topics, device duties and service mappings (model/ros_names): a relative name
            # resolves under the run's namespace as the duties' do.
            problem = ros_name_problem(m.service)
            if problem is not None:
                self.error(m.pos, f"service name {m.service!r} of {what} is not a valid ROS name: {problem}",
                           NAME_RULES)
            elif m.service in names:
                self.error(m.pos, f"service {m.service} of {what} is already served by service mapping "
                           f"{names[m.service]!r}", "one mapping per ROS service")
            names.setdefault(m.service, m.name)
            resolved = self.resolve_mapping(m, what)
            if resolved is not None:
                result.append(resolved)
        return result

    def resolve_mapping(self, m: ServiceMapping, what: str) -> ResolvedServiceMapping | None:
        s = self.spec
        if not protocol_of(m.protocol).v0:
            self.nested = self.dsdl.get
            try:
                found = resolve_cyphal_mapping(self, m, what)
            finally:
                self.nested = self.catalog.get
            if found is None:
                return None
            return ResolvedServiceMapping(m, found[0], None, found[1], found[2], m.data_type, found[3])
        if m.service_id is not None:
            self.error(m.pos, f"{what} has a `service_id`, which only Cyphal service mappings take",
                       "the DroneCAN type's data type id (no service_id), or protocol: cyphal")
        srv = s.services.get(m.type)
        if srv is None:
            self.error(m.pos, f"unknown service type {m.type!r} of {what}",
                       "a type of `services` or `external_services` (pkg/Name)")
        struct = self.catalog.get(m.data_type)
        if struct is None:
            self.error(m.pos, f"unknown DroneCAN type {m.data_type!r} of {what}",
                       "a service type of dronecan_types or a standard one, e.g. uavcan.protocol.GetNodeInfo")
        elif not struct.service:
            self.error(m.pos, f"DroneCAN type {m.data_type!r} of {what} is a message type", "a service type")
            struct = None
        device = s.devices_by_node_id().get(m.destination_node_id)
        if m.destination_field is not None:
            dest = next((f for f in srv.request if f.name == m.destination_field), None) if srv is not None else None
            if srv is not None and (dest is None or not isinstance(dest.type, RosType)
                                    or _ros_kind(dest.type) != "int"):
                self.error(m.pos, f"destination_node_id {m.destination_field!r} of {what} is not an integer field of "
                           f"the srv request", "a node id, or the name of an integer field of the request")
                return None
        elif device is None or DRONECAN.name not in device.protocols:
            self.error(m.pos, f"destination node id {m.destination_node_id} of {what} is not a DroneCAN device",
                       "the node id of a device with DroneCAN ports")
        if srv is None or struct is None or srv.full_name in self.bad or struct.name in self.bad:
            return None
        signed = self.catalog.signed(struct.name)
        assert signed is not None
        links = self.links(m, what, srv, struct.fields, struct.response, struct.name)
        if links is None:
            return None
        return ResolvedServiceMapping(m, srv, signed, links[0], links[1], signed.name, signed.data_type_id or 0)

    def links(self, m: ServiceMapping, what: str, srv: RosService, request_fields: list[Field],
              response_fields: list[Field], type_name: str) -> tuple[list[ServiceLink], list[ServiceLink]] | None:
        """The request links (every UAVCAN request field, in order) and the response links of a mapping."""
        self.srv = srv
        ros_req = {f.name: f for f in srv.request}
        ros_res = {f.name: f for f in srv.response}
        uav_req = {f.name: f for f in request_fields if f.name}
        uav_res = {f.name: f for f in response_fields if f.name}
        request: dict[str, ServiceLink] = {}
        ok = True
        for link in m.request:
            found = self.link(link, what, "request", ros_req, uav_req, to_uavcan=True)
            if found is None:
                ok = False
            elif found.target in request:
                self.error(link.pos, f"{what} writes UAVCAN request field {found.target!r} twice")
                ok = False
            else:
                request[found.target] = found
        for name, value in m.uavcan_values.items():
            f = uav_req.get(name)
            if f is None:
                self.error(m.pos, f"uavcan_values of {what} name {name!r}, not a field of the request of "
                           f"{type_name}", ", ".join(uav_req) or "none: the request is empty")
                ok = False
                continue
            assert isinstance(f.type, DsdlType)
            kind = _v0_kind(f.type)
            if kind in (None, "text"):
                self.error(m.pos, f"uavcan value {name!r} of {what} is not a number or bool field ({f.type})")
                ok = False
                continue
            check_dsdl_value(self.diag, f.type, value, m.pos, f"uavcan value {name!r} of {what}",
                             v0=protocol_of(m.protocol).v0)
            if name in request:
                self.error(m.pos, f"{what} writes UAVCAN request field {name!r} twice")
                ok = False
            request[name] = ServiceLink(name, None, kind, value)
        missing = [n for n in uav_req if n not in request]
        if missing and ok:  # not after a broken line: its field would be reported again
            self.error(m.pos, f"{what} leaves request fields of {type_name} without a value: {', '.join(missing)}",
                       "a `request` line or a `uavcan_values` entry for each")
            ok = False
        response: list[ServiceLink] = []
        for link in m.response:
            found = self.link(link, what, "response", ros_res, uav_res, to_uavcan=False)
            if found is None:
                ok = False
            elif any(r.target == found.target for r in response):
                self.error(link.pos, f"{what} writes ROS response field {found.target!r} twice")
                ok = False
            else:
                response.append(found)
        if not ok:
            return None
        # every response field written (the lines; `success` / `message`, which a failure writes) or kept
        written = {r.target for r in response} | bridge_written(srv)
        if not check_response_written(self.diag, m.pos, srv, written, m.response_defaults, what, "a `response` line",
                                      self.ros.get):
            return None
        return [request[n] for n in uav_req], response

    def link(self, link: FieldLink, what: str, part: str, ros: dict, uavcan: dict, to_uavcan: bool
             ) -> ServiceLink | None:
        """One `ros_field: uavcan_field` line of a request (ROS->UAVCAN) or a response (UAVCAN->ROS)."""
        if link.table is not None or link.limits is not None or link.round:
            self.error(link.pos, f"{part} field {link.ros_path!r} of {what}: a service line takes `from`, `scale`, "
                       "`offset` or `value`", "no table, limits or round in a service mapping")
            return None
        ros_field = ros.get(link.ros_path)
        if ros_field is None and not to_uavcan and "." in link.ros_path and self.srv is not None:
            ros_field = response_leaf(self.srv, link.ros_path, self.ros.get)  # `status.uptime_sec`
        if ros_field is None:
            self.error(link.pos, f"{link.ros_path!r} of {what} is not a field of the srv {part}",
                       ", ".join(ros) or "none: the srv's " + part + " is empty")
            return None
        if link.value is not None:
            if to_uavcan:
                self.error(link.pos, f"{part} field {link.ros_path!r} of {what} has a `value`",
                           "`from` a UAVCAN field; constants for the device go in uavcan_values")
                return None
            kind = _ros_kind(ros_field.type)
            if kind is None:
                self.error(link.pos, f"ROS {part} field {link.ros_path!r} of {what} is {ros_field.type}",
                           "a number, bool or string field")
                return None
            return ServiceLink(link.ros_path, None, kind, link.value)
        uav_field = self.uavcan_field(link.uavcan_path or "", uavcan, nested=not to_uavcan)
        if uav_field is None:
            self.error(link.pos, f"{link.uavcan_path!r} of {what} is not a field of the UAVCAN {part}",
                       (", ".join(uavcan) or "none: the UAVCAN " + part + " is empty")
                       + ("" if to_uavcan else " (a field of a nested type as a.b)"))
            return None
        ros_t, uav_t = ros_field.type, uav_field.type
        assert isinstance(ros_t, RosType) and isinstance(uav_t, DsdlType)
        ros_kind, uav_kind = _ros_kind(ros_t), _v0_kind(uav_t)
        scaled = link.scale is not None or link.offset is not None
        if ros_kind is None or uav_kind is None or (ros_kind == "text") != (uav_kind == "text") \
                or (scaled and "bool" in (ros_kind, uav_kind)):
            self.error(link.pos, f"{part} field {link.ros_path!r} ({ros_field.type}) of {what} cannot take "
                       f"{link.uavcan_path} ({uav_field.type})", "numbers or bools (scale/offset on numbers), or "
                       "a string with a uint8 array")
            return None
        target_kind = uav_kind if to_uavcan else ros_kind
        lo, hi = -math.inf, math.inf
        if target_kind == "int":
            lo, hi = uav_t.range if to_uavcan else ROS_INT_RANGES[ros_t.base]
        elif target_kind == "text" and to_uavcan:
            hi = float(uav_t.capacity or 0)
        elif target_kind == "text" and ros_t.string_bound is not None:
            hi = float(ros_t.string_bound)
        elif target_kind == "float" and not to_uavcan and ros_t.base == "float32":
            lo, hi = -_F32_MAX, _F32_MAX
        elif target_kind == "float" and to_uavcan and uav_t.bits == 16:
            lo, hi = -65504.0, 65504.0
        elif target_kind == "float" and to_uavcan and uav_t.bits == 32:
            lo, hi = -_F32_MAX, _F32_MAX
        assert target_kind is not None
        if to_uavcan:
            return ServiceLink(uav_field.name, ros_field.name, target_kind, None, link.scale, link.offset, lo, hi)
        return ServiceLink(link.ros_path, link.uavcan_path, target_kind, None, link.scale, link.offset, lo, hi)

    def uavcan_field(self, path: str, fields: dict, nested: bool) -> Field | None:
        """The field a UAVCAN path names: a field of the request or response, or with `nested` (responses) a
        field of a composite field's type (`status.uptime_sec`), never an element of an array."""
        names = path.split(".")
        if len(names) > 1 and not nested:
            return None
        found: Field | None = fields.get(names[0])
        for name in names[1:]:
            t = found.type if found is not None else None
            if not isinstance(t, DsdlType) or t.kind != "composite" or t.array or not t.composite:
                return None
            inner = self.nested(t.composite)
            found = inner.field(name) if inner is not None else None
        return found
