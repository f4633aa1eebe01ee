# Generated from interfaces.yaml by sam-codegen; do not edit.
"""Wire codecs of the sam bridge for its DroneCAN mappings: UAVCAN v0 payloads <-> ROS 2 CDR bytes.

The converters of convert_v0.py, straight from and to the bytes (no dronecan object, no ROS message):

- ``<mapping>_wire_to_ros(payload, receive_ns, stats)``: the payload of a v0 transfer (its CRC removed) ->
  ``(CDR, stamp)``: the ROS message's CDR bytes, encapsulation header included (rclpy's raw publish), and its
  header stamp in ns (-1 without a std_msgs/Header ``header``); None when ``<mapping>_to_ros`` drops it;
- ``<mapping>_ros_to_wire(cdr, stats)``: CDR bytes (a raw subscription's) -> the payload to broadcast;
  None when ``<mapping>_to_uavcan`` drops the message.

``stats`` counts as convert_v0's ConversionStats does (``.saturate(key)``, ``.reject(key)``, the same keys).
``WIRE_MATCHES[mapping](payload)`` is ``MATCHES[mapping]`` of the decoded message (mappings with a selection).

The payload layout is dronecan's (1.0.27), bit for bit, for classic CAN: tail array optimisation on. WireError
is raised where dronecan's decoding refuses a payload (a field, length prefix or union tag beyond its end, a
tail array element cut short, a union tag beyond the union's fields), where a decoded array exceeds the bound
of the ROS sequence it goes into (rclpy would not serialize it), and for CDR that does not hold the message;
never another exception. dronecan accepts bits beyond the type's end, padding cut by the end, and arrays
longer than their capacity (a length prefix may count more, a tail array takes every whole element): so do
these codecs.

The frame ids the spec gives are written after ``FRAME_PREFIX`` ("" on import): ``bind(frame_prefix)`` sets it
for a namespaced run ("sam1/"), with the bytes and structs that depend on it, once; one module object serves
one prefix.

Standard library only.
"""

from __future__ import annotations

import struct as _struct
from collections.abc import Callable
from typing import Any

from . import conversion_support as _support

__all__ = ["CODECS", "FRAME_PREFIX", "WIRE_MATCHES", "ConversionStats", "WireError", "bind"]

ConversionStats = _support.ConversionStats
WireError = _support.WireError
_NAN = float("nan")
_INF = float("inf")
_ZEROS = bytes(64)
_K0 = _struct.Struct('<7s4x3e12x3e')
_K1 = b'\t\x00\x00\x00imu_link\x00'
_K2 = b'\x00\x01\x00\x00'
_K3 = (
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\xf0?\x00\x00\x00\x00\x00\x00\xf0\xbf'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    b'\x00\x00\x00\x00'
)
_K4 = _struct.Struct('<4siI13s3x104sddd72xddd72x')
_K5 = _struct.Struct('<iII')
_K6 = _struct.Struct('<104xddd72xddd72x')
_K7 = _struct.Struct('<7s4xHHH12xHHH12x')
_K8 = _struct.Struct('<3e')
_K9 = b'\x12\x00\x00\x00magnetometer_link\x00'
_K10 = _struct.Struct('<4siI22s2xddd9d')
_K11 = _struct.Struct('<8xI')
_K12 = _struct.Struct('<dddddddddddd')
_K13 = _struct.Struct('<HHH')
_K14 = _struct.Struct('<7s')
_K15 = b'\t\x00\x00\x00gps_link\x00'
_K16 = b'\x01\x00'
_K17 = _struct.Struct('<4siI13sb2sddd73x')
_K18 = _struct.Struct('<b')
_K19 = _struct.Struct('<ddd73x')
_K20 = _struct.Struct('<7s7x')
_K21 = b'\x00\x00\x00'
_K22 = b'\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
_K23 = b'\x00\x00\x00\x00'
_K24 = _struct.Struct('<fe')
_K25 = b'\x0e\x00\x00\x00pressure_link\x00'
_K26 = _struct.Struct('<4siI18s6xdd')
_K27 = _struct.Struct('<dd')
_K28 = _struct.Struct('<fH')
_K29 = _struct.Struct('<eee')
_K30 = b'\n\x00\x00\x00base_link\x00'
_K31 = b'\x00\x00\xc0\x7f\x00\x00\xc0\x7f\x00\x00\xc0\x7f'
_K32 = b'\x00\x00\x00\x01\x00\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x00'
_K33 = _struct.Struct('<4siI14s2xfff12sf25s')
_K34 = _struct.Struct('<fff12xf4xI')
_K35 = _struct.Struct('<I')
_K36 = _struct.Struct('<HHH8x')
_K37 = b'\x00\x00\x00\x00\x00'
_K38 = _struct.Struct('<eeeeeee')
_K39 = _struct.Struct('<BI')
_K40 = _struct.Struct('<4siI14s2xfffffffHBBBB2xI')
_K41 = _struct.Struct('<fffffffHBBBB2xII')
_K42 = _struct.Struct('<HHHHHHH')
_K43 = _struct.Struct('<7sfe')
_K44 = b'\x0f\x00\x00\x00altimeter_link\x00'
_K45 = b'\xcd\xcc\xcc=\x9a\x99\x99>\x00\x00\xc8B'
_K46 = _struct.Struct('<4siI19sx12sff')
_K47 = _struct.Struct('<12xff')
_K48 = _struct.Struct('<7sfH')
_K49 = b'\x01\x00\x00\x00\x00'
_K50 = _struct.Struct('<4siiiI5s')
_K51 = _struct.Struct('<ii8xI')
_K52 = _struct.Struct('<BBe')
_K53 = _struct.Struct('<4sffiI5s')
_K54 = _struct.Struct('<ff8xI')
_K55 = _struct.Struct('<BBHBBH')
_K56 = _struct.Struct('<4sfiI5s')
_K57 = _struct.Struct('<f8xI')
_K58 = _struct.Struct('<BBH')
_K59 = _struct.Struct('<ee')
_K60 = _struct.Struct('<4siI14s2xifB')
_K61 = _struct.Struct('<ifB')
_K62 = _struct.Struct('<6xHH')
_K63 = _struct.Struct('<4siI14shh')
_K64 = _struct.Struct('<hh')
_K65 = _struct.Struct('<7se3s')
_K66 = _struct.Struct('<4siI14s2xfI')
_K67 = _struct.Struct('<fI')
_K68 = _struct.Struct('<7sH3s')

# ---- the frame prefix: the frame ids, and what the CDR alignment after them depends on ---------------------

FRAME_PREFIX = ""  # written before every frame id: bind(frame_prefix)


