"""The DroneCAN (UAVCAN v0) side of a spec: its own v0 types, the devices' v0 ports, the DroneCAN mappings' routing
and the layouts (which protocol each device speaks)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from sam_codegen.catalogs.dronecan import (
    DRONECAN_ROOTS,
    MESSAGE_ID_MAX,
    VENDOR_MESSAGE_IDS,
    V0Catalog,
)
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.protocols.description import ProtocolDescription
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.spec import (
    UAVCAN_TO_ROS,
    Constant,
    Device,
    Field,
    Layout,
    Mapping,
    Spec,
    V0Port,
    V0Struct,
)
from sam_codegen.model.types import V0_MAX_FULL_NAME, V0_NAMESPACE_COMPONENT, V0_SHORT_NAME, DsdlType
from sam_codegen.validate.dronecan_namespaces import check_namespaces, clash_message, outside_message
from sam_codegen.validate.mapping_rules import ResolvedMapping
from sam_codegen.validate.mappings import MappingValidator
from sam_codegen.validate.routing import check_shared_broadcasts, routed_node_ids
from sam_codegen.validate.type_graph import dsdl_children, type_graph
from sam_codegen.validate.values import check_dsdl_value, python_safe

V0_NODE_IDS = DRONECAN.node_ids  # 0 is anonymous, 126 and 127 are kept for maintenance tools
V0_FIELD_NAME = re.compile(r"^[a-zA-Z][a-zA-Z0-9_]*$")
DEFAULT_LAYOUT = "default"
# Types inside types: the cycle check, the signatures and the codecs walk them recursively, a few frames a level,
# and a spec whose YAML is flat can still chain thousands. The standard DroneCAN types nest at most ~4 levels.
_MAX_NESTING = 32


@dataclass(frozen=True)
class ResolvedLayout:
    """A layout with every device's protocol and the mappings the bridge runs in it."""

    name: str
    description: str
    protocols: dict[str, str]  # device -> protocol, in spec order
    cyphal_mappings: list[str] = field(default_factory=list)
    dronecan_mappings: list[str] = field(default_factory=list)

    def devices(self, protocol: str) -> list[str]:
        return [d for d, p in self.protocols.items() if p == protocol]

    def mappings_of(self, protocol: ProtocolDescription) -> list[str]:
        """The layout's mappings on `protocol`."""
        mappings: list[str] = getattr(self, protocol.layout_mappings_field)
        return mappings


def _v0_ports(device: Device) -> list[tuple[V0Port, bool]]:
    return [(p, True) for p in device.dronecan_publishes] + [(p, False) for p in device.dronecan_subscribes]


