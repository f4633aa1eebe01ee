# Generated from interfaces.yaml by sam-codegen; do not edit.
"""Wire codecs of the sam bridge: Cyphal transfer payloads <-> ROS 2 CDR bytes, without objects.

Per mapping ``m`` of the spec (both directions, whichever the bridge runs):

- ``m_wire_to_ros(payload, receive_ns, stats) -> (cdr, stamp_ns) | None``: the UAVCAN payload -> the ROS
  message as CDR bytes, encapsulation header (00 01 00 00) included, for rclpy's raw publish, and its header
  stamp in ns (-1 when the message has no std_msgs/Header ``header``);
- ``m_ros_to_wire(cdr, stats) -> bytes | None``: CDR bytes with their header, as a raw subscription gives
  them -> the UAVCAN transfer payload.

They compute exactly what convert.py's ``m_to_ros`` / ``m_to_uavcan`` compute (the same checks, saturation,
tables and stamps, counted in ``stats`` under the same "<mapping>.<field>" keys; None where they return
None) and serialize it as pycyphal and rclpy would. ``stats`` needs ``saturate(key)`` and ``reject(key)``.

A payload pycyphal's deserialize would refuse (an array length prefix beyond its capacity, a delimiter
header beyond the payload) and CDR that is not a message of the type (truncated, a string without its NUL,
a bound exceeded, not little-endian plain CDR) raise WireError, a ValueError; nothing else is raised for
any bytes. A short payload reads as zero-extended and a long one as truncated (a newer minor version), as
in pycyphal.

The frame ids the spec gives are written after ``FRAME_PREFIX`` ("" on import): ``bind(frame_prefix)`` sets it
for a namespaced run ("sam1/"), with the bytes and structs that depend on it, once; one module object serves
one prefix.

Standard library only: importable without ROS or pycyphal.
"""

from __future__ import annotations

import struct as _struct
from collections.abc import Callable
from typing import Any

from . import conversion_support as _support

__all__ = ["CODECS", "FRAME_PREFIX", "WireError", "bind"]

WireError = _support.WireError
_NAN = float("nan")
_INF = float("inf")
_ZEROS = bytes(64)


def _extend(data: Any, size: int) -> Any:
    """`data` zero-extended to `size` bytes (the implicit zero extension), as it is when long enough."""
    return data if len(data) >= size else bytes(data) + bytes(size - len(data))

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



# ---- the structs and constant bytes the codecs pack and unpack ---------------------------------------------

_W0 = _struct.Struct('<IHBxxxxeeexxxxxxxxxxxxeeexxxxxxxxxxxxB')
_W1 = b'\t\x00\x00\x00imu_link\x00'
_W2 = b'\x00\x01\x00\x00'
_W3 = (
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\xf0?\x00\x00\x00\x00\x00\x00\xf0\xbf'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00'
)
_W4 = _struct.Struct('<4siI13s3x104sddd72xddd72x')
_W5 = _struct.Struct('<iII')
_W6 = _struct.Struct('<104xddd72xddd72x')
_W7 = _struct.Struct('<IHBfeeefffeeefffB')
_W8 = _struct.Struct('<eeeB')
_W9 = b'\x12\x00\x00\x00magnetometer_link\x00'
_W10 = _struct.Struct('<4siI22s2xddd9d')
_W11 = _struct.Struct('<8xI')
_W12 = _struct.Struct('<dddddddddddd')
_W13 = _struct.Struct('<eee')
_W14 = _struct.Struct('<B')
_W15 = _struct.Struct('<IHBQQxxxxxxxxxxxxBxxB')
_W16 = b'\t\x00\x00\x00gps_link\x00'
_W17 = b'\x01\x00'
_W18 = b'\x03'
_W19 = _struct.Struct('<4siI13sb2sddd9d1s')
_W20 = _struct.Struct('<b')
_W21 = _struct.Struct('<ddddddddddddx')
_W22 = _struct.Struct('<IHBQQfffBe')
_W23 = _struct.Struct('<fe')
_W24 = b'\x0e\x00\x00\x00pressure_link\x00'
_W25 = _struct.Struct('<4siI18s6xdd')
_W26 = _struct.Struct('<dd')
_W27 = _struct.Struct('<eeexxxxxxxxIxxxxxB')
_W28 = b'\n\x00\x00\x00base_link\x00'
_W29 = b'\x00\x00\xc0\x7f\x00\x00\xc0\x7f\x00\x00\xc0\x7f'
_W30 = b'\x00\x01\x00\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x00'
_W31 = _struct.Struct('<4siI14s2xfff12sfxB23s')
_W32 = _struct.Struct('<fff12xfxB2xI')
_W33 = _struct.Struct('<I')
_W34 = _struct.Struct('<eeeeeeeIBIB')
_W35 = _struct.Struct('<IHBfe')
_W36 = b'\x0f\x00\x00\x00altimeter_link\x00'
_W37 = b'\xcd\xcc\xcc=\x9a\x99\x99>\x00\x00\xc8B'
_W38 = _struct.Struct('<4siI19sx12sff')
_W39 = _struct.Struct('<12xff')
_W40 = _struct.Struct('<4siI14s2xfffffffHBBBB2xI')
_W41 = _struct.Struct('<fffffffHBBBB2xII')
_W42 = _struct.Struct('<eeeeeeeIBI')
_W43 = _struct.Struct('<HB')
_W44 = b'\x01\x00\x00\x00\x00'
_W45 = _struct.Struct('<4si4xiI5s')
_W46 = _struct.Struct('<i12xI')
_W47 = b'\x00\x01\x00\x00\x00\x00\x00\x00'
_W48 = _struct.Struct('<8siiI5s')
_W49 = _struct.Struct('<4xi8xI')
_W50 = _struct.Struct('<ee')
_W51 = _struct.Struct('<4sffiI5s')
_W52 = _struct.Struct('<ff8xI')
_W53 = _struct.Struct('<e')
_W54 = _struct.Struct('<4sfiI5s')
_W55 = _struct.Struct('<f8xI')
_W56 = _struct.Struct('<H')
_W57 = _struct.Struct('<IHBIH')
_W58 = _struct.Struct('<4siI14s2xifB')
_W59 = _struct.Struct('<ifB')
_W60 = _struct.Struct('<IHBI')
_W61 = _struct.Struct('<4siI14shh')
_W62 = _struct.Struct('<hh')
_W63 = _struct.Struct('<IHBeHB')
_W64 = _struct.Struct('<4siI14s2xfI')
_W65 = _struct.Struct('<fI')

# ---- the frame prefix: the frame ids, and what the CDR alignment after them depends on ---------------------

FRAME_PREFIX = ""  # written before every frame id: bind(frame_prefix)


