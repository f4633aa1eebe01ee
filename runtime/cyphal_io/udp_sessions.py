"""pycyphal's Cyphal/UDP input sessions received on the asyncio event loop: no reader thread per session (issue 26).

The bridge's subjects are received by :mod:`.udp_receiver` (one socket, the payload bytes straight to the codecs).
What stayed on pycyphal's UDP input sessions are the ports of pycyphal's own presentation layer: the node's service
servers (``uavcan.node.GetInfo``, ``uavcan.register.Access`` and ``List``; ``ExecuteCommand`` where served), the
response sessions of the bridge's service clients (issue 19's mappings), the heartbeat publisher's own heartbeat
subscription (its node-id conflict check) and any subject subscribed through pycyphal (the object path). pycyphal 1.27
gives each a socket and a thread that polls ``select`` every 0.1 s: the four of an idle bridge were 40 wake-ups a
second, about a third of its idle CPU, with nothing to receive.

:func:`loop_sessions_udp_transport` is :func:`.udp_receiver.loop_udp_transport` whose ``get_input_session`` gives a
:class:`LoopInputSession` instead of pycyphal's session:

- one :class:`SessionSocket` per transport, made when the first session is, watched with ``loop.add_reader``: bound
  to the Cyphal/UDP port on every address with ``IP_MULTICAST_ALL`` off (only the groups it joined) and
  ``IP_PKTINFO`` (each datagram's destination group), joining each session's group on the transport's interface (a
  subject's group; for every service session the node's own service group, as pycyphal's ``make_input_socket``);
  a wake-up drains what is queued, at most :data:`~.udp_receiver.BATCH` datagrams;
- each datagram is timestamped as pycyphal's reader thread does (``Timestamp.now()`` when read), parsed once with
  pycyphal's ``UDPFrame.parse`` and given to every session of its group, as the kernel gave a copy to each of
  pycyphal's per-session sockets;
- :meth:`LoopInputSession.receive` is pycyphal's ``UDPInputSession.receive`` step by step: the same filters (data
  specifier, the node's own frames, the remote node of a selective session), pycyphal's ``TransferReassembler`` per
  source node, pycyphal's statistics classes with the same counts; it waits on a future with a timer at the
  deadline instead of ``asyncio.wait_for`` on a queue. A closed session wakes its waiting ``receive`` at once
  (pycyphal's waits for its deadline), which then raises ``ResourceClosedError`` as pycyphal's does.

One difference, deliberate (the loop receiver's too): a datagram that makes pycyphal's parser raise (a priority
above 7, a service frame from an anonymous node) is one more error of each session of its group, and logged at a
bounded rate; pycyphal's thread logs a traceback for it and counts nothing.
Output sessions (publications, responses, requests) stay pycyphal's.

The proof against the library is tests/runtime/cyphal_io/test_udp_sessions.py (the same datagram sequences fed to
pycyphal's sessions and to these: the same transfers and statistics; services and the heartbeat on real sockets,
yakut's calls answered).
"""

from __future__ import annotations

import asyncio
import collections
import copy
import functools
import logging
import socket
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from sam_runtime.cyphal_io.multicast import (
    ANC_PKTINFO_SIZE,
    IP_PKTINFO,
    join_group,
    leave_group,
    open_socket,
    stop_reading,
)
from sam_runtime.cyphal_io.udp_receiver import BATCH, loop_udp_transport_class, subject_group

if TYPE_CHECKING:  # pycyphal is imported where it is used (a DroneCAN-only vehicle imports this module too)
    from pycyphal.transport import InputSessionSpecifier, PayloadMetadata, Timestamp, TransferFrom
    from pycyphal.transport.commons.high_overhead_transport import TransferReassembler
    from pycyphal.transport.udp import UDPFrame

__all__ = ["LoopInputSession", "SessionSocket", "loop_sessions_udp_transport", "parse_datagram", "service_group"]

_log = logging.getLogger(__name__)

DEFAULT_TRANSFER_ID_TIMEOUT_S = 2.0  # pycyphal's UDPInputSession.DEFAULT_TRANSFER_ID_TIMEOUT
_READ_SIZE = 0xFFFF  # as pycyphal's reader: any UDP/IPv4 datagram fits


