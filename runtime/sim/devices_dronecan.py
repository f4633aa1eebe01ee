"""What the simulated devices measure, for their DroneCAN (UAVCAN v0) firmware: the same vehicle and physics as the
Cyphal firmware (:mod:`sam_runtime.sim.devices`), on dronecan message objects.

- Generic values: :func:`generic_fill_v0` fills every field of any v0 type from dronecan's type description (slow
  sines within each field's range, ``uavcan.Timestamp`` in microseconds, arrays, nested types), so any spec's v0
  messages get plausible, changing values.
- Physics (:data:`PHYSICS_V0`, keyed by the v0 full name, e.g. ``uavcan.equipment.ahrs.RawIMU``): the Cyphal physics
  where the field names are the same (RawIMU, MagneticFieldStrength, StaticPressure, BatteryInfo, the spec's own
  sam.* types; a v0 timestamp's ``usec`` is set like Cyphal's ``microsecond``), small adapters where they differ
  (RawIMU: the covariance's diagonal only; gnss.Fix2: its 6x6 covariance and GNSS time; esc.Status instead of
  Cyphal's ThrusterFeedback: rpm, current, temperature in kelvin, the battery's voltage, power rating, ESC index).
  A spec's own (custom) v0 type without an entry gets the Cyphal physics of the same name without the root
  namespace, if there is one.
- Commands: v0 commands are broadcasts; each actuator takes its own element of them (``rpm[1]``,
  ``commands[actuator_id=4]``, see :func:`parse_element`). :data:`SAM_ACTUATORS_V0` is SAM's firmware: which element
  each actuator device takes and which input of the vehicle model it drives.
"""

from __future__ import annotations

import logging
import math
import re
from dataclasses import dataclass
from typing import Any

from sam_runtime.sim.devices import (
    PHYSICS,
    SAM_ACTUATORS,
    DeviceState,
    PhysicsFn,
    VehicleState,
    fill_altitude,
    fill_battery,
    fill_gnss,
    fill_imu,
    fill_magnetometer,
    fill_position_feedback,
    fill_pressure,
    fill_thrust_vector_feedback,
    set_field,
    vehicle_actuator,
)

__all__ = ["PHYSICS_V0", "SAM_ACTUATORS_V0", "Element", "element_value", "ensure_element", "esc_index_of",
           "generic_fill_v0", "parse_element", "physics_v0", "sam_command_fields", "to_builtin_v0"]

_log = logging.getLogger("sam_runtime.sim.simulator")
V0_TIMESTAMP = "uavcan.Timestamp"

# SAM's DroneCAN firmware (by the spec's device name): the element of a broadcast command the device takes ->
# (the vehicle model's input, scale from the command's value to the input's unit). An ArrayCommand item's value is
# its command_value (radians for the servos, 0..1 for the two position actuators whose inputs are in percent).
SAM_ACTUATORS_V0: dict[str, dict[str, tuple[str, float]]] = {
    "thruster_1": {"rpm[0]": ("rpm_1", 1.0)},
    "thruster_2": {"rpm[1]": ("rpm_2", 1.0)},
    "thrust_vector": {"commands[actuator_id=0]": ("vertical_rad", 1.0),
                      "commands[actuator_id=1]": ("horizontal_rad", 1.0)},
    "ballast": {"commands[actuator_id=2]": ("ballast_1_rad", 1.0), "commands[actuator_id=3]": ("ballast_2_rad", 1.0)},
    "longitudinal_weight": {"commands[actuator_id=4]": ("longitudinal_weight_pct", 100.0)},
    "buoyancy_piston": {"commands[actuator_id=5]": ("buoyancy_pct", 100.0)},
}


# ============================================================================================ elements
@dataclass(frozen=True)
class Element:
    """An element of a broadcast array: ``path[index]`` or the item ``path[key=value]``."""

    text: str
    path: str
    index: int | None = None
    key: str | None = None
    value: int | None = None


_ELEMENT = re.compile(r"^([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)\[(?:(\d+)|([A-Za-z_]\w*)=(-?\d+))\]$")


def parse_element(text: str) -> Element:
    """``rpm[1]`` or ``commands[actuator_id=4]`` (the ``elements`` of the generated DroneCAN mappings).

    >>> parse_element("rpm[1]"), parse_element("commands[actuator_id=4]").key
    (Element(text='rpm[1]', path='rpm', index=1, key=None, value=None), 'actuator_id')
    """
    m = _ELEMENT.match(text)
    if m is None:
        raise ValueError(f"not an array element: {text!r}")
    path, index, key, value = m.groups()
    if index is not None:
        return Element(text, path, index=int(index))
    return Element(text, path, key=key, value=int(value))


def _path(obj: Any, path: str) -> Any:
    for part in path.split("."):
        obj = getattr(obj, part)
    return obj


def element_value(msg: Any, el: Element) -> Any:
    """The element in ``msg`` (a number, or a dronecan object for an item), or None if the message lacks it."""
    try:
        arr = _path(msg, el.path)
    except AttributeError:
        return None
    if el.index is not None:
        return arr[el.index] if el.index < len(arr) else None
    for item in arr:
        if getattr(item, el.key, None) == el.value:  # type: ignore[arg-type]
            return item
    return None