def _cdr_string(text: str) -> bytes:
    data = text.encode()
    return _struct.pack('<I', len(data) + 1) + data + b'\0'


def bind(frame_prefix: str) -> None:
    """Make this module's codecs write `frame_prefix` (a namespace's, "sam1/") before every frame id: the
    constants that depend on it computed once. One module object serves one prefix: a run with another loads
    a copy of the module (sam_runtime.genpkg)."""
    global FRAME_PREFIX, _W1, _W4, _W9, _W10, _W16, _W19, _W24, _W25, _W28, _W31, _W36, _W38, _W40, _W58, _W61
    global _W64
    shift = len(frame_prefix.encode()) % 8  # the CDR padding after a frame id depends on it
    FRAME_PREFIX = frame_prefix
    _W1 = _cdr_string(frame_prefix + 'imu_link')
    _W4 = _struct.Struct(
        (
            '<4siI{}s3x104sddd72xddd72x', '<4siI{}s2x104sddd72xddd72x', '<4siI{}sx104sddd72xddd72x',
            '<4siI{}s104sddd72xddd72x', '<4siI{}s7x104sddd72xddd72x', '<4siI{}s6x104sddd72xddd72x',
            '<4siI{}s5x104sddd72xddd72x', '<4siI{}s4x104sddd72xddd72x',
        )[shift].format(len(_W1)),
    )
    _W9 = _cdr_string(frame_prefix + 'magnetometer_link')
    _W10 = _struct.Struct(
        (
            '<4siI{}s2xddd9d', '<4siI{}sxddd9d', '<4siI{}sddd9d', '<4siI{}s7xddd9d', '<4siI{}s6xddd9d',
            '<4siI{}s5xddd9d', '<4siI{}s4xddd9d', '<4siI{}s3xddd9d',
        )[shift].format(len(_W9)),
    )
    _W16 = _cdr_string(frame_prefix + 'gps_link')
    _W19 = _struct.Struct(
        (
            '<4siI{}sb2sddd9d1s', '<4siI{}sbx2s6xddd9d1s', '<4siI{}sb2s6xddd9d1s', '<4siI{}sbx2s4xddd9d1s',
            '<4siI{}sb2s4xddd9d1s', '<4siI{}sbx2s2xddd9d1s', '<4siI{}sb2s2xddd9d1s', '<4siI{}sbx2sddd9d1s',
        )[shift].format(len(_W16)),
    )
    _W24 = _cdr_string(frame_prefix + 'pressure_link')
    _W25 = _struct.Struct(
        (
            '<4siI{}s6xdd', '<4siI{}s5xdd', '<4siI{}s4xdd', '<4siI{}s3xdd', '<4siI{}s2xdd', '<4siI{}sxdd',
            '<4siI{}sdd', '<4siI{}s7xdd',
        )[shift].format(len(_W24)),
    )
    _W28 = _cdr_string(frame_prefix + 'base_link')
    _W31 = _struct.Struct(
        (
            '<4siI{}s2xfff12sfxB23s', '<4siI{}sxfff12sfxB23s', '<4siI{}sfff12sfxB23s',
            '<4siI{}s3xfff12sfxB23s', '<4siI{}s2xfff12sfxB23s', '<4siI{}sxfff12sfxB23s',
            '<4siI{}sfff12sfxB23s', '<4siI{}s3xfff12sfxB23s',
        )[shift].format(len(_W28)),
    )
    _W36 = _cdr_string(frame_prefix + 'altimeter_link')
    _W38 = _struct.Struct(
        (
            '<4siI{}sx12sff', '<4siI{}s4x12sff', '<4siI{}s3x12sff', '<4siI{}s2x12sff', '<4siI{}sx12sff',
            '<4siI{}s4x12sff', '<4siI{}s3x12sff', '<4siI{}s2x12sff',
        )[shift].format(len(_W36)),
    )
    _W40 = _struct.Struct(
        (
            '<4siI{}s2xfffffffHBBBB2xI', '<4siI{}sxfffffffHBBBB2xI', '<4siI{}sfffffffHBBBB2xI',
            '<4siI{}s3xfffffffHBBBB2xI', '<4siI{}s2xfffffffHBBBB2xI', '<4siI{}sxfffffffHBBBB2xI',
            '<4siI{}sfffffffHBBBB2xI', '<4siI{}s3xfffffffHBBBB2xI',
        )[shift].format(len(_W28)),
    )
    _W58 = _struct.Struct(
        (
            '<4siI{}s2xifB', '<4siI{}sxifB', '<4siI{}sifB', '<4siI{}s3xifB', '<4siI{}s2xifB', '<4siI{}sxifB',
            '<4siI{}sifB', '<4siI{}s3xifB',
        )[shift].format(len(_W28)),
    )
    _W61 = _struct.Struct(
        (
            '<4siI{}shh', '<4siI{}sxhh', '<4siI{}shh', '<4siI{}sxhh', '<4siI{}shh', '<4siI{}sxhh',
            '<4siI{}shh', '<4siI{}sxhh',
        )[shift].format(len(_W28)),
    )
    _W64 = _struct.Struct(
        (
            '<4siI{}s2xfI', '<4siI{}sxfI', '<4siI{}sfI', '<4siI{}s3xfI', '<4siI{}s2xfI', '<4siI{}sxfI',
            '<4siI{}sfI', '<4siI{}s3xfI',
        )[shift].format(len(_W28)),
    )


