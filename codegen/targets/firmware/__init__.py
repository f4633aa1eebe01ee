"""The firmware target: generated/firmware/<board>.h, one C99 header per board of the spec, what its firmware is
built against (issue 28 part 4): its node id, its ports on each protocol (Cyphal subject ids and types; DroneCAN
data type ids and signatures), its interface version (validate.interface_version) as a 64-bit constant and as 8
bytes, and its settings' names on each protocol, defaults, ranges and enum values.

Names: every macro starts with `<VEHICLE>_<BOARD>_` (upper case, each character outside A-Z0-9 as `_`), so that the
headers of several boards compile together. A port is named by its direction and its type's full name
(`..._CYPHAL_PUB_SAM_SENSOR_RAWIMU_SUBJECT_ID`; a second port of the same type and direction gets `_2`, in the
spec's order), a setting by its spec name (`..._PARAM_IMU_RATE_HZ_DEFAULT`). Only macros: a `static const` that a
file does not use would be a warning under -Wall (-Wunused-const-variable), so the hash's bytes are an initializer
(`static const uint8_t hash[8] = <...>_INTERFACE_HASH_BYTES;`). Every spec text reaches the output through
`_c_string` (octal escapes) or `_c_comment` (no comment end); the rest is numbers and identifiers made here.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from sam_codegen.model.device_params import DeviceParameter, ParamValue
from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.dronecan import DRONECAN
from sam_codegen.model.spec import Device
from sam_codegen.render.templating import render
from sam_codegen.validate.interface_version import RULE, hex_hash, interface_versions
from sam_codegen.validate.resolve import Resolved

__all__ = ["FOLDER", "c_identifier", "emit", "header_path", "macro_prefix"]

FOLDER = "firmware"
_SAFE = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789 _.,:;/+-=()[]{}<>!#$%&*@^|~'")

Constant = tuple[str, str, str]  # (macro name, C expression, comment)


def header_path(board: str) -> str:
    return f"{FOLDER}/{board}.h"


def c_identifier(text: str) -> str:
    """Upper case, every character outside A-Z0-9 as `_`: `sam.sensor.RawIMU` -> `SAM_SENSOR_RAWIMU`."""
    return re.sub(r"[^A-Z0-9]", "_", text.upper())


def macro_prefix(vehicle: str, board: str) -> str:
    return f"{c_identifier(vehicle)}_{c_identifier(board)}"


def _c_string(text: str) -> str:
    """A C string literal of `text`'s UTF-8 bytes: every byte outside a safe printable set as a 3-digit octal escape
    (never \\x, which would swallow the hex digits after it; never `?`, no trigraph)."""
    return '"' + "".join(chr(b) if chr(b) in _SAFE else f"\\{b:03o}" for b in text.encode()) + '"'


def _c_comment(text: str) -> str:
    return " ".join(text.split()).replace("*/", "* /")


def _c_value(p: DeviceParameter, value: ParamValue | float | None) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, str):
        return _c_string(value)
    if p.type == "real":
        assert value is not None and math.isfinite(value), (p.name, value)  # validation bounds every real
        return f"{float(value)!r}f"  # repr of a finite float has a "." or an exponent: a C double, then float
    return f"INT64_C({value})"


def _port_constants(prefix: str, device: Device, resolved: Resolved) -> list[Constant]:
    constants: list[Constant] = []
    seen: dict[str, int] = {}

    def name(kind: str, type_name: str) -> str:
        base = f"{prefix}_{kind}_{c_identifier(type_name)}"
        seen[base] = seen.get(base, 0) + 1
        return base if seen[base] == 1 else f"{base}_{seen[base]}"

    if CYPHAL.name in device.protocols:
        for kind, ports in (("CYPHAL_PUB", device.publishes), ("CYPHAL_SUB", device.subscribes)):
            for port in ports:
                base = name(kind, ".".join(port.type.split(".")[:-2]))  # the full name without its version
                constants += [(f"{base}_SUBJECT_ID", f"{port.subject_id}u", f"{port.type} at {port.rate_hz:g} Hz"),
                              (f"{base}_TYPE", _c_string(port.type), "")]
    if DRONECAN.name in device.protocols and resolved.dronecan is not None:
        for kind, v0_ports in (("DRONECAN_PUB", device.dronecan_publishes),
                               ("DRONECAN_SUB", device.dronecan_subscribes)):
            for v0 in v0_ports:
                signed = resolved.dronecan.signed(v0.type)
                assert signed is not None and signed.data_type_id is not None, v0.type  # validation checked it
                base = name(kind, v0.type)
                constants += [(f"{base}_DATA_TYPE_ID", f"{signed.data_type_id}u", f"{v0.type} at {v0.rate_hz:g} Hz"),
                              (f"{base}_SIGNATURE", f"UINT64_C(0x{signed.signature:016x})", ""),
                              (f"{base}_TYPE", _c_string(v0.type), "")]
    return constants


def _param_constants(prefix: str, device: Device) -> list[Constant]:
    constants: list[Constant] = []
    for p in sorted(device.parameters, key=lambda p: p.name):
        base = f"{prefix}_PARAM_{c_identifier(p.name)}"
        for protocol, on_name in p.names:
            constants.append((f"{base}_{c_identifier(protocol)}_NAME", _c_string(on_name),
                              f"{p.type}{', restart' if p.restart else ''}: {_c_comment(p.description)}"
                              if protocol == p.names[0][0] else ""))
        for label, value in (("VALUE", p.stored(p.default)), ("MIN", p.minimum), ("MAX", p.maximum)):
            if value is not None:
                constants.append((f"{base}_{'DEFAULT' if label == 'VALUE' else label}", _c_value(p, value),
                                  f"[{_c_comment(p.unit)}]" if p.unit and label == "VALUE" else ""))
        if p.max_length is not None:
            constants.append((f"{base}_MAX_LENGTH", f"{p.max_length}u", "bytes"))
        constants += [(f"{base}_{c_identifier(value_name)}", f"INT64_C({stored})", "")
                      for value_name, stored in p.values]
    return constants


def emit(resolved: Resolved) -> dict[str, str]:
    """One header per board of the spec, by path under generated/."""
    spec = resolved.spec
    versions = interface_versions(resolved)
    out: dict[str, str] = {}
    for name, device in spec.devices.items():
        prefix = macro_prefix(spec.vehicle, name)
        value = versions.of(name)
        hash_bytes = ", ".join(f"0x{b:02x}u" for b in value.to_bytes(8, "big"))
        constants: list[Constant] = [
            (f"{prefix}_NODE_ID", f"{device.node_id}u", ""),
            (f"{prefix}_INTERFACE_HASH", f"UINT64_C(0x{hex_hash(value)})", f"{RULE}: report it as it is"),
            (f"{prefix}_INTERFACE_HASH_BYTES", "{" + hash_bytes + "}", "big-endian: the SHA-256's first 8 bytes"),
            (f"{prefix}_SPEC_INTERFACE_HASH", f"UINT64_C(0x{hex_hash(versions.whole)})", "the whole spec's"),
            *_port_constants(prefix, device, resolved),
            *_param_constants(prefix, device),
        ]
        out[header_path(name)] = render("firmware/board.h.j2", spec_name=_c_comment(Path(spec.file).name),
                                        vehicle=_c_comment(spec.vehicle), board=name, guard=f"{prefix}_H",
                                        description=_c_comment(device.description), protocols=device.protocols,
                                        constants=constants)
    return out
