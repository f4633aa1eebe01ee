# Generated from interfaces.yaml by sam-codegen; do not edit.
"""Converters of the sam bridge for its DroneCAN mappings: UAVCAN v0 (dronecan objects) <-> ROS 2 messages.

Every DroneCAN mapping of the spec has both converters, whichever direction the bridge runs:

- ``<mapping>_to_ros(src, receive_ns, stats)``: a dronecan message object -> a new ROS message;
- ``<mapping>_to_uavcan(src, stats)``: a ROS message -> a new dronecan message object, to broadcast.

As in convert.py, they return None when the message must be dropped, and count in ``stats`` under
"<mapping>.<field>" every value saturated to fit and every message rejected (a value the `reject` policy
refuses, NaN into an integer, a table without the value; and, UAVCAN->ROS, a broadcast array without the
element or item this mapping reads, counted under its UAVCAN path: "thrust_vector.commands[actuator_id=1]").
A message is this mapping's when ``MATCHES[mapping](src)`` holds (its `select` values, and the elements it
reads are there): the bridge routes by it, beside the source node id. ROS->UAVCAN builds broadcast arrays with
exactly the elements the mapping names. A UAVCAN timestamp of 0 (unknown) becomes the receive time.

dronecan.load_dsdl() replaces every data type object, so types are looked up by name at each call. The
spec's own types must be loaded first: ``load_types(generated_dir)`` loads them and checks every type these
converters use against the definitions they were generated from (data type id and signature).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import dronecan
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Vector3
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

__all__ = [
    "CONVERTERS", "CUSTOM_DSDL_DIRS", "MATCHES", "TYPES", "ConversionStats", "check_types", "load_types",
]

ConversionStats = _support.ConversionStats
_NAN = float("nan")
_INF = float("inf")
# full name -> the data type loaded now; dronecan.load_dsdl() refills this same dict with new type objects.
_TYPENAMES: dict[str, Any] = dronecan.TYPENAMES

# gps_fix: status -> status.status
_GPS_FIX_STATUS_STATUS_TO_ROS: dict[int, int] = {0: -1, 1: -1, 2: 0, 3: 0}

# gps_fix: status.status -> status (first key per value)
_GPS_FIX_STATUS_STATUS_TO_UAVCAN: dict[int, int] = {-1: 0, 0: 2}

# Every message type of the DroneCAN mappings and devices: full name -> (data type id, data type signature).
TYPES: dict[str, tuple[int, int]] = {
    'sam.actuator.PositionFeedback': (20102, 0x4F9415770AF42BD6),
    'sam.actuator.ThrustVectorFeedback': (20101, 0x05FD0D1CC24F4B59),
    'sam.sensor.Altitude': (20103, 0x48A1C8047B5312FA),
    'uavcan.equipment.actuator.ArrayCommand': (1010, 0xD8A7486238EC3AF3),
    'uavcan.equipment.ahrs.MagneticFieldStrength': (1001, 0xE2A7D4A9460BC2F2),
    'uavcan.equipment.ahrs.RawIMU': (1003, 0x8280632C40E574B5),
    'uavcan.equipment.air_data.StaticPressure': (1028, 0xCDC7C43412BDC89A),
    'uavcan.equipment.esc.RPMCommand': (1031, 0xCE0F9F621CF7E70B),
    'uavcan.equipment.esc.Status': (1034, 0xA9AF28AEA2FBB254),
    'uavcan.equipment.gnss.Fix2': (1063, 0xCA41E7000F37435F),
    'uavcan.equipment.power.BatteryInfo': (1092, 0x249C26548A711966),
}
# The spec's own types, under the generated folder: what load_types() gives dronecan.load_dsdl().
CUSTOM_DSDL_DIRS: tuple[str, ...] = ('dsdl_v0/sam',)


def check_types() -> list[str]:
    """What differs between the types dronecan has loaded and those these converters were generated for."""
    problems = []
    for name, expected in TYPES.items():
        loaded = _TYPENAMES.get(name)
        if loaded is None:
            problems.append(f"{name} is not loaded")
            continue
        found = (loaded.default_dtid, loaded.get_data_type_signature())
        if found != expected:
            problems.append(f"{name} is loaded with data type id {found[0]} and signature 0x{found[1]:016X}, "
                            f"generated for {expected[0]} and 0x{expected[1]:016X}")
    return problems


def load_types(generated: str | Path) -> None:
    """Load the spec's own types from the generated folder into dronecan, then check all types (RuntimeError).

    Call it before any node registers handlers: dronecan.load_dsdl() replaces every type object.
    """
    if CUSTOM_DSDL_DIRS:
        dronecan.load_dsdl(*[str(Path(generated) / folder) for folder in CUSTOM_DSDL_DIRS])
    problems = check_types()
    if problems:
        raise RuntimeError("the DroneCAN types differ from the generated converters': " + "; ".join(problems))



def _item(items: Any, field: str, value: int) -> Any:
    """The first item of an array of composites whose `field` is `value`, or None."""
    for item in items:
        if getattr(item, field) == value:
            return item
    return None


def _always(src: Any) -> bool:
    return True


def imu_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> Imu | None:
    """Mapping 'imu', UAVCAN -> ROS.

    uavcan.equipment.ahrs.RawIMU -> sensor_msgs/Imu
    """
    rate_gyro_latest = list(src.rate_gyro_latest)
    accelerometer_latest = list(src.accelerometer_latest)
    us = src.timestamp.usec
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
    return Imu(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id='imu_link'),
        orientation_covariance=[-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        angular_velocity=Vector3(x=rate_gyro_latest[0], y=rate_gyro_latest[1], z=rate_gyro_latest[2]),
        linear_acceleration=Vector3(
            x=accelerometer_latest[0],
            y=accelerometer_latest[1],
            z=accelerometer_latest[2],
        ),
    )


def imu_to_uavcan(src: Imu, stats: ConversionStats) -> Any | None:
    """Mapping 'imu', ROS -> UAVCAN.

    sensor_msgs/Imu -> uavcan.equipment.ahrs.RawIMU
    """
    stamp = src.header.stamp
    angular_velocity = src.angular_velocity
    linear_acceleration = src.linear_acceleration
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('imu.timestamp.usec')
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
    return _TYPENAMES['uavcan.equipment.ahrs.RawIMU'](
        timestamp=_TYPENAMES['uavcan.Timestamp'](usec=us),
        rate_gyro_latest=[rate_gyro_latest_0, rate_gyro_latest_1, rate_gyro_latest_2],
        accelerometer_latest=[accelerometer_latest_0, accelerometer_latest_1, accelerometer_latest_2],
    )


def magnetic_field_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> MagneticField | None:
    """Mapping 'magnetic_field', UAVCAN -> ROS.

    uavcan.equipment.ahrs.MagneticFieldStrength -> sensor_msgs/MagneticField
    """
    magnetic_field_ga = list(src.magnetic_field_ga)
    magnetic_field_covariance = [x * 1e-08 for x in list(src.magnetic_field_covariance)]
    magnetic_field_covariance += [0.0] * (9 - len(magnetic_field_covariance))  # zero = unknown
    return MagneticField(
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='magnetometer_link',
        ),
        magnetic_field=Vector3(
            x=magnetic_field_ga[0] * 0.0001,
            y=magnetic_field_ga[1] * 0.0001,
            z=magnetic_field_ga[2] * 0.0001,
        ),
        magnetic_field_covariance=magnetic_field_covariance,
    )


def magnetic_field_to_uavcan(src: MagneticField, stats: ConversionStats) -> Any | None:
    """Mapping 'magnetic_field', ROS -> UAVCAN.

    sensor_msgs/MagneticField -> uavcan.equipment.ahrs.MagneticFieldStrength
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
    return _TYPENAMES['uavcan.equipment.ahrs.MagneticFieldStrength'](
        magnetic_field_ga=[magnetic_field_ga_0, magnetic_field_ga_1, magnetic_field_ga_2],
        magnetic_field_covariance=magnetic_field_covariance,
    )


