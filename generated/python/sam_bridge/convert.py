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
from typing import Any

import sam.actuator
import sam.power
import sam.sensor
import uavcan.time
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
from sensor_msgs.msg import BatteryState, FluidPressure, Imu, MagneticField, NavSatFix

__all__ = ["CONVERTERS", "ConversionStats"]

_NAN = float("nan")
_INF = float("inf")

# gps_fix: status -> status.status
_GPS_FIX_STATUS_STATUS_TO_ROS: dict[int, int] = {0: -1, 1: -1, 2: 0, 3: 0}

# gps_fix: status.status -> status (first key per value)
_GPS_FIX_STATUS_STATUS_TO_UAVCAN: dict[int, int] = {-1: 0, 0: 2}


class ConversionStats:
    """Counts, per "<mapping>.<field>", the values that were saturated and the messages that were rejected."""

    __slots__ = ("rejected", "saturated")

    def __init__(self) -> None:
        self.saturated: dict[str, int] = {}
        self.rejected: dict[str, int] = {}

    def saturate(self, key: str) -> None:
        self.saturated[key] = self.saturated.get(key, 0) + 1

    def reject(self, key: str) -> None:
        self.rejected[key] = self.rejected.get(key, 0) + 1


def _clamp_floats(
    values: list[float], bound: float, stats: ConversionStats, key: str, reject: bool
) -> list[float] | None:
    """Saturate the elements beyond +-bound (infinities too) into it, or reject; NaN passes."""
    for x in values:
        if x > bound or x < -bound:
            break
    else:
        return values
    if reject:
        stats.reject(key)
        return None
    stats.saturate(key)
    return [bound if x > bound else -bound if x < -bound else x for x in values]


def _clamp_finite_floats(
    values: list[float], bound: float, stats: ConversionStats, key: str, reject: bool
) -> list[float] | None:
    """Saturate the finite elements beyond +-bound into it, or reject; infinities and NaN pass."""
    for x in values:
        if bound < x < _INF or -_INF < x < -bound:
            break
    else:
        return values
    if reject:
        stats.reject(key)
        return None
    stats.saturate(key)
    return [bound if bound < x < _INF else -bound if -_INF < x < -bound else x for x in values]


def _clamp_ints(
    values: list[int], lo: int, hi: int, stats: ConversionStats, key: str, reject: bool
) -> list[int] | None:
    """Saturate integer elements into [lo, hi], or reject."""
    if values and (max(values) > hi or min(values) < lo):
        if reject:
            stats.reject(key)
            return None
        stats.saturate(key)
        return [hi if x > hi else lo if x < lo else x for x in values]
    return values


def _round_ints(
    values: list[float], lo: int, hi: int, stats: ConversionStats, key: str, reject: bool
) -> list[int] | None:
    """Round float elements half to even into [lo, hi], saturating (or rejecting) beyond; NaN rejects."""
    out = []
    saturated = False
    for x in values:
        if x != x:
            stats.reject(key)
            return None
        if x >= hi + 0.5:
            out.append(hi)
            saturated = True
        elif x <= lo - 0.5:
            out.append(lo)
            saturated = True
        else:
            out.append(round(x))
    if saturated:
        if reject:
            stats.reject(key)
            return None
        stats.saturate(key)
    return out


def imu_to_ros(src: sam.sensor.RawIMU_0_1, receive_ns: int, stats: ConversionStats) -> Imu | None:
    """Mapping 'imu', UAVCAN -> ROS.

    sam.sensor.RawIMU.0.1 -> sensor_msgs/Imu
    """
    msg = Imu()
    angular_velocity = msg.angular_velocity
    linear_acceleration = msg.linear_acceleration
    rate_gyro_latest = src.rate_gyro_latest.tolist()
    accelerometer_latest = src.accelerometer_latest.tolist()
    msg.header.frame_id = 'imu_link'
    stamp = msg.header.stamp
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        stamp.sec = receive_ns // 1_000_000_000
        stamp.nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('imu.header.stamp')
        stamp.sec = 2147483647
        stamp.nanosec = 999_999_999
    else:
        stamp.sec = us // 1_000_000
        stamp.nanosec = us % 1_000_000 * 1000
    angular_velocity.x = rate_gyro_latest[0]
    angular_velocity.y = rate_gyro_latest[1]
    angular_velocity.z = rate_gyro_latest[2]
    linear_acceleration.x = accelerometer_latest[0]
    linear_acceleration.y = accelerometer_latest[1]
    linear_acceleration.z = accelerometer_latest[2]
    msg.orientation_covariance[0] = -1.0
    return msg


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
    return sam.sensor.RawIMU_0_1(
        timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=us),
        rate_gyro_latest=[rate_gyro_latest_0, rate_gyro_latest_1, rate_gyro_latest_2],
        accelerometer_latest=[accelerometer_latest_0, accelerometer_latest_1, accelerometer_latest_2],
    )