def ensure_element(msg: Any, el: Element, claimed: set[int], tt: float, now_us: int) -> None:
    """Make a broadcast carry ``el`` (a reader of the message looks for it): an array at least that long, or an item
    with that key (an item whose key no other wanted element ``claimed`` is re-keyed, else one is added)."""
    arr = _path(msg, el.path)
    cap = arr._type.max_size
    if el.index is not None:
        primitive = arr._type.value_type.category == arr._type.value_type.CATEGORY_PRIMITIVE
        while len(arr) <= el.index < cap:
            if primitive:
                arr.append(0)
            else:
                arr.append(generic_fill_v0(arr.new_item(), tt, now_us, seed=len(arr)))
        return
    if element_value(msg, el) is not None:
        return
    free = next((item for item in arr if getattr(item, el.key) not in claimed), None)  # type: ignore[arg-type]
    if free is None and len(arr) < cap:
        free = arr.new_item()
        generic_fill_v0(free, tt, now_us, seed=len(arr))
        arr.append(free)
    if free is not None:
        setattr(free, el.key, el.value)  # type: ignore[arg-type]


# ============================================================================================ generic values
def _scalar(t: Any, phase: float, tt: float) -> Any:
    from dronecan import dsdl

    s = math.sin(2.0 * math.pi * tt / 20.0 + phase)
    if t.kind == dsdl.PrimitiveType.KIND_BOOLEAN:
        return s > 0
    lo, hi = t.value_range
    if t.kind == dsdl.PrimitiveType.KIND_FLOAT:
        return max(lo, min(hi, round(10.0 * s, 3)))
    lo, hi = int(lo), int(hi)
    mid = (lo + hi) // 2 if lo < 0 else min(hi, 100)
    amp = min(1000, (hi - lo) // 4)
    return max(lo, min(hi, round(mid + amp * s)))


def generic_fill_v0(obj: Any, tt: float, now_us: int, seed: int = 0) -> Any:
    """Fill every field of a dronecan message object with a slowly changing in-range value (any v0 type): numbers
    by their width and signedness, fixed arrays whole, variable arrays with a few elements (text "sim"), nested types
    recursively, ``uavcan.Timestamp`` with ``now_us``. Unions keep their first field."""
    t = obj._type
    if obj._is_union:
        return obj
    fields = t.fields if t.kind == t.KIND_MESSAGE else (
        t.request_fields if obj._mode == "request" else t.response_fields)
    for i, f in enumerate(fields):
        if f.type.category != f.type.CATEGORY_VOID:
            try:
                _fill_field(obj, f.name, f.type, 0.7 * (i + seed), tt, now_us, seed + i + 1)
            except (ValueError, TypeError, AttributeError) as ex:  # a value the type refuses: keep the default
                _log.debug("generic value for %s.%s refused: %s", t.full_name, f.name, ex)
    return obj


def _fill_field(obj: Any, name: str, ft: Any, phase: float, tt: float, now_us: int, seed: int) -> None:
    from dronecan import dsdl

    if ft.category == ft.CATEGORY_PRIMITIVE:
        setattr(obj, name, _scalar(ft, phase, tt))
    elif ft.category == ft.CATEGORY_COMPOUND:
        sub = getattr(obj, name)
        if ft.full_name == V0_TIMESTAMP:
            sub.usec = now_us
        else:
            generic_fill_v0(sub, tt, now_us, seed)
    elif ft.category == ft.CATEGORY_ARRAY:
        vt = ft.value_type
        static = ft.mode == dsdl.ArrayType.MODE_STATIC
        if vt.category == vt.CATEGORY_PRIMITIVE:
            if ft.is_string_like and "name" in name:
                setattr(obj, name, b"sim"[: ft.max_size])
            else:
                n = ft.max_size if static else min(ft.max_size, 3)
                setattr(obj, name, [_scalar(vt, phase + 0.3 * k, tt) for k in range(n)])
        elif vt.category == vt.CATEGORY_COMPOUND:
            arr = getattr(obj, name)
            n = ft.max_size if static else min(ft.max_size, 1)
            setattr(obj, name, [generic_fill_v0(arr.new_item(), tt, now_us, seed + k) for k in range(n)])


def to_builtin_v0(obj: Any) -> Any:
    """A dronecan object as plain Python (dicts, lists, numbers; text arrays as str), e.g. for JSON."""
    from dronecan import transport

    if isinstance(obj, transport.CompoundValue):
        names = [n for n in obj._fields if not n.startswith("_void_")]
        if obj._is_union:
            names = [obj._union_field or names[0]] if names else []
        return {n: to_builtin_v0(getattr(obj, n)) for n in names}
    if isinstance(obj, transport.ArrayValue):
        if obj._type.is_string_like:
            try:
                return obj.decode()
            except UnicodeDecodeError:
                pass
        return [to_builtin_v0(x) for x in obj]
    return obj


# ============================================================================================ SAM physics
def _fix2(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: Any) -> None:
    """gnss.Fix2: Cyphal's fix, plus its GNSS time and a 6x6 position/velocity covariance (empty without a fix)."""
    fill_gnss(obj, dev, veh, t, dt, rng)
    set_field(obj, "mode", 0)  # MODE_SINGLE
    set_field(obj, "sub_mode", 0)
    set_field(obj, "num_leap_seconds", 0)  # unknown
    set_field(obj, "ecef_position_velocity", [])
    if obj.status == veh.model.sensors.GPS_STATUS_NO_FIX:
        obj.gnss_timestamp.usec = 0
        set_field(obj, "gnss_time_standard", 0)  # NONE
        set_field(obj, "covariance", [])
        return
    obj.gnss_timestamp.usec = veh.now_us()
    set_field(obj, "gnss_time_standard", 2)  # UTC
    pos_var, vel_var = veh.model.sensors.noise.gps ** 2, 0.05 ** 2
    set_field(obj, "covariance",
              [(pos_var if i < 3 else vel_var) if i == j else 0.0 for i in range(6) for j in range(6)])


def esc_index_of(device: str) -> int | None:
    """The ESC index of a SAM thruster device (its ``rpm[i]`` element), or None."""
    for element in SAM_ACTUATORS_V0.get(device, {}):
        el = parse_element(element)
        if el.path == "rpm" and el.index is not None:
            return el.index
    return None


def _number(value: Any) -> float:
    """A command's value as a number: the first element of a whole array (a command not addressed by element)."""
    if isinstance(value, list):
        value = value[0] if value else 0.0
    return float(value) if isinstance(value, int | float) and math.isfinite(value) else 0.0


def _esc_status(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: Any) -> None:
    """esc.Status (what Cyphal's ThrusterFeedback reports, in v0's fields): a SAM thruster's rpm from the vehicle,
    another device's from its own model (spinning up at 2000 rpm/s toward its command)."""
    rpm = vehicle_actuator(dev, veh, t, "rpm")
    if rpm is None:
        if "rpm" in dev.command:
            target = _number(dev.command["rpm"])
        else:  # a RawCommand throttle, -8192..8191 full scale
            target = _number(dev.command.get("cmd", 0)) / 8191.0 * 2000.0
        rpm = dev.approach("rpm", target, 2000.0, t)
    max_rpm = veh.vehicle.params.max_rpm
    set_field(obj, "rpm", round(max(-131072, min(131071, rpm))))
    set_field(obj, "current", 0.3 + 2.0 * abs(rpm) / 1000.0)
    set_field(obj, "temperature", 273.15 + min(127, 25 + abs(rpm) / 200.0))  # kelvin
    set_field(obj, "voltage", veh.model.sensors.battery().voltage)
    set_field(obj, "error_count", 0)
    set_field(obj, "power_rating_pct", int(min(100, round(100.0 * abs(rpm) / max_rpm))))
    index = esc_index_of(dev.name)
    if index is not None:
        set_field(obj, "esc_index", index)


def _raw_imu(obj: Any, dev: DeviceState, veh: VehicleState, t: float, dt: float, rng: Any) -> None:
    """ahrs.RawIMU: Cyphal's IMU sample (the spec maps its axes 1:1 to imu_link, as the Cyphal one) with the diagonal
    of the covariance (6 elements, as its DSDL allows)."""
    fill_imu(obj, dev, veh, t, dt, rng, full_covariance=False)


# Keyed by the v0 full name (no version: v0 types have none).
PHYSICS_V0: dict[str, PhysicsFn] = {
    "uavcan.equipment.ahrs.RawIMU": _raw_imu,
    "uavcan.equipment.ahrs.MagneticFieldStrength": fill_magnetometer,
    "uavcan.equipment.ahrs.MagneticFieldStrength2": fill_magnetometer,
    "uavcan.equipment.gnss.Fix2": _fix2,
    "uavcan.equipment.air_data.StaticPressure": fill_pressure,
    "uavcan.equipment.power.BatteryInfo": fill_battery,
    "uavcan.equipment.esc.Status": _esc_status,
    "sam.sensor.Altitude": fill_altitude,
    "sam.actuator.ThrustVectorFeedback": fill_thrust_vector_feedback,
    "sam.actuator.PositionFeedback": fill_position_feedback,
}


def physics_v0(name: str, custom: bool = False) -> PhysicsFn | None:
    """The physics of a v0 type: :data:`PHYSICS_V0`, else for a spec's own type the Cyphal physics of the same name
    without its root namespace (``boat.sensor.Altitude`` -> ``sensor.Altitude``)."""
    fn = PHYSICS_V0.get(name)
    if fn is None and custom and "." in name:
        fn = PHYSICS.get(name.split(".", 1)[1])
    return fn


def sam_command_fields(device: str) -> dict[str, str]:
    """The vehicle input -> the Cyphal command field of a SAM actuator device (``rpm_1`` -> ``rpm``)."""
    return {inp: fld for fld, inp in SAM_ACTUATORS.get(device, {}).items()}
