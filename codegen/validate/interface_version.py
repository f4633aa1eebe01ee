"""The interface version: one hash of everything a board's firmware must agree on with the bridge, per board and for
the whole spec (issue 28 part 4). The rule lives here, once; the docs, the tables and the firmware headers print it.

What a board's hash covers (a change to any of it is a firmware the bridge can no longer read or write):

- its node id;
- on each protocol it has firmware for: its ports, sorted (Cyphal: subject id, direction and the type's full name
  and version; DroneCAN: direction, the type's full name, data type id and data type signature);
- every Cyphal type those ports carry, and every type nested in them, as a canonical DSDL text (constants, fields in
  declaration order with their padding, union, sealed or extent; no comments, no descriptions). DroneCAN's data type
  signature already covers a type's nested types, as dronecan computes it;
- its settings (`parameters:`): name, name on each protocol, type, default, range, unit, enum values (the pairs of
  name and stored integer, in any order), longest string, restart.

Not covered: publication rates (a board that publishes slower still speaks the same bytes), descriptions, comments,
the YAML's formatting and order (ports and settings are sorted; the spec is read into the model first), the device's
name in the spec (the firmware does not know it). The whole spec's hash covers every board's by name.

The hash is SHA-256 of the canonical form as compact JSON (sorted keys), its first 8 bytes read big-endian: a uint64,
what Cyphal's GetInfo ``software_vcs_revision_id`` and DroneCAN's GetNodeInfo ``software_version.image_crc`` carry.
0 is a board that reports none, so a hash that comes out 0 is made 1.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from typing import Any

from sam_codegen.model.device_params import DeviceParameter
from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.spec import Device, DsdlStruct
from sam_codegen.model.types import DsdlType
from sam_codegen.validate.resolve import Resolved

__all__ = ["RULE", "InterfaceVersions", "board_form", "hash_form", "hex_hash", "interface_versions"]

RULE = "sam-interface-1"  # names the rule below: a change of what is hashed changes it (and so every hash)


def hash_form(form: Any) -> int:
    """The uint64 of a canonical form: the first 8 bytes of SHA-256 of its compact JSON, big-endian; never 0."""
    text = json.dumps(form, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    value = int.from_bytes(hashlib.sha256(text.encode()).digest()[:8], "big")
    return value or 1


def hex_hash(value: int) -> str:
    """16 lower-case hex digits, as the docs, the logs and /diagnostics print a hash."""
    return f"{value:016x}"


def _dsdl_text(struct: DsdlStruct) -> str:
    # a constant's value as DSDL writes it: exact (a Fraction as n/d), a bool as true/false
    lines = [f"{c.type} {c.name} = {str(c.value).lower() if isinstance(c.value, bool) else c.value}"
             for c in struct.constants]
    if struct.union:
        lines.append("@union")
    lines += [f"{f.type} {f.name}".rstrip() for f in struct.declared_fields]
    lines.append("@sealed" if struct.sealed else f"@extent {struct.extent}")
    return "\n".join(lines)


def _cyphal_types(resolved: Resolved, roots: list[str]) -> dict[str, str]:
    """Every type of `roots` and those nested in them: full name with version -> canonical DSDL text."""
    texts: dict[str, str] = {}
    todo = list(roots)
    while todo:
        name = todo.pop()
        if name in texts:
            continue
        struct = resolved.dsdl.get(name)
        if struct is None:  # validation has reported it; nothing to hash but the name
            texts[name] = ""
            continue
        texts[name] = _dsdl_text(struct)
        todo += [f.type.composite for f in struct.declared_fields
                 if isinstance(f.type, DsdlType) and f.type.composite is not None]
    return texts


def _parameter_form(p: DeviceParameter) -> dict[str, Any]:
    return {"name": p.name, "names": sorted(map(list, p.names)), "type": p.type, "default": p.default,
            "minimum": p.minimum, "maximum": p.maximum, "unit": p.unit, "values": sorted(map(list, p.values)),
            "max_length": p.max_length, "restart": p.restart}


def board_form(resolved: Resolved, device: Device) -> dict[str, Any]:
    """The canonical form of what `device`'s firmware must agree on (see the module's text)."""
    form: dict[str, Any] = {"rule": RULE, "node_id": device.node_id,
                            "parameters": sorted((_parameter_form(p) for p in device.parameters),
                                                 key=lambda f: f["name"])}
    if CYPHAL.name in device.protocols:
        ports = sorted([("publishes", p.subject_id, p.type) for p in device.publishes]
                       + [("subscribes", p.subject_id, p.type) for p in device.subscribes])
        form[CYPHAL.name] = {"ports": [list(p) for p in ports],
                             "types": _cyphal_types(resolved, [p[2] for p in ports])}
    if DRONECAN.name in device.protocols:
        v0_ports = []
        for direction, ports_v0 in (("publishes", device.dronecan_publishes),
                                    ("subscribes", device.dronecan_subscribes)):
            for port in ports_v0:
                signed = resolved.dronecan.signed(port.type) if resolved.dronecan is not None else None
                dtid = signed.data_type_id if signed is not None else None
                v0_ports.append([direction, port.type, dtid, signed.signature if signed is not None else 0])
        form[DRONECAN.name] = {"ports": sorted(v0_ports, key=json.dumps)}
    return form


@dataclass(frozen=True)
class InterfaceVersions:
    """Every board's hash (by device name, in spec order) and the whole spec's."""

    boards: tuple[tuple[str, int], ...]
    whole: int

    def of(self, device: str) -> int:
        return dict(self.boards)[device]


def interface_versions(resolved: Resolved) -> InterfaceVersions:
    """The hash of each board of the spec and of the whole spec (every board's, by name)."""
    boards = tuple((name, hash_form(board_form(resolved, d))) for name, d in resolved.spec.devices.items())
    whole = hash_form({"rule": RULE, "boards": {name: hex_hash(h) for name, h in boards}})
    return InterfaceVersions(boards, whole)
