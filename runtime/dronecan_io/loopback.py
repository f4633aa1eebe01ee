"""A dronecan CAN driver for a multicast bus that never leaves the machine.

Same packets, groups and ports as dronecan's own ``mcast:`` driver (see :mod:`.mcast_packet`), so the dronecan
library and its GUI tool can join the bus, but:

- it sends with ``IP_MULTICAST_IF`` 127.0.0.1 and TTL 0 and joins the group on 127.0.0.1 only: no frame and no
  IGMP report leaves through the outward interface (dronecan's ``mcast:`` joins and sends on the default route);
- no IO process and no busy wait: a non-blocking socket whose :meth:`fileno` an event loop can watch, and a
  blocking :meth:`receive` (dronecan's ``Node.spin(timeout)``) that sleeps in ``poll``.

Like dronecan's SocketCAN and ``mcast:`` drivers it does not hand a node its own frames back (dronecan's Node has
no loopback handling: an echo would be received as a transfer from itself); on Linux a socket filter drops them in
the kernel. Frames of other drivers on the same bus in the same process are delivered. Datagrams the kernel drops
because the node did not read in time are counted, not lost silently.

An :class:`Acceptance` filter (a CAN controller's acceptance filter: the service transfers addressed to one node and
the broadcasts of some data types) drops every other frame in the kernel, so a node that listens to little (a
simulated sensor) is not woken by every frame of the bus. The kernel counts the datagrams a socket filter drops
together with those it drops for a full buffer: under an acceptance filter ``rx_overflow`` is not counted.

Each frame sent leaves its transmission window, the bounds of its send system call (``last_tx_ns``, with the
count ``frames_sent``): the time-sync master's transmission time on this bus. Each frame received is stamped with
the time the kernel received it (``SO_TIMESTAMPNS``; ``ts_monotonic`` and ``ts_real``), not the time a possibly
held-up loop read it: a time-sync slave's reception time.
"""

from __future__ import annotations

import ctypes
import errno
import select
import socket
import struct
import time
from dataclasses import dataclass

from dronecan.driver.common import AbstractDriver, CANFrame, DriverError, TxQueueFullError

from sam_runtime.dronecan_io.drops import DropCounter, DropReason
from sam_runtime.dronecan_io.mcast_packet import MCAST_PORT, PacketError, decode_packet, encode_packet, group_for_bus

__all__ = ["LOOPBACK_ADDRESS", "Acceptance", "LoopbackMulticastDriver"]

LOOPBACK_ADDRESS = "127.0.0.1"
OVERFLOW_CHECK_S = 0.05
_RECV_SIZE = 2048  # more than the largest valid packet (74 bytes), so an oversized one is seen whole and rejected


@dataclass(frozen=True)
class Acceptance:
    """Which frames a node takes: service frames (requests and responses) addressed to ``node_id`` and message
    frames of ``data_type_ids`` (from any source node but the anonymous one).

    >>> a = Acceptance(21, frozenset({1031}))
    >>> a.accepts(0x1404071F), a.accepts(0x1403EB0A), a.accepts(0x1401958B), a.accepts(0x1401968B)
    (True, False, True, False)
    """

    node_id: int | None
    data_type_ids: frozenset[int] = frozenset()

    def accepts(self, can_id: int) -> bool:
        if can_id & 0x80:  # a service frame: to whom
            return self.node_id is not None and (can_id >> 8) & 0x7F == self.node_id
        return can_id & 0x7F != 0 and (can_id >> 8) & 0xFFFF in self.data_type_ids