def imu_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'imu', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.sensor.RawIMU.0.1 -> sensor_msgs/Imu
    """
    buf = _extend(payload, 128)
    (
        bits, bits_2, bits_3, rate_gyro_latest_0, rate_gyro_latest_1, rate_gyro_latest_2,
        accelerometer_latest_0, accelerometer_latest_1, accelerometer_latest_2, count,
    ) = _W0.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    if count > 36:
        raise WireError('array length prefix beyond float16[<=36]')
    us = timestamp_microsecond
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
    return (
        _W4.pack(
            _W2, sec, nanosec, _W1, _W3, rate_gyro_latest_0, rate_gyro_latest_1, rate_gyro_latest_2,
            accelerometer_latest_0, accelerometer_latest_1, accelerometer_latest_2,
        ),
        sec * 1_000_000_000 + nanosec,
    )


def imu_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'imu', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sensor_msgs/Imu -> sam.sensor.RawIMU.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 7
    if size < offset + 300:
        raise WireError('CDR: truncated')
    (
        angular_velocity_x, angular_velocity_y, angular_velocity_z, linear_acceleration_x,
        linear_acceleration_y, linear_acceleration_z,
    ) = _W6.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('imu.timestamp.microsecond')
        us = 0
    rate_gyro_latest_0 = angular_velocity_x
    if rate_gyro_latest_0 > 65504.0:
        stats.saturate('imu.rate_gyro_latest[0]')
        rate_gyro_latest_0 = 65504.0
    elif rate_gyro_latest_0 < -65504.0:
        stats.saturate('imu.rate_gyro_latest[0]')
        rate_gyro_latest_0 = -65504.0
    rate_gyro_latest_1 = angular_velocity_y
    if rate_gyro_latest_1 > 65504.0:
        stats.saturate('imu.rate_gyro_latest[1]')
        rate_gyro_latest_1 = 65504.0
    elif rate_gyro_latest_1 < -65504.0:
        stats.saturate('imu.rate_gyro_latest[1]')
        rate_gyro_latest_1 = -65504.0
    rate_gyro_latest_2 = angular_velocity_z
    if rate_gyro_latest_2 > 65504.0:
        stats.saturate('imu.rate_gyro_latest[2]')
        rate_gyro_latest_2 = 65504.0
    elif rate_gyro_latest_2 < -65504.0:
        stats.saturate('imu.rate_gyro_latest[2]')
        rate_gyro_latest_2 = -65504.0
    accelerometer_latest_0 = linear_acceleration_x
    if accelerometer_latest_0 > 65504.0:
        stats.saturate('imu.accelerometer_latest[0]')
        accelerometer_latest_0 = 65504.0
    elif accelerometer_latest_0 < -65504.0:
        stats.saturate('imu.accelerometer_latest[0]')
        accelerometer_latest_0 = -65504.0
    accelerometer_latest_1 = linear_acceleration_y
    if accelerometer_latest_1 > 65504.0:
        stats.saturate('imu.accelerometer_latest[1]')
        accelerometer_latest_1 = 65504.0
    elif accelerometer_latest_1 < -65504.0:
        stats.saturate('imu.accelerometer_latest[1]')
        accelerometer_latest_1 = -65504.0
    accelerometer_latest_2 = linear_acceleration_z
    if accelerometer_latest_2 > 65504.0:
        stats.saturate('imu.accelerometer_latest[2]')
        accelerometer_latest_2 = 65504.0
    elif accelerometer_latest_2 < -65504.0:
        stats.saturate('imu.accelerometer_latest[2]')
        accelerometer_latest_2 = -65504.0
    bits = us
    return _W7.pack(
        bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255, 0.0, rate_gyro_latest_0, rate_gyro_latest_1,
        rate_gyro_latest_2, 0.0, 0.0, 0.0, accelerometer_latest_0, accelerometer_latest_1,
        accelerometer_latest_2, 0.0, 0.0, 0.0, 0,
    )


def magnetic_field_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'magnetic_field', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.sensor.MagneticFieldStrength.0.1 -> sensor_msgs/MagneticField
    """
    buf = _extend(payload, 33)
    magnetic_field_ga_0, magnetic_field_ga_1, magnetic_field_ga_2, count = _W8.unpack_from(buf, 0)
    offset = 7
    if count > 9:
        raise WireError('array length prefix beyond float16[<=9]')
    magnetic_field_covariance = list(_struct.unpack_from(f'<{count}e', buf, offset))
    magnetic_field_covariance_2 = [x * 1e-08 for x in magnetic_field_covariance]
    magnetic_field_covariance_2 += [0.0] * (9 - len(magnetic_field_covariance_2))  # zero = unknown
    return (
        _W10.pack(
            _W2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W9, magnetic_field_ga_0 * 0.0001,
            magnetic_field_ga_1 * 0.0001, magnetic_field_ga_2 * 0.0001, *magnetic_field_covariance_2,
        ),
        receive_ns,
    )


def magnetic_field_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'magnetic_field', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sensor_msgs/MagneticField -> sam.sensor.MagneticFieldStrength.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _W11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 7
    if size < offset + 100:
        raise WireError('CDR: truncated')
    (
        magnetic_field_x, magnetic_field_y, magnetic_field_z, magnetic_field_covariance_0,
        magnetic_field_covariance_1, magnetic_field_covariance_2, magnetic_field_covariance_3,
        magnetic_field_covariance_4, magnetic_field_covariance_5, magnetic_field_covariance_6,
        magnetic_field_covariance_7, magnetic_field_covariance_8,
    ) = _W12.unpack_from(cdr, offset + 4)
    magnetic_field_covariance = [
        magnetic_field_covariance_0, magnetic_field_covariance_1, magnetic_field_covariance_2,
        magnetic_field_covariance_3, magnetic_field_covariance_4, magnetic_field_covariance_5,
        magnetic_field_covariance_6, magnetic_field_covariance_7, magnetic_field_covariance_8,
    ]
    magnetic_field_ga_0 = magnetic_field_x / 0.0001
    if magnetic_field_ga_0 > 65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[0]')
        magnetic_field_ga_0 = 65504.0
    elif magnetic_field_ga_0 < -65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[0]')
        magnetic_field_ga_0 = -65504.0
    magnetic_field_ga_1 = magnetic_field_y / 0.0001
    if magnetic_field_ga_1 > 65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[1]')
        magnetic_field_ga_1 = 65504.0
    elif magnetic_field_ga_1 < -65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[1]')
        magnetic_field_ga_1 = -65504.0
    magnetic_field_ga_2 = magnetic_field_z / 0.0001
    if magnetic_field_ga_2 > 65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[2]')
        magnetic_field_ga_2 = 65504.0
    elif magnetic_field_ga_2 < -65504.0:
        stats.saturate('magnetic_field.magnetic_field_ga[2]')
        magnetic_field_ga_2 = -65504.0
    magnetic_field_covariance_9 = [x / 1e-08 for x in magnetic_field_covariance]
    magnetic_field_covariance_9 = _support.clamp_floats(
        magnetic_field_covariance_9, 65504.0, stats, 'magnetic_field.magnetic_field_covariance', False
    )
    if magnetic_field_covariance_9 is None:
        return None
    magnetic_field_covariance_10 = magnetic_field_covariance_9
    return (
        _W13.pack(magnetic_field_ga_0, magnetic_field_ga_1, magnetic_field_ga_2)
        + _struct.pack(
            f'<B{len(magnetic_field_covariance_10)}e', len(magnetic_field_covariance_10),
            *magnetic_field_covariance_10,
        )
    )


