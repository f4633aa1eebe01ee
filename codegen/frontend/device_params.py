"""A device's `parameters:`, the settings its board holds (model.device_params), read with an exact error for each
misuse: a key the setting's type has no use for, a range that is empty or does not fit the wire, a default outside
its range or not among an enum's values, a name a protocol the board speaks cannot carry, two settings under one
name on a protocol.

    parameters:
      pole_count: {type: integer, range: [2, 48], default: 14, restart: true, description: Motor pole count.}
      direction: {type: enum, values: {forward: 1, reverse: -1}, default: forward, dronecan: ESC_DIR}
      trim: {type: real, range: [-0.1, 0.1], unit: rad, default: 0.0}
"""

from __future__ import annotations

import math

from sam_codegen.frontend.reading import Reader, kind_of, map_items, scalar, seq_items, text_of
from sam_codegen.frontend.yaml_source import YMap, YNode, YSeq
from sam_codegen.model.device_params import (
    FLOAT32_MAX,
    INT64_MAX,
    INT64_MIN,
    PARAM_TYPES,
    DeviceParameter,
    ParamValue,
    default_name_on,
    name_problem,
    register_name_problem,
)
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.protocols.registry import protocol_names

__all__ = ["parse_parameters"]

# The keys each type has use for (besides type, default, description, restart and a name per protocol).
_TYPE_KEYS: dict[str, tuple[str, ...]] = {
    "bool": (), "integer": ("range", "unit"), "real": ("range", "unit"), "string": ("max_length",),
    "enum": ("values",),
}
_COMMON_KEYS = ("type", "default", "description", "restart")


def parse_parameters(node: YNode | None, device: str, protocols: tuple[str, ...],
                     diag: Diagnostics) -> tuple[DeviceParameter, ...]:
    """The settings of `device`, whose board speaks `protocols` (its firmware's protocols)."""
    out: list[DeviceParameter] = []
    for name, pos, value in map_items(node, f"the parameters of device {device!r}", diag):
        parameter = _parameter(name, pos, value, f"parameter {name!r} of device {device!r}", protocols, diag)
        if parameter is not None:
            out.append(parameter)
    for protocol in protocols:  # two settings under one name on a protocol: the board could hold only one
        seen: dict[str, DeviceParameter] = {}
        for p in out:
            wire = p.name_on(protocol)
            if wire in seen:
                diag.error(p.pos, f"parameters {seen[wire].name!r} and {p.name!r} of device {device!r} are both "
                           f"{protocol_of(protocol).setting_noun} {wire!r} on {protocol_of(protocol).label}",
                           "a name of its own on each protocol")
            seen.setdefault(wire, p)
    return tuple(out)


def _parameter(name: str, pos: Pos, node: YNode, what: str, protocols: tuple[str, ...],
               diag: Diagnostics) -> DeviceParameter | None:
    problem = register_name_problem(name)
    if problem is not None:  # also a ROS parameter name: checked once here, not again as each protocol's name
        diag.error(pos, f"{what}: {problem}", "a name like motor.pole_count (lowercase, digits, '_' and '.')")
    r = Reader(node, what, diag, (*_COMMON_KEYS, *sorted({k for ks in _TYPE_KEYS.values() for k in ks}),
                                  *protocol_names()))
    type_ = r.get("type", str)
    if type_ is not None and type_ not in PARAM_TYPES:
        diag.error(r.key_pos("type"), f"type {type_!r} of {what} is unknown", " or ".join(PARAM_TYPES))
        return None
    if not r.ok or type_ is None:
        return None
    for key in sorted({k for ks in _TYPE_KEYS.values() for k in ks} - set(_TYPE_KEYS[type_])):
        if r.node(key) is not None:
            uses = ", ".join(t for t, ks in _TYPE_KEYS.items() if key in ks)
            diag.error(r.key_pos(key), f"{what} is {type_}: `{key}` is for {uses} parameters")
    names = _names(r, name, what, protocols, diag, derived_checked=problem is None)
    minimum, maximum = _range(r, type_, what, diag) if type_ in ("integer", "real") else (None, None)
    unit = text_of(r, "unit") if r.node("unit") is not None else ""
    if type_ == "real" and r.node("unit") is None:
        diag.error(r.pos, f"{what} is real: it needs its `unit`", "an SI unit (REP 103), e.g. m, rad, m/s, 1")
    values = _enum_values(r.node("values"), what, diag) if type_ == "enum" else ()
    if type_ == "enum" and r.node("values") is None:
        diag.error(r.pos, f"{what} is enum: it needs its `values`", "{name: integer, ...} or a list of names")
    max_length = _max_length(r, what, protocols, diag) if type_ == "string" else None
    restart = r.get("restart", bool, False)
    default = _default(r, type_, what, minimum, maximum, values, max_length, diag)
    if default is None or names is None:
        return None
    return DeviceParameter(name, type_, default, text_of(r, "description"), minimum, maximum, unit, values,
                           max_length, bool(restart), names, pos)