def _cdr_string(text: str) -> bytes:
    data = text.encode()
    return _struct.pack('<I', len(data) + 1) + data + b'\0'


def bind(frame_prefix: str) -> None:
    """Make this module's codecs write `frame_prefix` (a namespace's, "sam1/") before every frame id: the
    constants that depend on it computed once. One module object serves one prefix: a run with another loads
    a copy of the module (sam_runtime.genpkg)."""
    global FRAME_PREFIX, _K1, _K4, _K9, _K10, _K15, _K17, _K25, _K26, _K30, _K33, _K40, _K44, _K46, _K60, _K63
    global _K66
    shift = len(frame_prefix.encode()) % 8  # the CDR padding after a frame id depends on it
    FRAME_PREFIX = frame_prefix
    _K1 = _cdr_string(frame_prefix + 'imu_link')
    _K4 = _struct.Struct(
        (
            '<4siI{}s3x104sddd72xddd72x', '<4siI{}s2x104sddd72xddd72x', '<4siI{}sx104sddd72xddd72x',
            '<4siI{}s104sddd72xddd72x', '<4siI{}s7x104sddd72xddd72x', '<4siI{}s6x104sddd72xddd72x',
            '<4siI{}s5x104sddd72xddd72x', '<4siI{}s4x104sddd72xddd72x',
        )[shift].format(len(_K1)),
    )
    _K9 = _cdr_string(frame_prefix + 'magnetometer_link')
    _K10 = _struct.Struct(
        (
            '<4siI{}s2xddd9d', '<4siI{}sxddd9d', '<4siI{}sddd9d', '<4siI{}s7xddd9d', '<4siI{}s6xddd9d',
            '<4siI{}s5xddd9d', '<4siI{}s4xddd9d', '<4siI{}s3xddd9d',
        )[shift].format(len(_K9)),
    )
    _K15 = _cdr_string(frame_prefix + 'gps_link')
    _K17 = _struct.Struct(
        (
            '<4siI{}sb2sddd73x', '<4siI{}sbx2s6xddd73x', '<4siI{}sb2s6xddd73x', '<4siI{}sbx2s4xddd73x',
            '<4siI{}sb2s4xddd73x', '<4siI{}sbx2s2xddd73x', '<4siI{}sb2s2xddd73x', '<4siI{}sbx2sddd73x',
        )[shift].format(len(_K15)),
    )
    _K25 = _cdr_string(frame_prefix + 'pressure_link')
    _K26 = _struct.Struct(
        (
            '<4siI{}s6xdd', '<4siI{}s5xdd', '<4siI{}s4xdd', '<4siI{}s3xdd', '<4siI{}s2xdd', '<4siI{}sxdd',
            '<4siI{}sdd', '<4siI{}s7xdd',
        )[shift].format(len(_K25)),
    )
    _K30 = _cdr_string(frame_prefix + 'base_link')
    _K33 = _struct.Struct(
        (
            '<4siI{}s2xfff12sf25s', '<4siI{}sxfff12sf25s', '<4siI{}sfff12sf25s', '<4siI{}s3xfff12sf25s',
            '<4siI{}s2xfff12sf25s', '<4siI{}sxfff12sf25s', '<4siI{}sfff12sf25s', '<4siI{}s3xfff12sf25s',
        )[shift].format(len(_K30)),
    )
    _K40 = _struct.Struct(
        (
            '<4siI{}s2xfffffffHBBBB2xI', '<4siI{}sxfffffffHBBBB2xI', '<4siI{}sfffffffHBBBB2xI',
            '<4siI{}s3xfffffffHBBBB2xI', '<4siI{}s2xfffffffHBBBB2xI', '<4siI{}sxfffffffHBBBB2xI',
            '<4siI{}sfffffffHBBBB2xI', '<4siI{}s3xfffffffHBBBB2xI',
        )[shift].format(len(_K30)),
    )
    _K44 = _cdr_string(frame_prefix + 'altimeter_link')
    _K46 = _struct.Struct(
        (
            '<4siI{}sx12sff', '<4siI{}s4x12sff', '<4siI{}s3x12sff', '<4siI{}s2x12sff', '<4siI{}sx12sff',
            '<4siI{}s4x12sff', '<4siI{}s3x12sff', '<4siI{}s2x12sff',
        )[shift].format(len(_K44)),
    )
    _K60 = _struct.Struct(
        (
            '<4siI{}s2xifB', '<4siI{}sxifB', '<4siI{}sifB', '<4siI{}s3xifB', '<4siI{}s2xifB', '<4siI{}sxifB',
            '<4siI{}sifB', '<4siI{}s3xifB',
        )[shift].format(len(_K30)),
    )
    _K63 = _struct.Struct(
        (
            '<4siI{}shh', '<4siI{}sxhh', '<4siI{}shh', '<4siI{}sxhh', '<4siI{}shh', '<4siI{}sxhh',
            '<4siI{}shh', '<4siI{}sxhh',
        )[shift].format(len(_K30)),
    )
    _K66 = _struct.Struct(
        (
            '<4siI{}s2xfI', '<4siI{}sxfI', '<4siI{}sfI', '<4siI{}s3xfI', '<4siI{}s2xfI', '<4siI{}sxfI',
            '<4siI{}sfI', '<4siI{}s3xfI',
        )[shift].format(len(_K30)),
    )

# gps_fix: status -> status.status
_GPS_FIX_STATUS_STATUS_TO_ROS: dict[int, int] = {0: -1, 1: -1, 2: 0, 3: 0}

# gps_fix: status.status -> status (first key per value)
_GPS_FIX_STATUS_STATUS_TO_UAVCAN: dict[int, int] = {-1: 0, 0: 2}


_F32 = _struct.Struct("<f")
_U32 = _struct.Struct("<I")


def _f16(x: float) -> int:
    """The float16 bits dronecan writes for a saturated float16 field (its cast, then its f16_from_f32)."""
    if x > 65504.0:
        x = 65504.0
    elif x < -65504.0:
        x = -65504.0
    return _half(x)


def _f16t(x: float) -> int:
    """The float16 bits dronecan writes for a truncated float16 field (beyond the range: infinite)."""
    if x > 65504.0:
        x = _INF
    elif x < -65504.0:
        x = -_INF
    return _half(x)