def gps_fix_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'gps_fix', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.sensor.GNSSFix.0.1 -> sensor_msgs/NavSatFix
    """
    buf = _extend(payload, 65)
    bits, bits_2, bits_3, bits_5, bits_6, bits_8, count = _W15.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    bits_7 = bits_5 | bits_6 << 64
    longitude_deg_1e8 = (((bits_7 & 137438953471) ^ 68719476736) - 68719476736)
    latitude_deg_1e8 = (((bits_7 >> 37 & 137438953471) ^ 68719476736) - 68719476736)
    height_ellipsoid_mm = (((bits_7 >> 74 & 134217727) ^ 67108864) - 67108864)
    status = (bits_8 >> 6 & 3)
    offset = 39
    if count > 9:
        raise WireError('array length prefix beyond float16[<=9]')
    position_covariance = list(_struct.unpack_from(f'<{count}e', buf, offset))
    us = timestamp_microsecond
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
    status_status = _GPS_FIX_STATUS_STATUS_TO_ROS.get(status)
    if status_status is None:
        stats.reject('gps_fix.status.status')
        return None
    position_covariance_2 = position_covariance
    position_covariance_2 += [0.0] * (9 - len(position_covariance_2))  # zero = unknown
    return (
        _W19.pack(
            _W2, sec, nanosec, _W16, status_status, _W17, latitude_deg_1e8 * 1e-08, longitude_deg_1e8 * 1e-08,
            height_ellipsoid_mm * 0.001, *position_covariance_2, _W18,
        ),
        sec * 1_000_000_000 + nanosec,
    )


def gps_fix_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'gps_fix', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sensor_msgs/NavSatFix -> sam.sensor.GNSSFix.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    if size < offset + 5:
        raise WireError('CDR: truncated')
    status_status, = _W20.unpack_from(cdr, offset + 4)
    offset += 1
    offset += -offset & 1
    if size < offset + 6:
        raise WireError('CDR: truncated')
    offset += 2
    offset += -offset & 7
    if size < offset + 101:
        raise WireError('CDR: truncated')
    (
        latitude, longitude, altitude, position_covariance_0, position_covariance_1, position_covariance_2,
        position_covariance_3, position_covariance_4, position_covariance_5, position_covariance_6,
        position_covariance_7, position_covariance_8,
    ) = _W21.unpack_from(cdr, offset + 4)
    position_covariance = [
        position_covariance_0, position_covariance_1, position_covariance_2, position_covariance_3,
        position_covariance_4, position_covariance_5, position_covariance_6, position_covariance_7,
        position_covariance_8,
    ]
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('gps_fix.timestamp.microsecond')
        us = 0
    latitude_deg_1e8 = latitude / 1e-08
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
    longitude_deg_1e8 = longitude / 1e-08
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
    height_ellipsoid_mm = altitude / 0.001
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
    status = _GPS_FIX_STATUS_STATUS_TO_UAVCAN.get(status_status)
    if status is None:
        stats.reject('gps_fix.status')
        return None
    position_covariance_9 = position_covariance
    position_covariance_9 = _support.clamp_floats(
        position_covariance_9, 65504.0, stats, 'gps_fix.position_covariance', False
    )
    if position_covariance_9 is None:
        return None
    bits = us
    bits_2 = (
        (longitude_deg_1e8 & 137438953471)
        | (latitude_deg_1e8 & 137438953471) << 37
        | (height_ellipsoid_mm & 134217727) << 74
    )
    position_covariance_10 = position_covariance_9
    return (
        _W22.pack(
            bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255, bits_2 & 18446744073709551615,
            bits_2 >> 64 & 18446744073709551615, 0.0, 0.0, 0.0, status << 6, 0.0,
        )
        + _struct.pack(
            f'<B{len(position_covariance_10)}e', len(position_covariance_10), *position_covariance_10,
        )
    )


def pressure_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'pressure', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.sensor.StaticPressure.0.1 -> sensor_msgs/FluidPressure
    """
    buf = _extend(payload, 14)
    static_pressure, static_pressure_variance = _W23.unpack_from(buf, 0)
    return (
        _W25.pack(
            _W2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W24, static_pressure,
            static_pressure_variance,
        ),
        receive_ns,
    )


def pressure_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'pressure', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sensor_msgs/FluidPressure -> sam.sensor.StaticPressure.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _W11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 7
    if size < offset + 20:
        raise WireError('CDR: truncated')
    fluid_pressure, variance = _W26.unpack_from(cdr, offset + 4)
    static_pressure = fluid_pressure
    if 3.4028234663852886e+38 < static_pressure < _INF:
        stats.saturate('pressure.static_pressure')
        static_pressure = 3.4028234663852886e+38
    elif -_INF < static_pressure < -3.4028234663852886e+38:
        stats.saturate('pressure.static_pressure')
        static_pressure = -3.4028234663852886e+38
    static_pressure_variance = variance
    if static_pressure_variance > 65504.0:
        stats.saturate('pressure.static_pressure_variance')
        static_pressure_variance = 65504.0
    elif static_pressure_variance < -65504.0:
        stats.saturate('pressure.static_pressure_variance')
        static_pressure_variance = -65504.0
    return _W23.pack(static_pressure, static_pressure_variance)


def battery_state_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'battery_state', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.power.BatteryInfo.0.1 -> sensor_msgs/BatteryState
    """
    buf = _extend(payload, 63)
    temperature, voltage, current, bits, count = _W27.unpack_from(buf, 0)
    state_of_health_pct = (bits >> 11 & 127)
    state_of_charge_pct = (bits >> 18 & 127)
    if count > 31:
        raise WireError('array length prefix beyond uint8[<=31]')
    power_supply_health = _BATTERY_STATE_POWER_SUPPLY_HEALTH_TO_ROS.get(state_of_health_pct, 1)
    return (
        _W31.pack(
            _W2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W28, voltage, temperature - 273.15,
            current, _W29, state_of_charge_pct * 0.01, power_supply_health, _W30,
        ),
        receive_ns,
    )


def battery_state_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'battery_state', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sensor_msgs/BatteryState -> sam.power.BatteryInfo.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _W11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 40:
        raise WireError('CDR: truncated')
    voltage, temperature, current, percentage, power_supply_health, count = _W32.unpack_from(cdr, offset + 4)
    offset += 36
    if size < offset + 4 + count * 4:
        raise WireError('CDR: sequence beyond the buffer')
    offset += count * 4
    if size < offset + 8:
        raise WireError('CDR: truncated')
    count_2, = _W33.unpack_from(cdr, offset + 4)
    offset += 4
    if size < offset + 4 + count_2 * 4:
        raise WireError('CDR: sequence beyond the buffer')
    offset += count_2 * 4
    if size < offset + 8:
        raise WireError('CDR: truncated')
    length_2, = _W33.unpack_from(cdr, offset + 4)
    offset += 4
    if length_2 and (size < offset + 4 + length_2 or cdr[offset + 3 + length_2] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length_2
    offset += -offset & 3
    if size < offset + 8:
        raise WireError('CDR: truncated')
    length_3, = _W33.unpack_from(cdr, offset + 4)
    offset += 4
    if length_3 and (size < offset + 4 + length_3 or cdr[offset + 3 + length_3] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    voltage_2 = voltage
    if voltage_2 > 65504.0:
        stats.saturate('battery_state.voltage')
        voltage_2 = 65504.0
    elif voltage_2 < -65504.0:
        stats.saturate('battery_state.voltage')
        voltage_2 = -65504.0
    current_2 = current
    if current_2 > 65504.0:
        stats.saturate('battery_state.current')
        current_2 = 65504.0
    elif current_2 < -65504.0:
        stats.saturate('battery_state.current')
        current_2 = -65504.0
    temperature_2 = temperature + 273.15
    if temperature_2 > 65504.0:
        stats.saturate('battery_state.temperature')
        temperature_2 = 65504.0
    elif temperature_2 < -65504.0:
        stats.saturate('battery_state.temperature')
        temperature_2 = -65504.0
    state_of_charge_pct = percentage / 0.01
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
    state_of_health_pct = _BATTERY_STATE_POWER_SUPPLY_HEALTH_TO_UAVCAN.get(power_supply_health)
    if state_of_health_pct is None:
        stats.reject('battery_state.state_of_health_pct')
        return None
    return _W34.pack(
        temperature_2, voltage_2, current_2, 0.0, 0.0, 0.0, 0.0,
        state_of_health_pct << 11 | state_of_charge_pct << 18, 0, 0, 0,
    )


def altitude_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'altitude', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.sensor.Altitude.0.1 -> sensor_msgs/Range
    """
    buf = _extend(payload, 21)
    bits, bits_2, bits_3, altitude, altitude_variance = _W35.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    us = timestamp_microsecond
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
    return (
        _W38.pack(_W2, sec, nanosec, _W36, _W37, altitude, altitude_variance), sec * 1_000_000_000 + nanosec,
    )


