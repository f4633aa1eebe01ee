"""The Cyphal/UDP receive socket of the loop receivers (:mod:`.udp_receiver` for subjects, :mod:`.udp_sessions` for
pycyphal's presentation-layer sessions): one definition of how it is opened, joins and leaves a group, and stops.

The socket is bound to Cyphal's port on every address: the destination group of each datagram comes with it
(IP_PKTINFO), so one socket serves every group it joined, and only those (IP_MULTICAST_ALL off: Linux's default
delivers every group any socket of the host joined). It is shared with pycyphal's sockets and other nodes of this
host (SO_REUSEADDR and SO_REUSEPORT, set before bind as pycyphal does).
"""

from __future__ import annotations

import asyncio
import logging
import socket

__all__ = [
    "ANC_OVERFLOW_SIZE",
    "ANC_PKTINFO_SIZE",
    "CYPHAL_PORT",
    "IP_PKTINFO",
    "SO_RXQ_OVFL",
    "join_group",
    "leave_group",
    "open_socket",
    "stop_reading",
]

_log = logging.getLogger(__name__)

CYPHAL_PORT = 9382  # pycyphal.transport.udp's CYPHAL_PORT
IP_PKTINFO = 8  # Linux values; Python 3.11's socket module names neither these nor SO_RXQ_OVFL
_IP_MULTICAST_ALL = 49
SO_RXQ_OVFL = 40
ANC_PKTINFO_SIZE = socket.CMSG_SPACE(12)  # struct in_pktinfo
ANC_OVERFLOW_SIZE = socket.CMSG_SPACE(4)  # the kernel's drop counter (uint32)


def open_socket(*, rcvbuf_bytes: int | None = None, overflow_counter: bool = False) -> socket.socket:
    """A non-blocking UDP socket bound to Cyphal's port, with the destination address of each datagram given
    (IP_PKTINFO); ``overflow_counter``: and the kernel's count of datagrams it dropped (SO_RXQ_OVFL)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        sock.setblocking(False)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.setsockopt(socket.IPPROTO_IP, _IP_MULTICAST_ALL, 0)
        sock.setsockopt(socket.IPPROTO_IP, IP_PKTINFO, 1)
        if overflow_counter:
            sock.setsockopt(socket.SOL_SOCKET, SO_RXQ_OVFL, 1)
        if rcvbuf_bytes is not None:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, int(rcvbuf_bytes))
        sock.bind(("", CYPHAL_PORT))  # every destination: the group (IP_PKTINFO) says whose a datagram is
    except BaseException:
        sock.close()
        raise
    return sock


def join_group(sock: socket.socket, group: bytes, iface: bytes) -> None:
    """Join the multicast ``group`` (4 bytes) on the interface address ``iface`` (4 bytes); raises OSError."""
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, group + iface)


def leave_group(sock: socket.socket, group: bytes, iface: bytes) -> None:
    try:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_DROP_MEMBERSHIP, group + iface)
    except OSError as ex:  # the interface went away: the membership went with it
        _log.debug("leaving %s: %s", socket.inet_ntoa(group), ex)


def stop_reading(loop: asyncio.AbstractEventLoop, sock: socket.socket | None, *, close: bool = False) -> None:
    """No more reads of ``sock`` on ``loop`` (no busy loop on a broken socket), and closed if asked."""
    if sock is None:
        return
    if not loop.is_closed():
        loop.remove_reader(sock.fileno())
    if close:
        sock.close()