def _half(x: float) -> int:
    # dronecan's f16_from_f32 (libuavcan's): float32 first, the low 12 bits dropped, half an ulp added.
    u = _U32.unpack(_F32.pack(x))[0]
    sign = u >> 16 & 0x8000
    u &= 0x7FFFFFFF
    if u >= 0x7F800000:
        return (0x7FFF if u > 0x7F800000 else 0x7C00) | sign
    u &= 0xFFFFF000
    if u >= 0x38800000:  # the product by 2**-112 is a normal float32: exact
        u -= 0x37FFF000
        return (0x7C00 if u > 0x0F800000 else u >> 13) | sign
    u = _U32.unpack(_F32.pack(_F32.unpack(_U32.pack(u))[0] * 2.0**-112))[0] + 0x1000
    return u >> 13 | sign


def _clamp(x: float, m: float) -> float:
    """dronecan's saturated cast of a float: beyond +-m (infinities too) -> +-m; NaN stays."""
    return m if x > m else -m if x < -m else x


def _trunc(x: float, m: float) -> float:
    """dronecan's truncated cast of a float: beyond +-m -> +-inf; NaN stays."""
    return _INF if x > m else -_INF if x < -m else x


def _item(items: list[tuple[Any, ...]], field: int, value: int) -> Any:
    """The first record of an array of composites whose field at position `field` is `value`, or None."""
    for item in items:
        if item[field] == value:
            return item
    return None


def imu_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'imu', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.ahrs.RawIMU -> sensor_msgs/Imu
    """
    _n = len(payload)
    _L = _n << 3
    if _n < 47:
        raise WireError('uavcan.equipment.ahrs.RawIMU: payload too short')
    _t1 = _K0.unpack_from(payload, 0)
    u_timestamp_usec = int.from_bytes(_t1[0], 'little')
    u_rate_gyro_latest = list(_t1[1:4])
    u_accelerometer_latest = list(_t1[4:7])
    _o = 376
    _t3 = (_L - _o - 8) // 16 + 1 if _L - _o >= 8 else 0
    if _t3 and _L - _o - (_t3 - 1) * 16 < 16:
        raise WireError('uavcan.equipment.ahrs.RawIMU: tail array element cut short')
    rate_gyro_latest = list(u_rate_gyro_latest)
    accelerometer_latest = list(u_accelerometer_latest)
    us = u_timestamp_usec
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
        _K4.pack(
            _K2, sec, nanosec, _K1, _K3, rate_gyro_latest[0], rate_gyro_latest[1], rate_gyro_latest[2],
            accelerometer_latest[0], accelerometer_latest[1], accelerometer_latest[2],
        ),
        sec * 1_000_000_000 + nanosec,
    )


def imu_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'imu', ROS -> UAVCAN: CDR -> payload.

    sensor_msgs/Imu -> uavcan.equipment.ahrs.RawIMU
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _K5.unpack_from(cdr, 4)
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
    ) = _K6.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('imu.timestamp.usec')
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
    return _K7.pack(
        (us & 0xffffffffffffff).to_bytes(7, 'little'), _f16(rate_gyro_latest_0), _f16(rate_gyro_latest_1),
        _f16(rate_gyro_latest_2), _f16(accelerometer_latest_0), _f16(accelerometer_latest_1),
        _f16(accelerometer_latest_2),
    )


def magnetic_field_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'magnetic_field', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.ahrs.MagneticFieldStrength -> sensor_msgs/MagneticField
    """
    _n = len(payload)
    _L = _n << 3
    if _n < 6:
        raise WireError('uavcan.equipment.ahrs.MagneticFieldStrength: payload too short')
    _t1 = _K8.unpack_from(payload, 0)
    u_magnetic_field_ga = list(_t1[0:3])
    _o = 48
    _t2 = (_L - _o - 8) // 16 + 1 if _L - _o >= 8 else 0
    if _t2 and _L - _o - (_t2 - 1) * 16 < 16:
        raise WireError('uavcan.equipment.ahrs.MagneticFieldStrength: tail array element cut short')
    u_magnetic_field_covariance = list(_struct.unpack_from(f'<{_t2}e', payload, _o >> 3))
    magnetic_field_ga = list(u_magnetic_field_ga)
    magnetic_field_covariance = [x * 1e-08 for x in list(u_magnetic_field_covariance)]
    magnetic_field_covariance += [0.0] * (9 - len(magnetic_field_covariance))  # zero = unknown
    return (
        _K10.pack(
            _K2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _K9, magnetic_field_ga[0] * 0.0001,
            magnetic_field_ga[1] * 0.0001, magnetic_field_ga[2] * 0.0001, *magnetic_field_covariance[:9],
        ),
        receive_ns,
    )


def magnetic_field_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'magnetic_field', ROS -> UAVCAN: CDR -> payload.

    sensor_msgs/MagneticField -> uavcan.equipment.ahrs.MagneticFieldStrength
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _K11.unpack_from(cdr, 4)
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
    ) = _K12.unpack_from(cdr, offset + 4)
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
    magnetic_field_covariance_9 = [x / 1e-08 for x in list(magnetic_field_covariance)]
    magnetic_field_covariance_9 = _support.clamp_floats(
        magnetic_field_covariance_9, 65504.0, stats, 'magnetic_field.magnetic_field_covariance', False
    )
    if magnetic_field_covariance_9 is None:
        return None
    return (
        _K13.pack(_f16(magnetic_field_ga_0), _f16(magnetic_field_ga_1), _f16(magnetic_field_ga_2))
        + _struct.pack(
            f'<{len(magnetic_field_covariance_9)}H', *[_f16(x) for x in magnetic_field_covariance_9],
        )
    )