def altitude_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'altitude', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sensor_msgs/Range -> sam.sensor.Altitude.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    if size < offset + 5:
        raise WireError('CDR: truncated')
    offset += 1
    offset += -offset & 3
    if size < offset + 24:
        raise WireError('CDR: truncated')
    range_2, variance = _W39.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('altitude.timestamp.microsecond')
        us = 0
    altitude_variance = variance
    if altitude_variance > 65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = 65504.0
    elif altitude_variance < -65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = -65504.0
    bits = us
    return _W35.pack(bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255, range_2, altitude_variance)


def battery_info_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'battery_info', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.power.BatteryInfo.0.1 -> sam_msgs/BatteryInfo
    """
    buf = _extend(payload, 63)
    (
        temperature, voltage, current, average_power_10sec, remaining_capacity_wh, full_charge_capacity_wh,
        hours_to_full_charge, bits, battery_id, model_instance_id, count,
    ) = _W34.unpack_from(buf, 0)
    status_flags = (bits & 2047)
    state_of_health_pct = (bits >> 11 & 127)
    state_of_charge_pct = (bits >> 18 & 127)
    state_of_charge_pct_stdev = (bits >> 25 & 127)
    offset = 24
    if count > 31:
        raise WireError('array length prefix beyond uint8[<=31]')
    model_name = list(buf[offset:offset + count])
    model_name_2 = model_name
    return (
        (
            _W40.pack(
                _W2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W28, temperature, voltage,
                current, average_power_10sec, remaining_capacity_wh, full_charge_capacity_wh,
                hours_to_full_charge, status_flags, state_of_health_pct, state_of_charge_pct,
                state_of_charge_pct_stdev, battery_id, model_instance_id,
            )
            + _W33.pack(len(model_name_2))
            + bytes(model_name_2)
        ),
        receive_ns,
    )


def battery_info_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'battery_info', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/BatteryInfo -> sam.power.BatteryInfo.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _W11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 48:
        raise WireError('CDR: truncated')
    (
        temperature, voltage, current, average_power_10sec, remaining_capacity_wh, full_charge_capacity_wh,
        hours_to_full_charge, status_flags, state_of_health_pct, state_of_charge_pct,
        state_of_charge_pct_stdev, battery_id, model_instance_id, count,
    ) = _W41.unpack_from(cdr, offset + 4)
    if count > 31:
        raise WireError('CDR: seq bound exceeded')
    offset += 44
    if size < offset + 4 + count:
        raise WireError('CDR: sequence beyond the buffer')
    model_name = list(cdr[offset + 4:offset + 4 + count])
    temperature_2 = temperature
    if temperature_2 > 65504.0:
        stats.saturate('battery_info.temperature')
        temperature_2 = 65504.0
    elif temperature_2 < -65504.0:
        stats.saturate('battery_info.temperature')
        temperature_2 = -65504.0
    voltage_2 = voltage
    if voltage_2 > 65504.0:
        stats.saturate('battery_info.voltage')
        voltage_2 = 65504.0
    elif voltage_2 < -65504.0:
        stats.saturate('battery_info.voltage')
        voltage_2 = -65504.0
    current_2 = current
    if current_2 > 65504.0:
        stats.saturate('battery_info.current')
        current_2 = 65504.0
    elif current_2 < -65504.0:
        stats.saturate('battery_info.current')
        current_2 = -65504.0
    average_power_10sec_2 = average_power_10sec
    if average_power_10sec_2 > 65504.0:
        stats.saturate('battery_info.average_power_10sec')
        average_power_10sec_2 = 65504.0
    elif average_power_10sec_2 < -65504.0:
        stats.saturate('battery_info.average_power_10sec')
        average_power_10sec_2 = -65504.0
    remaining_capacity_wh_2 = remaining_capacity_wh
    if remaining_capacity_wh_2 > 65504.0:
        stats.saturate('battery_info.remaining_capacity_wh')
        remaining_capacity_wh_2 = 65504.0
    elif remaining_capacity_wh_2 < -65504.0:
        stats.saturate('battery_info.remaining_capacity_wh')
        remaining_capacity_wh_2 = -65504.0
    full_charge_capacity_wh_2 = full_charge_capacity_wh
    if full_charge_capacity_wh_2 > 65504.0:
        stats.saturate('battery_info.full_charge_capacity_wh')
        full_charge_capacity_wh_2 = 65504.0
    elif full_charge_capacity_wh_2 < -65504.0:
        stats.saturate('battery_info.full_charge_capacity_wh')
        full_charge_capacity_wh_2 = -65504.0
    hours_to_full_charge_2 = hours_to_full_charge
    if hours_to_full_charge_2 > 65504.0:
        stats.saturate('battery_info.hours_to_full_charge')
        hours_to_full_charge_2 = 65504.0
    elif hours_to_full_charge_2 < -65504.0:
        stats.saturate('battery_info.hours_to_full_charge')
        hours_to_full_charge_2 = -65504.0
    status_flags_2 = status_flags
    if status_flags_2 > 2047:
        stats.saturate('battery_info.status_flags')
        status_flags_2 = 2047
    state_of_health_pct_2 = state_of_health_pct
    if state_of_health_pct_2 > 127:
        stats.saturate('battery_info.state_of_health_pct')
        state_of_health_pct_2 = 127
    state_of_charge_pct_2 = state_of_charge_pct
    if state_of_charge_pct_2 > 127:
        stats.saturate('battery_info.state_of_charge_pct')
        state_of_charge_pct_2 = 127
    state_of_charge_pct_stdev_2 = state_of_charge_pct_stdev
    if state_of_charge_pct_stdev_2 > 127:
        stats.saturate('battery_info.state_of_charge_pct_stdev')
        state_of_charge_pct_stdev_2 = 127
    model_name_2 = model_name
    model_name_3 = bytes(model_name_2)
    return (
        _W42.pack(
            temperature_2, voltage_2, current_2, average_power_10sec_2, remaining_capacity_wh_2,
            full_charge_capacity_wh_2, hours_to_full_charge_2,
            (
                status_flags_2
                | state_of_health_pct_2 << 11
                | state_of_charge_pct_2 << 18
                | state_of_charge_pct_stdev_2 << 25
            ),
            battery_id, model_instance_id,
        )
        + _W14.pack(len(model_name_3))
        + model_name_3
    )


def thruster_1_rpm_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thruster_1_rpm', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.ThrusterRPM.0.1 -> sam_msgs/ThrusterRPMs
    """
    buf = _extend(payload, 11)
    bits, bits_2 = _W43.unpack_from(buf, 0)
    bits_3 = bits | bits_2 << 16
    rpm = (((bits_3 & 262143) ^ 131072) - 131072)
    return _W45.pack(_W2, rpm, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W44), receive_ns


