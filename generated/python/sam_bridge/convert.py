# Generated from interfaces.yaml by sam-codegen; do not edit.
"""Converters of the sam bridge: UAVCAN (pycyphal objects) <-> ROS 2 messages.

Every mapping of the spec has both converters, whichever direction the bridge runs:

- ``<mapping>_to_ros(src, receive_ns, stats)``: a pycyphal object -> a new ROS message;
- ``<mapping>_to_uavcan(src, stats)``: a ROS message -> a new pycyphal object.

They return None when the message must be dropped: a value that cannot be converted (NaN into an integer, a
value missing from a table) or one out of range under the mapping's ``reject`` policy. They never raise for
bad values. Each value that was changed to fit (saturated, truncated) or that made a message be dropped is
counted in ``stats`` under "<mapping>.<field>", the field being the one written: the ROS path in to_ros,
the UAVCAN path in to_uavcan. ROS messages are assumed to hold values of their declared types (as they do
when they come from DDS). A UAVCAN timestamp of 0 (unknown) becomes the receive time.

The pycyphal-compiled DSDL packages must be on sys.path and the ROS message packages installed.
"""

from __future__ import annotations

from collections.abc import Callable
from copy import copy as _copy
from typing import Any

import numpy as _np
import sam.actuator
import sam.power
import sam.sensor
import uavcan.time
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion, Vector3
from sam_msgs.msg import (
    BallastAngles,
    BatteryInfo,
    PercentStamped,
    PositionFeedback,
    ThrusterAngles,
    ThrusterFeedback,
    ThrusterRPMs,
    ThrustVectorFeedback,
)
from sensor_msgs.msg import BatteryState, FluidPressure, Imu, MagneticField, NavSatFix, NavSatStatus, Range
from std_msgs.msg import Header

from . import conversion_support as _support

__all__ = ["CONVERTERS", "FAST_CONSTRUCTORS", "ConversionStats"]

ConversionStats = _support.ConversionStats
_NAN = float("nan")
_INF = float("inf")

# gps_fix: status -> status.status
_GPS_FIX_STATUS_STATUS_TO_ROS: dict[int, int] = {0: -1, 1: -1, 2: 0, 3: 0}

# gps_fix: status.status -> status (first key per value)
_GPS_FIX_STATUS_STATUS_TO_UAVCAN: dict[int, int] = {-1: 0, 0: 2}

# battery_state: state_of_health_pct -> power_supply_health
_BATTERY_STATE_POWER_SUPPLY_HEALTH_TO_ROS: dict[int, int] = {
    0: 3, 1: 3, 2: 3, 3: 3, 4: 3, 5: 3, 6: 3, 7: 3, 8: 3, 9: 3, 10: 3, 11: 3, 12: 3, 13: 3, 14: 3, 15: 3,
    16: 3, 17: 3, 18: 3, 19: 3, 20: 3, 21: 3, 22: 3, 23: 3, 24: 3, 25: 3, 26: 3, 27: 3, 28: 3, 29: 3, 127: 0,
}

# battery_state: power_supply_health -> state_of_health_pct (first key per value)
_BATTERY_STATE_POWER_SUPPLY_HEALTH_TO_UAVCAN: dict[int, int] = {0: 127, 3: 0}



# ---- constructors of the messages the converters build ----------------------------------------------------
# A rosidl_generator_py class's __init__ builds every default sub-message even when one is passed in, and
# goes through a property per field (Imu(): ~6 us); a pycyphal class's checks every value again and copies
# every array twice (RawIMU: ~4 us). These set each field's attribute (`_<field>`) directly, as the classes'
# setters do (rclpy's when ROS_PYTHON_CHECK_FIELDS is not 1), with the classes' defaults; the converters have
# checked every value already. _same() proves at import that each builds what its class builds; if one does
# not (another rosidl_generator_py or nunavut layout) or rclpy's field checks are on, FAST_CONSTRUCTORS is
# False and the classes themselves are used (they take the same arguments).

_NEW = object.__new__
_DEFAULT_BatteryInfo = BatteryInfo()
_DEFAULT_BatteryState = BatteryState()
_DEFAULT_Imu = Imu()
_DEFAULT_MagneticField = MagneticField()
_DEFAULT_NavSatFix = NavSatFix()


def _new_Time(sec: int = 0, nanosec: int = 0) -> Time:
    _m = _NEW(Time)
    _m._check_fields = False
    _m._sec = sec
    _m._nanosec = nanosec
    return _m


def _new_Quaternion(x: float = 0.0, y: float = 0.0, z: float = 0.0, w: float = 1.0) -> Quaternion:
    _m = _NEW(Quaternion)
    _m._check_fields = False
    _m._x = x
    _m._y = y
    _m._z = z
    _m._w = w
    return _m