def magnetic_field_to_ros(
    src: sam.sensor.MagneticFieldStrength_0_1, receive_ns: int, stats: ConversionStats
) -> MagneticField | None:
    """Mapping 'magnetic_field', UAVCAN -> ROS.

    sam.sensor.MagneticFieldStrength.0.1 -> sensor_msgs/MagneticField
    """
    msg = MagneticField()
    magnetic_field = msg.magnetic_field
    magnetic_field_ga = src.magnetic_field_ga.tolist()
    msg.header.frame_id = 'magnetometer_link'
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    magnetic_field.x = magnetic_field_ga[0] * 0.0001
    magnetic_field.y = magnetic_field_ga[1] * 0.0001
    magnetic_field.z = magnetic_field_ga[2] * 0.0001
    magnetic_field_covariance = [x * 1e-08 for x in src.magnetic_field_covariance.tolist()]
    magnetic_field_covariance += [0.0] * (9 - len(magnetic_field_covariance))  # zero = unknown
    msg.magnetic_field_covariance = magnetic_field_covariance
    return msg


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
    magnetic_field_covariance = _clamp_floats(
        magnetic_field_covariance, 65504.0, stats, 'magnetic_field.magnetic_field_covariance', False
    )
    if magnetic_field_covariance is None:
        return None
    return sam.sensor.MagneticFieldStrength_0_1(
        magnetic_field_ga=[magnetic_field_ga_0, magnetic_field_ga_1, magnetic_field_ga_2],
        magnetic_field_covariance=magnetic_field_covariance,
    )


def gps_fix_to_ros(src: sam.sensor.GNSSFix_0_1, receive_ns: int, stats: ConversionStats) -> NavSatFix | None:
    """Mapping 'gps_fix', UAVCAN -> ROS.

    sam.sensor.GNSSFix.0.1 -> sensor_msgs/NavSatFix
    """
    msg = NavSatFix()
    status = msg.status
    msg.header.frame_id = 'gps_link'
    stamp = msg.header.stamp
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        stamp.sec = receive_ns // 1_000_000_000
        stamp.nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('gps_fix.header.stamp')
        stamp.sec = 2147483647
        stamp.nanosec = 999_999_999
    else:
        stamp.sec = us // 1_000_000
        stamp.nanosec = us % 1_000_000 * 1000
    msg.latitude = src.latitude_deg_1e8 * 1e-08
    msg.longitude = src.longitude_deg_1e8 * 1e-08
    msg.altitude = src.height_ellipsoid_mm * 0.001
    status_status = _GPS_FIX_STATUS_STATUS_TO_ROS.get(src.status)
    if status_status is None:
        stats.reject('gps_fix.status.status')
        return None
    status.status = status_status
    status.service = 1
    position_covariance = src.position_covariance.tolist()
    position_covariance += [0.0] * (9 - len(position_covariance))  # zero = unknown
    msg.position_covariance = position_covariance
    msg.position_covariance_type = 3
    return msg


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
        stats.reject('gps_fix.latitude_deg_1e8')
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
        stats.reject('gps_fix.longitude_deg_1e8')
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
        stats.reject('gps_fix.height_ellipsoid_mm')
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
    position_covariance = _clamp_floats(
        position_covariance, 65504.0, stats, 'gps_fix.position_covariance', False
    )
    if position_covariance is None:
        return None
    return sam.sensor.GNSSFix_0_1(
        timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=us),
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
    msg = FluidPressure()
    msg.header.frame_id = 'pressure_link'
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.fluid_pressure = src.static_pressure
    msg.variance = src.static_pressure_variance
    return msg


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
    return sam.sensor.StaticPressure_0_1(
        static_pressure=static_pressure,
        static_pressure_variance=static_pressure_variance,
    )