def gps_fix_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> NavSatFix | None:
    """Mapping 'gps_fix', UAVCAN -> ROS.

    uavcan.equipment.gnss.Fix2 -> sensor_msgs/NavSatFix
    """
    us = src.timestamp.usec
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
    return NavSatFix(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id='gps_link'),
        status=NavSatStatus(status=status_status, service=1),
        latitude=src.latitude_deg_1e8 * 1e-08,
        longitude=src.longitude_deg_1e8 * 1e-08,
        altitude=src.height_ellipsoid_mm * 0.001,
        position_covariance_type=0,
    )


def gps_fix_to_uavcan(src: NavSatFix, stats: ConversionStats) -> Any | None:
    """Mapping 'gps_fix', ROS -> UAVCAN.

    sensor_msgs/NavSatFix -> uavcan.equipment.gnss.Fix2
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('gps_fix.timestamp.usec')
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
    return _TYPENAMES['uavcan.equipment.gnss.Fix2'](
        timestamp=_TYPENAMES['uavcan.Timestamp'](usec=us),
        longitude_deg_1e8=longitude_deg_1e8,
        latitude_deg_1e8=latitude_deg_1e8,
        height_ellipsoid_mm=height_ellipsoid_mm,
        status=status,
    )


def pressure_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> FluidPressure | None:
    """Mapping 'pressure', UAVCAN -> ROS.

    uavcan.equipment.air_data.StaticPressure -> sensor_msgs/FluidPressure
    """
    return FluidPressure(
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='pressure_link',
        ),
        fluid_pressure=src.static_pressure,
        variance=src.static_pressure_variance,
    )


def pressure_to_uavcan(src: FluidPressure, stats: ConversionStats) -> Any | None:
    """Mapping 'pressure', ROS -> UAVCAN.

    sensor_msgs/FluidPressure -> uavcan.equipment.air_data.StaticPressure
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
    return _TYPENAMES['uavcan.equipment.air_data.StaticPressure'](
        static_pressure=static_pressure,
        static_pressure_variance=static_pressure_variance,
    )