def _new_Vector3(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Vector3:
    _m = _NEW(Vector3)
    _m._check_fields = False
    _m._x = x
    _m._y = y
    _m._z = z
    return _m


def _new_BallastAngles(
    weight_1_offset_radians: float = 0.0,
    weight_2_offset_radians: float = 0.0,
    header: Header | None = None,
) -> BallastAngles:
    _m = _NEW(BallastAngles)
    _m._check_fields = False
    _m._weight_1_offset_radians = weight_1_offset_radians
    _m._weight_2_offset_radians = weight_2_offset_radians
    _m._header = _new_Header() if header is None else header
    return _m


def _new_BatteryInfo(
    header: Header | None = None,
    temperature: float = 0.0,
    voltage: float = 0.0,
    current: float = 0.0,
    average_power_10sec: float = 0.0,
    remaining_capacity_wh: float = 0.0,
    full_charge_capacity_wh: float = 0.0,
    hours_to_full_charge: float = 0.0,
    status_flags: int = 0,
    state_of_health_pct: int = 0,
    state_of_charge_pct: int = 0,
    state_of_charge_pct_stdev: int = 0,
    battery_id: int = 0,
    model_instance_id: int = 0,
    model_name: Any = None,
) -> BatteryInfo:
    _m = _NEW(BatteryInfo)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._temperature = temperature
    _m._voltage = voltage
    _m._current = current
    _m._average_power_10sec = average_power_10sec
    _m._remaining_capacity_wh = remaining_capacity_wh
    _m._full_charge_capacity_wh = full_charge_capacity_wh
    _m._hours_to_full_charge = hours_to_full_charge
    _m._status_flags = status_flags
    _m._state_of_health_pct = state_of_health_pct
    _m._state_of_charge_pct = state_of_charge_pct
    _m._state_of_charge_pct_stdev = state_of_charge_pct_stdev
    _m._battery_id = battery_id
    _m._model_instance_id = model_instance_id
    if model_name is None:
        _m._model_name = _copy(_DEFAULT_BatteryInfo._model_name)
    else:
        _m.model_name = model_name
    return _m


def _new_PercentStamped(percent: float = 0.0, header: Header | None = None) -> PercentStamped:
    _m = _NEW(PercentStamped)
    _m._check_fields = False
    _m._percent = percent
    _m._header = _new_Header() if header is None else header
    return _m


def _new_PositionFeedback(
    header: Header | None = None,
    percent: float = 0.0,
    encoder_count: int = 0,
) -> PositionFeedback:
    _m = _NEW(PositionFeedback)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._percent = percent
    _m._encoder_count = encoder_count
    return _m


def _new_ThrustVectorFeedback(
    header: Header | None = None,
    vertical_mrad: int = 0,
    horizontal_mrad: int = 0,
) -> ThrustVectorFeedback:
    _m = _NEW(ThrustVectorFeedback)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._vertical_mrad = vertical_mrad
    _m._horizontal_mrad = horizontal_mrad
    return _m


def _new_ThrusterAngles(
    thruster_vertical_radians: float = 0.0,
    thruster_horizontal_radians: float = 0.0,
    header: Header | None = None,
) -> ThrusterAngles:
    _m = _NEW(ThrusterAngles)
    _m._check_fields = False
    _m._thruster_vertical_radians = thruster_vertical_radians
    _m._thruster_horizontal_radians = thruster_horizontal_radians
    _m._header = _new_Header() if header is None else header
    return _m


def _new_ThrusterFeedback(
    header: Header | None = None,
    rpm: int = 0,
    current: float = 0.0,
    temperature_c: int = 0,
) -> ThrusterFeedback:
    _m = _NEW(ThrusterFeedback)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._rpm = rpm
    _m._current = current
    _m._temperature_c = temperature_c
    return _m


def _new_ThrusterRPMs(
    thruster_1_rpm: int = 0,
    thruster_2_rpm: int = 0,
    header: Header | None = None,
) -> ThrusterRPMs:
    _m = _NEW(ThrusterRPMs)
    _m._check_fields = False
    _m._thruster_1_rpm = thruster_1_rpm
    _m._thruster_2_rpm = thruster_2_rpm
    _m._header = _new_Header() if header is None else header
    return _m


def _new_BatteryState(
    header: Header | None = None,
    voltage: float = 0.0,
    temperature: float = 0.0,
    current: float = 0.0,
    charge: float = 0.0,
    capacity: float = 0.0,
    design_capacity: float = 0.0,
    percentage: float = 0.0,
    power_supply_status: int = 0,
    power_supply_health: int = 0,
    power_supply_technology: int = 0,
    present: bool = False,
    cell_voltage: Any = None,
    cell_temperature: Any = None,
    location: str = '',
    serial_number: str = '',
) -> BatteryState:
    _m = _NEW(BatteryState)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._voltage = voltage
    _m._temperature = temperature
    _m._current = current
    _m._charge = charge
    _m._capacity = capacity
    _m._design_capacity = design_capacity
    _m._percentage = percentage
    _m._power_supply_status = power_supply_status
    _m._power_supply_health = power_supply_health
    _m._power_supply_technology = power_supply_technology
    _m._present = present
    if cell_voltage is None:
        _m._cell_voltage = _copy(_DEFAULT_BatteryState._cell_voltage)
    else:
        _m.cell_voltage = cell_voltage
    if cell_temperature is None:
        _m._cell_temperature = _copy(_DEFAULT_BatteryState._cell_temperature)
    else:
        _m.cell_temperature = cell_temperature
    _m._location = location
    _m._serial_number = serial_number
    return _m


def _new_FluidPressure(
    header: Header | None = None,
    fluid_pressure: float = 0.0,
    variance: float = 0.0,
) -> FluidPressure:
    _m = _NEW(FluidPressure)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._fluid_pressure = fluid_pressure
    _m._variance = variance
    return _m


def _new_Imu(
    header: Header | None = None,
    orientation: Quaternion | None = None,
    orientation_covariance: Any = None,
    angular_velocity: Vector3 | None = None,
    angular_velocity_covariance: Any = None,
    linear_acceleration: Vector3 | None = None,
    linear_acceleration_covariance: Any = None,
) -> Imu:
    _m = _NEW(Imu)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._orientation = _new_Quaternion() if orientation is None else orientation
    if orientation_covariance is None:
        _m._orientation_covariance = _DEFAULT_Imu._orientation_covariance.copy()
    else:
        _m.orientation_covariance = orientation_covariance
    if angular_velocity is None:
        _m._angular_velocity = _new_Vector3()
    else:
        _m._angular_velocity = angular_velocity
    if angular_velocity_covariance is None:
        _m._angular_velocity_covariance = _DEFAULT_Imu._angular_velocity_covariance.copy()
    else:
        _m.angular_velocity_covariance = angular_velocity_covariance
    if linear_acceleration is None:
        _m._linear_acceleration = _new_Vector3()
    else:
        _m._linear_acceleration = linear_acceleration
    if linear_acceleration_covariance is None:
        _m._linear_acceleration_covariance = _DEFAULT_Imu._linear_acceleration_covariance.copy()
    else:
        _m.linear_acceleration_covariance = linear_acceleration_covariance
    return _m


def _new_MagneticField(
    header: Header | None = None,
    magnetic_field: Vector3 | None = None,
    magnetic_field_covariance: Any = None,
) -> MagneticField:
    _m = _NEW(MagneticField)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    if magnetic_field is None:
        _m._magnetic_field = _new_Vector3()
    else:
        _m._magnetic_field = magnetic_field
    if magnetic_field_covariance is None:
        _m._magnetic_field_covariance = _DEFAULT_MagneticField._magnetic_field_covariance.copy()
    else:
        _m.magnetic_field_covariance = magnetic_field_covariance
    return _m


def _new_NavSatFix(
    header: Header | None = None,
    status: NavSatStatus | None = None,
    latitude: float = 0.0,
    longitude: float = 0.0,
    altitude: float = 0.0,
    position_covariance: Any = None,
    position_covariance_type: int = 0,
) -> NavSatFix:
    _m = _NEW(NavSatFix)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._status = _new_NavSatStatus() if status is None else status
    _m._latitude = latitude
    _m._longitude = longitude
    _m._altitude = altitude
    if position_covariance is None:
        _m._position_covariance = _DEFAULT_NavSatFix._position_covariance.copy()
    else:
        _m.position_covariance = position_covariance
    _m._position_covariance_type = position_covariance_type
    return _m


def _new_NavSatStatus(status: int = -2, service: int = 0) -> NavSatStatus:
    _m = _NEW(NavSatStatus)
    _m._check_fields = False
    _m._status = status
    _m._service = service
    return _m


def _new_Range(
    header: Header | None = None,
    radiation_type: int = 0,
    field_of_view: float = 0.0,
    min_range: float = 0.0,
    max_range: float = 0.0,
    range: float = 0.0,
    variance: float = 0.0,
) -> Range:
    _m = _NEW(Range)
    _m._check_fields = False
    _m._header = _new_Header() if header is None else header
    _m._radiation_type = radiation_type
    _m._field_of_view = field_of_view
    _m._min_range = min_range
    _m._max_range = max_range
    _m._range = range
    _m._variance = variance
    return _m


def _new_Header(stamp: Time | None = None, frame_id: str = '') -> Header:
    _m = _NEW(Header)
    _m._check_fields = False
    _m._stamp = _new_Time() if stamp is None else stamp
    _m._frame_id = frame_id
    return _m


def _new_sam_actuator_BallastAngles_0_1(
    weight_1_offset_radians: float = 0.0,
    weight_2_offset_radians: float = 0.0,
) -> sam.actuator.BallastAngles_0_1:
    _m = _NEW(sam.actuator.BallastAngles_0_1)
    _m._weight_1_offset_radians = float(weight_1_offset_radians)
    _m._weight_2_offset_radians = float(weight_2_offset_radians)
    return _m


def _new_sam_actuator_PercentCommand_0_1(percent: float = 0.0) -> sam.actuator.PercentCommand_0_1:
    _m = _NEW(sam.actuator.PercentCommand_0_1)
    _m._percent = float(percent)
    return _m


def _new_sam_actuator_PositionFeedback_0_1(
    timestamp: Any = None,
    percent: float = 0.0,
    encoder_count: int = 0,
) -> sam.actuator.PositionFeedback_0_1:
    _m = _NEW(sam.actuator.PositionFeedback_0_1)
    if timestamp is None:
        _m._timestamp = _new_uavcan_time_SynchronizedTimestamp_1_0()
    else:
        _m._timestamp = timestamp
    _m._percent = float(percent)
    _m._encoder_count = encoder_count
    return _m


def _new_sam_actuator_ThrustVector_0_1(
    vertical_radians: float = 0.0,
    horizontal_radians: float = 0.0,
) -> sam.actuator.ThrustVector_0_1:
    _m = _NEW(sam.actuator.ThrustVector_0_1)
    _m._vertical_radians = float(vertical_radians)
    _m._horizontal_radians = float(horizontal_radians)
    return _m


def _new_sam_actuator_ThrustVectorFeedback_0_1(
    timestamp: Any = None,
    vertical_mrad: int = 0,
    horizontal_mrad: int = 0,
) -> sam.actuator.ThrustVectorFeedback_0_1:
    _m = _NEW(sam.actuator.ThrustVectorFeedback_0_1)
    if timestamp is None:
        _m._timestamp = _new_uavcan_time_SynchronizedTimestamp_1_0()
    else:
        _m._timestamp = timestamp
    _m._vertical_mrad = vertical_mrad
    _m._horizontal_mrad = horizontal_mrad
    return _m


def _new_sam_actuator_ThrusterFeedback_0_1(
    timestamp: Any = None,
    rpm: int = 0,
    current: float = 0.0,
    temperature_c: int = 0,
) -> sam.actuator.ThrusterFeedback_0_1:
    _m = _NEW(sam.actuator.ThrusterFeedback_0_1)
    if timestamp is None:
        _m._timestamp = _new_uavcan_time_SynchronizedTimestamp_1_0()
    else:
        _m._timestamp = timestamp
    _m._rpm = rpm
    _m._current = float(current)
    _m._temperature_c = temperature_c
    return _m


def _new_sam_actuator_ThrusterRPM_0_1(rpm: int = 0) -> sam.actuator.ThrusterRPM_0_1:
    _m = _NEW(sam.actuator.ThrusterRPM_0_1)
    _m._rpm = rpm
    return _m


def _new_sam_power_BatteryInfo_0_1(
    temperature: float = 0.0,
    voltage: float = 0.0,
    current: float = 0.0,
    average_power_10sec: float = 0.0,
    remaining_capacity_wh: float = 0.0,
    full_charge_capacity_wh: float = 0.0,
    hours_to_full_charge: float = 0.0,
    status_flags: int = 0,
    state_of_health_pct: int = 0,
    state_of_charge_pct: int = 0,
    state_of_charge_pct_stdev: int = 0,
    battery_id: int = 0,
    model_instance_id: int = 0,
    model_name: Any = None,
) -> sam.power.BatteryInfo_0_1:
    _m = _NEW(sam.power.BatteryInfo_0_1)
    _m._temperature = float(temperature)
    _m._voltage = float(voltage)
    _m._current = float(current)
    _m._average_power_10sec = float(average_power_10sec)
    _m._remaining_capacity_wh = float(remaining_capacity_wh)
    _m._full_charge_capacity_wh = float(full_charge_capacity_wh)
    _m._hours_to_full_charge = float(hours_to_full_charge)
    _m._status_flags = status_flags
    _m._state_of_health_pct = state_of_health_pct
    _m._state_of_charge_pct = state_of_charge_pct
    _m._state_of_charge_pct_stdev = state_of_charge_pct_stdev
    _m._battery_id = battery_id
    _m._model_instance_id = model_instance_id
    if model_name is None:
        _m._model_name = _np.array([], _np.uint8)
    elif model_name.__class__ is bytes:
        _m._model_name = _np.frombuffer(model_name, _np.uint8)
    else:
        _m._model_name = _np.array(model_name, _np.uint8)
    return _m


def _new_sam_sensor_Altitude_0_1(
    timestamp: Any = None,
    altitude: float = 0.0,
    altitude_variance: float = 0.0,
) -> sam.sensor.Altitude_0_1:
    _m = _NEW(sam.sensor.Altitude_0_1)
    if timestamp is None:
        _m._timestamp = _new_uavcan_time_SynchronizedTimestamp_1_0()
    else:
        _m._timestamp = timestamp
    _m._altitude = float(altitude)
    _m._altitude_variance = float(altitude_variance)
    return _m


def _new_sam_sensor_GNSSFix_0_1(
    timestamp: Any = None,
    longitude_deg_1e8: int = 0,
    latitude_deg_1e8: int = 0,
    height_ellipsoid_mm: int = 0,
    height_msl_mm: int = 0,
    ned_velocity: Any = None,
    sats_used: int = 0,
    status: int = 0,
    pdop: float = 0.0,
    position_covariance: Any = None,
) -> sam.sensor.GNSSFix_0_1:
    _m = _NEW(sam.sensor.GNSSFix_0_1)
    if timestamp is None:
        _m._timestamp = _new_uavcan_time_SynchronizedTimestamp_1_0()
    else:
        _m._timestamp = timestamp
    _m._longitude_deg_1e8 = longitude_deg_1e8
    _m._latitude_deg_1e8 = latitude_deg_1e8
    _m._height_ellipsoid_mm = height_ellipsoid_mm
    _m._height_msl_mm = height_msl_mm
    if ned_velocity is None:
        _m._ned_velocity = _np.zeros(3, _np.float32)
    else:
        _m._ned_velocity = _np.array(ned_velocity, _np.float32)
    _m._sats_used = sats_used
    _m._status = status
    _m._pdop = float(pdop)
    if position_covariance is None:
        _m._position_covariance = _np.array([], _np.float16)
    else:
        _m._position_covariance = _np.array(position_covariance, _np.float16)
    return _m


def _new_sam_sensor_MagneticFieldStrength_0_1(
    magnetic_field_ga: Any = None,
    magnetic_field_covariance: Any = None,
) -> sam.sensor.MagneticFieldStrength_0_1:
    _m = _NEW(sam.sensor.MagneticFieldStrength_0_1)
    if magnetic_field_ga is None:
        _m._magnetic_field_ga = _np.zeros(3, _np.float16)
    else:
        _m._magnetic_field_ga = _np.array(magnetic_field_ga, _np.float16)
    if magnetic_field_covariance is None:
        _m._magnetic_field_covariance = _np.array([], _np.float16)
    else:
        _m._magnetic_field_covariance = _np.array(magnetic_field_covariance, _np.float16)
    return _m


def _new_sam_sensor_RawIMU_0_1(
    timestamp: Any = None,
    integration_interval: float = 0.0,
    rate_gyro_latest: Any = None,
    rate_gyro_integral: Any = None,
    accelerometer_latest: Any = None,
    accelerometer_integral: Any = None,
    covariance: Any = None,
) -> sam.sensor.RawIMU_0_1:
    _m = _NEW(sam.sensor.RawIMU_0_1)
    if timestamp is None:
        _m._timestamp = _new_uavcan_time_SynchronizedTimestamp_1_0()
    else:
        _m._timestamp = timestamp
    _m._integration_interval = float(integration_interval)
    if rate_gyro_latest is None:
        _m._rate_gyro_latest = _np.zeros(3, _np.float16)
    else:
        _m._rate_gyro_latest = _np.array(rate_gyro_latest, _np.float16)
    if rate_gyro_integral is None:
        _m._rate_gyro_integral = _np.zeros(3, _np.float32)
    else:
        _m._rate_gyro_integral = _np.array(rate_gyro_integral, _np.float32)
    if accelerometer_latest is None:
        _m._accelerometer_latest = _np.zeros(3, _np.float16)
    else:
        _m._accelerometer_latest = _np.array(accelerometer_latest, _np.float16)
    if accelerometer_integral is None:
        _m._accelerometer_integral = _np.zeros(3, _np.float32)
    else:
        _m._accelerometer_integral = _np.array(accelerometer_integral, _np.float32)
    if covariance is None:
        _m._covariance = _np.array([], _np.float16)
    else:
        _m._covariance = _np.array(covariance, _np.float16)
    return _m


def _new_sam_sensor_StaticPressure_0_1(
    static_pressure: float = 0.0,
    static_pressure_variance: float = 0.0,
) -> sam.sensor.StaticPressure_0_1:
    _m = _NEW(sam.sensor.StaticPressure_0_1)
    _m._static_pressure = float(static_pressure)
    _m._static_pressure_variance = float(static_pressure_variance)
    return _m


def _new_uavcan_time_SynchronizedTimestamp_1_0(microsecond: int = 0) -> uavcan.time.SynchronizedTimestamp_1_0:
    _m = _NEW(uavcan.time.SynchronizedTimestamp_1_0)
    _m._microsecond = microsecond
    return _m


def _same(a: Any, b: Any) -> bool:
    """a and b hold equal values of the same Python types, slot by slot (arrays: element type too)."""
    if type(a) is not type(b):
        return False
    slots = getattr(type(a), "__slots__", None)
    if slots is not None:
        return all(hasattr(a, s) and hasattr(b, s) and _same(getattr(a, s), getattr(b, s)) for s in slots)
    if isinstance(a, float):
        return a == b or (a != a and b != b)  # NaN (unknown) is the same value here
    if hasattr(a, "tolist"):  # numpy array or array.array
        if getattr(a, "dtype", None) != getattr(b, "dtype", None) or getattr(a, "typecode", None) != getattr(
            b, "typecode", None
        ):
            return False
        a, b = a.tolist(), b.tolist()
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if hasattr(a, "__dict__"):  # a pycyphal object
        return vars(a).keys() == vars(b).keys() and all(_same(v, vars(b)[k]) for k, v in vars(a).items())
    return bool(a == b)


# (generated constructor, class) pairs
_FACTORIES: tuple[tuple[Callable[..., Any], type], ...] = (
    (_new_Time, Time),
    (_new_Quaternion, Quaternion),
    (_new_Vector3, Vector3),
    (_new_BallastAngles, BallastAngles),
    (_new_BatteryInfo, BatteryInfo),
    (_new_PercentStamped, PercentStamped),
    (_new_PositionFeedback, PositionFeedback),
    (_new_ThrustVectorFeedback, ThrustVectorFeedback),
    (_new_ThrusterAngles, ThrusterAngles),
    (_new_ThrusterFeedback, ThrusterFeedback),
    (_new_ThrusterRPMs, ThrusterRPMs),
    (_new_BatteryState, BatteryState),
    (_new_FluidPressure, FluidPressure),
    (_new_Imu, Imu),
    (_new_MagneticField, MagneticField),
    (_new_NavSatFix, NavSatFix),
    (_new_NavSatStatus, NavSatStatus),
    (_new_Range, Range),
    (_new_Header, Header),
    (_new_sam_actuator_BallastAngles_0_1, sam.actuator.BallastAngles_0_1),
    (_new_sam_actuator_PercentCommand_0_1, sam.actuator.PercentCommand_0_1),
    (_new_sam_actuator_PositionFeedback_0_1, sam.actuator.PositionFeedback_0_1),
    (_new_sam_actuator_ThrustVector_0_1, sam.actuator.ThrustVector_0_1),
    (_new_sam_actuator_ThrustVectorFeedback_0_1, sam.actuator.ThrustVectorFeedback_0_1),
    (_new_sam_actuator_ThrusterFeedback_0_1, sam.actuator.ThrusterFeedback_0_1),
    (_new_sam_actuator_ThrusterRPM_0_1, sam.actuator.ThrusterRPM_0_1),
    (_new_sam_power_BatteryInfo_0_1, sam.power.BatteryInfo_0_1),
    (_new_sam_sensor_Altitude_0_1, sam.sensor.Altitude_0_1),
    (_new_sam_sensor_GNSSFix_0_1, sam.sensor.GNSSFix_0_1),
    (_new_sam_sensor_MagneticFieldStrength_0_1, sam.sensor.MagneticFieldStrength_0_1),
    (_new_sam_sensor_RawIMU_0_1, sam.sensor.RawIMU_0_1),
    (_new_sam_sensor_StaticPressure_0_1, sam.sensor.StaticPressure_0_1),
    (_new_uavcan_time_SynchronizedTimestamp_1_0, uavcan.time.SynchronizedTimestamp_1_0),
)


def _fast_constructors_match() -> bool:
    try:
        return all(_same(new(), cls()) for new, cls in _FACTORIES)
    except Exception:  # a slot or attribute this layout does not have: not the layout they were written for
        return False


FAST_CONSTRUCTORS: bool = _fast_constructors_match()
if not FAST_CONSTRUCTORS:
    _new_Time = Time
    _new_Quaternion = Quaternion
    _new_Vector3 = Vector3
    _new_BallastAngles = BallastAngles
    _new_BatteryInfo = BatteryInfo
    _new_PercentStamped = PercentStamped
    _new_PositionFeedback = PositionFeedback
    _new_ThrustVectorFeedback = ThrustVectorFeedback
    _new_ThrusterAngles = ThrusterAngles
    _new_ThrusterFeedback = ThrusterFeedback
    _new_ThrusterRPMs = ThrusterRPMs
    _new_BatteryState = BatteryState
    _new_FluidPressure = FluidPressure
    _new_Imu = Imu
    _new_MagneticField = MagneticField
    _new_NavSatFix = NavSatFix
    _new_NavSatStatus = NavSatStatus
    _new_Range = Range
    _new_Header = Header
    _new_sam_actuator_BallastAngles_0_1 = sam.actuator.BallastAngles_0_1
    _new_sam_actuator_PercentCommand_0_1 = sam.actuator.PercentCommand_0_1
    _new_sam_actuator_PositionFeedback_0_1 = sam.actuator.PositionFeedback_0_1
    _new_sam_actuator_ThrustVector_0_1 = sam.actuator.ThrustVector_0_1
    _new_sam_actuator_ThrustVectorFeedback_0_1 = sam.actuator.ThrustVectorFeedback_0_1
    _new_sam_actuator_ThrusterFeedback_0_1 = sam.actuator.ThrusterFeedback_0_1
    _new_sam_actuator_ThrusterRPM_0_1 = sam.actuator.ThrusterRPM_0_1
    _new_sam_power_BatteryInfo_0_1 = sam.power.BatteryInfo_0_1
    _new_sam_sensor_Altitude_0_1 = sam.sensor.Altitude_0_1
    _new_sam_sensor_GNSSFix_0_1 = sam.sensor.GNSSFix_0_1
    _new_sam_sensor_MagneticFieldStrength_0_1 = sam.sensor.MagneticFieldStrength_0_1
    _new_sam_sensor_RawIMU_0_1 = sam.sensor.RawIMU_0_1
    _new_sam_sensor_StaticPressure_0_1 = sam.sensor.StaticPressure_0_1
    _new_uavcan_time_SynchronizedTimestamp_1_0 = uavcan.time.SynchronizedTimestamp_1_0


def imu_to_ros(src: sam.sensor.RawIMU_0_1, receive_ns: int, stats: ConversionStats) -> Imu | None:
    """Mapping 'imu', UAVCAN -> ROS.

    sam.sensor.RawIMU.0.1 -> sensor_msgs/Imu
    """
    rate_gyro_latest = src.rate_gyro_latest.tolist()
    accelerometer_latest = src.accelerometer_latest.tolist()
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('imu.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    return _new_Imu(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='imu_link'),
        orientation_covariance=[-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        angular_velocity=_new_Vector3(x=rate_gyro_latest[0], y=rate_gyro_latest[1], z=rate_gyro_latest[2]),
        linear_acceleration=_new_Vector3(
            x=accelerometer_latest[0],
            y=accelerometer_latest[1],
            z=accelerometer_latest[2],
        ),
    )


def imu_to_uavcan(src: Imu, stats: ConversionStats) -> sam.sensor.RawIMU_0_1 | None:
    """Mapping 'imu', ROS -> UAVCAN.

    sensor_msgs/Imu -> sam.sensor.RawIMU.0.1
    """
    stamp = src.header.stamp
    angular_velocity = src.angular_velocity
    linear_acceleration = src.linear_acceleration
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('imu.timestamp.microsecond')
        us = 0
    rate_gyro_latest_0 = angular_velocity.x
    if rate_gyro_latest_0 > 65504.0:
        stats.saturate('imu.rate_gyro_latest[0]')
        rate_gyro_latest_0 = 65504.0
    elif rate_gyro_latest_0 < -65504.0:
        stats.saturate('imu.rate_gyro_latest[0]')
        rate_gyro_latest_0 = -65504.0
    rate_gyro_latest_1 = angular_velocity.y
    if rate_gyro_latest_1 > 65504.0:
        stats.saturate('imu.rate_gyro_latest[1]')
        rate_gyro_latest_1 = 65504.0
    elif rate_gyro_latest_1 < -65504.0:
        stats.saturate('imu.rate_gyro_latest[1]')
        rate_gyro_latest_1 = -65504.0
    rate_gyro_latest_2 = angular_velocity.z
    if rate_gyro_latest_2 > 65504.0:
        stats.saturate('imu.rate_gyro_latest[2]')
        rate_gyro_latest_2 = 65504.0
    elif rate_gyro_latest_2 < -65504.0:
        stats.saturate('imu.rate_gyro_latest[2]')
        rate_gyro_latest_2 = -65504.0
    accelerometer_latest_0 = linear_acceleration.x
    if accelerometer_latest_0 > 65504.0:
        stats.saturate('imu.accelerometer_latest[0]')
        accelerometer_latest_0 = 65504.0
    elif accelerometer_latest_0 < -65504.0:
        stats.saturate('imu.accelerometer_latest[0]')
        accelerometer_latest_0 = -65504.0
    accelerometer_latest_1 = linear_acceleration.y
    if accelerometer_latest_1 > 65504.0:
        stats.saturate('imu.accelerometer_latest[1]')
        accelerometer_latest_1 = 65504.0
    elif accelerometer_latest_1 < -65504.0:
        stats.saturate('imu.accelerometer_latest[1]')
        accelerometer_latest_1 = -65504.0
    accelerometer_latest_2 = linear_acceleration.z
    if accelerometer_latest_2 > 65504.0:
        stats.saturate('imu.accelerometer_latest[2]')
        accelerometer_latest_2 = 65504.0
    elif accelerometer_latest_2 < -65504.0:
        stats.saturate('imu.accelerometer_latest[2]')
        accelerometer_latest_2 = -65504.0
    return _new_sam_sensor_RawIMU_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        rate_gyro_latest=[rate_gyro_latest_0, rate_gyro_latest_1, rate_gyro_latest_2],
        accelerometer_latest=[accelerometer_latest_0, accelerometer_latest_1, accelerometer_latest_2],
    )


def magnetic_field_to_ros(
    src: sam.sensor.MagneticFieldStrength_0_1, receive_ns: int, stats: ConversionStats
) -> MagneticField | None:
    """Mapping 'magnetic_field', UAVCAN -> ROS.

    sam.sensor.MagneticFieldStrength.0.1 -> sensor_msgs/MagneticField
    """
    magnetic_field_ga = src.magnetic_field_ga.tolist()
    magnetic_field_covariance = [x * 1e-08 for x in src.magnetic_field_covariance.tolist()]
    magnetic_field_covariance += [0.0] * (9 - len(magnetic_field_covariance))  # zero = unknown
    return _new_MagneticField(
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='magnetometer_link',
        ),
        magnetic_field=_new_Vector3(
            x=magnetic_field_ga[0] * 0.0001,
            y=magnetic_field_ga[1] * 0.0001,
            z=magnetic_field_ga[2] * 0.0001,
        ),
        magnetic_field_covariance=magnetic_field_covariance,
    )