def gps_fix_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'gps_fix', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.gnss.Fix2 -> sensor_msgs/NavSatFix
    """
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    if _n < 48:
        raise WireError('uavcan.equipment.gnss.Fix2: payload too short')
    _t1 = _K14.unpack_from(payload, 0)
    u_timestamp_usec = int.from_bytes(_t1[0], 'little')
    _t2 = _P >> (_L - 237) & 0x1fffffffffffffffffffffffff
    u_longitude_deg_1e8 = (
        (
            (
                (_t2 >> 93 & 0xff)
                | (_t2 >> 85 & 0xff) << 8
                | (_t2 >> 77 & 0xff) << 16
                | (_t2 >> 69 & 0xff) << 24
                | (_t2 >> 64 & 0x1f) << 32
            )
        ) ^ 0x1000000000
    ) - 0x1000000000
    u_latitude_deg_1e8 = (
        (
            (
                (_t2 >> 56 & 0xff)
                | (_t2 >> 48 & 0xff) << 8
                | (_t2 >> 40 & 0xff) << 16
                | (_t2 >> 32 & 0xff) << 24
                | (_t2 >> 27 & 0x1f) << 32
            )
        ) ^ 0x1000000000
    ) - 0x1000000000
    u_height_ellipsoid_mm = (
        (
            (_t2 >> 19 & 0xff) | (_t2 >> 11 & 0xff) << 8 | (_t2 >> 3 & 0xff) << 16 | (_t2 & 0x7) << 24
        ) ^ 0x4000000
    ) - 0x4000000
    _t3 = _P >> (_L - 368) & 0x3
    u_status = _t3 & 0x3
    _o = 378
    if _L < _o + 6:
        raise WireError('uavcan.equipment.gnss.Fix2: payload too short')
    _t5 = _P >> (_L - (_o + 6)) & 0x3f
    _o += 6
    if _t5 and _L < _o + (_t5 - 1) * 16 + 16:
        raise WireError('uavcan.equipment.gnss.Fix2: array beyond the payload')
    _o += _t5 * 16
    if _L < _o + 16:
        raise WireError('uavcan.equipment.gnss.Fix2: payload too short')
    _o += 16
    while _L - _o >= 8:
        if _L < _o + 204:
            raise WireError('uavcan.equipment.gnss.Fix2: payload too short')
        _o += 210
        if _L < _o + 6:
            raise WireError('uavcan.equipment.gnss.Fix2: payload too short')
        _t9 = _P >> (_L - (_o + 6)) & 0x3f
        _o += 6
        if _t9 and _L < _o + (_t9 - 1) * 16 + 16:
            raise WireError('uavcan.equipment.gnss.Fix2: array beyond the payload')
        _o += _t9 * 16
    us = u_timestamp_usec
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
    status_status = _GPS_FIX_STATUS_STATUS_TO_ROS.get(u_status)
    if status_status is None:
        stats.reject('gps_fix.status.status')
        return None
    return (
        _K17.pack(
            _K2, sec, nanosec, _K15, status_status, _K16, u_latitude_deg_1e8 * 1e-08,
            u_longitude_deg_1e8 * 1e-08, u_height_ellipsoid_mm * 0.001,
        ),
        sec * 1_000_000_000 + nanosec,
    )


def gps_fix_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'gps_fix', ROS -> UAVCAN: CDR -> payload.

    sensor_msgs/NavSatFix -> uavcan.equipment.gnss.Fix2
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _K5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    if size < offset + 5:
        raise WireError('CDR: truncated')
    status_status, = _K18.unpack_from(cdr, offset + 4)
    offset += 1
    offset += -offset & 1
    if size < offset + 6:
        raise WireError('CDR: truncated')
    offset += 2
    offset += -offset & 7
    if size < offset + 101:
        raise WireError('CDR: truncated')
    latitude, longitude, altitude = _K19.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('gps_fix.timestamp.usec')
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
    _v1 = longitude_deg_1e8 & 0x1fffffffff
    _v2 = (
        (_v1 & 0xff) << 29
        | (_v1 >> 8 & 0xff) << 21
        | (_v1 >> 16 & 0xff) << 13
        | (_v1 >> 24 & 0xff) << 5
        | _v1 >> 32
    )
    _v3 = latitude_deg_1e8 & 0x1fffffffff
    _v4 = (
        (_v3 & 0xff) << 29
        | (_v3 >> 8 & 0xff) << 21
        | (_v3 >> 16 & 0xff) << 13
        | (_v3 >> 24 & 0xff) << 5
        | _v3 >> 32
    )
    _v5 = height_ellipsoid_mm & 0x7ffffff
    _v6 = (_v5 & 0xff) << 19 | (_v5 >> 8 & 0xff) << 11 | (_v5 >> 16 & 0xff) << 3 | _v5 >> 24
    _v7 = _v2 << 91 | _v4 << 54 | _v6 << 27
    _v8 = status & 0x3
    return (
        _K20.pack((us & 0xffffffffffffff).to_bytes(7, 'little'))
        + _K21
        + _v7.to_bytes(16, 'big')
        + _K22
        + _v8.to_bytes(1, 'big')
        + _K23
    )


def pressure_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'pressure', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.air_data.StaticPressure -> sensor_msgs/FluidPressure
    """
    _n = len(payload)
    if _n < 6:
        raise WireError('uavcan.equipment.air_data.StaticPressure: payload too short')
    u_static_pressure, u_static_pressure_variance = _K24.unpack_from(payload, 0)
    return (
        _K26.pack(
            _K2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _K25, u_static_pressure,
            u_static_pressure_variance,
        ),
        receive_ns,
    )


def pressure_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'pressure', ROS -> UAVCAN: CDR -> payload.

    sensor_msgs/FluidPressure -> uavcan.equipment.air_data.StaticPressure
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _K11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 7
    if size < offset + 20:
        raise WireError('CDR: truncated')
    fluid_pressure, variance = _K27.unpack_from(cdr, offset + 4)
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
    return _K28.pack(
        static_pressure if -3.4028234663852886e+38 <= static_pressure <= 3.4028234663852886e+38 else _clamp(
            static_pressure, 3.4028234663852886e+38,
        ),
        _f16(static_pressure_variance),
    )