def battery_state_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> BatteryState | None:
    """Mapping 'battery_state', UAVCAN -> ROS.

    uavcan.equipment.power.BatteryInfo -> sensor_msgs/BatteryState
    """
    return BatteryState(
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='base_link',
        ),
        voltage=src.voltage,
        temperature=src.temperature - 273.15,
        current=src.current,
        charge=_NAN,
        capacity=_NAN,
        design_capacity=_NAN,
        percentage=src.state_of_charge_pct * 0.01,
        present=True,
    )


def battery_state_to_uavcan(src: BatteryState, stats: ConversionStats) -> Any | None:
    """Mapping 'battery_state', ROS -> UAVCAN.

    sensor_msgs/BatteryState -> uavcan.equipment.power.BatteryInfo
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
    return _TYPENAMES['uavcan.equipment.power.BatteryInfo'](
        temperature=temperature,
        voltage=voltage,
        current=current,
        state_of_charge_pct=state_of_charge_pct,
    )


def battery_info_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> BatteryInfo | None:
    """Mapping 'battery_info', UAVCAN -> ROS.

    uavcan.equipment.power.BatteryInfo -> sam_msgs/BatteryInfo
    """
    return BatteryInfo(
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
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
        model_name=list(src.model_name),
    )


def battery_info_to_uavcan(src: BatteryInfo, stats: ConversionStats) -> Any | None:
    """Mapping 'battery_info', ROS -> UAVCAN.

    sam_msgs/BatteryInfo -> uavcan.equipment.power.BatteryInfo
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
    return _TYPENAMES['uavcan.equipment.power.BatteryInfo'](
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


def altitude_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> Range | None:
    """Mapping 'altitude', UAVCAN -> ROS.

    sam.sensor.Altitude -> sensor_msgs/Range
    """
    us = src.timestamp.usec
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
    return Range(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id='altimeter_link'),
        radiation_type=0,
        field_of_view=0.1,
        min_range=0.3,
        max_range=100.0,
        range=src.altitude,
        variance=src.altitude_variance,
    )