def _names(r: Reader, name: str, what: str, protocols: tuple[str, ...], diag: Diagnostics,
           derived_checked: bool) -> tuple[tuple[str, str], ...] | None:
    """The setting's name on each protocol the board speaks; a name derived from an invalid spec name is not
    reported again (`derived_checked` False)."""
    out: list[tuple[str, str]] = []
    ok = True
    for protocol in protocol_names():
        given = r.get(protocol, str, None)
        desc = protocol_of(protocol)
        if given is not None and protocol not in protocols:
            diag.error(r.key_pos(protocol), f"{what} names its {desc.label} {desc.setting_noun}, but the board has "
                       f"no {desc.label} firmware", f"a name for {', '.join(protocols)} only")
            continue
        if protocol not in protocols:
            continue
        if given is None and not derived_checked:
            ok = False
            continue
        wire = given if given is not None else default_name_on(desc, name)
        problem = name_problem(desc, wire)
        if problem is not None:
            diag.error(r.key_pos(protocol) if given is not None else r.pos,
                       f"{what}: {desc.label} {desc.setting_noun} name {wire!r}: {problem}")
            ok = False
        out.append((protocol, wire))
    return tuple(out) if ok else None


def _range(r: Reader, type_: str, what: str, diag: Diagnostics) -> tuple[int | float | None, int | float | None]:
    node = r.node("range")
    if node is None:
        diag.error(r.pos, f"{what} is {type_}: it needs its `range`", "[minimum, maximum]")
        return None, None
    items = seq_items(node, f"the range of {what}", diag)
    if isinstance(node, YSeq) and len(items) != 2:
        diag.error(node.pos, f"the range of {what} must be [minimum, maximum], found {len(items)} elements")
        return None, None
    if len(items) != 2:
        return None, None
    kind: type | tuple[type, ...] = int if type_ == "integer" else (int, float)
    low, high = (scalar(i, kind, f"the range of {what}", diag) for i in items)
    if low is None or high is None:
        return None, None
    limit = (INT64_MIN, INT64_MAX) if type_ == "integer" else (-FLOAT32_MAX, FLOAT32_MAX)
    for bound in (low, high):
        if not (isinstance(bound, int) or math.isfinite(bound)) or not limit[0] <= bound <= limit[1]:
            diag.error(node.pos, f"the range of {what}: {bound!r} does not fit its type on the wire",
                       "int64" if type_ == "integer" else "a finite float32")
            return None, None
    if low > high:
        diag.error(node.pos, f"the range of {what} is empty: {low!r} > {high!r}", "[minimum, maximum]")
        return None, None
    return (low, high) if type_ == "integer" else (float(low), float(high))


def _enum_values(node: YNode | None, what: str, diag: Diagnostics) -> tuple[tuple[str, int], ...]:
    if node is None:
        return ()
    out: list[tuple[str, int]] = []
    if isinstance(node, YSeq):  # a list of names: 0, 1, 2, ...
        for i, item in enumerate(node.items):
            name = scalar(item, str, f"a value of {what}", diag)
            if name is not None:
                out.append((name, i))
    elif isinstance(node, YMap):
        for name, _pos, value in map_items(node, f"the values of {what}", diag):
            number = scalar(value, int, f"value {name!r} of {what}", diag)
            if number is not None and not INT64_MIN <= number <= INT64_MAX:
                diag.error(value.pos, f"value {name!r} of {what} does not fit int64")
            elif number is not None:
                out.append((name, number))
    else:
        diag.error(node.pos, f"the values of {what} must be a mapping or a list, found {kind_of(node)}")
        return ()
    if not (node.items if isinstance(node, YSeq) else node.entries):
        diag.error(node.pos, f"{what} has no values", "at least one name")
    numbers = [n for _, n in out]
    for name, number in out:
        if numbers.count(number) > 1:
            diag.error(node.pos, f"value {name!r} of {what} shares the integer {number} with another value",
                       "one integer per name")
            break
    return tuple(out)


def _max_length(r: Reader, what: str, protocols: tuple[str, ...], diag: Diagnostics) -> int:
    carried = min((protocol_of(p).setting_string_max, protocol_of(p).label) for p in protocols) if protocols \
        else (256, "")
    given = r.get("max_length", int, None)
    if given is None:
        return carried[0]
    if not 1 <= given <= carried[0]:
        diag.error(r.key_pos("max_length"), f"max_length {given} of {what} is outside 1..{carried[0]}",
                   f"what {carried[1]} carries in a string value")
        return carried[0]
    return int(given)


def _default(r: Reader, type_: str, what: str, minimum: int | float | None, maximum: int | float | None,
             values: tuple[tuple[str, int], ...], max_length: int | None, diag: Diagnostics) -> ParamValue | None:
    kinds: dict[str, type | tuple[type, ...]] = {"bool": bool, "integer": int, "real": (int, float),
                                                 "string": str, "enum": str}
    kind = kinds[type_]
    value = r.get("default", kind)
    if value is None:
        return None
    where = r.key_pos("default")
    if type_ == "real" and not math.isfinite(value):
        diag.error(where, f"the default of {what} must be finite, found {value!r}")
        return None
    if minimum is not None and maximum is not None and not minimum <= value <= maximum:
        diag.error(where, f"the default {value!r} of {what} is outside its range [{minimum!r}, {maximum!r}]")
        return None
    if type_ == "enum" and values and value not in dict(values):
        diag.error(where, f"the default {value!r} of {what} is not one of its values",
                   ", ".join(name for name, _ in values))
        return None
    if type_ == "string" and max_length is not None and len(value.encode()) > max_length:
        diag.error(where, f"the default of {what} is {len(value.encode())} bytes long, more than its max_length "
                   f"{max_length}")
        return None
    return float(value) if type_ == "real" else value