def thruster_1_rpm_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thruster_1_rpm', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/ThrusterRPMs -> sam.actuator.ThrusterRPM.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 24:
        raise WireError('CDR: truncated')
    thruster_1_rpm, length = _W46.unpack_from(cdr, 4)
    offset = 20
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    rpm = thruster_1_rpm
    if rpm > 131071:
        stats.saturate('thruster_1_rpm.rpm')
        rpm = 131071
    elif rpm < -131072:
        stats.saturate('thruster_1_rpm.rpm')
        rpm = -131072
    bits = (rpm & 262143)
    return _W43.pack(bits & 65535, bits >> 16 & 255)


def thruster_2_rpm_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thruster_2_rpm', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.ThrusterRPM.0.1 -> sam_msgs/ThrusterRPMs
    """
    buf = _extend(payload, 11)
    bits, bits_2 = _W43.unpack_from(buf, 0)
    bits_3 = bits | bits_2 << 16
    rpm = (((bits_3 & 262143) ^ 131072) - 131072)
    return _W48.pack(_W47, rpm, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W44), receive_ns


def thruster_2_rpm_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thruster_2_rpm', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/ThrusterRPMs -> sam.actuator.ThrusterRPM.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 24:
        raise WireError('CDR: truncated')
    thruster_2_rpm, length = _W49.unpack_from(cdr, 4)
    offset = 20
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    rpm = thruster_2_rpm
    if rpm > 131071:
        stats.saturate('thruster_2_rpm.rpm')
        rpm = 131071
    elif rpm < -131072:
        stats.saturate('thruster_2_rpm.rpm')
        rpm = -131072
    bits = (rpm & 262143)
    return _W43.pack(bits & 65535, bits >> 16 & 255)


def thrust_vector_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thrust_vector', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.ThrustVector.0.1 -> sam_msgs/ThrusterAngles
    """
    buf = _extend(payload, 12)
    vertical_radians, horizontal_radians = _W50.unpack_from(buf, 0)
    return (
        _W51.pack(
            _W2, vertical_radians, horizontal_radians, receive_ns // 1_000_000_000,
            receive_ns % 1_000_000_000, _W44,
        ),
        receive_ns,
    )


def thrust_vector_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thrust_vector', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/ThrusterAngles -> sam.actuator.ThrustVector.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 24:
        raise WireError('CDR: truncated')
    thruster_vertical_radians, thruster_horizontal_radians, length = _W52.unpack_from(cdr, 4)
    offset = 20
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    vertical_radians = thruster_vertical_radians
    if vertical_radians != vertical_radians:  # NaN
        stats.reject_nan('thrust_vector.vertical_radians')
        return None
    if vertical_radians < -0.12:
        stats.saturate('thrust_vector.vertical_radians')
        vertical_radians = -0.12
    elif vertical_radians > 0.12:
        stats.saturate('thrust_vector.vertical_radians')
        vertical_radians = 0.12
    horizontal_radians = thruster_horizontal_radians
    if horizontal_radians != horizontal_radians:  # NaN
        stats.reject_nan('thrust_vector.horizontal_radians')
        return None
    if horizontal_radians < -0.12:
        stats.saturate('thrust_vector.horizontal_radians')
        horizontal_radians = -0.12
    elif horizontal_radians > 0.12:
        stats.saturate('thrust_vector.horizontal_radians')
        horizontal_radians = 0.12
    return _W50.pack(vertical_radians, horizontal_radians)


def ballast_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'ballast', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.BallastAngles.0.1 -> sam_msgs/BallastAngles
    """
    buf = _extend(payload, 12)
    weight_1_offset_radians, weight_2_offset_radians = _W50.unpack_from(buf, 0)
    return (
        _W51.pack(
            _W2, weight_1_offset_radians, weight_2_offset_radians, receive_ns // 1_000_000_000,
            receive_ns % 1_000_000_000, _W44,
        ),
        receive_ns,
    )


def ballast_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'ballast', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/BallastAngles -> sam.actuator.BallastAngles.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 24:
        raise WireError('CDR: truncated')
    weight_1_offset_radians, weight_2_offset_radians, length = _W52.unpack_from(cdr, 4)
    offset = 20
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    weight_1_offset_radians_2 = weight_1_offset_radians
    if weight_1_offset_radians_2 != weight_1_offset_radians_2:  # NaN
        stats.reject_nan('ballast.weight_1_offset_radians')
        return None
    if weight_1_offset_radians_2 < -1.5708:
        stats.saturate('ballast.weight_1_offset_radians')
        weight_1_offset_radians_2 = -1.5708
    elif weight_1_offset_radians_2 > 1.5708:
        stats.saturate('ballast.weight_1_offset_radians')
        weight_1_offset_radians_2 = 1.5708
    weight_2_offset_radians_2 = weight_2_offset_radians
    if weight_2_offset_radians_2 != weight_2_offset_radians_2:  # NaN
        stats.reject_nan('ballast.weight_2_offset_radians')
        return None
    if weight_2_offset_radians_2 < -1.5708:
        stats.saturate('ballast.weight_2_offset_radians')
        weight_2_offset_radians_2 = -1.5708
    elif weight_2_offset_radians_2 > 1.5708:
        stats.saturate('ballast.weight_2_offset_radians')
        weight_2_offset_radians_2 = 1.5708
    return _W50.pack(weight_1_offset_radians_2, weight_2_offset_radians_2)


def longitudinal_weight_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'longitudinal_weight', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.PercentCommand.0.1 -> sam_msgs/PercentStamped
    """
    buf = _extend(payload, 10)
    percent, = _W53.unpack_from(buf, 0)
    return _W54.pack(_W2, percent, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W44), receive_ns