def altitude_to_uavcan(src: Range, stats: ConversionStats) -> Any | None:
    """Mapping 'altitude', ROS -> UAVCAN.

    sensor_msgs/Range -> sam.sensor.Altitude
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('altitude.timestamp.usec')
        us = 0
    altitude_variance = src.variance
    if altitude_variance > 65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = 65504.0
    elif altitude_variance < -65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = -65504.0
    return _TYPENAMES['sam.sensor.Altitude'](
        timestamp=_TYPENAMES['uavcan.Timestamp'](usec=us),
        altitude=src.range,
        altitude_variance=altitude_variance,
    )


def thruster_rpms_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> ThrusterRPMs | None:
    """Mapping 'thruster_rpms', UAVCAN -> ROS.

    uavcan.equipment.esc.RPMCommand -> sam_msgs/ThrusterRPMs
    """
    rpm = list(src.rpm)
    if len(rpm) < 2:  # the element this mapping reads is missing
        stats.reject('thruster_rpms.rpm[1]')
        return None
    return ThrusterRPMs(
        thruster_1_rpm=rpm[0],
        thruster_2_rpm=rpm[1],
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def thruster_rpms_to_uavcan(src: ThrusterRPMs, stats: ConversionStats) -> Any | None:
    """Mapping 'thruster_rpms', ROS -> UAVCAN.

    sam_msgs/ThrusterRPMs -> uavcan.equipment.esc.RPMCommand
    """
    rpm_0 = src.thruster_1_rpm
    if rpm_0 > 131071:
        stats.saturate('thruster_rpms.rpm[0]')
        rpm_0 = 131071
    elif rpm_0 < -131072:
        stats.saturate('thruster_rpms.rpm[0]')
        rpm_0 = -131072
    rpm_1 = src.thruster_2_rpm
    if rpm_1 > 131071:
        stats.saturate('thruster_rpms.rpm[1]')
        rpm_1 = 131071
    elif rpm_1 < -131072:
        stats.saturate('thruster_rpms.rpm[1]')
        rpm_1 = -131072
    return _TYPENAMES['uavcan.equipment.esc.RPMCommand'](rpm=[rpm_0, rpm_1])


def thrust_vector_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> ThrusterAngles | None:
    """Mapping 'thrust_vector', UAVCAN -> ROS.

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/ThrusterAngles
    """
    commands_actuator_id_0 = _item(src.commands, 'actuator_id', 0)
    if commands_actuator_id_0 is None:  # no item for this mapping
        stats.reject('thrust_vector.commands[actuator_id=0]')
        return None
    commands_actuator_id_1 = _item(src.commands, 'actuator_id', 1)
    if commands_actuator_id_1 is None:  # no item for this mapping
        stats.reject('thrust_vector.commands[actuator_id=1]')
        return None
    return ThrusterAngles(
        thruster_vertical_radians=commands_actuator_id_0.command_value,
        thruster_horizontal_radians=commands_actuator_id_1.command_value,
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def thrust_vector_to_uavcan(src: ThrusterAngles, stats: ConversionStats) -> Any | None:
    """Mapping 'thrust_vector', ROS -> UAVCAN.

    sam_msgs/ThrusterAngles -> uavcan.equipment.actuator.ArrayCommand
    """
    commands_actuator_id_0_command_value = src.thruster_vertical_radians
    if commands_actuator_id_0_command_value != commands_actuator_id_0_command_value:  # NaN
        stats.reject_nan('thrust_vector.commands[actuator_id=0].command_value')
        return None
    if commands_actuator_id_0_command_value < -0.12:
        stats.saturate('thrust_vector.commands[actuator_id=0].command_value')
        commands_actuator_id_0_command_value = -0.12
    elif commands_actuator_id_0_command_value > 0.12:
        stats.saturate('thrust_vector.commands[actuator_id=0].command_value')
        commands_actuator_id_0_command_value = 0.12
    commands_actuator_id_1_command_value = src.thruster_horizontal_radians
    if commands_actuator_id_1_command_value != commands_actuator_id_1_command_value:  # NaN
        stats.reject_nan('thrust_vector.commands[actuator_id=1].command_value')
        return None
    if commands_actuator_id_1_command_value < -0.12:
        stats.saturate('thrust_vector.commands[actuator_id=1].command_value')
        commands_actuator_id_1_command_value = -0.12
    elif commands_actuator_id_1_command_value > 0.12:
        stats.saturate('thrust_vector.commands[actuator_id=1].command_value')
        commands_actuator_id_1_command_value = 0.12
    return _TYPENAMES['uavcan.equipment.actuator.ArrayCommand'](
        commands=[
            _TYPENAMES['uavcan.equipment.actuator.Command'](
                actuator_id=0,
                command_type=1,
                command_value=commands_actuator_id_0_command_value,
            ),
            _TYPENAMES['uavcan.equipment.actuator.Command'](
                actuator_id=1,
                command_type=1,
                command_value=commands_actuator_id_1_command_value,
            ),
        ],
    )


def ballast_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> BallastAngles | None:
    """Mapping 'ballast', UAVCAN -> ROS.

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/BallastAngles
    """
    commands_actuator_id_2 = _item(src.commands, 'actuator_id', 2)
    if commands_actuator_id_2 is None:  # no item for this mapping
        stats.reject('ballast.commands[actuator_id=2]')
        return None
    commands_actuator_id_3 = _item(src.commands, 'actuator_id', 3)
    if commands_actuator_id_3 is None:  # no item for this mapping
        stats.reject('ballast.commands[actuator_id=3]')
        return None
    return BallastAngles(
        weight_1_offset_radians=commands_actuator_id_2.command_value,
        weight_2_offset_radians=commands_actuator_id_3.command_value,
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def ballast_to_uavcan(src: BallastAngles, stats: ConversionStats) -> Any | None:
    """Mapping 'ballast', ROS -> UAVCAN.

    sam_msgs/BallastAngles -> uavcan.equipment.actuator.ArrayCommand
    """
    commands_actuator_id_2_command_value = src.weight_1_offset_radians
    if commands_actuator_id_2_command_value != commands_actuator_id_2_command_value:  # NaN
        stats.reject_nan('ballast.commands[actuator_id=2].command_value')
        return None
    if commands_actuator_id_2_command_value < -1.5708:
        stats.saturate('ballast.commands[actuator_id=2].command_value')
        commands_actuator_id_2_command_value = -1.5708
    elif commands_actuator_id_2_command_value > 1.5708:
        stats.saturate('ballast.commands[actuator_id=2].command_value')
        commands_actuator_id_2_command_value = 1.5708
    commands_actuator_id_3_command_value = src.weight_2_offset_radians
    if commands_actuator_id_3_command_value != commands_actuator_id_3_command_value:  # NaN
        stats.reject_nan('ballast.commands[actuator_id=3].command_value')
        return None
    if commands_actuator_id_3_command_value < -1.5708:
        stats.saturate('ballast.commands[actuator_id=3].command_value')
        commands_actuator_id_3_command_value = -1.5708
    elif commands_actuator_id_3_command_value > 1.5708:
        stats.saturate('ballast.commands[actuator_id=3].command_value')
        commands_actuator_id_3_command_value = 1.5708
    return _TYPENAMES['uavcan.equipment.actuator.ArrayCommand'](
        commands=[
            _TYPENAMES['uavcan.equipment.actuator.Command'](
                actuator_id=2,
                command_type=1,
                command_value=commands_actuator_id_2_command_value,
            ),
            _TYPENAMES['uavcan.equipment.actuator.Command'](
                actuator_id=3,
                command_type=1,
                command_value=commands_actuator_id_3_command_value,
            ),
        ],
    )


def longitudinal_weight_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> PercentStamped | None:
    """Mapping 'longitudinal_weight', UAVCAN -> ROS.

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/PercentStamped
    """
    commands_actuator_id_4 = _item(src.commands, 'actuator_id', 4)
    if commands_actuator_id_4 is None:  # no item for this mapping
        stats.reject('longitudinal_weight.commands[actuator_id=4]')
        return None
    return PercentStamped(
        percent=commands_actuator_id_4.command_value * 100.0,
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def longitudinal_weight_to_uavcan(src: PercentStamped, stats: ConversionStats) -> Any | None:
    """Mapping 'longitudinal_weight', ROS -> UAVCAN.

    sam_msgs/PercentStamped -> uavcan.equipment.actuator.ArrayCommand
    """
    commands_actuator_id_4_command_value = src.percent
    if commands_actuator_id_4_command_value != commands_actuator_id_4_command_value:  # NaN
        stats.reject_nan('longitudinal_weight.commands[actuator_id=4].command_value')
        return None
    if commands_actuator_id_4_command_value < 0.0:
        stats.saturate('longitudinal_weight.commands[actuator_id=4].command_value')
        commands_actuator_id_4_command_value = 0.0
    elif commands_actuator_id_4_command_value > 100.0:
        stats.saturate('longitudinal_weight.commands[actuator_id=4].command_value')
        commands_actuator_id_4_command_value = 100.0
    commands_actuator_id_4_command_value = commands_actuator_id_4_command_value / 100.0
    if commands_actuator_id_4_command_value > 65504.0:
        stats.saturate('longitudinal_weight.commands[actuator_id=4].command_value')
        commands_actuator_id_4_command_value = 65504.0
    elif commands_actuator_id_4_command_value < -65504.0:
        stats.saturate('longitudinal_weight.commands[actuator_id=4].command_value')
        commands_actuator_id_4_command_value = -65504.0
    return _TYPENAMES['uavcan.equipment.actuator.ArrayCommand'](
        commands=[
            _TYPENAMES['uavcan.equipment.actuator.Command'](
                actuator_id=4,
                command_type=0,
                command_value=commands_actuator_id_4_command_value,
            ),
        ],
    )


def buoyancy_piston_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> PercentStamped | None:
    """Mapping 'buoyancy_piston', UAVCAN -> ROS.

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/PercentStamped
    """
    commands_actuator_id_5 = _item(src.commands, 'actuator_id', 5)
    if commands_actuator_id_5 is None:  # no item for this mapping
        stats.reject('buoyancy_piston.commands[actuator_id=5]')
        return None
    return PercentStamped(
        percent=commands_actuator_id_5.command_value * 100.0,
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
        ),
    )


def buoyancy_piston_to_uavcan(src: PercentStamped, stats: ConversionStats) -> Any | None:
    """Mapping 'buoyancy_piston', ROS -> UAVCAN.

    sam_msgs/PercentStamped -> uavcan.equipment.actuator.ArrayCommand
    """
    commands_actuator_id_5_command_value = src.percent
    if commands_actuator_id_5_command_value != commands_actuator_id_5_command_value:  # NaN
        stats.reject_nan('buoyancy_piston.commands[actuator_id=5].command_value')
        return None
    if commands_actuator_id_5_command_value < 0.0:
        stats.saturate('buoyancy_piston.commands[actuator_id=5].command_value')
        commands_actuator_id_5_command_value = 0.0
    elif commands_actuator_id_5_command_value > 100.0:
        stats.saturate('buoyancy_piston.commands[actuator_id=5].command_value')
        commands_actuator_id_5_command_value = 100.0
    commands_actuator_id_5_command_value = commands_actuator_id_5_command_value / 100.0
    if commands_actuator_id_5_command_value > 65504.0:
        stats.saturate('buoyancy_piston.commands[actuator_id=5].command_value')
        commands_actuator_id_5_command_value = 65504.0
    elif commands_actuator_id_5_command_value < -65504.0:
        stats.saturate('buoyancy_piston.commands[actuator_id=5].command_value')
        commands_actuator_id_5_command_value = -65504.0
    return _TYPENAMES['uavcan.equipment.actuator.ArrayCommand'](
        commands=[
            _TYPENAMES['uavcan.equipment.actuator.Command'](
                actuator_id=5,
                command_type=0,
                command_value=commands_actuator_id_5_command_value,
            ),
        ],
    )


def thruster_1_feedback_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> ThrusterFeedback | None:
    """Mapping 'thruster_1_feedback', UAVCAN -> ROS.

    uavcan.equipment.esc.Status -> sam_msgs/ThrusterFeedback
    """
    temperature_c = src.temperature - 273.15
    if temperature_c != temperature_c:  # NaN
        stats.reject_nan('thruster_1_feedback.temperature_c')
        return None
    if temperature_c >= 255.5:
        stats.saturate('thruster_1_feedback.temperature_c')
        temperature_c = 255
    elif temperature_c <= -0.5:
        stats.saturate('thruster_1_feedback.temperature_c')
        temperature_c = 0
    else:
        temperature_c = round(temperature_c)
    return ThrusterFeedback(
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='base_link',
        ),
        rpm=src.rpm,
        current=src.current,
        temperature_c=temperature_c,
    )


def thruster_1_feedback_to_uavcan(src: ThrusterFeedback, stats: ConversionStats) -> Any | None:
    """Mapping 'thruster_1_feedback', ROS -> UAVCAN.

    sam_msgs/ThrusterFeedback -> uavcan.equipment.esc.Status
    """
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
    temperature = src.temperature_c + 273.15
    if temperature > 65504.0:
        stats.saturate('thruster_1_feedback.temperature')
        temperature = 65504.0
    elif temperature < -65504.0:
        stats.saturate('thruster_1_feedback.temperature')
        temperature = -65504.0
    return _TYPENAMES['uavcan.equipment.esc.Status'](
        current=current,
        temperature=temperature,
        rpm=rpm,
        esc_index=0,
    )


def thruster_2_feedback_to_ros(src: Any, receive_ns: int, stats: ConversionStats) -> ThrusterFeedback | None:
    """Mapping 'thruster_2_feedback', UAVCAN -> ROS.

    uavcan.equipment.esc.Status -> sam_msgs/ThrusterFeedback
    """
    temperature_c = src.temperature - 273.15
    if temperature_c != temperature_c:  # NaN
        stats.reject_nan('thruster_2_feedback.temperature_c')
        return None
    if temperature_c >= 255.5:
        stats.saturate('thruster_2_feedback.temperature_c')
        temperature_c = 255
    elif temperature_c <= -0.5:
        stats.saturate('thruster_2_feedback.temperature_c')
        temperature_c = 0
    else:
        temperature_c = round(temperature_c)
    return ThrusterFeedback(
        header=Header(
            stamp=Time(sec=receive_ns // 1_000_000_000, nanosec=receive_ns % 1_000_000_000),
            frame_id='base_link',
        ),
        rpm=src.rpm,
        current=src.current,
        temperature_c=temperature_c,
    )


def thruster_2_feedback_to_uavcan(src: ThrusterFeedback, stats: ConversionStats) -> Any | None:
    """Mapping 'thruster_2_feedback', ROS -> UAVCAN.

    sam_msgs/ThrusterFeedback -> uavcan.equipment.esc.Status
    """
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
    temperature = src.temperature_c + 273.15
    if temperature > 65504.0:
        stats.saturate('thruster_2_feedback.temperature')
        temperature = 65504.0
    elif temperature < -65504.0:
        stats.saturate('thruster_2_feedback.temperature')
        temperature = -65504.0
    return _TYPENAMES['uavcan.equipment.esc.Status'](
        current=current,
        temperature=temperature,
        rpm=rpm,
        esc_index=1,
    )


def thrust_vector_feedback_to_ros(
    src: Any, receive_ns: int, stats: ConversionStats
) -> ThrustVectorFeedback | None:
    """Mapping 'thrust_vector_feedback', UAVCAN -> ROS.

    sam.actuator.ThrustVectorFeedback -> sam_msgs/ThrustVectorFeedback
    """
    us = src.timestamp.usec
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
    return ThrustVectorFeedback(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        vertical_mrad=src.vertical_mrad,
        horizontal_mrad=src.horizontal_mrad,
    )


def thrust_vector_feedback_to_uavcan(src: ThrustVectorFeedback, stats: ConversionStats) -> Any | None:
    """Mapping 'thrust_vector_feedback', ROS -> UAVCAN.

    sam_msgs/ThrustVectorFeedback -> sam.actuator.ThrustVectorFeedback
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('thrust_vector_feedback.timestamp.usec')
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
    return _TYPENAMES['sam.actuator.ThrustVectorFeedback'](
        timestamp=_TYPENAMES['uavcan.Timestamp'](usec=us),
        vertical_mrad=vertical_mrad,
        horizontal_mrad=horizontal_mrad,
    )