def battery_state_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'battery_state', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.power.BatteryInfo -> sensor_msgs/BatteryState
    """
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    if _n < 23:
        raise WireError('uavcan.equipment.power.BatteryInfo: payload too short')
    u_temperature, u_voltage, u_current = _K29.unpack_from(payload, 0)
    _t1 = _P >> (_L - 137) & 0x7f
    u_state_of_charge_pct = _t1 & 0x7f
    return (
        _K33.pack(
            _K2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _K30, u_voltage,
            u_temperature - 273.15, u_current, _K31, u_state_of_charge_pct * 0.01, _K32,
        ),
        receive_ns,
    )


def battery_state_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'battery_state', ROS -> UAVCAN: CDR -> payload.

    sensor_msgs/BatteryState -> uavcan.equipment.power.BatteryInfo
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _K11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 40:
        raise WireError('CDR: truncated')
    voltage, temperature, current, percentage, count = _K34.unpack_from(cdr, offset + 4)
    offset += 36
    if size < offset + 4 + count * 4:
        raise WireError('CDR: sequence beyond the buffer')
    offset += count * 4
    if size < offset + 8:
        raise WireError('CDR: truncated')
    count_2, = _K35.unpack_from(cdr, offset + 4)
    offset += 4
    if size < offset + 4 + count_2 * 4:
        raise WireError('CDR: sequence beyond the buffer')
    offset += count_2 * 4
    if size < offset + 8:
        raise WireError('CDR: truncated')
    length_2, = _K35.unpack_from(cdr, offset + 4)
    offset += 4
    if length_2 and (size < offset + 4 + length_2 or cdr[offset + 3 + length_2] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length_2
    offset += -offset & 3
    if size < offset + 8:
        raise WireError('CDR: truncated')
    length_3, = _K35.unpack_from(cdr, offset + 4)
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
    _v1 = (state_of_charge_pct & 0x7f) << 7
    return _K36.pack(_f16(temperature_2), _f16(voltage_2), _f16(current_2)) + _v1.to_bytes(4, 'big') + _K37


def battery_info_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'battery_info', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.power.BatteryInfo -> sam_msgs/BatteryInfo
    """
    _n = len(payload)
    _L = _n << 3
    if _n < 23:
        raise WireError('uavcan.equipment.power.BatteryInfo: payload too short')
    (
        u_temperature, u_voltage, u_current, u_average_power_10sec, u_remaining_capacity_wh,
        u_full_charge_capacity_wh, u_hours_to_full_charge,
    ) = _K38.unpack_from(payload, 0)
    _t1 = int.from_bytes(payload[14:18], 'big')
    u_status_flags = (_t1 >> 24 & 0xff) | (_t1 >> 21 & 0x7) << 8
    u_state_of_health_pct = _t1 >> 14 & 0x7f
    u_state_of_charge_pct = _t1 >> 7 & 0x7f
    u_state_of_charge_pct_stdev = _t1 & 0x7f
    u_battery_id, u_model_instance_id = _K39.unpack_from(payload, 18)
    _o = 184
    _t2 = (_L - _o - 8) // 8 + 1 if _L - _o >= 8 else 0
    u_model_name = list(payload[_o >> 3:(_o >> 3) + _t2])
    if len(list(u_model_name)) > 31:
        raise WireError('model_name: more than 31 elements for the ROS field')
    model_name = list(u_model_name)
    return (
        (
            _K40.pack(
                _K2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _K30, u_temperature, u_voltage,
                u_current, u_average_power_10sec, u_remaining_capacity_wh, u_full_charge_capacity_wh,
                u_hours_to_full_charge, u_status_flags, u_state_of_health_pct, u_state_of_charge_pct,
                u_state_of_charge_pct_stdev, u_battery_id, u_model_instance_id,
            )
            + _K35.pack(len(model_name))
            + bytes(model_name)
        ),
        receive_ns,
    )


def battery_info_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'battery_info', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/BatteryInfo -> uavcan.equipment.power.BatteryInfo
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _K11.unpack_from(cdr, 4)
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
    ) = _K41.unpack_from(cdr, offset + 4)
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
    model_name_2 = list(model_name)
    _v1 = status_flags_2 & 0x7ff
    _v2 = (_v1 & 0xff) << 3 | _v1 >> 8
    _v3 = (
        _v2 << 21
        | (state_of_health_pct_2 & 0x7f) << 14
        | (state_of_charge_pct_2 & 0x7f) << 7
        | state_of_charge_pct_stdev_2 & 0x7f
    )
    return (
        _K42.pack(
            _f16(temperature_2), _f16(voltage_2), _f16(current_2), _f16(average_power_10sec_2),
            _f16(remaining_capacity_wh_2), _f16(full_charge_capacity_wh_2), _f16(hours_to_full_charge_2),
        )
        + _v3.to_bytes(4, 'big')
        + _K39.pack(battery_id, model_instance_id)
        + bytes(model_name_2)
    )


def altitude_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'altitude', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    sam.sensor.Altitude -> sensor_msgs/Range
    """
    _n = len(payload)
    if _n < 13:
        raise WireError('sam.sensor.Altitude: payload too short')
    _t1 = _K43.unpack_from(payload, 0)
    u_timestamp_usec = int.from_bytes(_t1[0], 'little')
    u_altitude = _t1[1]
    u_altitude_variance = _t1[2]
    us = u_timestamp_usec
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
        _K46.pack(_K2, sec, nanosec, _K44, _K45, u_altitude, u_altitude_variance),
        sec * 1_000_000_000 + nanosec,
    )


def altitude_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'altitude', ROS -> UAVCAN: CDR -> payload.

    sensor_msgs/Range -> sam.sensor.Altitude
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _K5.unpack_from(cdr, 4)
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
    range_2, variance = _K47.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('altitude.timestamp.usec')
        us = 0
    altitude_variance = variance
    if altitude_variance > 65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = 65504.0
    elif altitude_variance < -65504.0:
        stats.saturate('altitude.altitude_variance')
        altitude_variance = -65504.0
    return _K48.pack(
        (us & 0xffffffffffffff).to_bytes(7, 'little'),
        range_2 if -3.4028234663852886e+38 <= range_2 <= 3.4028234663852886e+38 else _clamp(
            range_2, 3.4028234663852886e+38,
        ),
        _f16(altitude_variance),
    )


def thruster_rpms_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thruster_rpms', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.esc.RPMCommand -> sam_msgs/ThrusterRPMs
    """
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    _o = 0
    _t1 = (_L - _o - 8) // 18 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 18 < 18:
        raise WireError('uavcan.equipment.esc.RPMCommand: tail array element cut short')
    _t2 = _P >> (_L - _o - _t1 * 18) & ((1 << _t1 * 18) - 1)
    u_rpm = [
        (
            (
                ((_t2 >> _s) >> 10 & 0xff) | ((_t2 >> _s) >> 2 & 0xff) << 8 | ((_t2 >> _s) & 0x3) << 16
            ) ^ 0x20000
        ) - 0x20000 for _s in range((_t1 - 1) * 18, -1, -18)
    ]
    rpm = list(u_rpm)
    if len(rpm) < 2:  # the element this mapping reads is missing
        stats.reject('thruster_rpms.rpm[1]')
        return None
    return (
        _K50.pack(_K2, rpm[0], rpm[1], receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _K49),
        receive_ns,
    )


def thruster_rpms_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thruster_rpms', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/ThrusterRPMs -> uavcan.equipment.esc.RPMCommand
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 24:
        raise WireError('CDR: truncated')
    thruster_1_rpm, thruster_2_rpm, length = _K51.unpack_from(cdr, 4)
    offset = 20
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    rpm_0 = thruster_1_rpm
    if rpm_0 > 131071:
        stats.saturate('thruster_rpms.rpm[0]')
        rpm_0 = 131071
    elif rpm_0 < -131072:
        stats.saturate('thruster_rpms.rpm[0]')
        rpm_0 = -131072
    rpm_1 = thruster_2_rpm
    if rpm_1 > 131071:
        stats.saturate('thruster_rpms.rpm[1]')
        rpm_1 = 131071
    elif rpm_1 < -131072:
        stats.saturate('thruster_rpms.rpm[1]')
        rpm_1 = -131072
    _v1 = rpm_0 & 0x3ffff
    _v2 = (_v1 & 0xff) << 10 | (_v1 >> 8 & 0xff) << 2 | _v1 >> 16
    _v3 = rpm_1 & 0x3ffff
    _v4 = (_v3 & 0xff) << 10 | (_v3 >> 8 & 0xff) << 2 | _v3 >> 16
    _a = _v2 << 18 | _v4
    return (_a << 4).to_bytes(5, 'big')