def battery_state_to_ros(
    src: sam.power.BatteryInfo_0_1, receive_ns: int, stats: ConversionStats
) -> BatteryState | None:
    """Mapping 'battery_state', UAVCAN -> ROS.

    sam.power.BatteryInfo.0.1 -> sensor_msgs/BatteryState
    """
    msg = BatteryState()
    msg.header.frame_id = 'base_link'
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.voltage = src.voltage
    msg.current = src.current
    msg.temperature = src.temperature - 273.15
    msg.percentage = src.state_of_charge_pct * 0.01
    msg.charge = _NAN
    msg.capacity = _NAN
    msg.design_capacity = _NAN
    msg.present = True
    return msg


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
        stats.reject('battery_state.state_of_charge_pct')
        return None
    if state_of_charge_pct >= 127.5:
        stats.saturate('battery_state.state_of_charge_pct')
        state_of_charge_pct = 127
    elif state_of_charge_pct <= -0.5:
        stats.saturate('battery_state.state_of_charge_pct')
        state_of_charge_pct = 0
    else:
        state_of_charge_pct = round(state_of_charge_pct)
    return sam.power.BatteryInfo_0_1(
        temperature=temperature,
        voltage=voltage,
        current=current,
        state_of_charge_pct=state_of_charge_pct,
    )