class DronecanValidator:
    """Checks the DroneCAN parts of a spec and resolves its DroneCAN mappings and layouts."""

    def __init__(self, spec: Spec, catalog: V0Catalog, diag: Diagnostics, mappings: MappingValidator) -> None:
        self.spec, self.catalog, self.diag, self.mappings = spec, catalog, diag, mappings
        self.unavailable_reported = False
        self.bad_types: set[str] = set()  # spec types reported broken: no follow-on errors where they are used

    def error(self, pos: Pos, message: str, expected: str | None = None) -> None:
        self.diag.error(pos, message, expected)

    def uses_dronecan(self) -> bool:
        s = self.spec
        return bool(s.dronecan_types or any(DRONECAN.name in d.protocols for d in s.devices.values())
                    or (s.bridge is not None and (s.bridge.dronecan_mappings or s.bridge.service_mappings)))

    def message_type(self, name: str, pos: Pos, what: str) -> V0Struct | None:
        """The v0 message type `name` for a port or mapping; reported (once per kind of problem) when unusable."""
        struct = self.catalog.get(name)
        if struct is None:
            if not self.catalog.roots:
                if not self.unavailable_reported:
                    self.unavailable_reported = True
                    self.error(pos, f"the DroneCAN standard types are not available, so {name!r} of {what} cannot "
                               "be looked up", "the `dronecan` package installed (pip install "
                               "'sam-codegen[runtime]') or DRONECAN_DSDL_PATH naming folders that hold uavcan/")
                return None
            outside = outside_message(self.catalog, name, what)
            if outside is not None:
                self.error(pos, *outside)
                return None
            self.error(pos, f"unknown DroneCAN type {name!r} of {what}",
                       "a type of dronecan_types or a standard one, e.g. uavcan.equipment.ahrs.RawIMU")
            return None
        if name in self.bad_types:
            return None
        if struct.service:
            self.error(pos, f"DroneCAN type {name!r} of {what} is a service type", "a message type")
            return None
        if struct.data_type_id is None:
            self.error(pos, f"DroneCAN type {name!r} of {what} has no data type id: it can only be nested in "
                       "other types", "a message type with a data type id")
            return None
        return self.catalog.signed(name)

    # ---- the spec's own types ------------------------------------------------------------------------------
    def check_types(self) -> None:
        check_namespaces(self.spec, self.catalog, self.diag)
        ids: dict[int, str] = {}
        standard = self.catalog.standard_ids() if self.catalog.roots else {}
        reserved_roots = set(DRONECAN_ROOTS) | {r.name for r in self.catalog.roots}
        for struct in self.spec.dronecan_types.values():
            what = f"DroneCAN type {struct.name}"
            bad = False
            parts = struct.name.split(".")
            if len(parts) < 2 or not all(V0_NAMESPACE_COMPONENT.fullmatch(p) for p in parts[:-1]) \
                    or not V0_SHORT_NAME.fullmatch(parts[-1]):
                self.error(struct.pos, f"{struct.name!r} is not a valid DroneCAN type name",
                           "root.namespace.Name: lower-case namespaces, a CamelCase name")
                bad = True
            elif parts[0] in reserved_roots:
                self.error(struct.pos, f"{what} is in the root namespace {parts[0]!r} of the standard definitions",
                           "a root namespace of your own, e.g. the vehicle's")
                bad = True
            if len(struct.name) > V0_MAX_FULL_NAME:
                self.error(struct.pos, f"{what} has a name longer than {V0_MAX_FULL_NAME} characters")
                bad = True
            dtid = struct.data_type_id
            if dtid is not None and not struct.service:  # a service's id: validate.services
                if not 0 <= dtid <= MESSAGE_ID_MAX or dtid not in VENDOR_MESSAGE_IDS:
                    self.error(struct.pos, f"data type id {dtid} of {what} is outside the vendor-specific range",
                               f"{VENDOR_MESSAGE_IDS.start}..{VENDOR_MESSAGE_IDS.stop - 1}")
                elif (False, dtid) in standard:
                    self.error(struct.pos, *clash_message(self.spec, self.catalog, dtid, what,
                                                          standard[(False, dtid)]))
                elif dtid in ids:
                    self.error(struct.pos, f"data type id {dtid} of {what} is taken by {ids[dtid]}",
                               "a unique data type id")
                else:
                    ids[dtid] = struct.name
            seen: set[str] = set()
            members: list[Field | Constant] = [*struct.fields, *struct.constants]
            for f in members:
                if not V0_FIELD_NAME.fullmatch(f.name) or not python_safe(f.name):
                    self.error(f.pos, f"{f.name!r} is not a valid DroneCAN field name in {what}",
                               "a letter, then letters, digits and underscores; not a Python keyword")
                    bad = True
                if f.name in seen:
                    self.error(f.pos, f"{f.name!r} appears twice in {what}")
                    bad = True
                seen.add(f.name)
            response_seen = {f.name for f in struct.response}  # the response's names (validate.services)
            for c in struct.response_constants:
                if not V0_FIELD_NAME.fullmatch(c.name) or not python_safe(c.name):
                    self.error(c.pos, f"{c.name!r} is not a valid DroneCAN constant name in the response of {what}",
                               "a letter, then letters, digits and underscores; not a Python keyword")
                    bad = True
                elif c.name in response_seen:
                    self.error(c.pos, f"{c.name!r} appears twice in the response of {what}")
                    bad = True
                response_seen.add(c.name)
            for f in struct.fields:
                t = f.type
                assert isinstance(t, DsdlType)
                if t.kind != "composite" or not t.composite:
                    continue
                nested = self.catalog.get(t.composite)
                outside = outside_message(self.catalog, t.composite, what) if nested is None else None
                if outside is not None:
                    self.error(f.pos, *outside)
                    bad = True
                elif nested is None:
                    self.error(f.pos, f"unknown DroneCAN type {t.composite!r} in {what}",
                               "a type of dronecan_types or a standard one, by its full name (e.g. uavcan.Timestamp)")
                    bad = True
                elif nested.service:
                    self.error(f.pos, f"{t.composite} in {what} is a service type", "a message type")
                    bad = True
            for c in [*struct.constants, *struct.response_constants]:
                assert isinstance(c.type, DsdlType)
                check_dsdl_value(self.diag, c.type, c.value, c.pos, f"constant {c.name} of {what}", v0=True)
            if bad:
                self.bad_types.add(struct.name)
        self.check_type_cycles()
        for struct in self.spec.dronecan_types.values():
            if struct.name not in self.bad_types:
                self.catalog.signature(struct.name)

    def check_type_cycles(self) -> None:
        """Types inside types: no cycle, at most _MAX_NESTING levels; one pass over them (validate.type_graph: a walk
        of every path was exponential). A type on a cycle, too deep, or holding such a type is bad."""
        types = self.spec.dronecan_types
        graph = type_graph(types, lambda name: dsdl_children(types.get(name)))
        for component in graph.cycles:
            name = component[0]
            self.error(types[name].pos, f"DroneCAN type {name} contains itself: {' -> '.join(graph.cycle_from(name))}")
        too_deep = {name for name in types if graph.height[name] > _MAX_NESTING}
        deep = next((name for name in types if name in too_deep), None)
        if deep is not None:  # one error is enough: a chain of N types would give N - 32
            chain = graph.chain(deep, _MAX_NESTING + 1)
            self.error(types[deep].pos, f"DroneCAN type {deep} nests types more than {_MAX_NESTING} levels deep "
                       f"({deep} -> {chain[1]} -> ... -> {chain[-1]})",
                       f"at most {_MAX_NESTING} levels of types inside types")
        self.bad_types |= graph.reaches(set(graph.cyclic) | too_deep)

    # ---- devices -------------------------------------------------------------------------------------------
    def check_devices(self) -> None:
        s = self.spec
        if self.uses_dronecan() and s.bridge is not None and s.bridge.node_id not in V0_NODE_IDS:
            self.error(s.bridge.pos, f"bridge node id {s.bridge.node_id} is out of range for DroneCAN",
                       f"{V0_NODE_IDS.start}..{V0_NODE_IDS.stop - 1}")
        for device in s.devices.values():
            if DRONECAN.name not in device.protocols:
                continue
            what = f"device {device.name}"
            if device.node_id >= 0 and device.node_id not in V0_NODE_IDS:
                self.error(device.protocol_pos["dronecan"], f"node id {device.node_id} of {what} is out of range "
                           "for DroneCAN", f"{V0_NODE_IDS.start}..{V0_NODE_IDS.stop - 1}")
            for port, _ in _v0_ports(device):
                self.message_type(port.type, port.pos, what)

    # ---- mappings ------------------------------------------------------------------------------------------
    def resolve_mappings(self) -> list[ResolvedMapping]:
        s = self.spec
        if s.bridge is None:
            return []
        by_id = s.devices_by_node_id()
        result = []
        for mapping in s.bridge.dronecan_mappings:
            resolved = self.resolve_mapping(mapping, by_id)
            if resolved is not None:
                result.append(resolved)
        self.check_broadcasts(result)
        return result

    def resolve_mapping(self, mapping: Mapping, by_id: dict[int, Device]) -> ResolvedMapping | None:
        s, what = self.spec, f"DroneCAN mapping {mapping.name!r}"
        if not re.fullmatch(r"[a-z][a-z0-9_]*", mapping.name) or not python_safe(mapping.name):
            self.error(mapping.pos, f"mapping name {mapping.name!r} is not valid", "lower_case identifier")
        topic = s.topics.get(mapping.topic)
        if topic is None:
            self.error(mapping.pos, f"{what} uses undeclared topic {mapping.topic!r}", "a topic of `topics`")
        struct = self.message_type(mapping.data_type, mapping.pos, what) if mapping.data_type else None
        rate = 0.0
        publishing = mapping.direction == UAVCAN_TO_ROS
        nodes = routed_node_ids(s, mapping)  # static ids, or with `any` every device with the port
        role = "source" if publishing else "destination"
        users: dict[int, V0Port] = {}
        for device in s.devices.values():
            if DRONECAN.name in device.protocols:
                for port, pub in _v0_ports(device):
                    if pub == publishing and port.type == mapping.data_type:
                        users.setdefault(device.node_id, port)
        verb, ports = ("publish", "publishes") if publishing else ("subscribe to", "subscribes")
        for node_id in nodes:
            if node_id not in V0_NODE_IDS:
                self.error(mapping.pos, f"{role} node id {node_id} of {what} is out of range for DroneCAN",
                           f"{V0_NODE_IDS.start}..{V0_NODE_IDS.stop - 1}")
            elif node_id not in users and struct is not None:
                owner = by_id.get(node_id)
                self.error(mapping.pos, f"{role} node id {node_id} of {what} does not {verb} {mapping.data_type} "
                           "on DroneCAN" + (f" (it is device {owner.name})" if owner else ""),
                           f"the node id of a device that does: {', '.join(map(str, sorted(users)))}" if users
                           else f"a device with `{mapping.data_type}` in its DroneCAN {ports}")
            else:
                rate = max(rate, users[node_id].rate_hz) if node_id in users else rate
        if len(set(nodes)) < len(nodes):
            self.error(mapping.pos, f"{what} lists a {role} node id twice")
        if struct is None:
            return None
        return self.mappings.resolve_body(mapping, what, topic, struct, rate)

    def check_broadcasts(self, resolved: list[ResolvedMapping]) -> None:
        """Two ROS->UAVCAN mappings that broadcast one data type must not command the same thing: they need
        different `select` values, or distinct items chosen by key (ArrayCommand's actuator ids), or both opt in
        with `shares_data_type` (validate.routing)."""
        check_shared_broadcasts(resolved, self.diag)

    # ---- layouts -------------------------------------------------------------------------------------------
    def resolve_layouts(self, cyphal: list[ResolvedMapping], dronecan: list[ResolvedMapping]) -> list[ResolvedLayout]:
        s = self.spec
        default = Layout(DEFAULT_LAYOUT, "Every device on its own `protocol`.")
        if DEFAULT_LAYOUT in s.layouts:
            self.error(s.layouts[DEFAULT_LAYOUT].pos, f"layout name {DEFAULT_LAYOUT!r} is reserved: it is every "
                       "device on its own `protocol`", "another name")
        result = []
        for layout in [default, *(v for k, v in s.layouts.items() if k != DEFAULT_LAYOUT)]:
            resolved = self.resolve_layout(layout, cyphal, dronecan)
            if resolved is not None:
                result.append(resolved)
        return result

    def resolve_layout(self, layout: Layout, cyphal: list[ResolvedMapping], dronecan: list[ResolvedMapping]
                       ) -> ResolvedLayout | None:
        s, what = self.spec, f"layout {layout.name!r}"
        if layout.name != DEFAULT_LAYOUT and not re.fullmatch(r"[a-z][a-z0-9_]*", layout.name):
            self.error(layout.pos, f"layout name {layout.name!r} is not valid", "lower_case identifier")
        ok = True
        for name, pos in layout.device_pos.items():
            if name not in s.devices:
                self.error(pos, f"{what} names unknown device {name!r}", "a device of `devices`")
                ok = False
            elif layout.devices[name] not in s.devices[name].protocols:
                self.error(pos, f"device {name} has no {layout.devices[name]} ports for {what}",
                           f"a `{layout.devices[name]}:` section in device {name}")
                ok = False
        protocols: dict[str, str] = {}
        for device in s.devices.values():
            chosen = layout.devices.get(device.name)
            if chosen is None:
                chosen = layout.protocol if layout.protocol in device.protocols else device.protocol
            protocols[device.name] = chosen
        if layout.protocol is not None and not any(p == layout.protocol for p in protocols.values()):
            self.error(layout.pos, f"{what}: no device has {layout.protocol} ports", f"devices with a "
                       f"`{layout.protocol}:` section or `protocol: {layout.protocol}`")
        active_mappings: dict[str, list[str]] = {"cyphal": [], "dronecan": []}
        by_id = s.devices_by_node_id()
        for protocol, rms in (("cyphal", cyphal), ("dronecan", dronecan)):
            active = active_mappings[protocol]
            for rm in rms:
                m = rm.mapping
                nodes = routed_node_ids(s, m)
                devices = [by_id[n].name for n in nodes if n in by_id]
                speaking = [d for d in devices if protocols[d] == protocol]
                if speaking and len(speaking) < len(devices):
                    others = [d for d in devices if protocols[d] != protocol]
                    self.error(layout.pos, f"{what} puts the devices of {protocol} mapping {m.name!r} on different "
                               f"protocols: {', '.join(speaking)} on {protocol}, {', '.join(others)} on "
                               f"{', '.join(sorted({protocols[d] for d in others}))}",
                               "every device a mapping reaches on its protocol")
                    ok = False
                elif speaking:
                    active.append(m.name)
        for name in sorted(set(active_mappings["cyphal"]) & set(active_mappings["dronecan"])):
            self.error(layout.pos, f"{what} runs a Cyphal and a DroneCAN mapping both named {name!r}",
                       "distinct names for mappings that run together")
            ok = False
        if not ok:
            return None
        return ResolvedLayout(layout.name, layout.description, protocols, active_mappings["cyphal"],
                              active_mappings["dronecan"])


__all__ = ["DEFAULT_LAYOUT", "V0_NODE_IDS", "DronecanValidator", "ResolvedLayout"]
