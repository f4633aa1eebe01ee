"""Reference (a) of the converter benchmark: converters written by hand the way the design document writes its
RawIMU -> Imu example (section IV.B): a new message, the timestamp through a ``convert_timestamp`` helper, then
one assignment per field, array elements indexed on the source (``uav_msg.accelerometer_latest[0]``).

They implement the same conversions as the spec's mappings (scale, offset, table, constant values, frame ids,
limits of the commands) for in-range values, but none of the generated code's range checks, saturation
counting or NaN handling: the document's converter has none. Signature as the generated ones:
``<mapping>_to_ros(uav_msg, receive_ns, stats)`` and ``<mapping>_to_uavcan(ros_msg, stats)``.

Import after the DSDL is compiled and on sys.path (bench.common.generated_package()).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import sam.actuator
import sam.power
import sam.sensor
import uavcan.time
from builtin_interfaces.msg import Time
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
from sensor_msgs.msg import BatteryState, FluidPressure, Imu, MagneticField, NavSatFix, Range

NAN = float("nan")


def convert_timestamp(timestamp: Any, receive_ns: int) -> Time:
    """UAVCAN SynchronizedTimestamp (us; 0 = unknown) -> builtin_interfaces/Time."""
    us = timestamp.microsecond
    t = Time()
    if us == 0:
        t.sec, t.nanosec = divmod(receive_ns, 1_000_000_000)
    else:
        t.sec, t.nanosec = us // 1_000_000, us % 1_000_000 * 1000
    return t


def receive_time(receive_ns: int) -> Time:
    t = Time()
    t.sec, t.nanosec = divmod(receive_ns, 1_000_000_000)
    return t


def convert_stamp(stamp: Any) -> Any:
    """builtin_interfaces/Time -> UAVCAN SynchronizedTimestamp."""
    return uavcan.time.SynchronizedTimestamp_1_0(microsecond=stamp.sec * 1_000_000 + stamp.nanosec // 1000)


# ----------------------------------------------------------------------------------------- UAVCAN -> ROS
def imu_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> Imu:
    ros_msg = Imu()
    ros_msg.header.stamp = convert_timestamp(uav_msg.timestamp, receive_ns)
    ros_msg.header.frame_id = "imu_link"
    ros_msg.linear_acceleration.x = uav_msg.accelerometer_latest[0]
    ros_msg.linear_acceleration.y = uav_msg.accelerometer_latest[1]
    ros_msg.linear_acceleration.z = uav_msg.accelerometer_latest[2]
    ros_msg.angular_velocity.x = uav_msg.rate_gyro_latest[0]
    ros_msg.angular_velocity.y = uav_msg.rate_gyro_latest[1]
    ros_msg.angular_velocity.z = uav_msg.rate_gyro_latest[2]
    ros_msg.orientation_covariance[0] = -1.0
    return ros_msg


def magnetic_field_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> MagneticField:
    ros_msg = MagneticField()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.header.frame_id = "magnetometer_link"
    # float(): arithmetic on a numpy float16 element would stay in float16 (1e-8 * 4e-6 underflows to 0).
    ros_msg.magnetic_field.x = float(uav_msg.magnetic_field_ga[0]) * 1e-4
    ros_msg.magnetic_field.y = float(uav_msg.magnetic_field_ga[1]) * 1e-4
    ros_msg.magnetic_field.z = float(uav_msg.magnetic_field_ga[2]) * 1e-4
    for i, c in enumerate(uav_msg.magnetic_field_covariance):
        ros_msg.magnetic_field_covariance[i] = float(c) * 1e-8
    return ros_msg


GPS_STATUS_TO_ROS = {0: -1, 1: -1, 2: 0, 3: 0}
GPS_STATUS_TO_UAVCAN = {-1: 0, 0: 2}


def gps_fix_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> NavSatFix:
    ros_msg = NavSatFix()
    ros_msg.header.stamp = convert_timestamp(uav_msg.timestamp, receive_ns)
    ros_msg.header.frame_id = "gps_link"
    ros_msg.latitude = uav_msg.latitude_deg_1e8 * 1e-8
    ros_msg.longitude = uav_msg.longitude_deg_1e8 * 1e-8
    ros_msg.altitude = uav_msg.height_ellipsoid_mm * 1e-3
    ros_msg.status.status = GPS_STATUS_TO_ROS[uav_msg.status]
    ros_msg.status.service = 1
    for i, c in enumerate(uav_msg.position_covariance):
        ros_msg.position_covariance[i] = c
    ros_msg.position_covariance_type = 3
    return ros_msg


def pressure_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> FluidPressure:
    ros_msg = FluidPressure()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.header.frame_id = "pressure_link"
    ros_msg.fluid_pressure = uav_msg.static_pressure
    ros_msg.variance = uav_msg.static_pressure_variance
    return ros_msg


def battery_state_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> BatteryState:
    ros_msg = BatteryState()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.header.frame_id = "base_link"
    ros_msg.voltage = uav_msg.voltage
    ros_msg.current = uav_msg.current
    ros_msg.temperature = uav_msg.temperature - 273.15
    ros_msg.percentage = uav_msg.state_of_charge_pct * 0.01
    pct = uav_msg.state_of_health_pct  # the spec's table: below 30 % DEAD, 127 UNKNOWN, else GOOD
    ros_msg.power_supply_health = 3 if pct < 30 else 0 if pct == 127 else 1
    ros_msg.charge = NAN
    ros_msg.capacity = NAN
    ros_msg.design_capacity = NAN
    ros_msg.present = True
    return ros_msg


def altitude_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> Range:
    ros_msg = Range()
    ros_msg.header.stamp = convert_timestamp(uav_msg.timestamp, receive_ns)
    ros_msg.header.frame_id = "altimeter_link"
    ros_msg.field_of_view = 0.1
    ros_msg.min_range = 0.3
    ros_msg.max_range = 100.0
    ros_msg.range = uav_msg.altitude
    ros_msg.variance = uav_msg.altitude_variance
    return ros_msg


def battery_info_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> BatteryInfo:
    ros_msg = BatteryInfo()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.header.frame_id = "base_link"
    ros_msg.temperature = uav_msg.temperature
    ros_msg.voltage = uav_msg.voltage
    ros_msg.current = uav_msg.current
    ros_msg.average_power_10sec = uav_msg.average_power_10sec
    ros_msg.remaining_capacity_wh = uav_msg.remaining_capacity_wh
    ros_msg.full_charge_capacity_wh = uav_msg.full_charge_capacity_wh
    ros_msg.hours_to_full_charge = uav_msg.hours_to_full_charge
    ros_msg.status_flags = uav_msg.status_flags
    ros_msg.state_of_health_pct = uav_msg.state_of_health_pct
    ros_msg.state_of_charge_pct = uav_msg.state_of_charge_pct
    ros_msg.state_of_charge_pct_stdev = uav_msg.state_of_charge_pct_stdev
    ros_msg.battery_id = uav_msg.battery_id
    ros_msg.model_instance_id = uav_msg.model_instance_id
    ros_msg.model_name = uav_msg.model_name.tolist()
    return ros_msg


def thruster_1_rpm_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> ThrusterRPMs:
    ros_msg = ThrusterRPMs()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.thruster_1_rpm = uav_msg.rpm
    return ros_msg


def thruster_2_rpm_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> ThrusterRPMs:
    ros_msg = ThrusterRPMs()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.thruster_2_rpm = uav_msg.rpm
    return ros_msg


def thrust_vector_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> ThrusterAngles:
    ros_msg = ThrusterAngles()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.thruster_vertical_radians = uav_msg.vertical_radians
    ros_msg.thruster_horizontal_radians = uav_msg.horizontal_radians
    return ros_msg


def ballast_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> BallastAngles:
    ros_msg = BallastAngles()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.weight_1_offset_radians = uav_msg.weight_1_offset_radians
    ros_msg.weight_2_offset_radians = uav_msg.weight_2_offset_radians
    return ros_msg


def percent_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> PercentStamped:
    ros_msg = PercentStamped()
    ros_msg.header.stamp = receive_time(receive_ns)
    ros_msg.percent = uav_msg.percent
    return ros_msg


def thruster_feedback_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> ThrusterFeedback:
    ros_msg = ThrusterFeedback()
    ros_msg.header.stamp = convert_timestamp(uav_msg.timestamp, receive_ns)
    ros_msg.header.frame_id = "base_link"
    ros_msg.rpm = uav_msg.rpm
    ros_msg.current = uav_msg.current
    ros_msg.temperature_c = uav_msg.temperature_c
    return ros_msg


def thrust_vector_feedback_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> ThrustVectorFeedback:
    ros_msg = ThrustVectorFeedback()
    ros_msg.header.stamp = convert_timestamp(uav_msg.timestamp, receive_ns)
    ros_msg.header.frame_id = "base_link"
    ros_msg.vertical_mrad = uav_msg.vertical_mrad
    ros_msg.horizontal_mrad = uav_msg.horizontal_mrad
    return ros_msg


def position_feedback_to_ros(uav_msg: Any, receive_ns: int, stats: Any) -> PositionFeedback:
    ros_msg = PositionFeedback()
    ros_msg.header.stamp = convert_timestamp(uav_msg.timestamp, receive_ns)
    ros_msg.header.frame_id = "base_link"
    ros_msg.percent = uav_msg.percent
    ros_msg.encoder_count = uav_msg.encoder_count
    return ros_msg


# ----------------------------------------------------------------------------------------- ROS -> UAVCAN
def imu_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.sensor.RawIMU_0_1()
    uav_msg.timestamp = convert_stamp(ros_msg.header.stamp)
    uav_msg.rate_gyro_latest[0] = ros_msg.angular_velocity.x
    uav_msg.rate_gyro_latest[1] = ros_msg.angular_velocity.y
    uav_msg.rate_gyro_latest[2] = ros_msg.angular_velocity.z
    uav_msg.accelerometer_latest[0] = ros_msg.linear_acceleration.x
    uav_msg.accelerometer_latest[1] = ros_msg.linear_acceleration.y
    uav_msg.accelerometer_latest[2] = ros_msg.linear_acceleration.z
    return uav_msg


def magnetic_field_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.sensor.MagneticFieldStrength_0_1()
    uav_msg.magnetic_field_ga[0] = ros_msg.magnetic_field.x / 1e-4
    uav_msg.magnetic_field_ga[1] = ros_msg.magnetic_field.y / 1e-4
    uav_msg.magnetic_field_ga[2] = ros_msg.magnetic_field.z / 1e-4
    uav_msg.magnetic_field_covariance = [c / 1e-8 for c in ros_msg.magnetic_field_covariance]
    return uav_msg


def gps_fix_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.sensor.GNSSFix_0_1()
    uav_msg.timestamp = convert_stamp(ros_msg.header.stamp)
    uav_msg.latitude_deg_1e8 = round(ros_msg.latitude / 1e-8)
    uav_msg.longitude_deg_1e8 = round(ros_msg.longitude / 1e-8)
    uav_msg.height_ellipsoid_mm = round(ros_msg.altitude / 1e-3)
    uav_msg.status = GPS_STATUS_TO_UAVCAN[ros_msg.status.status]
    uav_msg.position_covariance = ros_msg.position_covariance
    return uav_msg


def pressure_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.sensor.StaticPressure_0_1()
    uav_msg.static_pressure = ros_msg.fluid_pressure
    uav_msg.static_pressure_variance = ros_msg.variance
    return uav_msg


def battery_state_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.power.BatteryInfo_0_1()
    uav_msg.voltage = ros_msg.voltage
    uav_msg.current = ros_msg.current
    uav_msg.temperature = ros_msg.temperature + 273.15
    uav_msg.state_of_charge_pct = round(ros_msg.percentage / 0.01)
    health = {3: 0, 0: 127}.get(ros_msg.power_supply_health)  # the table's inverse: GOOD has no key
    if health is None:
        return None
    uav_msg.state_of_health_pct = health
    return uav_msg


def altitude_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.sensor.Altitude_0_1()
    uav_msg.timestamp = convert_stamp(ros_msg.header.stamp)
    uav_msg.altitude = ros_msg.range
    uav_msg.altitude_variance = ros_msg.variance
    return uav_msg


def battery_info_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.power.BatteryInfo_0_1()
    uav_msg.temperature = ros_msg.temperature
    uav_msg.voltage = ros_msg.voltage
    uav_msg.current = ros_msg.current
    uav_msg.average_power_10sec = ros_msg.average_power_10sec
    uav_msg.remaining_capacity_wh = ros_msg.remaining_capacity_wh
    uav_msg.full_charge_capacity_wh = ros_msg.full_charge_capacity_wh
    uav_msg.hours_to_full_charge = ros_msg.hours_to_full_charge
    uav_msg.status_flags = ros_msg.status_flags
    uav_msg.state_of_health_pct = ros_msg.state_of_health_pct
    uav_msg.state_of_charge_pct = ros_msg.state_of_charge_pct
    uav_msg.state_of_charge_pct_stdev = ros_msg.state_of_charge_pct_stdev
    uav_msg.battery_id = ros_msg.battery_id
    uav_msg.model_instance_id = ros_msg.model_instance_id
    uav_msg.model_name = ros_msg.model_name.tolist()
    return uav_msg


def thruster_1_rpm_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.ThrusterRPM_0_1()
    uav_msg.rpm = ros_msg.thruster_1_rpm
    return uav_msg


def thruster_2_rpm_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.ThrusterRPM_0_1()
    uav_msg.rpm = ros_msg.thruster_2_rpm
    return uav_msg


def thrust_vector_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.ThrustVector_0_1()
    uav_msg.vertical_radians = ros_msg.thruster_vertical_radians
    uav_msg.horizontal_radians = ros_msg.thruster_horizontal_radians
    return uav_msg


def ballast_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.BallastAngles_0_1()
    uav_msg.weight_1_offset_radians = ros_msg.weight_1_offset_radians
    uav_msg.weight_2_offset_radians = ros_msg.weight_2_offset_radians
    return uav_msg


def percent_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.PercentCommand_0_1()
    uav_msg.percent = min(max(ros_msg.percent, 0.0), 100.0)  # the spec's limits [0, 100]
    return uav_msg


def thruster_feedback_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.ThrusterFeedback_0_1()
    uav_msg.timestamp = convert_stamp(ros_msg.header.stamp)
    uav_msg.rpm = ros_msg.rpm
    uav_msg.current = ros_msg.current
    uav_msg.temperature_c = ros_msg.temperature_c
    return uav_msg


def thrust_vector_feedback_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.ThrustVectorFeedback_0_1()
    uav_msg.timestamp = convert_stamp(ros_msg.header.stamp)
    uav_msg.vertical_mrad = ros_msg.vertical_mrad
    uav_msg.horizontal_mrad = ros_msg.horizontal_mrad
    return uav_msg


def position_feedback_to_uavcan(ros_msg: Any, stats: Any) -> Any:
    uav_msg = sam.actuator.PositionFeedback_0_1()
    uav_msg.timestamp = convert_stamp(ros_msg.header.stamp)
    uav_msg.percent = ros_msg.percent
    uav_msg.encoder_count = ros_msg.encoder_count
    return uav_msg


# mapping name -> (to_ros, to_uavcan), as the generated CONVERTERS
CONVERTERS: dict[str, tuple[Callable[..., Any], Callable[..., Any]]] = {
    "imu": (imu_to_ros, imu_to_uavcan),
    "magnetic_field": (magnetic_field_to_ros, magnetic_field_to_uavcan),
    "gps_fix": (gps_fix_to_ros, gps_fix_to_uavcan),
    "pressure": (pressure_to_ros, pressure_to_uavcan),
    "battery_state": (battery_state_to_ros, battery_state_to_uavcan),
    "altitude": (altitude_to_ros, altitude_to_uavcan),
    "battery_info": (battery_info_to_ros, battery_info_to_uavcan),
    "thruster_1_rpm": (thruster_1_rpm_to_ros, thruster_1_rpm_to_uavcan),
    "thruster_2_rpm": (thruster_2_rpm_to_ros, thruster_2_rpm_to_uavcan),
    "thrust_vector": (thrust_vector_to_ros, thrust_vector_to_uavcan),
    "ballast": (ballast_to_ros, ballast_to_uavcan),
    "longitudinal_weight": (percent_to_ros, percent_to_uavcan),
    "buoyancy_piston": (percent_to_ros, percent_to_uavcan),
    "thruster_1_feedback": (thruster_feedback_to_ros, thruster_feedback_to_uavcan),
    "thruster_2_feedback": (thruster_feedback_to_ros, thruster_feedback_to_uavcan),
    "thrust_vector_feedback": (thrust_vector_feedback_to_ros, thrust_vector_feedback_to_uavcan),
    "longitudinal_weight_feedback": (position_feedback_to_ros, position_feedback_to_uavcan),
    "buoyancy_piston_feedback": (position_feedback_to_ros, position_feedback_to_uavcan),
}
