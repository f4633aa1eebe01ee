"""SLCAN (Lawicel ASCII) lines, and the adapter side of the protocol as dronecan's SLCAN driver speaks it.

dronecan's ``slcan:`` driver initialises the adapter with ``C``, ``S<n>``, ``O`` and ``F`` and waits for each to be
acknowledged with CR (BEL is a refusal); then frames go both ways as ``T<id:8 hex><len><data hex>\\r`` (29-bit ids),
``t<id:3 hex>...`` (11-bit) and ``D...`` (CAN FD, dronecan's extension). :class:`SlcanAdapter` is that adapter
without the hardware: feed it what the host wrote, get the replies and the frames to put on a bus; it lets a
serial-port stand-in connect dronecan's SLCAN driver to another bus (tests/helpers/slcan_standin.py).
"""

from __future__ import annotations

import binascii

from dronecan.driver.common import CANFrame

__all__ = ["SlcanAdapter", "SlcanError", "decode_line", "encode_line"]

ACK = b"\r"
NACK = b"\x07"
# S0..S8, as dronecan's driver maps them.
BITRATES = {0: 10_000, 1: 20_000, 2: 50_000, 3: 100_000, 4: 125_000, 5: 250_000, 6: 500_000, 7: 800_000,
            8: 1_000_000}


class SlcanError(ValueError):
    """A line that is not a well-formed SLCAN frame."""


def encode_line(frame: CANFrame) -> bytes:
    """The SLCAN line of a frame.

    >>> encode_line(CANFrame(0x1403EB0A, bytearray(b"\\x01\\xc0"), True))
    b'T1403EB0A201C0\\r'
    >>> encode_line(CANFrame(0x12, bytearray(), False))
    b't0120\\r'
    """
    dlc = CANFrame.datalength_to_dlc(len(frame.data))
    if frame.extended or frame.canfd:
        head = f"{'D' if frame.canfd else 'T'}{frame.id:08X}"
    else:
        head = f"t{frame.id:03X}"
    return f"{head}{dlc:X}{bytes(frame.data).hex().upper()}\r".encode("ascii")


def decode_line(line: bytes) -> CANFrame:
    """The frame of one SLCAN frame line (without its CR); :class:`SlcanError` if it is not one.

    >>> f = decode_line(b"T1403EB0A201C0")
    >>> hex(f.id), bytes(f.data), f.extended
    ('0x1403eb0a', b'\\x01\\xc0', True)
    >>> decode_line(b"T1403EB0A901")
    Traceback (most recent call last):
    ...
    sam_runtime.dronecan_io.slcan.SlcanError: b'T1403EB0A901': length code 9 in a classic CAN frame
    """
    if not line or line[:1] not in (b"T", b"t", b"D"):
        raise SlcanError(f"{line!r}: not a frame line")
    canfd = line[:1] == b"D"
    id_len = 3 if line[:1] == b"t" else 8
    try:
        can_id = int(line[1:1 + id_len], 16)
        dlc = int(line[1 + id_len:2 + id_len], 16)
    except ValueError:
        raise SlcanError(f"{line!r}: bad id or length") from None
    if dlc > 8 and not canfd:
        raise SlcanError(f"{line!r}: length code {dlc} in a classic CAN frame")
    length = CANFrame.dlc_to_datalength(dlc)
    hex_data = line[2 + id_len:2 + id_len + 2 * length]
    # Anything after the data is the optional 4-digit timestamp of the protocol.
    if len(hex_data) != 2 * length or len(line) not in (2 + id_len + 2 * length, 6 + id_len + 2 * length):
        raise SlcanError(f"{line!r}: {length} data bytes announced, line length does not match")
    if can_id > (0x1FFFFFFF if id_len == 8 else 0x7FF):
        raise SlcanError(f"{line!r}: id out of range")
    try:
        data = binascii.a2b_hex(hex_data)
    except binascii.Error:
        raise SlcanError(f"{line!r}: bad data") from None
    return CANFrame(can_id, bytearray(data), id_len == 8, canfd=canfd)


class SlcanAdapter:
    """The command side of an SLCAN adapter.

    >>> a = SlcanAdapter()
    >>> a.feed(b"\\rC\\rS8\\rO\\rF\\r")
    (b'\\r\\r\\r\\rF00\\r', [])
    >>> a.is_open, a.bitrate
    (True, 1000000)
    >>> replies, frames = a.feed(b"T1403EB0A201C0\\rT14")
    >>> replies, [hex(f.id) for f in frames]
    (b'Z\\r', ['0x1403eb0a'])
    >>> a.feed(b"X\\r")
    (b'\\x07', [])
    """

    def __init__(self) -> None:
        self.is_open = False
        self.bitrate: int | None = None
        self.rejected_lines = 0
        self._buffer = b""

    def feed(self, data: bytes) -> tuple[bytes, list[CANFrame]]:
        """Replies to write back to the host, and the frames the host asked to transmit."""
        self._buffer += data
        *lines, self._buffer = self._buffer.split(b"\r")
        replies: list[bytes] = []
        frames: list[CANFrame] = []
        for line in lines:
            reply, frame = self._command(line.strip(b"\n"))
            replies.append(reply)
            if frame is not None:
                frames.append(frame)
        return b"".join(replies), frames

    def to_host(self, frame: CANFrame) -> bytes:
        """The line for a frame received from the bus; nothing while the channel is closed (as an adapter)."""
        return encode_line(frame) if self.is_open else b""

    def _command(self, line: bytes) -> tuple[bytes, CANFrame | None]:
        cmd, arg = line[:1], line[1:]
        if cmd in (b"T", b"t", b"D"):
            if not self.is_open:
                return self._reject()
            try:
                frame = decode_line(line)
            except SlcanError:
                return self._reject()
            return (b"z\r" if cmd == b"t" else b"Z\r"), frame
        if cmd == b"":
            return ACK, None
        if cmd == b"S" and arg.isdigit() and int(arg) in BITRATES and not self.is_open:
            self.bitrate = BITRATES[int(arg)]
            return ACK, None
        if cmd == b"O" and not arg and self.bitrate is not None:
            self.is_open = True
            return ACK, None
        if cmd == b"C" and not arg:
            self.is_open = False
            return ACK, None
        if cmd == b"F" and not arg:
            return b"F00\r", None
        if cmd == b"V" and not arg:
            return b"V1013\r", None
        if cmd == b"N" and not arg:
            return b"NSAM0\r", None
        return self._reject()

    def _reject(self) -> tuple[bytes, None]:
        self.rejected_lines += 1
        return NACK, None