def battery_info_to_ros(
    src: sam.power.BatteryInfo_0_1, receive_ns: int, stats: ConversionStats
) -> BatteryInfo | None:
    """Mapping 'battery_info', UAVCAN -> ROS.

    sam.power.BatteryInfo.0.1 -> sam_msgs/BatteryInfo
    """
    msg = BatteryInfo()
    msg.header.frame_id = 'base_link'
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.temperature = src.temperature
    msg.voltage = src.voltage
    msg.current = src.current
    msg.average_power_10sec = src.average_power_10sec
    msg.remaining_capacity_wh = src.remaining_capacity_wh
    msg.full_charge_capacity_wh = src.full_charge_capacity_wh
    msg.hours_to_full_charge = src.hours_to_full_charge
    msg.status_flags = src.status_flags
    msg.state_of_health_pct = src.state_of_health_pct
    msg.state_of_charge_pct = src.state_of_charge_pct
    msg.state_of_charge_pct_stdev = src.state_of_charge_pct_stdev
    msg.battery_id = src.battery_id
    msg.model_instance_id = src.model_instance_id
    msg.model_name = src.model_name.tolist()
    return msg


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
    return sam.power.BatteryInfo_0_1(
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
    msg = ThrusterRPMs()
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.thruster_1_rpm = src.rpm
    return msg


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
    return sam.actuator.ThrusterRPM_0_1(rpm=rpm)


def thruster_2_rpm_to_ros(
    src: sam.actuator.ThrusterRPM_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterRPMs | None:
    """Mapping 'thruster_2_rpm', UAVCAN -> ROS.

    sam.actuator.ThrusterRPM.0.1 -> sam_msgs/ThrusterRPMs
    """
    msg = ThrusterRPMs()
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.thruster_2_rpm = src.rpm
    return msg


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
    return sam.actuator.ThrusterRPM_0_1(rpm=rpm)


def thrust_vector_to_ros(
    src: sam.actuator.ThrustVector_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterAngles | None:
    """Mapping 'thrust_vector', UAVCAN -> ROS.

    sam.actuator.ThrustVector.0.1 -> sam_msgs/ThrusterAngles
    """
    msg = ThrusterAngles()
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.thruster_vertical_radians = src.vertical_radians
    msg.thruster_horizontal_radians = src.horizontal_radians
    return msg


def thrust_vector_to_uavcan(
    src: ThrusterAngles, stats: ConversionStats
) -> sam.actuator.ThrustVector_0_1 | None:
    """Mapping 'thrust_vector', ROS -> UAVCAN.

    sam_msgs/ThrusterAngles -> sam.actuator.ThrustVector.0.1
    """
    vertical_radians = src.thruster_vertical_radians
    if vertical_radians > 65504.0:
        stats.saturate('thrust_vector.vertical_radians')
        vertical_radians = 65504.0
    elif vertical_radians < -65504.0:
        stats.saturate('thrust_vector.vertical_radians')
        vertical_radians = -65504.0
    horizontal_radians = src.thruster_horizontal_radians
    if horizontal_radians > 65504.0:
        stats.saturate('thrust_vector.horizontal_radians')
        horizontal_radians = 65504.0
    elif horizontal_radians < -65504.0:
        stats.saturate('thrust_vector.horizontal_radians')
        horizontal_radians = -65504.0
    return sam.actuator.ThrustVector_0_1(
        vertical_radians=vertical_radians,
        horizontal_radians=horizontal_radians,
    )


def ballast_to_ros(
    src: sam.actuator.BallastAngles_0_1, receive_ns: int, stats: ConversionStats
) -> BallastAngles | None:
    """Mapping 'ballast', UAVCAN -> ROS.

    sam.actuator.BallastAngles.0.1 -> sam_msgs/BallastAngles
    """
    msg = BallastAngles()
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.weight_1_offset_radians = src.weight_1_offset_radians
    msg.weight_2_offset_radians = src.weight_2_offset_radians
    return msg


def ballast_to_uavcan(src: BallastAngles, stats: ConversionStats) -> sam.actuator.BallastAngles_0_1 | None:
    """Mapping 'ballast', ROS -> UAVCAN.

    sam_msgs/BallastAngles -> sam.actuator.BallastAngles.0.1
    """
    weight_1_offset_radians = src.weight_1_offset_radians
    if weight_1_offset_radians > 65504.0:
        stats.saturate('ballast.weight_1_offset_radians')
        weight_1_offset_radians = 65504.0
    elif weight_1_offset_radians < -65504.0:
        stats.saturate('ballast.weight_1_offset_radians')
        weight_1_offset_radians = -65504.0
    weight_2_offset_radians = src.weight_2_offset_radians
    if weight_2_offset_radians > 65504.0:
        stats.saturate('ballast.weight_2_offset_radians')
        weight_2_offset_radians = 65504.0
    elif weight_2_offset_radians < -65504.0:
        stats.saturate('ballast.weight_2_offset_radians')
        weight_2_offset_radians = -65504.0
    return sam.actuator.BallastAngles_0_1(
        weight_1_offset_radians=weight_1_offset_radians,
        weight_2_offset_radians=weight_2_offset_radians,
    )


def longitudinal_weight_to_ros(
    src: sam.actuator.PercentCommand_0_1, receive_ns: int, stats: ConversionStats
) -> PercentStamped | None:
    """Mapping 'longitudinal_weight', UAVCAN -> ROS.

    sam.actuator.PercentCommand.0.1 -> sam_msgs/PercentStamped
    """
    msg = PercentStamped()
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.percent = src.percent
    return msg


def longitudinal_weight_to_uavcan(
    src: PercentStamped, stats: ConversionStats
) -> sam.actuator.PercentCommand_0_1 | None:
    """Mapping 'longitudinal_weight', ROS -> UAVCAN.

    sam_msgs/PercentStamped -> sam.actuator.PercentCommand.0.1
    """
    percent = src.percent
    if percent != percent:  # NaN
        stats.reject('longitudinal_weight.percent')
        return None
    if percent < 0.0:
        stats.saturate('longitudinal_weight.percent')
        percent = 0.0
    elif percent > 100.0:
        stats.saturate('longitudinal_weight.percent')
        percent = 100.0
    return sam.actuator.PercentCommand_0_1(percent=percent)


def buoyancy_piston_to_ros(
    src: sam.actuator.PercentCommand_0_1, receive_ns: int, stats: ConversionStats
) -> PercentStamped | None:
    """Mapping 'buoyancy_piston', UAVCAN -> ROS.

    sam.actuator.PercentCommand.0.1 -> sam_msgs/PercentStamped
    """
    msg = PercentStamped()
    stamp = msg.header.stamp
    stamp.sec = receive_ns // 1_000_000_000
    stamp.nanosec = receive_ns % 1_000_000_000
    msg.percent = src.percent
    return msg


def buoyancy_piston_to_uavcan(
    src: PercentStamped, stats: ConversionStats
) -> sam.actuator.PercentCommand_0_1 | None:
    """Mapping 'buoyancy_piston', ROS -> UAVCAN.

    sam_msgs/PercentStamped -> sam.actuator.PercentCommand.0.1
    """
    percent = src.percent
    if percent != percent:  # NaN
        stats.reject('buoyancy_piston.percent')
        return None
    if percent < 0.0:
        stats.saturate('buoyancy_piston.percent')
        percent = 0.0
    elif percent > 100.0:
        stats.saturate('buoyancy_piston.percent')
        percent = 100.0
    return sam.actuator.PercentCommand_0_1(percent=percent)


def thruster_1_feedback_to_ros(
    src: sam.actuator.ThrusterFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> ThrusterFeedback | None:
    """Mapping 'thruster_1_feedback', UAVCAN -> ROS.

    sam.actuator.ThrusterFeedback.0.1 -> sam_msgs/ThrusterFeedback
    """
    msg = ThrusterFeedback()
    msg.header.frame_id = 'base_link'
    stamp = msg.header.stamp
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        stamp.sec = receive_ns // 1_000_000_000
        stamp.nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('thruster_1_feedback.header.stamp')
        stamp.sec = 2147483647
        stamp.nanosec = 999_999_999
    else:
        stamp.sec = us // 1_000_000
        stamp.nanosec = us % 1_000_000 * 1000
    msg.rpm = src.rpm
    msg.current = src.current
    msg.temperature_c = src.temperature_c
    return msg


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
    return sam.actuator.ThrusterFeedback_0_1(
        timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=us),
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
    msg = ThrusterFeedback()
    msg.header.frame_id = 'base_link'
    stamp = msg.header.stamp
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        stamp.sec = receive_ns // 1_000_000_000
        stamp.nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('thruster_2_feedback.header.stamp')
        stamp.sec = 2147483647
        stamp.nanosec = 999_999_999
    else:
        stamp.sec = us // 1_000_000
        stamp.nanosec = us % 1_000_000 * 1000
    msg.rpm = src.rpm
    msg.current = src.current
    msg.temperature_c = src.temperature_c
    return msg


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
    return sam.actuator.ThrusterFeedback_0_1(
        timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=us),
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
    msg = ThrustVectorFeedback()
    msg.header.frame_id = 'base_link'
    stamp = msg.header.stamp
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        stamp.sec = receive_ns // 1_000_000_000
        stamp.nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('thrust_vector_feedback.header.stamp')
        stamp.sec = 2147483647
        stamp.nanosec = 999_999_999
    else:
        stamp.sec = us // 1_000_000
        stamp.nanosec = us % 1_000_000 * 1000
    msg.vertical_mrad = src.vertical_mrad
    msg.horizontal_mrad = src.horizontal_mrad
    return msg


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
    return sam.actuator.ThrustVectorFeedback_0_1(
        timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=us),
        vertical_mrad=vertical_mrad,
        horizontal_mrad=horizontal_mrad,
    )


def longitudinal_weight_feedback_to_ros(
    src: sam.actuator.PositionFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> PositionFeedback | None:
    """Mapping 'longitudinal_weight_feedback', UAVCAN -> ROS.

    sam.actuator.PositionFeedback.0.1 -> sam_msgs/PositionFeedback
    """
    msg = PositionFeedback()
    msg.header.frame_id = 'base_link'
    stamp = msg.header.stamp
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        stamp.sec = receive_ns // 1_000_000_000
        stamp.nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('longitudinal_weight_feedback.header.stamp')
        stamp.sec = 2147483647
        stamp.nanosec = 999_999_999
    else:
        stamp.sec = us // 1_000_000
        stamp.nanosec = us % 1_000_000 * 1000
    msg.percent = src.percent
    msg.encoder_count = src.encoder_count
    return msg


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
    return sam.actuator.PositionFeedback_0_1(
        timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=us),
        percent=percent,
        encoder_count=encoder_count,
    )


def buoyancy_piston_feedback_to_ros(
    src: sam.actuator.PositionFeedback_0_1, receive_ns: int, stats: ConversionStats
) -> PositionFeedback | None:
    """Mapping 'buoyancy_piston_feedback', UAVCAN -> ROS.

    sam.actuator.PositionFeedback.0.1 -> sam_msgs/PositionFeedback
    """
    msg = PositionFeedback()
    msg.header.frame_id = 'base_link'
    stamp = msg.header.stamp
    us = src.timestamp.microsecond
    if us == 0:  # unknown: the receive time
        stamp.sec = receive_ns // 1_000_000_000
        stamp.nanosec = receive_ns % 1_000_000_000
    elif us > 2147483647999999:  # beyond builtin_interfaces/Time
        stats.saturate('buoyancy_piston_feedback.header.stamp')
        stamp.sec = 2147483647
        stamp.nanosec = 999_999_999
    else:
        stamp.sec = us // 1_000_000
        stamp.nanosec = us % 1_000_000 * 1000
    msg.percent = src.percent
    msg.encoder_count = src.encoder_count
    return msg


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
    return sam.actuator.PositionFeedback_0_1(
        timestamp=uavcan.time.SynchronizedTimestamp_1_0(microsecond=us),
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
