"""The UDP packet format of dronecan's ``mcast:`` driver, and its group/port per bus number.

One CAN frame per datagram, all little endian (dronecan/driver/mcast.py)::

    magic 0x2934 (u16) | CRC-16-CCITT of the rest (u16) | flags (u16, bit 0 = CAN FD) |
    CAN id (u32, bit 31 = 29-bit id) | data (0..8 bytes, 0..64 with CAN FD)

Bus ``B`` is the group ``239.65.82.B`` on UDP port 57732. dronecan does no length checks on receive; here a
datagram that could not be a CAN frame is rejected with a :class:`PacketError` naming why, so it can be counted.
"""

from __future__ import annotations

import binascii
import struct

from dronecan.driver.common import CANFrame

__all__ = [
    "MCAST_ADDRESS_BASE",
    "MCAST_FLAG_CANFD",
    "MCAST_MAGIC",
    "MCAST_PORT",
    "PacketError",
    "decode_packet",
    "encode_packet",
    "group_for_bus",
]

MCAST_ADDRESS_BASE = "239.65.82"
MCAST_PORT = 57732
MCAST_MAGIC = 0x2934
MCAST_FLAG_CANFD = 0x0001
HEADER = struct.Struct("<HHHI")
_BODY_HEAD = struct.Struct("<HI")
_EXTENDED = 1 << 31
_CANFD_LENGTHS = frozenset((*range(9), 12, 16, 20, 24, 32, 48, 64))


class PacketError(ValueError):
    """A datagram on the bus that is not a valid ``mcast:`` CAN frame."""


def group_for_bus(bus: int) -> str:
    """The multicast group of a bus number, as dronecan's ``mcast:<bus>``.

    >>> group_for_bus(0)
    '239.65.82.0'
    >>> group_for_bus(256)
    Traceback (most recent call last):
    ...
    ValueError: mcast bus number must be 0..255, got 256
    """
    if not 0 <= bus <= 255:
        raise ValueError(f"mcast bus number must be 0..255, got {bus}")
    return f"{MCAST_ADDRESS_BASE}.{bus}"


def _crc16(data: bytes) -> int:
    # binascii.crc_hqx is the same CRC-16-CCITT (poly 0x1021, no reflection) as dronecan.dsdl.common.crc16_from_bytes
    # with its 0xFFFF seed, in C.
    return binascii.crc_hqx(data, 0xFFFF)


def encode_packet(frame: CANFrame) -> bytes:
    """One datagram for one frame.

    >>> encode_packet(CANFrame(0x1403EB0A, bytearray(b"\\x01\\xc0"), True)).hex()
    '342997b500000aeb039401c0'
    """
    can_id = frame.id | (_EXTENDED if frame.extended else 0)
    body = _BODY_HEAD.pack(MCAST_FLAG_CANFD if frame.canfd else 0, can_id) + bytes(frame.data)
    return struct.pack("<HH", MCAST_MAGIC, _crc16(body)) + body


def decode_packet(data: bytes, ts_monotonic: float = 0.0, ts_real: float = 0.0) -> CANFrame:
    """The frame in a datagram; :class:`PacketError` if it is not one. ``ts_monotonic``, ``ts_real``: its reception
    times (0: now, as dronecan's CANFrame stamps a frame).

    >>> f = decode_packet(encode_packet(CANFrame(0x123, bytearray(b"ab"), False)))
    >>> (hex(f.id), bytes(f.data), f.extended, f.canfd)
    ('0x123', b'ab', False, False)
    >>> decode_packet(b"\\x34\\x29")
    Traceback (most recent call last):
    ...
    sam_runtime.dronecan_io.mcast_packet.PacketError: 2 bytes, shorter than the 10-byte header
    """
    if len(data) < HEADER.size:
        raise PacketError(f"{len(data)} bytes, shorter than the {HEADER.size}-byte header")
    magic, crc, flags, can_id = HEADER.unpack_from(data)
    if magic != MCAST_MAGIC:
        raise PacketError(f"magic 0x{magic:04x}, expected 0x{MCAST_MAGIC:04x}")
    if crc != _crc16(data[4:]):
        raise PacketError(f"packet CRC 0x{crc:04x} does not match its content")
    payload = data[HEADER.size:]
    canfd = bool(flags & MCAST_FLAG_CANFD)
    if (len(payload) not in _CANFD_LENGTHS) if canfd else len(payload) > 8:
        raise PacketError(f"{len(payload)} data bytes in a {'CAN FD' if canfd else 'classic CAN'} frame")
    extended = bool(can_id & _EXTENDED)
    can_id &= 0x1FFFFFFF
    if not extended and can_id > 0x7FF:
        raise PacketError(f"11-bit frame with id 0x{can_id:x}")
    return CANFrame(can_id, bytearray(payload), extended, ts_monotonic=ts_monotonic, ts_real=ts_real, canfd=canfd)
