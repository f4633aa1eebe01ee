"""When a datagram left: the kernel's transmission timestamps of a UDP socket (Linux ``SO_TIMESTAMPING``), and the
window in which a frame was sent (:class:`TxWindow`), the time-sync master's measure of its own transmissions.

- :class:`KernelTxStamps` asks the kernel for a software transmission timestamp of every datagram the socket sends
  (``SOF_TIMESTAMPING_TX_SOFTWARE``: taken by the network device's transmit routine, on the loopback device within
  the send system call) and reads them from the socket's error queue (``MSG_ERRQUEUE``, never blocking), each with
  the socket's send counter (``SOF_TIMESTAMPING_OPT_ID``), so a timestamp is matched to the last send, never to
  another. The timestamps are CLOCK_REALTIME (``time.time_ns``). A thread that is preempted or an asyncio loop that
  is held up between the send and the reading does not change them: that is what they are for.
- Where the kernel refuses (not Linux, an old kernel), :meth:`KernelTxStamps.attach` returns None and the caller
  measures the send itself.
"""

from __future__ import annotations

import errno
import socket
import struct
import sys
from dataclasses import dataclass

__all__ = ["KernelTxStamps", "TxWindow"]

# linux/net_tstamp.h, asm-generic/socket.h, linux/errqueue.h (not exported by the socket module)
SO_TIMESTAMPING = 37  # also the cmsg type SCM_TIMESTAMPING
SOF_TIMESTAMPING_TX_SOFTWARE = 1 << 1
SOF_TIMESTAMPING_SOFTWARE = 1 << 4
SOF_TIMESTAMPING_OPT_TSONLY = 1 << 11
SO_EE_ORIGIN_TIMESTAMPING = 4
_FLAGS = SOF_TIMESTAMPING_TX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE | SOF_TIMESTAMPING_OPT_TSONLY
_TIMESPEC = struct.Struct("qq")  # struct scm_timestamping: ts[0] is the software timestamp
_EXTENDED_ERR = struct.Struct("IBBBBII")  # struct sock_extended_err: errno, origin, type, code, pad, info, data
_MAX_DRAIN = 64  # error-queue entries read at once (one per datagram sent since the last reading)


@dataclass(frozen=True)
class TxWindow:
    """A frame left between ``earliest_ns`` and ``latest_ns`` (CLOCK_REALTIME, ``time.time_ns``); equal for a kernel
    timestamp. ``source``: who measured it (``kernel``, ``driver``)."""

    earliest_ns: int
    latest_ns: int
    source: str

    @property
    def span_ns(self) -> int:
        return self.latest_ns - self.earliest_ns


class KernelTxStamps:
    """The kernel's transmission timestamps of ``sock`` (a UDP socket, which keeps its owner: this only sets an
    option and reads the error queue)."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.read = 0  # timestamps read
        self.missing = 0  # takes that found none, or several

    @classmethod
    def attach(cls, sock: socket.socket) -> KernelTxStamps | None:
        """Timestamps on ``sock`` from now on; None where the kernel cannot give them."""
        if not sys.platform.startswith("linux"):
            return None
        try:
            sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPING, _FLAGS)
        except OSError:
            return None
        return cls(sock)

    def take(self) -> TxWindow | None:
        """The transmission time of the one datagram sent since the last take; None when the kernel gave none or
        more than one (the error queue is read empty either way, so an old timestamp is never taken for a new
        send)."""
        stamps: list[int] = []
        for _ in range(_MAX_DRAIN):
            try:
                _data, ancdata, _flags, _addr = self.sock.recvmsg(1, 512, socket.MSG_ERRQUEUE | socket.MSG_DONTWAIT)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:
                break  # closed meanwhile: no timestamp
            ts_ns: int | None = None
            ours = False
            for level, kind, data in ancdata:
                if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPING and len(data) >= _TIMESPEC.size:
                    sec, nsec = _TIMESPEC.unpack_from(data, 0)
                    ts_ns = sec * 1_000_000_000 + nsec
                elif level in (socket.IPPROTO_IP, socket.IPPROTO_IPV6) and len(data) >= _EXTENDED_ERR.size:
                    err, origin = _EXTENDED_ERR.unpack_from(data, 0)[:2]
                    ours = err == errno.ENOMSG and origin == SO_EE_ORIGIN_TIMESTAMPING
            if ts_ns and ours:
                stamps.append(ts_ns)
        self.read += len(stamps)
        if len(stamps) != 1:
            self.missing += 1
            return None
        return TxWindow(stamps[0], stamps[0], "kernel")