def service_group(node_id: int) -> bytes:
    """The multicast group of the service transfers to ``node_id``, packed (pycyphal's
    ``service_node_id_to_multicast_group``).

    >>> socket.inet_ntoa(service_group(456))
    '239.1.1.200'
    """
    return bytes((239, 1, (node_id >> 8) & 0xFF, node_id & 0xFF))


def parse_datagram(data: bytes) -> UDPFrame | None:
    """pycyphal's ``UDPFrame.parse`` (None: not a valid frame), None also where it raises (see the module's doc)."""
    from pycyphal.transport.udp import UDPFrame

    try:
        return UDPFrame.parse(memoryview(data))
    except (ValueError, TypeError, LookupError) as ex:  # Priority(8), an anonymous service frame's __post_init__
        _note_unparsable(ex)
        return None


_unparsable = 0


def _note_unparsable(ex: Exception) -> None:
    global _unparsable
    _unparsable += 1
    if not _unparsable & (_unparsable - 1):  # 1, 2, 4, 8, ...: bounded, never silent
        _log.warning("a Cyphal/UDP datagram pycyphal cannot parse (%d so far), counted as an error: %s: %s",
                     _unparsable, type(ex).__name__, ex)


class LoopInputSession:
    """pycyphal's Promiscuous/SelectiveUDPInputSession without its socket and thread: its datagrams come from the
    transport's :class:`SessionSocket` (:meth:`push`, in the loop's thread). It has pycyphal's ``InputSession``
    interface (pycyphal's presentation layer uses it as one; it is not a subclass, so that pycyphal is imported only
    where it is used, as :class:`.udp_receiver.SubjectPort`).

    ``statistics``: a ``PromiscuousUDPInputSessionStatistics`` (promiscuous specifier) or a
    ``SelectiveUDPInputSessionStatistics``, filled as pycyphal fills them."""

    def __init__(self, specifier: InputSessionSpecifier, payload_metadata: PayloadMetadata,
                 source: SessionSocket | None, group: bytes, finalizer: Callable[[], None] | None,
                 local_node_id: int | None, statistics: Any) -> None:
        self._specifier = specifier
        self._payload_metadata = payload_metadata
        self._source, self._group = source, group
        self._finalizer = finalizer
        self._local_node_id = local_node_id
        self._statistics = statistics
        self._transfer_id_timeout = DEFAULT_TRANSFER_ID_TIMEOUT_S
        self._queue: collections.deque[tuple[Timestamp, UDPFrame | None]] = collections.deque()
        self._waiter: asyncio.Future[None] | None = None
        self._closed = False
        self._reassemblers: dict[int, TransferReassembler] = {}
        if source is not None:
            source.attach(group, self)

    # ---------------------------------------------------------------------------------------------- pycyphal's API
    @property
    def specifier(self) -> InputSessionSpecifier:
        return self._specifier

    @property
    def payload_metadata(self) -> PayloadMetadata:
        return self._payload_metadata

    @property
    def transfer_id_timeout(self) -> float:
        return self._transfer_id_timeout

    @transfer_id_timeout.setter
    def transfer_id_timeout(self, value: float) -> None:
        if value > 0:
            self._transfer_id_timeout = float(value)
        else:
            raise ValueError(f"Invalid value for transfer-ID timeout [second]: {value}")

    @property
    def source_node_id(self) -> int | None:
        return self._specifier.remote_node_id  # (pycyphal's InputSession's)

    def sample_statistics(self) -> Any:
        return copy.copy(self._statistics)

    async def receive(self, monotonic_deadline: float) -> TransferFrom | None:
        """pycyphal's UDPInputSession.receive: the next transfer, or None at the deadline (loop time)."""
        from pycyphal.transport import ResourceClosedError
        from pycyphal.transport.commons.high_overhead_transport import TransferReassembler

        if self._closed:
            raise ResourceClosedError(f"{self} is closed")
        loop = asyncio.get_running_loop()
        queue, stats, spec = self._queue, self._statistics, self._specifier
        while True:
            if not queue and monotonic_deadline > loop.time() and not self._closed:
                await self._wait(loop, monotonic_deadline)
            if not queue:
                # As pycyphal: what was queued can be read after closing; then it raises.
                if self._finalizer is None:
                    raise ResourceClosedError(f"{self} is closed") from None
                return None
            ts, frame = queue.popleft()
            if frame is None:
                stats.errors += 1
                continue
            if frame.data_specifier != spec.data_specifier:
                continue
            if self._local_node_id is not None and frame.source_node_id == self._local_node_id:
                continue
            if not spec.is_promiscuous and frame.source_node_id != spec.remote_node_id:
                continue
            stats.frames += 1
            src = frame.source_node_id
            if src is None:
                transfer = TransferReassembler.construct_anonymous_transfer(ts, frame)
            else:
                transfer = self._reassembler(src).process_frame(ts, frame, self._transfer_id_timeout)
            if transfer is not None:
                stats.transfers += 1
                stats.payload_bytes += sum(map(len, transfer.fragmented_payload))
                return transfer

    async def _wait(self, loop: asyncio.AbstractEventLoop, deadline: float) -> None:
        waiter = self._waiter = loop.create_future()
        timer = loop.call_at(deadline, _wake, waiter)
        try:
            await waiter
        finally:
            timer.cancel()
            self._waiter = None

    def close(self) -> None:
        self._closed = True
        if self._finalizer is not None:
            self._finalizer()
            self._finalizer = None
        source, self._source = self._source, None
        if source is not None:
            source.detach(self._group, self)
        _wake(self._waiter)

    # ---------------------------------------------------------------------------------------------- the feed
    def push(self, ts: Timestamp, frame: UDPFrame | None) -> None:
        """A datagram of this session's group (None: not a valid frame), as pycyphal's reader thread queues it."""
        self._queue.append((ts, frame))
        _wake(self._waiter)

    def _reassembler(self, src: int) -> TransferReassembler:
        reasm = self._reassemblers.get(src)
        if reasm is None:
            from pycyphal.transport.commons.high_overhead_transport import TransferReassembler

            stats = self._statistics
            if self._specifier.is_promiscuous:
                errors = stats.reassembly_errors_per_source_node_id.setdefault(src, {})
            else:
                errors = stats.reassembly_errors

            def on_error(error: TransferReassembler.Error) -> None:
                stats.errors += 1
                errors[error] = errors.get(error, 0) + 1

            reasm = self._reassemblers[src] = TransferReassembler(
                source_node_id=src, extent_bytes=self._payload_metadata.extent_bytes, on_error_callback=on_error)
        return reasm

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._specifier}, {self._payload_metadata})"