def longitudinal_weight_feedback_to_ros(
    src: Any, receive_ns: int, stats: ConversionStats
) -> PositionFeedback | None:
    """Mapping 'longitudinal_weight_feedback', UAVCAN -> ROS.

    sam.actuator.PositionFeedback -> sam_msgs/PositionFeedback
    """
    us = src.timestamp.usec
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
    return PositionFeedback(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        percent=src.percent,
        encoder_count=src.encoder_count,
    )


def longitudinal_weight_feedback_to_uavcan(src: PositionFeedback, stats: ConversionStats) -> Any | None:
    """Mapping 'longitudinal_weight_feedback', ROS -> UAVCAN.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('longitudinal_weight_feedback.timestamp.usec')
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
    return _TYPENAMES['sam.actuator.PositionFeedback'](
        timestamp=_TYPENAMES['uavcan.Timestamp'](usec=us),
        percent=percent,
        encoder_count=encoder_count,
    )


def buoyancy_piston_feedback_to_ros(
    src: Any, receive_ns: int, stats: ConversionStats
) -> PositionFeedback | None:
    """Mapping 'buoyancy_piston_feedback', UAVCAN -> ROS.

    sam.actuator.PositionFeedback -> sam_msgs/PositionFeedback
    """
    us = src.timestamp.usec
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
    return PositionFeedback(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id='base_link'),
        percent=src.percent,
        encoder_count=src.encoder_count,
    )


def buoyancy_piston_feedback_to_uavcan(src: PositionFeedback, stats: ConversionStats) -> Any | None:
    """Mapping 'buoyancy_piston_feedback', ROS -> UAVCAN.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback
    """
    stamp = src.header.stamp
    us = stamp.sec * 1_000_000 + stamp.nanosec // 1000
    if us < 0:
        stats.saturate('buoyancy_piston_feedback.timestamp.usec')
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
    return _TYPENAMES['sam.actuator.PositionFeedback'](
        timestamp=_TYPENAMES['uavcan.Timestamp'](usec=us),
        percent=percent,
        encoder_count=encoder_count,
    )


def _matches_thruster_rpms(src: Any) -> bool:
    return len(src.rpm) > 1


def _matches_thrust_vector(src: Any) -> bool:
    return (
        _item(src.commands, 'actuator_id', 0) is not None
        and _item(src.commands, 'actuator_id', 1) is not None
    )


def _matches_ballast(src: Any) -> bool:
    return (
        _item(src.commands, 'actuator_id', 2) is not None
        and _item(src.commands, 'actuator_id', 3) is not None
    )


def _matches_longitudinal_weight(src: Any) -> bool:
    return _item(src.commands, 'actuator_id', 4) is not None


def _matches_buoyancy_piston(src: Any) -> bool:
    return _item(src.commands, 'actuator_id', 5) is not None


def _matches_thruster_1_feedback(src: Any) -> bool:
    return src.esc_index == 0


def _matches_thruster_2_feedback(src: Any) -> bool:
    return src.esc_index == 1


# mapping name -> whether a received message is the mapping's
MATCHES: dict[str, Callable[[Any], bool]] = {
    'imu': _always,
    'magnetic_field': _always,
    'gps_fix': _always,
    'pressure': _always,
    'battery_state': _always,
    'battery_info': _always,
    'altitude': _always,
    'thruster_rpms': _matches_thruster_rpms,
    'thrust_vector': _matches_thrust_vector,
    'ballast': _matches_ballast,
    'longitudinal_weight': _matches_longitudinal_weight,
    'buoyancy_piston': _matches_buoyancy_piston,
    'thruster_1_feedback': _matches_thruster_1_feedback,
    'thruster_2_feedback': _matches_thruster_2_feedback,
    'thrust_vector_feedback': _always,
    'longitudinal_weight_feedback': _always,
    'buoyancy_piston_feedback': _always,
}

# mapping name -> (to_ros, to_uavcan)
CONVERTERS: dict[str, tuple[Callable[..., Any], Callable[..., Any]]] = {
    'imu': (imu_to_ros, imu_to_uavcan),
    'magnetic_field': (magnetic_field_to_ros, magnetic_field_to_uavcan),
    'gps_fix': (gps_fix_to_ros, gps_fix_to_uavcan),
    'pressure': (pressure_to_ros, pressure_to_uavcan),
    'battery_state': (battery_state_to_ros, battery_state_to_uavcan),
    'battery_info': (battery_info_to_ros, battery_info_to_uavcan),
    'altitude': (altitude_to_ros, altitude_to_uavcan),
    'thruster_rpms': (thruster_rpms_to_ros, thruster_rpms_to_uavcan),
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