def longitudinal_weight_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'longitudinal_weight', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/PercentStamped -> sam.actuator.PercentCommand.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 20:
        raise WireError('CDR: truncated')
    percent, length = _W55.unpack_from(cdr, 4)
    offset = 16
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    percent_2 = percent
    if percent_2 != percent_2:  # NaN
        stats.reject_nan('longitudinal_weight.percent')
        return None
    if percent_2 < 0.0:
        stats.saturate('longitudinal_weight.percent')
        percent_2 = 0.0
    elif percent_2 > 100.0:
        stats.saturate('longitudinal_weight.percent')
        percent_2 = 100.0
    return _W53.pack(percent_2)


def buoyancy_piston_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'buoyancy_piston', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.PercentCommand.0.1 -> sam_msgs/PercentStamped
    """
    buf = _extend(payload, 10)
    percent, = _W53.unpack_from(buf, 0)
    return _W54.pack(_W2, percent, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _W44), receive_ns


def buoyancy_piston_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'buoyancy_piston', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/PercentStamped -> sam.actuator.PercentCommand.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 20:
        raise WireError('CDR: truncated')
    percent, length = _W55.unpack_from(cdr, 4)
    offset = 16
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    percent_2 = percent
    if percent_2 != percent_2:  # NaN
        stats.reject_nan('buoyancy_piston.percent')
        return None
    if percent_2 < 0.0:
        stats.saturate('buoyancy_piston.percent')
        percent_2 = 0.0
    elif percent_2 > 100.0:
        stats.saturate('buoyancy_piston.percent')
        percent_2 = 100.0
    return _W53.pack(percent_2)


def thruster_1_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thruster_1_feedback', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.ThrusterFeedback.0.1 -> sam_msgs/ThrusterFeedback
    """
    buf = _extend(payload, 21)
    bits, bits_2, bits_3, bits_5, bits_6 = _W57.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    bits_7 = bits_5 | bits_6 << 32
    rpm = (((bits_7 & 262143) ^ 131072) - 131072)
    current = _W53.unpack(_W56.pack(bits_7 >> 18 & 65535))[0]
    temperature_c = (bits_7 >> 34 & 127)
    us = timestamp_microsecond
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
    return _W58.pack(_W2, sec, nanosec, _W28, rpm, current, temperature_c), sec * 1_000_000_000 + nanosec


def thruster_1_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thruster_1_feedback', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/ThrusterFeedback -> sam.actuator.ThrusterFeedback.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 13:
        raise WireError('CDR: truncated')
    rpm, current, temperature_c = _W59.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('thruster_1_feedback.timestamp.microsecond')
        us = 0
    rpm_2 = rpm
    if rpm_2 > 131071:
        stats.saturate('thruster_1_feedback.rpm')
        rpm_2 = 131071
    elif rpm_2 < -131072:
        stats.saturate('thruster_1_feedback.rpm')
        rpm_2 = -131072
    current_2 = current
    if current_2 > 65504.0:
        stats.saturate('thruster_1_feedback.current')
        current_2 = 65504.0
    elif current_2 < -65504.0:
        stats.saturate('thruster_1_feedback.current')
        current_2 = -65504.0
    temperature_c_2 = temperature_c
    if temperature_c_2 > 127:
        stats.saturate('thruster_1_feedback.temperature_c')
        temperature_c_2 = 127
    bits = us
    bits_2 = (rpm_2 & 262143) | _W56.unpack(_W53.pack(current_2))[0] << 18 | temperature_c_2 << 34
    return _W57.pack(
        bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255, bits_2 & 4294967295, bits_2 >> 32 & 65535,
    )


def thruster_2_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thruster_2_feedback', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.ThrusterFeedback.0.1 -> sam_msgs/ThrusterFeedback
    """
    buf = _extend(payload, 21)
    bits, bits_2, bits_3, bits_5, bits_6 = _W57.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    bits_7 = bits_5 | bits_6 << 32
    rpm = (((bits_7 & 262143) ^ 131072) - 131072)
    current = _W53.unpack(_W56.pack(bits_7 >> 18 & 65535))[0]
    temperature_c = (bits_7 >> 34 & 127)
    us = timestamp_microsecond
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
    return _W58.pack(_W2, sec, nanosec, _W28, rpm, current, temperature_c), sec * 1_000_000_000 + nanosec


def thruster_2_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thruster_2_feedback', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/ThrusterFeedback -> sam.actuator.ThrusterFeedback.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 13:
        raise WireError('CDR: truncated')
    rpm, current, temperature_c = _W59.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('thruster_2_feedback.timestamp.microsecond')
        us = 0
    rpm_2 = rpm
    if rpm_2 > 131071:
        stats.saturate('thruster_2_feedback.rpm')
        rpm_2 = 131071
    elif rpm_2 < -131072:
        stats.saturate('thruster_2_feedback.rpm')
        rpm_2 = -131072
    current_2 = current
    if current_2 > 65504.0:
        stats.saturate('thruster_2_feedback.current')
        current_2 = 65504.0
    elif current_2 < -65504.0:
        stats.saturate('thruster_2_feedback.current')
        current_2 = -65504.0
    temperature_c_2 = temperature_c
    if temperature_c_2 > 127:
        stats.saturate('thruster_2_feedback.temperature_c')
        temperature_c_2 = 127
    bits = us
    bits_2 = (rpm_2 & 262143) | _W56.unpack(_W53.pack(current_2))[0] << 18 | temperature_c_2 << 34
    return _W57.pack(
        bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255, bits_2 & 4294967295, bits_2 >> 32 & 65535,
    )


def thrust_vector_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thrust_vector_feedback', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.ThrustVectorFeedback.0.1 -> sam_msgs/ThrustVectorFeedback
    """
    buf = _extend(payload, 19)
    bits, bits_2, bits_3, bits_5 = _W60.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    vertical_mrad = (((bits_5 & 8191) ^ 4096) - 4096)
    horizontal_mrad = (((bits_5 >> 13 & 8191) ^ 4096) - 4096)
    us = timestamp_microsecond
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
    return _W61.pack(_W2, sec, nanosec, _W28, vertical_mrad, horizontal_mrad), sec * 1_000_000_000 + nanosec