def magnetic_field_to_uavcan(
    src: MagneticField, stats: ConversionStats
) -> sam.sensor.MagneticFieldStrength_0_1 | None:
    """Mapping 'magnetic_field', ROS -> UAVCAN.

    sensor_msgs/MagneticField -> sam.sensor.MagneticFieldStrength.0.1
    """
    magnetic_field = src.magnetic_field
    magnetic_field_ga_0 = magnetic_field.x / 0.0001
    if magnetic_field_ga_0 > 65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[0]')
        magnetic_field_ga_0 = 65504.0
    elif magnetic_field_ga_0 < -65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[0]')
        magnetic_field_ga_0 = -65504.0
    magnetic_field_ga_1 = magnetic_field.y / 0.0001
    if magnetic_field_ga_1 > 65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[1]')
        magnetic_field_ga_1 = 65504.0
    elif magnetic_field_ga_1 < -65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[1]')
        magnetic_field_ga_1 = -65504.0
    magnetic_field_ga_2 = magnetic_field.z / 0.0001
    if magnetic_field_ga_2 > 65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[2]')
        magnetic_field_ga_2 = 65504.0
    elif magnetic_field_ga_2 < -65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[2]')
        magnetic_field_ga_2 = -65504.0
    magnetic_field_covariance = [x / 1e-08 for x in src.magnetic_field_covariance.tolist()]
    magnetic_field_covariance = _support.clamp_floats(
        magnetic_field_covariance, 65504.0, stats, 'magnetic_field.magnetic_field_covariance', False
    )
    if magnetic_field_covariance is None:
        return None
    return _new_sam_sensor_MagneticFieldStrength_0_1(
        magnetic_field_ga=[magnetic_field_ga_0, magnetic_field_ga_1, magnetic_field_ga_2],
        magnetic_field_covariance=magnetic_field_covariance,
    )