def thrust_vector_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thrust_vector', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/ThrusterAngles
    """
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    commands_actuator_id_0 = _item(u_commands, 0, 0)
    if commands_actuator_id_0 is None:  # no item for this mapping
        stats.reject('thrust_vector.commands[actuator_id=0]')
        return None
    commands_actuator_id_1 = _item(u_commands, 0, 1)
    if commands_actuator_id_1 is None:  # no item for this mapping
        stats.reject('thrust_vector.commands[actuator_id=1]')
        return None
    return (
        _K53.pack(
            _K2, commands_actuator_id_0[2], commands_actuator_id_1[2], receive_ns // 1_000_000_000,
            receive_ns % 1_000_000_000, _K49,
        ),
        receive_ns,
    )


def thrust_vector_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thrust_vector', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/ThrusterAngles -> uavcan.equipment.actuator.ArrayCommand
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 24:
        raise WireError('CDR: truncated')
    thruster_vertical_radians, thruster_horizontal_radians, length = _K54.unpack_from(cdr, 4)
    offset = 20
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    commands_actuator_id_0_command_value = thruster_vertical_radians
    if commands_actuator_id_0_command_value != commands_actuator_id_0_command_value:  # NaN
        stats.reject_nan('thrust_vector.commands[actuator_id=0].command_value')
        return None
    if commands_actuator_id_0_command_value < -0.12:
        stats.saturate('thrust_vector.commands[actuator_id=0].command_value')
        commands_actuator_id_0_command_value = -0.12
    elif commands_actuator_id_0_command_value > 0.12:
        stats.saturate('thrust_vector.commands[actuator_id=0].command_value')
        commands_actuator_id_0_command_value = 0.12
    commands_actuator_id_1_command_value = thruster_horizontal_radians
    if commands_actuator_id_1_command_value != commands_actuator_id_1_command_value:  # NaN
        stats.reject_nan('thrust_vector.commands[actuator_id=1].command_value')
        return None
    if commands_actuator_id_1_command_value < -0.12:
        stats.saturate('thrust_vector.commands[actuator_id=1].command_value')
        commands_actuator_id_1_command_value = -0.12
    elif commands_actuator_id_1_command_value > 0.12:
        stats.saturate('thrust_vector.commands[actuator_id=1].command_value')
        commands_actuator_id_1_command_value = 0.12
    return _K55.pack(
        0, 1, _f16(commands_actuator_id_0_command_value), 1, 1, _f16(commands_actuator_id_1_command_value),
    )


def ballast_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'ballast', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/BallastAngles
    """
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    commands_actuator_id_2 = _item(u_commands, 0, 2)
    if commands_actuator_id_2 is None:  # no item for this mapping
        stats.reject('ballast.commands[actuator_id=2]')
        return None
    commands_actuator_id_3 = _item(u_commands, 0, 3)
    if commands_actuator_id_3 is None:  # no item for this mapping
        stats.reject('ballast.commands[actuator_id=3]')
        return None
    return (
        _K53.pack(
            _K2, commands_actuator_id_2[2], commands_actuator_id_3[2], receive_ns // 1_000_000_000,
            receive_ns % 1_000_000_000, _K49,
        ),
        receive_ns,
    )


def ballast_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'ballast', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/BallastAngles -> uavcan.equipment.actuator.ArrayCommand
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 24:
        raise WireError('CDR: truncated')
    weight_1_offset_radians, weight_2_offset_radians, length = _K54.unpack_from(cdr, 4)
    offset = 20
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    commands_actuator_id_2_command_value = weight_1_offset_radians
    if commands_actuator_id_2_command_value != commands_actuator_id_2_command_value:  # NaN
        stats.reject_nan('ballast.commands[actuator_id=2].command_value')
        return None
    if commands_actuator_id_2_command_value < -1.5708:
        stats.saturate('ballast.commands[actuator_id=2].command_value')
        commands_actuator_id_2_command_value = -1.5708
    elif commands_actuator_id_2_command_value > 1.5708:
        stats.saturate('ballast.commands[actuator_id=2].command_value')
        commands_actuator_id_2_command_value = 1.5708
    commands_actuator_id_3_command_value = weight_2_offset_radians
    if commands_actuator_id_3_command_value != commands_actuator_id_3_command_value:  # NaN
        stats.reject_nan('ballast.commands[actuator_id=3].command_value')
        return None
    if commands_actuator_id_3_command_value < -1.5708:
        stats.saturate('ballast.commands[actuator_id=3].command_value')
        commands_actuator_id_3_command_value = -1.5708
    elif commands_actuator_id_3_command_value > 1.5708:
        stats.saturate('ballast.commands[actuator_id=3].command_value')
        commands_actuator_id_3_command_value = 1.5708
    return _K55.pack(
        2, 1, _f16(commands_actuator_id_2_command_value), 3, 1, _f16(commands_actuator_id_3_command_value),
    )


def longitudinal_weight_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'longitudinal_weight', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/PercentStamped
    """
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    commands_actuator_id_4 = _item(u_commands, 0, 4)
    if commands_actuator_id_4 is None:  # no item for this mapping
        stats.reject('longitudinal_weight.commands[actuator_id=4]')
        return None
    return (
        _K56.pack(
            _K2, commands_actuator_id_4[2] * 100.0, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000,
            _K49,
        ),
        receive_ns,
    )


def longitudinal_weight_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'longitudinal_weight', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/PercentStamped -> uavcan.equipment.actuator.ArrayCommand
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 20:
        raise WireError('CDR: truncated')
    percent, length = _K57.unpack_from(cdr, 4)
    offset = 16
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    commands_actuator_id_4_command_value = percent
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
    return _K58.pack(4, 0, _f16(commands_actuator_id_4_command_value))


def buoyancy_piston_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'buoyancy_piston', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.actuator.ArrayCommand -> sam_msgs/PercentStamped
    """
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    commands_actuator_id_5 = _item(u_commands, 0, 5)
    if commands_actuator_id_5 is None:  # no item for this mapping
        stats.reject('buoyancy_piston.commands[actuator_id=5]')
        return None
    return (
        _K56.pack(
            _K2, commands_actuator_id_5[2] * 100.0, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000,
            _K49,
        ),
        receive_ns,
    )