def _wake(waiter: asyncio.Future[None] | None) -> None:
    if waiter is not None and not waiter.done():
        waiter.set_result(None)


class SessionSocket:
    """One socket on the running loop for the input sessions of one transport (see the module's doc). Create, attach
    and close it in the loop's thread."""

    def __init__(self, local_ip: str) -> None:
        self.local_ip = str(local_ip)
        self.failure: str | None = None  # why the socket stopped (the link supervisor reopens the transport)
        self.datagrams = 0
        self._loop = asyncio.get_running_loop()
        self._iface = socket.inet_aton(self.local_ip)
        self._groups: dict[bytes, list[LoopInputSession]] = {}
        sock = open_socket()
        self._sock: socket.socket | None = sock
        self._loop.add_reader(sock.fileno(), self._on_readable)

    @property
    def groups(self) -> list[str]:
        return sorted(socket.inet_ntoa(g) for g in self._groups)

    def attach(self, group: bytes, session: LoopInputSession) -> None:
        import pycyphal.transport

        sock = self._sock
        if sock is None:
            raise pycyphal.transport.ResourceClosedError(f"the Cyphal/UDP session socket on {self.local_ip} is closed")
        sessions = self._groups.get(group)
        if sessions is None:
            try:
                join_group(sock, group, self._iface)
            except OSError as ex:  # as pycyphal's make_input_socket
                raise pycyphal.transport.InvalidMediaConfigurationError(
                    f"could not join {socket.inet_ntoa(group)} via {self.local_ip}: {ex}") from None
            sessions = self._groups[group] = []
        sessions.append(session)

    def detach(self, group: bytes, session: LoopInputSession) -> None:
        sessions = self._groups.get(group)
        if sessions is None or session not in sessions:
            return
        sessions.remove(session)
        if not sessions:
            del self._groups[group]
            if self._sock is not None:
                leave_group(self._sock, group, self._iface)

    def close(self) -> None:
        sock, self._sock = self._sock, None
        self._groups.clear()
        stop_reading(self._loop, sock, close=True)

    def _on_readable(self) -> None:
        sock = self._sock
        if sock is None:
            return
        from pycyphal.transport import Timestamp

        groups, now = self._groups, Timestamp.now
        for _ in range(BATCH):
            try:
                data, ancdata, _flags, _addr = sock.recvmsg(_READ_SIZE, ANC_PKTINFO_SIZE)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as ex:
                self._fail(ex)
                return
            ts = now()
            self.datagrams += 1
            group = b""
            for level, kind, cdata in ancdata:
                if kind == IP_PKTINFO and level == socket.IPPROTO_IP:
                    group = cdata[8:12]  # in_pktinfo.ipi_addr: the datagram's destination
            sessions = groups.get(group)
            if sessions:
                frame = parse_datagram(data)
                for session in tuple(sessions):
                    session.push(ts, frame)

    def _fail(self, ex: OSError) -> None:
        self.failure = f"Cyphal/UDP session receive on {self.local_ip}: {type(ex).__name__}: {ex}"
        _log.warning("%s", self.failure)
        stop_reading(self._loop, self._sock)

    def __repr__(self) -> str:
        return f"SessionSocket({self.local_ip!r}, groups={self.groups})"