def gps_fix_to_ros(src: sam.sensor.GNSSFix_0_1, receive_ns: int, stats: ConversionStats) -> NavSatFix | None:
    """Mapping 'gps_fix', UAVCAN -> ROS.

    sam.sensor.GNSSFix.0.1 -> sensor_msgs/NavSatFix
    """
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('gps_fix.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    status_status = _GPS_FIX_STATUS_STATUS_TO_ROS.get(src.status)
    if status_status is None:
        stats.reject('gps_fix.status.status')
        return None
    position_covariance = src.position_covariance.tolist()
    position_covariance += [0.0] * (9 - len(position_covariance))  # zero = unknown
    return _new_NavSatFix(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='gps_link'),
        status=_new_NavSatStatus(status=status_status, service=1),
        latitude=src.latitude_deg_1e8 * 1e-08,
        longitude=src.longitude_deg_1e8 * 1e-08,
        altitude=src.height_ellipsoid_mm * 0.001,
        position_covariance=position_covariance,
        position_covariance_type=3,
    )


def gps_fix_to_uavcan(src: NavSatFix, stats: ConversionStats) -> sam.sensor.GNSSFix_0_1 | None:
    """Mapping 'gps_fix', ROS -> UAVCAN.

    sensor_msgs/NavSatFix -> sam.sensor.GNSSFix.0.1
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('gps_fix.timestamp.microsecond')
        us = 0
    latitude_deg_1e8 = src.latitude / 1e-08
    if latitude_deg_1e8 != latitude_deg_1e8:  # NaN
        stats.reject_nan('gps_fix.latitude_deg_1e8')
        return None
    if latitude_deg_1e8 >= 68719476735.5:
        stats.saturate('gps_fix.latitude_deg_1e8')
        latitude_deg_1e8 = 68719476735
    elif latitude_deg_1e8 <= -68719476736.5:
        stats.saturate('gps_fix.latitude_deg_1e8')
        latitude_deg_1e8 = -68719476736
    else:
        latitude_deg_1e8 = round(latitude_deg_1e8)
    longitude_deg_1e8 = src.longitude / 1e-08
    if longitude_deg_1e8 != longitude_deg_1e8:  # NaN
        stats.reject_nan('gps_fix.longitude_deg_1e8')
        return None
    if longitude_deg_1e8 >= 68719476735.5:
        stats.saturate('gps_fix.longitude_deg_1e8')
        longitude_deg_1e8 = 68719476735
    elif longitude_deg_1e8 <= -68719476736.5:
        stats.saturate('gps_fix.longitude_deg_1e8')
        longitude_deg_1e8 = -68719476736
    else:
        longitude_deg_1e8 = round(longitude_deg_1e8)
    height_ellipsoid_mm = src.altitude / 0.001
    if height_ellipsoid_mm != height_ellipsoid_mm:  # NaN
        stats.reject_nan('gps_fix.height_ellipsoid_mm')
        return None
    if height_ellipsoid_mm >= 67108863.5:
        stats.saturate('gps_fix.height_ellipsoid_mm')
        height_ellipsoid_mm = 67108863
    elif height_ellipsoid_mm <= -67108864.5:
        stats.saturate('gps_fix.height_ellipsoid_mm')
        height_ellipsoid_mm = -67108864
    else:
        height_ellipsoid_mm = round(height_ellipsoid_mm)
    status = _GPS_FIX_STATUS_STATUS_TO_UAVCAN.get(src.status.status)
    if status is None:
        stats.reject('gps_fix.status')
        return None
    position_covariance = src.position_covariance.tolist()
    position_covariance = _support.clamp_floats(
        position_covariance, 65504.0, stats, 'gps_fix.position_covariance', False
    )
    if position_covariance is None:
        return None
    return _new_sam_sensor_GNSSFix_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        longitude_deg_1e8=longitude_deg_1e8,
        latitude_deg_1e8=latitude_deg_1e8,
        height_ellipsoid_mm=height_ellipsoid_mm,
        status=status,
        position_covariance=position_covariance,
    )


def pressure_to_ros(
    src: sam.sensor.StaticPressure_0_1, receive_ns: int, stats: ConversionStats
) -> FluidPressure | None:
    """Mapping 'pressure', UAVCAN -> ROS.

    sam.sensor.StaticPressure.0.1 -> sensor_msgs/FluidPressure
    """
    return _new_FluidPressure(
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='pressure_link',
        ),
        fluid_pressure=src.static_pressure,
        variance=src.static_pressure_variance,
    )


def pressure_to_uavcan(src: FluidPressure, stats: ConversionStats) -> sam.sensor.StaticPressure_0_1 | None:
    """Mapping 'pressure', ROS -> UAVCAN.

    sensor_msgs/FluidPressure -> sam.sensor.StaticPressure.0.1
    """
    static_pressure = src.fluid_pressure
    if 3.4028234663852886e+38 < static_pressure < _INF:
        stats.saturate('pressure.static_pressure')
        static_pressure = 3.4028234663852886e+38
    elif -_INF < static_pressure < -3.4028234663852886e+38:
        stats.saturate('pressure.static_pressure')
        static_pressure = -3.4028234663852886e+38
    static_pressure_variance = src.variance
    if static_pressure_variance > 65504.0:
        stats.saturate('pressure.static_pressure_variance')
        static_pressure_variance = 65504.0
    elif static_pressure_variance < -65504.0:
        stats.saturate('pressure.static_pressure_variance')
        static_pressure_variance = -65504.0
    return _new_sam_sensor_StaticPressure_0_1(
        static_pressure=static_pressure,
        static_pressure_variance=static_pressure_variance,
    )


def battery_state_to_ros(
    src: sam.power.BatteryInfo_0_1, receive_ns: int, stats: ConversionStats
) -> BatteryState | None:
    """Mapping 'battery_state', UAVCAN -> ROS.

    sam.power.BatteryInfo.0.1 -> sensor_msgs/BatteryState
    """
    power_supply_health = _BATTERY_STATE_POWER_SUPPLY_HEALTH_TO_ROS.get(src.state_of_health_pct, 1)
    return _new_BatteryState(
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='base_link',
        ),
        voltage=src.voltage,
        temperature=src.temperature - 273.15,
        current=src.current,
        charge=_NAN,
        capacity=_NAN,
        design_capacity=_NAN,
        percentage=src.state_of_charge_pct * 0.01,
        power_supply_health=power_supply_health,
        present=True,
    )


def battery_state_to_uavcan(src: BatteryState, stats: ConversionStats) -> sam.power.BatteryInfo_0_1 | None:
    """Mapping 'battery_state', ROS -> UAVCAN.

    sensor_msgs/BatteryState -> sam.power.BatteryInfo.0.1
    """
    voltage = src.voltage
    if voltage > 65504.0:
        stats.saturate('battery_state.voltage')
        voltage = 65504.0
    elif voltage < -65504.0:
        stats.saturate('battery_state.voltage')
        voltage = -65504.0
    current = src.current
    if current > 65504.0:
        stats.saturate('battery_state.current')
        current = 65504.0
    elif current < -65504.0:
        stats.saturate('battery_state.current')
        current = -65504.0
    temperature = src.temperature + 273.15
    if temperature > 65504.0:
        stats.saturate('battery_state.temperature')
        temperature = 65504.0
    elif temperature < -65504.0:
        stats.saturate('battery_state.temperature')
        temperature = -65504.0
    state_of_charge_pct = src.percentage / 0.01
    if state_of_charge_pct != state_of_charge_pct:  # NaN
        stats.reject_nan('battery_state.state_of_charge_pct')
        return None
    if state_of_charge_pct >= 127.5:
        stats.saturate('battery_state.state_of_charge_pct')
        state_of_charge_pct = 127
    elif state_of_charge_pct <= -0.5:
        stats.saturate('battery_state.state_of_charge_pct')
        state_of_charge_pct = 0
    else:
        state_of_charge_pct = round(state_of_charge_pct)
    state_of_health_pct = _BATTERY_STATE_POWER_SUPPLY_HEALTH_TO_UAVCAN.get(src.power_supply_health)
    if state_of_health_pct is None:
        stats.reject('battery_state.state_of_health_pct')
        return None
    return _new_sam_power_BatteryInfo_0_1(
        temperature=temperature,
        voltage=voltage,
        current=current,
        state_of_health_pct=state_of_health_pct,
        state_of_charge_pct=state_of_charge_pct,
    )


def altitude_to_ros(src: sam.sensor.Altitude_0_1, receive_ns: int, stats: ConversionStats) -> Range | None:
    """Mapping 'altitude', UAVCAN -> ROS.

    sam.sensor.Altitude.0.1 -> sensor_msgs/Range
    """
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('altitude.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    return _new_Range(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='altimeter_link'),
        radiation_type=0,
        field_of_view=0.1,
        min_range=0.3,
        max_range=100.0,
        range=src.altitude,
        variance=src.altitude_variance,
    )


def altitude_to_uavcan(src: Range, stats: ConversionStats) -> sam.sensor.Altitude_0_1 | None:
    """Mapping 'altitude', ROS -> UAVCAN.

    sensor_msgs/Range -> sam.sensor.Altitude.0.1
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('altitude.timestamp.microsecond')
        us = 0
    altitude_variance = src.variance
    if altitude_variance > 65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = 65504.0
    elif altitude_variance < -65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = -65504.0
    return _new_sam_sensor_Altitude_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        altitude=src.range,
        altitude_variance=altitude_variance,
    )