def buoyancy_piston_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'buoyancy_piston', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/PercentStamped -> uavcan.equipment.actuator.ArrayCommand
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 20:
        raise WireError('CDR: truncated')
    percent, length = _K57.unpack_from(cdr, 4)
    offset = 16
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    commands_actuator_id_5_command_value = percent
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
    return _K58.pack(5, 0, _f16(commands_actuator_id_5_command_value))


def thruster_1_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thruster_1_feedback', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.esc.Status -> sam_msgs/ThrusterFeedback
    """
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    if _n < 14:
        raise WireError('uavcan.equipment.esc.Status: payload too short')
    u_current, u_temperature = _K59.unpack_from(payload, 6)
    _t1 = _P >> (_L - 98) & 0x3ffff
    u_rpm = (((_t1 >> 10 & 0xff) | (_t1 >> 2 & 0xff) << 8 | (_t1 & 0x3) << 16) ^ 0x20000) - 0x20000
    temperature_c = u_temperature - 273.15
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
    return (
        _K60.pack(
            _K2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _K30, u_rpm, u_current,
            temperature_c,
        ),
        receive_ns,
    )


def thruster_1_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thruster_1_feedback', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/ThrusterFeedback -> uavcan.equipment.esc.Status
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _K11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 13:
        raise WireError('CDR: truncated')
    rpm, current, temperature_c = _K61.unpack_from(cdr, offset + 4)
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
    temperature = temperature_c + 273.15
    if temperature > 65504.0:
        stats.saturate('thruster_1_feedback.temperature')
        temperature = 65504.0
    elif temperature < -65504.0:
        stats.saturate('thruster_1_feedback.temperature')
        temperature = -65504.0
    _v1 = rpm_2 & 0x3ffff
    _v2 = (_v1 & 0xff) << 10 | (_v1 >> 8 & 0xff) << 2 | _v1 >> 16
    _a = _v2 << 12
    return _K62.pack(_f16(current_2), _f16(temperature)) + (_a << 2).to_bytes(4, 'big')


def thruster_2_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thruster_2_feedback', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    uavcan.equipment.esc.Status -> sam_msgs/ThrusterFeedback
    """
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    if _n < 14:
        raise WireError('uavcan.equipment.esc.Status: payload too short')
    u_current, u_temperature = _K59.unpack_from(payload, 6)
    _t1 = _P >> (_L - 98) & 0x3ffff
    u_rpm = (((_t1 >> 10 & 0xff) | (_t1 >> 2 & 0xff) << 8 | (_t1 & 0x3) << 16) ^ 0x20000) - 0x20000
    temperature_c = u_temperature - 273.15
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
    return (
        _K60.pack(
            _K2, receive_ns // 1_000_000_000, receive_ns % 1_000_000_000, _K30, u_rpm, u_current,
            temperature_c,
        ),
        receive_ns,
    )


def thruster_2_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thruster_2_feedback', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/ThrusterFeedback -> uavcan.equipment.esc.Status
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    length, = _K11.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 13:
        raise WireError('CDR: truncated')
    rpm, current, temperature_c = _K61.unpack_from(cdr, offset + 4)
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
    temperature = temperature_c + 273.15
    if temperature > 65504.0:
        stats.saturate('thruster_2_feedback.temperature')
        temperature = 65504.0
    elif temperature < -65504.0:
        stats.saturate('thruster_2_feedback.temperature')
        temperature = -65504.0
    _v1 = rpm_2 & 0x3ffff
    _v2 = (_v1 & 0xff) << 10 | (_v1 >> 8 & 0xff) << 2 | _v1 >> 16
    _a = _v2 << 12 | 0x1
    return _K62.pack(_f16(current_2), _f16(temperature)) + (_a << 2).to_bytes(4, 'big')


def thrust_vector_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'thrust_vector_feedback', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    sam.actuator.ThrustVectorFeedback -> sam_msgs/ThrustVectorFeedback
    """
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    if _n < 11:
        raise WireError('sam.actuator.ThrustVectorFeedback: payload too short')
    _t1 = _K14.unpack_from(payload, 0)
    u_timestamp_usec = int.from_bytes(_t1[0], 'little')
    _t2 = _P >> (_L - 82) & 0x3ffffff
    u_vertical_mrad = (((_t2 >> 18 & 0xff) | (_t2 >> 13 & 0x1f) << 8) ^ 0x1000) - 0x1000
    u_horizontal_mrad = (((_t2 >> 5 & 0xff) | (_t2 & 0x1f) << 8) ^ 0x1000) - 0x1000
    us = u_timestamp_usec
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
    return (
        _K63.pack(_K2, sec, nanosec, _K30, u_vertical_mrad, u_horizontal_mrad), sec * 1_000_000_000 + nanosec,
    )


def thrust_vector_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'thrust_vector_feedback', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/ThrustVectorFeedback -> sam.actuator.ThrustVectorFeedback
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _K5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 1
    if size < offset + 8:
        raise WireError('CDR: truncated')
    vertical_mrad, horizontal_mrad = _K64.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('thrust_vector_feedback.timestamp.usec')
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
    _v1 = vertical_mrad_2 & 0x1fff
    _v2 = (_v1 & 0xff) << 5 | _v1 >> 8
    _v3 = horizontal_mrad_2 & 0x1fff
    _v4 = (_v3 & 0xff) << 5 | _v3 >> 8
    _a = _v2 << 13 | _v4
    return _K14.pack((us & 0xffffffffffffff).to_bytes(7, 'little')) + (_a << 6).to_bytes(4, 'big')


def longitudinal_weight_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'longitudinal_weight_feedback', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    sam.actuator.PositionFeedback -> sam_msgs/PositionFeedback
    """
    _n = len(payload)
    if _n < 12:
        raise WireError('sam.actuator.PositionFeedback: payload too short')
    _t1 = _K65.unpack_from(payload, 0)
    u_timestamp_usec = int.from_bytes(_t1[0], 'little')
    u_percent = _t1[1]
    u_encoder_count = int.from_bytes(_t1[2], 'little')
    us = u_timestamp_usec
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
    return _K66.pack(_K2, sec, nanosec, _K30, u_percent, u_encoder_count), sec * 1_000_000_000 + nanosec


def longitudinal_weight_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'longitudinal_weight_feedback', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _K5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 12:
        raise WireError('CDR: truncated')
    percent, encoder_count = _K67.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('longitudinal_weight_feedback.timestamp.usec')
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
    return _K68.pack(
        (us & 0xffffffffffffff).to_bytes(7, 'little'), _f16(percent_2),
        (encoder_count_2 & 0xffffff).to_bytes(3, 'little'),
    )