class LoopbackMulticastDriver(AbstractDriver):
    """dronecan driver for bus ``bus`` (group 239.65.82.<bus>) on UDP ``port``, confined to 127.0.0.1.

    ``drops`` counts datagrams that are not CAN frames (``bad_packet``), frames lost because the receive buffer was
    full (``rx_overflow``) and frames that could not be sent (``tx_failed``); a :class:`~.node_loop.NodeLoop`
    reports them with its own. ``rcvbuf`` is the receive buffer asked for (the kernel caps it at
    net.core.rmem_max): how long the node may be kept from reading, at a given bus load, before frames are lost.
    """

    def __init__(self, bus: int = 0, port: int = MCAST_PORT, *, drops: DropCounter | None = None,
                 rcvbuf: int = 1 << 21, send_timeout: float = 0.1, accept: Acceptance | None = None) -> None:
        super().__init__()
        if not 1 <= port <= 65535:
            raise ValueError(f"UDP port must be 1..65535, got {port}")
        self.bus = bus
        self.port = port
        self.group = group_for_bus(bus)
        self.drops = drops if drops is not None else DropCounter()
        self.accept = accept
        self._rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self._tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            self._rx.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            self._rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
            # Bound to the group (as dronecan's driver), so unicast to the port and other groups are not received.
            self._rx.bind((self.group, port))
            mreq = socket.inet_aton(self.group) + socket.inet_aton(LOOPBACK_ADDRESS)
            self._rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
            self._rx.setblocking(False)
            try:  # when each datagram arrived, not when it is read (Linux; elsewhere the reading time)
                self._rx.setsockopt(socket.SOL_SOCKET, _SO_TIMESTAMPNS, 1)
            except OSError:
                pass

            self._tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(LOOPBACK_ADDRESS))
            self._tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
            self._tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            self._tx.bind((LOOPBACK_ADDRESS, 0))
            self._tx.connect((self.group, port))
            self._tx.settimeout(send_timeout)
        except OSError as ex:
            self._rx.close()
            self._tx.close()
            raise DriverError(f"cannot open the loopback multicast bus {self.group}:{port}: {ex}") from ex
        # Datagrams from this address are this driver's own (dronecan's mcast: compares the port only). The kernel
        # drops them before they take receive-buffer space (half the buffer on a bus where this node sends as much
        # as it receives) when the filter can be attached; the check in receive() stays for when it cannot.
        self._own_address = self._tx.getsockname()
        self.kernel_self_filter = _attach_self_filter(self._rx, self._own_address, accept)
        self.own_frames_skipped = 0
        # The kernel counts the datagrams it dropped for this socket (full buffer), and this driver's own ones the
        # filter above dropped: one per frame sent. Read when the socket is empty (SO_MEMINFO). The frames an
        # acceptance filter drops are counted there too, indistinguishably.
        self._count_drops = _kernel_drops(self._rx) is not None and not (accept and self.kernel_self_filter)
        self._sent = 0
        # When the last frame was handed to the kernel: the system call's bounds (CLOCK_REALTIME, time.time_ns), so
        # that a time-sync master knows when its frame left however late its caller reads it.
        self.last_tx_ns: tuple[int, int] | None = None
        self._overflow_reported = 0
        # The kernel's drop counter is read when the socket is found empty, at most every OVERFLOW_CHECK_S: a
        # system call per wake-up of a loop that reads every frame at once (hundreds a second) costs more than the
        # frames; an overflow is reported at the next empty read after that (a NodeLoop reads at least once a
        # second), never lost.
        self._next_overflow_check = 0.0
        self._poll = select.poll()
        self._poll.register(self._rx.fileno(), select.POLLIN)
        self._closed = False

    def __repr__(self) -> str:
        return f"{type(self).__name__}(bus={self.bus}, port={self.port})"

    @property
    def receive_buffer_size(self) -> int:
        """What the kernel granted for ``rcvbuf`` (Linux doubles the request, capped by net.core.rmem_max)."""
        return int(self._rx.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF))

    def fileno(self) -> int:
        """The receive socket: readable when :meth:`receive` may return a frame without waiting."""
        self._check_open()
        return self._rx.fileno()

    def receive(self, timeout: float | None = None) -> CANFrame | None:
        """The next frame from another driver on the bus; None when none came within ``timeout`` seconds
        (0: only what is already there; None: wait for ever)."""
        if self._closed:
            self._check_open()
        # (Per frame of the bus: a NodeLoop drains the socket with receive(0) at every wake-up, so the empty read
        # that ends a wake-up takes no clock and no poll, and each frame is stamped once, not again by CANFrame.)
        drain = timeout is not None and timeout <= 0
        deadline = None if timeout is None or drain else time.monotonic() + timeout
        rx = self._rx
        while True:
            try:
                data, ancdata, _flags, source = rx.recvmsg(_RECV_SIZE, _ANC_SIZE)
            except BlockingIOError:
                if self._count_drops and time.monotonic() >= self._next_overflow_check:
                    self._count_overflow()
                if drain or not self._wait_readable(deadline):
                    return None
                continue
            if source == self._own_address:
                self.own_frames_skipped += 1
                continue
            ts_monotonic = ts_real = 0.0  # (0: CANFrame reads the clocks itself)
            for level, kind, cdata in ancdata:
                if kind == _SO_TIMESTAMPNS and level == _SOL_SOCKET and len(cdata) >= _TIMESPEC.size:
                    sec, nsec = _TIMESPEC.unpack_from(cdata)
                    arrived_ns = sec * 1_000_000_000 + nsec
                    ts_real = arrived_ns * 1e-9
                    ts_monotonic = time.monotonic() - (time.time_ns() - arrived_ns) * 1e-9
            try:
                frame = decode_packet(data, ts_monotonic, ts_real)
            except PacketError as ex:
                self.drops.add(DropReason.BAD_PACKET, detail=f"datagram from {source[0]}:{source[1]}: {ex}")
                continue
            if self.accept is not None and not self.kernel_self_filter and not (
                    frame.extended and self.accept.accepts(frame.id)):
                continue  # what the kernel filter would have dropped
            if self._io_hooks:  # (dronecan's _rx_hook, without its two calls per frame when nobody listens)
                self._rx_hook(frame)
            return frame

    def _wait_readable(self, deadline: float | None) -> bool:
        if deadline is None:
            self._poll.poll()
            return True
        left = deadline - time.monotonic()
        if left <= 0:
            return False
        # poll() takes milliseconds; round up so a short timeout does not become a busy loop of zero-waits.
        return bool(self._poll.poll(max(1, int(left * 1000 + 0.999))))

    def send_frame(self, frame: CANFrame) -> None:
        self._check_open()
        packet = encode_packet(frame)
        try:
            before = time.time_ns()
            self._tx.send(packet)
            after = time.time_ns()
        except (TimeoutError, BlockingIOError) as ex:
            self.drops.add(DropReason.TX_FAILED, detail=f"socket full for the send timeout: {ex}")
            raise TxQueueFullError(f"{self!r}: could not send within {self._tx.gettimeout()} s") from ex
        except OSError as ex:
            if ex.errno != errno.ENOBUFS:
                raise DriverError(f"{self!r}: send failed: {ex}") from ex
            self.drops.add(DropReason.TX_FAILED, detail=str(ex))
            raise TxQueueFullError(f"{self!r}: {ex}") from ex
        self._sent += 1
        self.last_tx_ns = (before, after)
        self._tx_hook(frame)

    @property
    def frames_sent(self) -> int:
        return self._sent

    def _count_overflow(self) -> None:
        self._next_overflow_check = time.monotonic() + OVERFLOW_CHECK_S
        kernel_drops = _kernel_drops(self._rx)
        if kernel_drops is None:
            return
        # An own frame still on its way to the filter makes the difference smaller, never larger: an overflow may
        # be reported a little late, never invented.
        lost = kernel_drops - (self._sent if self.kernel_self_filter else 0) - self._overflow_reported
        if lost > 0:
            self._overflow_reported += lost
            self.drops.add(DropReason.RX_OVERFLOW, detail=f"the receive buffer of {self!r} was full", count=lost)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._rx.close()
        self._tx.close()

    def _check_open(self) -> None:
        if self._closed:
            raise DriverError(f"{self!r} is closed")

    def __enter__(self) -> LoopbackMulticastDriver:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()