def battery_info_to_ros(
    src: sam.power.BatteryInfo_0_1, receive_ns: int, stats: ConversionStats
) -> BatteryInfo | None:
    """Mapping 'battery_info', UAVCAN -> ROS.

    sam.power.BatteryInfo.0.1 -> sam_msgs/BatteryInfo
    """
    return _new_BatteryInfo(
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='base_link',
        ),
        temperature=src.temperature,
        voltage=src.voltage,
        current=src.current,
        average_power_10sec=src.average_power_10sec,
        remaining_capacity_wh=src.remaining_capacity_wh,
        full_charge_capacity_wh=src.full_charge_capacity_wh,
        hours_to_full_charge=src.hours_to_full_charge,
        status_flags=src.status_flags,
        state_of_health_pct=src.state_of_health_pct,
        state_of_charge_pct=src.state_of_charge_pct,
        state_of_charge_pct_stdev=src.state_of_charge_pct_stdev,
        battery_id=src.battery_id,
        model_instance_id=src.model_instance_id,
        model_name=src.model_name.tolist(),
    )


def battery_info_to_uavcan(src: BatteryInfo, stats: ConversionStats) -> sam.power.BatteryInfo_0_1 | None:
    """Mapping 'battery_info', ROS -> UAVCAN.

    sam_msgs/BatteryInfo -> sam.power.BatteryInfo.0.1
    """
    temperature = src.temperature
    if temperature > 65504.0:
        stats.saturate('battery_info.temperature')
        temperature = 65504.0
    elif temperature < -65504.0:
        stats.saturate('battery_info.temperature')
        temperature = -65504.0
    voltage = src.voltage
    if voltage > 65504.0:
        stats.saturate('battery_info.voltage')
        voltage = 65504.0
    elif voltage < -65504.0:
        stats.saturate('battery_info.voltage')
        voltage = -65504.0
    current = src.current
    if current > 65504.0:
        stats.saturate('battery_info.current')
        current = 65504.0
    elif current < -65504.0:
        stats.saturate('battery_info.current')
        current = -65504.0
    average_power_10sec = src.average_power_10sec
    if average_power_10sec > 65504.0:
        stats.saturate('battery_info.average_power_10sec')
        average_power_10sec = 65504.0
    elif average_power_10sec < -65504.0:
        stats.saturate('battery_info.average_power_10sec')
        average_power_10sec = -65504.0
    remaining_capacity_wh = src.remaining_capacity_wh
    if remaining_capacity_wh > 65504.0:
        stats.saturate('battery_info.remaining_capacity_wh')
        remaining_capacity_wh = 65504.0
    elif remaining_capacity_wh < -65504.0:
        stats.saturate('battery_info.remaining_capacity_wh')
        remaining_capacity_wh = -65504.0
    full_charge_capacity_wh = src.full_charge_capacity_wh
    if full_charge_capacity_wh > 65504.0:
        stats.saturate('battery_info.full_charge_capacity_wh')
        full_charge_capacity_wh = 65504.0
    elif full_charge_capacity_wh < -65504.0:
        stats.saturate('battery_info.full_charge_capacity_wh')
        full_charge_capacity_wh = -65504.0
    hours_to_full_charge = src.hours_to_full_charge
    if hours_to_full_charge > 65504.0:
        stats.saturate('battery_info.hours_to_full_charge')
        hours_to_full_charge = 65504.0
    elif hours_to_full_charge < -65504.0:
        stats.saturate('battery_info.hours_to_full_charge')
        hours_to_full_charge = -65504.0
    status_flags = src.status_flags
    if status_flags > 2047:
        stats.saturate('battery_info.status_flags')
        status_flags = 2047
    state_of_health_pct = src.state_of_health_pct
    if state_of_health_pct > 127:
        stats.saturate('battery_info.state_of_health_pct')
        state_of_health_pct = 127
    state_of_charge_pct = src.state_of_charge_pct
    if state_of_charge_pct > 127:
        stats.saturate('battery_info.state_of_charge_pct')
        state_of_charge_pct = 127
    state_of_charge_pct_stdev = src.state_of_charge_pct_stdev
    if state_of_charge_pct_stdev > 127:
        stats.saturate('battery_info.state_of_charge_pct_stdev')
        state_of_charge_pct_stdev = 127
    model_name = src.model_name.tolist()
    return _new_sam_power_BatteryInfo_0_1(
        temperature=temperature,
        voltage=voltage,
        current=current,
        average_power_10sec=average_power_10sec,
        remaining_capacity_wh=remaining_capacity_wh,
        full_charge_capacity_wh=full_charge_capacity_wh,
        hours_to_full_charge=hours_to_full_charge,
        status_flags=status_flags,
        state_of_health_pct=state_of_health_pct,
        state_of_charge_pct=state_of_charge_pct,
        state_of_charge_pct_stdev=state_of_charge_pct_stdev,
        battery_id=src.battery_id,
        model_instance_id=src.model_instance_id,
        model_name=model_name,
    )