def loop_sessions_udp_transport(local_ip_address: str, local_node_id: int | None, **kwargs: Any) -> Any:
    """:func:`.udp_receiver.loop_udp_transport` whose pycyphal input sessions are received on the loop too (no
    reader thread; see the module's doc). ``kwargs``: UDPTransport's (mtu, service_transfer_multiplier).
    Create it, open its sessions and close it in the loop's thread."""
    return _transport_class()(local_ip_address, local_node_id, **kwargs)


@functools.cache
def _transport_class() -> type:
    import pycyphal.transport
    from pycyphal.transport import MessageDataSpecifier
    from pycyphal.transport.udp import PromiscuousUDPInputSessionStatistics, SelectiveUDPInputSessionStatistics

    base = loop_udp_transport_class()

    class LoopSessionsUDPTransport(base):  # type: ignore[misc,valid-type]
        __doc__ = loop_sessions_udp_transport.__doc__

        def __init__(self, local_ip_address: str, local_node_id: int | None, **kw: Any) -> None:
            super().__init__(local_ip_address, local_node_id, **kw)
            self._session_socket: SessionSocket | None = None

        @property
        def session_socket(self) -> SessionSocket | None:
            """The socket of the input sessions (None until the first session is made)."""
            return self._session_socket

        def get_input_session(self, specifier: InputSessionSpecifier,
                              payload_metadata: PayloadMetadata) -> LoopInputSession:
            self._ensure_not_closed()
            session = self._input_registry.get(specifier)
            if session is not None:
                return session
            node_id = self.local_node_id
            if isinstance(specifier.data_specifier, MessageDataSpecifier):
                group = subject_group(specifier.data_specifier.subject_id)
            elif node_id is None:  # pycyphal: no service input socket for an anonymous node
                raise pycyphal.transport.OperationNotDefinedForAnonymousNodeError(
                    "Anonymous UDP Transport cannot create service input sessions")
            else:
                group = service_group(node_id)
            if not specifier.is_promiscuous and node_id is None:
                raise pycyphal.transport.OperationNotDefinedForAnonymousNodeError(
                    "Anonymous UDP Transport cannot create non-promiscuous input session")
            stats = (PromiscuousUDPInputSessionStatistics() if specifier.is_promiscuous
                     else SelectiveUDPInputSessionStatistics())
            if self._session_socket is None:
                self._session_socket = SessionSocket(str(self.local_ip_address))

            def finalizer() -> None:
                self._input_registry.pop(specifier, None)

            session = LoopInputSession(specifier, payload_metadata, self._session_socket, group, finalizer,
                                       node_id, stats)
            self._statistics.received_datagrams[specifier] = stats
            self._input_registry[specifier] = session
            return session

        def close(self) -> None:
            super().close()  # closes the sessions (each leaves its group)
            sock, self._session_socket = self._session_socket, None
            if sock is not None:
                sock.close()

    return LoopSessionsUDPTransport