def thrust_vector_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thrust_vector_feedback', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/ThrustVectorFeedback -> sam.actuator.ThrustVectorFeedback.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 1
    if size < offset + 8:
        raise WireError('CDR: truncated')
    vertical_mrad, horizontal_mrad = _W62.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('thrust_vector_feedback.timestamp.microsecond')
        us = 0
    vertical_mrad_2 = vertical_mrad
    if vertical_mrad_2 > 4095:
        stats.saturate('thrust_vector_feedback.vertical_mrad')
        vertical_mrad_2 = 4095
    elif vertical_mrad_2 < -4096:
        stats.saturate('thrust_vector_feedback.vertical_mrad')
        vertical_mrad_2 = -4096
    horizontal_mrad_2 = horizontal_mrad
    if horizontal_mrad_2 > 4095:
        stats.saturate('thrust_vector_feedback.horizontal_mrad')
        horizontal_mrad_2 = 4095
    elif horizontal_mrad_2 < -4096:
        stats.saturate('thrust_vector_feedback.horizontal_mrad')
        horizontal_mrad_2 = -4096
    bits = us
    return _W60.pack(
        bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255,
        (vertical_mrad_2 & 8191) | (horizontal_mrad_2 & 8191) << 13,
    )


def longitudinal_weight_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'longitudinal_weight_feedback', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.PositionFeedback.0.1 -> sam_msgs/PositionFeedback
    """
    buf = _extend(payload, 20)
    bits, bits_2, bits_3, percent, bits_5, bits_6 = _W63.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    bits_7 = bits_5 | bits_6 << 16
    encoder_count = (bits_7 & 16777215)
    us = timestamp_microsecond
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
    return _W64.pack(_W2, sec, nanosec, _W28, percent, encoder_count), sec * 1_000_000_000 + nanosec


def longitudinal_weight_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'longitudinal_weight_feedback', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 12:
        raise WireError('CDR: truncated')
    percent, encoder_count = _W65.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('longitudinal_weight_feedback.timestamp.microsecond')
        us = 0
    percent_2 = percent
    if percent_2 > 65504.0:
        stats.saturate('longitudinal_weight_feedback.percent')
        percent_2 = 65504.0
    elif percent_2 < -65504.0:
        stats.saturate('longitudinal_weight_feedback.percent')
        percent_2 = -65504.0
    encoder_count_2 = encoder_count
    if encoder_count_2 > 16777215:
        stats.saturate('longitudinal_weight_feedback.encoder_count')
        encoder_count_2 = 16777215
    bits = us
    bits_2 = encoder_count_2
    return _W63.pack(
        bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255, percent_2, bits_2 & 65535,
        bits_2 >> 16 & 255,
    )


def buoyancy_piston_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'buoyancy_piston_feedback', UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].

    sam.actuator.PositionFeedback.0.1 -> sam_msgs/PositionFeedback
    """
    buf = _extend(payload, 20)
    bits, bits_2, bits_3, percent, bits_5, bits_6 = _W63.unpack_from(buf, 0)
    bits_4 = bits | bits_2 << 32 | bits_3 << 48
    timestamp_microsecond = (bits_4 & 72057594037927935)
    bits_7 = bits_5 | bits_6 << 16
    encoder_count = (bits_7 & 16777215)
    us = timestamp_microsecond
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
    return _W64.pack(_W2, sec, nanosec, _W28, percent, encoder_count), sec * 1_000_000_000 + nanosec


def buoyancy_piston_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'buoyancy_piston_feedback', ROS -> UAVCAN, CDR bytes -> payload bytes.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback.0.1
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _W5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 12:
        raise WireError('CDR: truncated')
    percent, encoder_count = _W65.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('buoyancy_piston_feedback.timestamp.microsecond')
        us = 0
    percent_2 = percent
    if percent_2 > 65504.0:
        stats.saturate('buoyancy_piston_feedback.percent')
        percent_2 = 65504.0
    elif percent_2 < -65504.0:
        stats.saturate('buoyancy_piston_feedback.percent')
        percent_2 = -65504.0
    encoder_count_2 = encoder_count
    if encoder_count_2 > 16777215:
        stats.saturate('buoyancy_piston_feedback.encoder_count')
        encoder_count_2 = 16777215
    bits = us
    bits_2 = encoder_count_2
    return _W63.pack(
        bits & 4294967295, bits >> 32 & 65535, bits >> 48 & 255, percent_2, bits_2 & 65535,
        bits_2 >> 16 & 255,
    )


# mapping name -> (wire_to_ros, ros_to_wire)
CODECS: dict[str, tuple[Callable[..., Any], Callable[..., Any]]] = {
    'imu': (imu_wire_to_ros, imu_ros_to_wire),
    'magnetic_field': (magnetic_field_wire_to_ros, magnetic_field_ros_to_wire),
    'gps_fix': (gps_fix_wire_to_ros, gps_fix_ros_to_wire),
    'pressure': (pressure_wire_to_ros, pressure_ros_to_wire),
    'battery_state': (battery_state_wire_to_ros, battery_state_ros_to_wire),
    'altitude': (altitude_wire_to_ros, altitude_ros_to_wire),
    'battery_info': (battery_info_wire_to_ros, battery_info_ros_to_wire),
    'thruster_1_rpm': (thruster_1_rpm_wire_to_ros, thruster_1_rpm_ros_to_wire),
    'thruster_2_rpm': (thruster_2_rpm_wire_to_ros, thruster_2_rpm_ros_to_wire),
    'thrust_vector': (thrust_vector_wire_to_ros, thrust_vector_ros_to_wire),
    'ballast': (ballast_wire_to_ros, ballast_ros_to_wire),
    'longitudinal_weight': (longitudinal_weight_wire_to_ros, longitudinal_weight_ros_to_wire),
    'buoyancy_piston': (buoyancy_piston_wire_to_ros, buoyancy_piston_ros_to_wire),
    'thruster_1_feedback': (thruster_1_feedback_wire_to_ros, thruster_1_feedback_ros_to_wire),
    'thruster_2_feedback': (thruster_2_feedback_wire_to_ros, thruster_2_feedback_ros_to_wire),
    'thrust_vector_feedback': (thrust_vector_feedback_wire_to_ros, thrust_vector_feedback_ros_to_wire),
    'longitudinal_weight_feedback': (
        longitudinal_weight_feedback_wire_to_ros,
        longitudinal_weight_feedback_ros_to_wire,
    ),
    'buoyancy_piston_feedback': (buoyancy_piston_feedback_wire_to_ros, buoyancy_piston_feedback_ros_to_wire),
}