def thruster_1_rpm_to_ros(
    src: sam.actuator.ThrusterRPM_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterRPMs | None:
    """Mapping 'thruster_1_rpm', UAVCAN -> ROS.

    sam.actuator.ThrusterRPM.0.1 -> sam_msgs/ThrusterRPMs
    """
    return _new_ThrusterRPMs(
        thruster_1_rpm=src.rpm,
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def thruster_1_rpm_to_uavcan(
    src: ThrusterRPMs, stats: ConversionStats
) -> sam.actuator.ThrusterRPM_0_1 | None:
    """Mapping 'thruster_1_rpm', ROS -> UAVCAN.

    sam_msgs/ThrusterRPMs -> sam.actuator.ThrusterRPM.0.1
    """
    rpm = src.thruster_1_rpm
    if rpm > 131071:
        stats.saturate('thruster_1_rpm.rpm')
        rpm = 131071
    elif rpm < -131072:
        stats.saturate('thruster_1_rpm.rpm')
        rpm = -131072
    return _new_sam_actuator_ThrusterRPM_0_1(rpm=rpm)


def thruster_2_rpm_to_ros(
    src: sam.actuator.ThrusterRPM_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterRPMs | None:
    """Mapping 'thruster_2_rpm', UAVCAN -> ROS.

    sam.actuator.ThrusterRPM.0.1 -> sam_msgs/ThrusterRPMs
    """
    return _new_ThrusterRPMs(
        thruster_2_rpm=src.rpm,
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def thruster_2_rpm_to_uavcan(
    src: ThrusterRPMs, stats: ConversionStats
) -> sam.actuator.ThrusterRPM_0_1 | None:
    """Mapping 'thruster_2_rpm', ROS -> UAVCAN.

    sam_msgs/ThrusterRPMs -> sam.actuator.ThrusterRPM.0.1
    """
    rpm = src.thruster_2_rpm
    if rpm > 131071:
        stats.saturate('thruster_2_rpm.rpm')
        rpm = 131071
    elif rpm < -131072:
        stats.saturate('thruster_2_rpm.rpm')
        rpm = -131072
    return _new_sam_actuator_ThrusterRPM_0_1(rpm=rpm)


def thrust_vector_to_ros(
    src: sam.actuator.ThrustVector_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterAngles | None:
    """Mapping 'thrust_vector', UAVCAN -> ROS.

    sam.actuator.ThrustVector.0.1 -> sam_msgs/ThrusterAngles
    """
    return _new_ThrusterAngles(
        thruster_vertical_radians=src.vertical_radians,
        thruster_horizontal_radians=src.horizontal_radians,
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def thrust_vector_to_uavcan(
    src: ThrusterAngles, stats: ConversionStats
) -> sam.actuator.ThrustVector_0_1 | None:
    """Mapping 'thrust_vector', ROS -> UAVCAN.

    sam_msgs/ThrusterAngles -> sam.actuator.ThrustVector.0.1
    """
    vertical_radians = src.thruster_vertical_radians
    if vertical_radians != vertical_radians:  # NaN
        stats.reject_nan('thrust_vector.vertical_radians')
        return None
    if vertical_radians < -0.12:
        stats.saturate('thrust_vector.vertical_radians')
        vertical_radians = -0.12
    elif vertical_radians > 0.12:
        stats.saturate('thrust_vector.vertical_radians')
        vertical_radians = 0.12
    horizontal_radians = src.thruster_horizontal_radians
    if horizontal_radians != horizontal_radians:  # NaN
        stats.reject_nan('thrust_vector.horizontal_radians')
        return None
    if horizontal_radians < -0.12:
        stats.saturate('thrust_vector.horizontal_radians')
        horizontal_radians = -0.12
    elif horizontal_radians > 0.12:
        stats.saturate('thrust_vector.horizontal_radians')
        horizontal_radians = 0.12
    return _new_sam_actuator_ThrustVector_0_1(
        vertical_radians=vertical_radians,
        horizontal_radians=horizontal_radians,
    )


def ballast_to_ros(
    src: sam.actuator.BallastAngles_0_1, receive_ns: int, stats: ConversionStats
) -> BallastAngles | None:
    """Mapping 'ballast', UAVCAN -> ROS.

    sam.actuator.BallastAngles.0.1 -> sam_msgs/BallastAngles
    """
    return _new_BallastAngles(
        weight_1_offset_radians=src.weight_1_offset_radians,
        weight_2_offset_radians=src.weight_2_offset_radians,
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def ballast_to_uavcan(src: BallastAngles, stats: ConversionStats) -> sam.actuator.BallastAngles_0_1 | None:
    """Mapping 'ballast', ROS -> UAVCAN.

    sam_msgs/BallastAngles -> sam.actuator.BallastAngles.0.1
    """
    weight_1_offset_radians = src.weight_1_offset_radians
    if weight_1_offset_radians != weight_1_offset_radians:  # NaN
        stats.reject_nan('ballast.weight_1_offset_radians')
        return None
    if weight_1_offset_radians < -1.5708:
        stats.saturate('ballast.weight_1_offset_radians')
        weight_1_offset_radians = -1.5708
    elif weight_1_offset_radians > 1.5708:
        stats.saturate('ballast.weight_1_offset_radians')
        weight_1_offset_radians = 1.5708
    weight_2_offset_radians = src.weight_2_offset_radians
    if weight_2_offset_radians != weight_2_offset_radians:  # NaN
        stats.reject_nan('ballast.weight_2_offset_radians')
        return None
    if weight_2_offset_radians < -1.5708:
        stats.saturate('ballast.weight_2_offset_radians')
        weight_2_offset_radians = -1.5708
    elif weight_2_offset_radians > 1.5708:
        stats.saturate('ballast.weight_2_offset_radians')
        weight_2_offset_radians = 1.5708
    return _new_sam_actuator_BallastAngles_0_1(
        weight_1_offset_radians=weight_1_offset_radians,
        weight_2_offset_radians=weight_2_offset_radians,
    )


def longitudinal_weight_to_ros(
    src: sam.actuator.PercentCommand_0_1, receive_ns: int, stats: ConversionStats
) -> PercentStamped | None:
    """Mapping 'longitudinal_weight', UAVCAN -> ROS.

    sam.actuator.PercentCommand.0.1 -> sam_msgs/PercentStamped
    """
    return _new_PercentStamped(
        percent=src.percent,
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def longitudinal_weight_to_uavcan(
    src: PercentStamped, stats: ConversionStats
) -> sam.actuator.PercentCommand_0_1 | None:
    """Mapping 'longitudinal_weight', ROS -> UAVCAN.

    sam_msgs/PercentStamped -> sam.actuator.PercentCommand.0.1
    """
    percent = src.percent
    if percent != percent:  # NaN
        stats.reject_nan('longitudinal_weight.percent')
        return None
    if percent < 0.0:
        stats.saturate('longitudinal_weight.percent')
        percent = 0.0
    elif percent > 100.0:
        stats.saturate('longitudinal_weight.percent')
        percent = 100.0
    return _new_sam_actuator_PercentCommand_0_1(percent=percent)


def buoyancy_piston_to_ros(
    src: sam.actuator.PercentCommand_0_1, receive_ns: int, stats: ConversionStats
) -> PercentStamped | None:
    """Mapping 'buoyancy_piston', UAVCAN -> ROS.

    sam.actuator.PercentCommand.0.1 -> sam_msgs/PercentStamped
    """
    return _new_PercentStamped(
        percent=src.percent,
        header=_new_Header(
            stamp=_new_Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def buoyancy_piston_to_uavcan(
    src: PercentStamped, stats: ConversionStats
) -> sam.actuator.PercentCommand_0_1 | None:
    """Mapping 'buoyancy_piston', ROS -> UAVCAN.

    sam_msgs/PercentStamped -> sam.actuator.PercentCommand.0.1
    """
    percent = src.percent
    if percent != percent:  # NaN
        stats.reject_nan('buoyancy_piston.percent')
        return None
    if percent < 0.0:
        stats.saturate('buoyancy_piston.percent')
        percent = 0.0
    elif percent > 100.0:
        stats.saturate('buoyancy_piston.percent')
        percent = 100.0
    return _new_sam_actuator_PercentCommand_0_1(percent=percent)


def thruster_1_feedback_to_ros(
    src: sam.actuator.ThrusterFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterFeedback | None:
    """Mapping 'thruster_1_feedback', UAVCAN -> ROS.

    sam.actuator.ThrusterFeedback.0.1 -> sam_msgs/ThrusterFeedback
    """
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('thruster_1_feedback.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    return _new_ThrusterFeedback(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        rpm=src.rpm,
        current=src.current,
        temperature_c=src.temperature_c,
    )


def thruster_1_feedback_to_uavcan(
    src: ThrusterFeedback, stats: ConversionStats
) -> sam.actuator.ThrusterFeedback_0_1 | None:
    """Mapping 'thruster_1_feedback', ROS -> UAVCAN.

    sam_msgs/ThrusterFeedback -> sam.actuator.ThrusterFeedback.0.1
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('thruster_1_feedback.timestamp.microsecond')
        us = 0
    rpm = src.rpm
    if rpm > 131071:
        stats.saturate('thruster_1_feedback.rpm')
        rpm = 131071
    elif rpm < -131072:
        stats.saturate('thruster_1_feedback.rpm')
        rpm = -131072
    current = src.current
    if current > 65504.0:
        stats.saturate('thruster_1_feedback.current')
        current = 65504.0
    elif current < -65504.0:
        stats.saturate('thruster_1_feedback.current')
        current = -65504.0
    temperature_c = src.temperature_c
    if temperature_c > 127:
        stats.saturate('thruster_1_feedback.temperature_c')
        temperature_c = 127
    return _new_sam_actuator_ThrusterFeedback_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        rpm=rpm,
        current=current,
        temperature_c=temperature_c,
    )


def thruster_2_feedback_to_ros(
    src: sam.actuator.ThrusterFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterFeedback | None:
    """Mapping 'thruster_2_feedback', UAVCAN -> ROS.

    sam.actuator.ThrusterFeedback.0.1 -> sam_msgs/ThrusterFeedback
    """
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('thruster_2_feedback.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    return _new_ThrusterFeedback(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        rpm=src.rpm,
        current=src.current,
        temperature_c=src.temperature_c,
    )


def thruster_2_feedback_to_uavcan(
    src: ThrusterFeedback, stats: ConversionStats
) -> sam.actuator.ThrusterFeedback_0_1 | None:
    """Mapping 'thruster_2_feedback', ROS -> UAVCAN.

    sam_msgs/ThrusterFeedback -> sam.actuator.ThrusterFeedback.0.1
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('thruster_2_feedback.timestamp.microsecond')
        us = 0
    rpm = src.rpm
    if rpm > 131071:
        stats.saturate('thruster_2_feedback.rpm')
        rpm = 131071
    elif rpm < -131072:
        stats.saturate('thruster_2_feedback.rpm')
        rpm = -131072
    current = src.current
    if current > 65504.0:
        stats.saturate('thruster_2_feedback.current')
        current = 65504.0
    elif current < -65504.0:
        stats.saturate('thruster_2_feedback.current')
        current = -65504.0
    temperature_c = src.temperature_c
    if temperature_c > 127:
        stats.saturate('thruster_2_feedback.temperature_c')
        temperature_c = 127
    return _new_sam_actuator_ThrusterFeedback_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        rpm=rpm,
        current=current,
        temperature_c=temperature_c,
    )


def thrust_vector_feedback_to_ros(
    src: sam.actuator.ThrustVectorFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> ThrustVectorFeedback | None:
    """Mapping 'thrust_vector_feedback', UAVCAN -> ROS.

    sam.actuator.ThrustVectorFeedback.0.1 -> sam_msgs/ThrustVectorFeedback
    """
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('thrust_vector_feedback.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    return _new_ThrustVectorFeedback(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        vertical_mrad=src.vertical_mrad,
        horizontal_mrad=src.horizontal_mrad,
    )


def thrust_vector_feedback_to_uavcan(
    src: ThrustVectorFeedback, stats: ConversionStats
) -> sam.actuator.ThrustVectorFeedback_0_1 | None:
    """Mapping 'thrust_vector_feedback', ROS -> UAVCAN.

    sam_msgs/ThrustVectorFeedback -> sam.actuator.ThrustVectorFeedback.0.1
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('thrust_vector_feedback.timestamp.microsecond')
        us = 0
    vertical_mrad = src.vertical_mrad
    if vertical_mrad > 4095:
        stats.saturate('thrust_vector_feedback.vertical_mrad')
        vertical_mrad = 4095
    elif vertical_mrad < -4096:
        stats.saturate('thrust_vector_feedback.vertical_mrad')
        vertical_mrad = -4096
    horizontal_mrad = src.horizontal_mrad
    if horizontal_mrad > 4095:
        stats.saturate('thrust_vector_feedback.horizontal_mrad')
        horizontal_mrad = 4095
    elif horizontal_mrad < -4096:
        stats.saturate('thrust_vector_feedback.horizontal_mrad')
        horizontal_mrad = -4096
    return _new_sam_actuator_ThrustVectorFeedback_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        vertical_mrad=vertical_mrad,
        horizontal_mrad=horizontal_mrad,
    )


def longitudinal_weight_feedback_to_ros(
    src: sam.actuator.PositionFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> PositionFeedback | None:
    """Mapping 'longitudinal_weight_feedback', UAVCAN -> ROS.

    sam.actuator.PositionFeedback.0.1 -> sam_msgs/PositionFeedback
    """
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('longitudinal_weight_feedback.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    return _new_PositionFeedback(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        percent=src.percent,
        encoder_count=src.encoder_count,
    )


def longitudinal_weight_feedback_to_uavcan(
    src: PositionFeedback, stats: ConversionStats
) -> sam.actuator.PositionFeedback_0_1 | None:
    """Mapping 'longitudinal_weight_feedback', ROS -> UAVCAN.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback.0.1
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('longitudinal_weight_feedback.timestamp.microsecond')
        us = 0
    percent = src.percent
    if percent > 65504.0:
        stats.saturate('longitudinal_weight_feedback.percent')
        percent = 65504.0
    elif percent < -65504.0:
        stats.saturate('longitudinal_weight_feedback.percent')
        percent = -65504.0
    encoder_count = src.encoder_count
    if encoder_count > 16777215:
        stats.saturate('longitudinal_weight_feedback.encoder_count')
        encoder_count = 16777215
    return _new_sam_actuator_PositionFeedback_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        percent=percent,
        encoder_count=encoder_count,
    )


def buoyancy_piston_feedback_to_ros(
    src: sam.actuator.PositionFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> PositionFeedback | None:
    """Mapping 'buoyancy_piston_feedback', UAVCAN -> ROS.

    sam.actuator.PositionFeedback.0.1 -> sam_msgs/PositionFeedback
    """
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        sec = receive_ns // 1_000_000_000
        nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('buoyancy_piston_feedback.header.stamp')
        sec = 2147483647
        nanosec = 999_999_999
    else:
        sec = us // 1_000_000
        nanosec = us % 1_000_000 * 1000
    return _new_PositionFeedback(
        header=_new_Header(stamp=_new_Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        percent=src.percent,
        encoder_count=src.encoder_count,
    )


def buoyancy_piston_feedback_to_uavcan(
    src: PositionFeedback, stats: ConversionStats
) -> sam.actuator.PositionFeedback_0_1 | None:
    """Mapping 'buoyancy_piston_feedback', ROS -> UAVCAN.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback.0.1
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('buoyancy_piston_feedback.timestamp.microsecond')
        us = 0
    percent = src.percent
    if percent > 65504.0:
        stats.saturate('buoyancy_piston_feedback.percent')
        percent = 65504.0
    elif percent < -65504.0:
        stats.saturate('buoyancy_piston_feedback.percent')
        percent = -65504.0
    encoder_count = src.encoder_count
    if encoder_count > 16777215:
        stats.saturate('buoyancy_piston_feedback.encoder_count')
        encoder_count = 16777215
    return _new_sam_actuator_PositionFeedback_0_1(
        timestamp=_new_uavcan_time_SynchronizedTimestamp_1_0(microsecond=us),
        percent=percent,
        encoder_count=encoder_count,
    )


# mapping name -> (to_ros, to_uavcan)
CONVERTERS: dict[str, tuple[Callable[..., Any], Callable[..., Any]]] = {
    'imu': (imu_to_ros, imu_to_uavcan),
    'magnetic_field': (magnetic_field_to_ros, magnetic_field_to_uavcan),
    'gps_fix': (gps_fix_to_ros, gps_fix_to_uavcan),
    'pressure': (pressure_to_ros, pressure_to_uavcan),
    'battery_state': (battery_state_to_ros, battery_state_to_uavcan),
    'altitude': (altitude_to_ros, altitude_to_uavcan),
    'battery_info': (battery_info_to_ros, battery_info_to_uavcan),
    'thruster_1_rpm': (thruster_1_rpm_to_ros, thruster_1_rpm_to_uavcan),
    'thruster_2_rpm': (thruster_2_rpm_to_ros, thruster_2_rpm_to_uavcan),
    'thrust_vector': (thrust_vector_to_ros, thrust_vector_to_uavcan),
    'ballast': (ballast_to_ros, ballast_to_uavcan),
    'longitudinal_weight': (longitudinal_weight_to_ros, longitudinal_weight_to_uavcan),
    'buoyancy_piston': (buoyancy_piston_to_ros, buoyancy_piston_to_uavcan),
    'thruster_1_feedback': (thruster_1_feedback_to_ros, thruster_1_feedback_to_uavcan),
    'thruster_2_feedback': (thruster_2_feedback_to_ros, thruster_2_feedback_to_uavcan),
    'thrust_vector_feedback': (thrust_vector_feedback_to_ros, thrust_vector_feedback_to_uavcan),
    'longitudinal_weight_feedback': (
        longitudinal_weight_feedback_to_ros,
        longitudinal_weight_feedback_to_uavcan,
    ),
    'buoyancy_piston_feedback': (buoyancy_piston_feedback_to_ros, buoyancy_piston_feedback_to_uavcan),
}