_SO_ATTACH_FILTER = 26  # Linux; not exported by the socket module
_SO_TIMESTAMPNS = 35  # Linux; also the cmsg type SCM_TIMESTAMPNS
_SOL_SOCKET = socket.SOL_SOCKET
_TIMESPEC = struct.Struct("qq")
_ANC_SIZE = 64  # room for one struct timespec message
_SO_MEMINFO = 55  # Linux >= 4.12: u32[SK_MEMINFO_VARS]
_MEMINFO = struct.Struct("9I")
_SK_MEMINFO_DROPS = 8


def _kernel_drops(sock: socket.socket) -> int | None:
    """How many datagrams the kernel dropped for ``sock`` so far (sk_drops), or None where it cannot tell."""
    try:
        raw = sock.getsockopt(socket.SOL_SOCKET, _SO_MEMINFO, _MEMINFO.size)
    except OSError:
        return None
    return _MEMINFO.unpack(raw)[_SK_MEMINFO_DROPS] if len(raw) == _MEMINFO.size else None
_SKF_NET_OFF = -0x100000
_BPF = struct.Struct("HBBI")


def _attach_self_filter(sock: socket.socket, own: tuple[str, int], accept: Acceptance | None = None) -> bool:
    """A classic BPF socket filter dropping datagrams from ``own`` (address, port) and, with ``accept``, the frames
    it does not accept; False where unsupported (or the acceptance list is too long for one program).

    A UDP socket's filter sees the packet at its UDP header; the IP source address is reached through
    SKF_NET_OFF. Loads of header fields are in network order and compared as numbers. The CAN id is the
    little-endian u32 at byte 6 of the datagram's payload (:mod:`.mcast_packet`): bytes 14..17 from the UDP header.
    """
    address = struct.unpack("!I", socket.inet_aton(own[0]))[0]
    drop, keep = "drop", "accept"
    program: list[tuple[int, int | str, int | str, int] | str] = [
        (0x20, 0, 0, (_SKF_NET_OFF + 12) & 0xFFFFFFFF),  # A = IP source address
        (0x15, 0, 2, address),                            # A != own address: not this driver's own
        (0x28, 0, 0, 0),                                  # A = UDP source port
        (0x15, drop, 0, own[1]),                          # A == own port: drop
    ]
    if accept is None:
        program.append((0x06, 0, 0, 0xFFFFFFFF))
    else:
        program += [
            (0x30, 0, 0, 14),                             # A = CAN id bits 0..7: service flag, source node
            (0x45, 0, "message", 0x80),                   # not a service frame: a message
            (0x30, 0, 0, 15),                             # A = bits 8..15: request flag, destination node
            (0x54, 0, 0, 0x7F),                           # A &= 0x7F
            (0x15, keep, drop, accept.node_id) if accept.node_id is not None else (0x06, 0, 0, 0),
            "message",
            (0x30, 0, 0, 14),
            (0x54, 0, 0, 0x7F),                           # the source node
            (0x15, drop, 0, 0),                           # anonymous: drop (only 2 bits of its data type id)
            (0x28, 0, 0, 15),                             # A = bytes 15, 16: the data type id, byte-swapped
        ]
        for dtid in sorted(accept.data_type_ids):
            program.append((0x15, keep, 0, ((dtid & 0xFF) << 8) | (dtid >> 8)))
        program.append((0x06, 0, 0, 0))
    program += [drop, (0x06, 0, 0, 0), keep, (0x06, 0, 0, 0xFFFFFFFF)]
    code = _assemble(program)
    if code is None:
        return False
    buf = ctypes.create_string_buffer(b"".join(_BPF.pack(*ins) for ins in code))
    fprog = struct.pack("HL", len(code), ctypes.addressof(buf))
    try:
        sock.setsockopt(socket.SOL_SOCKET, _SO_ATTACH_FILTER, fprog)
    except OSError:
        return False
    return True


def _assemble(program: list[tuple[int, int | str, int | str, int] | str]) -> list[tuple[int, int, int, int]] | None:
    """Instructions with jump targets given as labels (strings in the list) -> relative jumps; None if a jump is
    longer than a classic BPF jump can be (255 instructions)."""
    labels: dict[str, int] = {}
    n = 0
    for item in program:
        if isinstance(item, str):
            labels[item] = n
        else:
            n += 1
    out: list[tuple[int, int, int, int]] = []
    for item in program:
        if isinstance(item, str):
            continue
        code, jt, jf, k = item
        here = len(out) + 1  # jumps are relative to the next instruction
        rel = [labels[j] - here if isinstance(j, str) else j for j in (jt, jf)]
        if not all(0 <= r <= 255 for r in rel):
            return None
        out.append((code, rel[0], rel[1], k))
    return out