def buoyancy_piston_feedback_wire_to_ros(
    payload: bytes | bytearray | memoryview, receive_ns: int, stats: Any
) -> tuple[bytes, int] | None:
    """Mapping 'buoyancy_piston_feedback', UAVCAN -> ROS: payload -> (CDR, stamp in ns).

    sam.actuator.PositionFeedback -> sam_msgs/PositionFeedback
    """
    _n = len(payload)
    if _n < 12:
        raise WireError('sam.actuator.PositionFeedback: payload too short')
    _t1 = _K65.unpack_from(payload, 0)
    u_timestamp_usec = int.from_bytes(_t1[0], 'little')
    u_percent = _t1[1]
    u_encoder_count = int.from_bytes(_t1[2], 'little')
    us = u_timestamp_usec
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
    return _K66.pack(_K2, sec, nanosec, _K30, u_percent, u_encoder_count), sec * 1_000_000_000 + nanosec


def buoyancy_piston_feedback_ros_to_wire(cdr: bytes | memoryview, stats: Any) -> bytes | None:
    """Mapping 'buoyancy_piston_feedback', ROS -> UAVCAN: CDR -> payload.

    sam_msgs/PositionFeedback -> sam.actuator.PositionFeedback
    """
    size = len(cdr)
    if size < 4 or cdr[0] != 0 or cdr[1] != 1:
        raise WireError('CDR: not little-endian plain CDR (encapsulation 00 01)')
    if size < 16:
        raise WireError('CDR: truncated')
    header_stamp_sec, header_stamp_nanosec, length = _K5.unpack_from(cdr, 4)
    offset = 12
    if length and (size < offset + 4 + length or cdr[offset + 3 + length] != 0):
        raise WireError('CDR: string beyond the buffer or without its NUL')
    offset += length
    offset += -offset & 3
    if size < offset + 12:
        raise WireError('CDR: truncated')
    percent, encoder_count = _K67.unpack_from(cdr, offset + 4)
    us = header_stamp_sec * 1_000_000 + header_stamp_nanosec // 1000
    if us < 0:
        stats.saturate('buoyancy_piston_feedback.timestamp.usec')
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
    return _K68.pack(
        (us & 0xffffffffffffff).to_bytes(7, 'little'), _f16(percent_2),
        (encoder_count_2 & 0xffffff).to_bytes(3, 'little'),
    )


def _wire_matches_thruster_rpms(payload: bytes | bytearray | memoryview) -> bool:
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    _o = 0
    _t1 = (_L - _o - 8) // 18 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 18 < 18:
        raise WireError('uavcan.equipment.esc.RPMCommand: tail array element cut short')
    _t2 = _P >> (_L - _o - _t1 * 18) & ((1 << _t1 * 18) - 1)
    u_rpm = [
        (
            (
                ((_t2 >> _s) >> 10 & 0xff) | ((_t2 >> _s) >> 2 & 0xff) << 8 | ((_t2 >> _s) & 0x3) << 16
            ) ^ 0x20000
        ) - 0x20000 for _s in range((_t1 - 1) * 18, -1, -18)
    ]
    return len(u_rpm) > 1


def _wire_matches_thrust_vector(payload: bytes | bytearray | memoryview) -> bool:
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    return _item(u_commands, 0, 0) is not None and _item(u_commands, 0, 1) is not None


def _wire_matches_ballast(payload: bytes | bytearray | memoryview) -> bool:
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    return _item(u_commands, 0, 2) is not None and _item(u_commands, 0, 3) is not None


def _wire_matches_longitudinal_weight(payload: bytes | bytearray | memoryview) -> bool:
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    return _item(u_commands, 0, 4) is not None


def _wire_matches_buoyancy_piston(payload: bytes | bytearray | memoryview) -> bool:
    _n = len(payload)
    _L = _n << 3
    _o = 0
    _t1 = (_L - _o - 8) // 32 + 1 if _L - _o >= 8 else 0
    if _t1 and _L - _o - (_t1 - 1) * 32 < 32:
        raise WireError('uavcan.equipment.actuator.ArrayCommand: tail array element cut short')
    u_commands = list(_K52.iter_unpack(payload[_o >> 3:(_o >> 3) + _t1 * 4]))
    return _item(u_commands, 0, 5) is not None


def _wire_matches_thruster_1_feedback(payload: bytes | bytearray | memoryview) -> bool:
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    if _n < 14:
        raise WireError('uavcan.equipment.esc.Status: payload too short')
    _t1 = _P >> (_L - 110) & 0x1f
    u_esc_index = _t1 & 0x1f
    return u_esc_index == 0


def _wire_matches_thruster_2_feedback(payload: bytes | bytearray | memoryview) -> bool:
    _n = len(payload)
    _L = _n << 3
    _P = int.from_bytes(payload, 'big')
    if _n < 14:
        raise WireError('uavcan.equipment.esc.Status: payload too short')
    _t1 = _P >> (_L - 110) & 0x1f
    u_esc_index = _t1 & 0x1f
    return u_esc_index == 1


# mapping name -> whether a payload is the mapping's (MATCHES of convert_v0.py, on the payload)
WIRE_MATCHES: dict[str, Callable[[bytes | bytearray | memoryview], bool]] = {
    'thruster_rpms': _wire_matches_thruster_rpms,
    'thrust_vector': _wire_matches_thrust_vector,
    'ballast': _wire_matches_ballast,
    'longitudinal_weight': _wire_matches_longitudinal_weight,
    'buoyancy_piston': _wire_matches_buoyancy_piston,
    'thruster_1_feedback': _wire_matches_thruster_1_feedback,
    'thruster_2_feedback': _wire_matches_thruster_2_feedback,
}

# mapping name -> (wire_to_ros, ros_to_wire)
CODECS: dict[str, tuple[Callable[..., Any], Callable[..., Any]]] = {
    'imu': (imu_wire_to_ros, imu_ros_to_wire),
    'magnetic_field': (magnetic_field_wire_to_ros, magnetic_field_ros_to_wire),
    'gps_fix': (gps_fix_wire_to_ros, gps_fix_ros_to_wire),
    'pressure': (pressure_wire_to_ros, pressure_ros_to_wire),
    'battery_state': (battery_state_wire_to_ros, battery_state_ros_to_wire),
    'battery_info': (battery_info_wire_to_ros, battery_info_ros_to_wire),
    'altitude': (altitude_wire_to_ros, altitude_ros_to_wire),
    'thruster_rpms': (thruster_rpms_wire_to_ros, thruster_rpms_ros_to_wire),
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
