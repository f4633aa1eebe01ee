"""The Cyphal backend's wire path: ports at pycyphal's transport layer, carrying payload bytes.

The presentation layer deserializes every transfer into a numpy-backed object and serializes every object it sends;
the generated codecs do both straight from and to the bytes, so the wire path skips it:

- :func:`open_receiver`: on Cyphal/UDP (one interface: a ``loop_udp_transport``) a :class:`LoopReceiver`: the subject's
  port of the transport's receiver on the event loop (sam_runtime.cyphal_io.udp_receiver: one socket, no thread,
  pycyphal's parsing, reassembly and counters), which calls the core's handler with each transfer's payload bytes,
  source node id, transfer id and timestamp; on any other transport (CAN, loopback, custom, redundant) a
  :class:`RawReceiver`: one transport input session per subject (extent: the DSDL type's) and one task that hands
  every transfer's payload to the handler, as pycyphal's own subscriber task does (no queue: the handler is quick
  and never raises);
- :class:`RawSender`: one transport output session per subject and a transfer-id counter that lives across
  reopenings of the transport (pycyphal keeps it per presentation; a reopened node would start again at 0). On
  Cyphal/UDP a transfer that fits one frame is sent straight on the session's non-blocking socket, its datagram
  made as pycyphal makes it (sam_runtime.cyphal_io.udp_receiver.single_frame_datagram): pycyphal's send builds
  frame objects and a task per frame (``wait_for(sock_sendall)``), some 40 us a message against 7 here; when the
  socket would block, and for multi-frame transfers, pycyphal's session sends it.

Either way the transport lists the ports (pycyphal's node still names them in ``uavcan.node.port.List``) and
:meth:`statistics` gives pycyphal's session statistics: frames, transfers, errors and drops, with the reassembly
errors per source node on UDP, exactly as under a presentation-layer port.
"""

from __future__ import annotations

import abc
import asyncio
import logging
import socket
import time
from collections.abc import Callable
from typing import Any

from sam_runtime.cyphal_io.udp_receiver import UDPLoopReceiver, single_frame_datagram

__all__ = ["LoopReceiver", "RawReceiver", "RawSender", "Receiver", "open_receiver"]

_log = logging.getLogger(__name__)
_RECEIVE_TIMEOUT_S = 1.0  # pycyphal's subscriber task wakes up as often; the task is cancelled on close anyway


def _extent_bytes(dtype: Any) -> int:
    import nunavut_support

    return int(nunavut_support.get_extent_bytes(dtype))


Handler = Callable[[bytes, "int | None", int, float], None]


def open_receiver(transport: Any, subject_id: int, dtype: Any, handler: Handler) -> Receiver:
    """The subject's receiver on ``transport``: on the event loop where the transport allows (Cyphal/UDP)."""
    loop_rx = getattr(transport, "loop_receiver", None)  # sam_runtime.cyphal_io.udp_receiver.loop_udp_transport's
    if loop_rx is not None:
        return LoopReceiver(loop_rx, subject_id, dtype, handler)
    return RawReceiver(transport, subject_id, dtype, handler)


class Receiver(abc.ABC):
    """Receives the transfers of one subject as payload bytes until closed."""

    @abc.abstractmethod
    def statistics(self) -> Any:
        """pycyphal's statistics of the subject's input session."""

    @abc.abstractmethod
    def abort(self) -> None:
        """Stop at once (a failed open; no await)."""

    @abc.abstractmethod
    async def close(self) -> None:
        """Stop and release the port."""


class LoopReceiver(Receiver):
    """The subject's port of a UDPLoopReceiver: the handler is called from the event loop's reader."""

    def __init__(self, receiver: UDPLoopReceiver, subject_id: int, dtype: Any, handler: Handler) -> None:
        self.port = receiver.subscribe(subject_id, _extent_bytes(dtype), handler)

    def statistics(self) -> Any:
        return self.port.sample_statistics()

    def abort(self) -> None:
        self.port.close()

    async def close(self) -> None:
        self.port.close()


class RawReceiver(Receiver):
    """Receives the transfers of one subject as payload bytes until closed: a transport input session and a task."""

    def __init__(self, transport: Any, subject_id: int, dtype: Any, handler: Handler) -> None:
        from pycyphal.transport import InputSessionSpecifier, MessageDataSpecifier, PayloadMetadata

        self.session = transport.get_input_session(
            InputSessionSpecifier(MessageDataSpecifier(subject_id), None), PayloadMetadata(_extent_bytes(dtype)))
        self._handler = handler
        self.task = asyncio.get_running_loop().create_task(self._receive(), name=f"bridge-rx-{subject_id}")

    async def _receive(self) -> None:
        from pycyphal.transport import ResourceClosedError

        loop, session, handler = asyncio.get_running_loop(), self.session, self._handler
        try:
            while True:
                tr = await session.receive(loop.time() + _RECEIVE_TIMEOUT_S)
                if tr is None:
                    continue
                fragments = tr.fragmented_payload
                payload = bytes(fragments[0]) if len(fragments) == 1 else b"".join(fragments)
                try:
                    stamp = tr.timestamp.monotonic_ns * 1e-9  # .monotonic builds a Decimal
                except Exception:
                    stamp = time.monotonic()
                handler(payload, tr.source_node_id, tr.transfer_id, stamp)
        except (asyncio.CancelledError, ResourceClosedError):
            pass
        except Exception as ex:  # the transport failed under us: the link supervisor sees it and reopens
            _log.warning("the receive task of %s stopped: %s: %s", self.session, type(ex).__name__, ex)

    def statistics(self) -> Any:
        return self.session.sample_statistics()

    def abort(self) -> None:
        self.task.cancel()

    async def close(self) -> None:
        self.task.cancel()
        try:
            self.session.close()
        except Exception as ex:  # a dead transport may refuse
            _log.debug("closing %s: %s", self.session, ex)
        await asyncio.gather(self.task, return_exceptions=True)


class RawSender:
    """Sends payload bytes on one subject; the transfer ids go on across reopenings (:meth:`reopen`)."""

    def __init__(self) -> None:
        self.session: Any = None
        self._next_transfer_id = 0
        self._sock: socket.socket | None = None  # Cyphal/UDP: the session's socket (connected to the group)
        self._udp: tuple[int | None, int, int] = (None, 0, 0)  # source node id, subject id, largest one-frame payload

    def reopen(self, transport: Any, subject_id: int, dtype: Any) -> None:
        from pycyphal.transport import MessageDataSpecifier, OutputSessionSpecifier, PayloadMetadata

        self.session = transport.get_output_session(
            OutputSessionSpecifier(MessageDataSpecifier(subject_id), None), PayloadMetadata(_extent_bytes(dtype)))
        sock = getattr(self.session, "socket", None)  # a UDPOutputSession's
        self._sock = sock if isinstance(sock, socket.socket) else None
        if self._sock is not None:
            mtu = int(transport.protocol_parameters.mtu)
            self._udp = (transport.local_node_id, int(subject_id), mtu - 4)

    async def send(self, payload: bytes, timeout: float) -> bool:
        from pycyphal.transport import Priority, Timestamp, Transfer

        session = self.session
        tid = self._next_transfer_id
        self._next_transfer_id = tid + 1  # the transport takes it modulo its own transfer-id modulo
        sock = self._sock
        if sock is not None and len(payload) <= self._udp[2] and sock.fileno() >= 0:
            src, subject, _ = self._udp
            try:
                sock.send(single_frame_datagram(src, subject, tid, payload))
                return True
            except BlockingIOError:  # the socket's buffer is full: pycyphal's send waits for room
                pass
        loop = asyncio.get_running_loop()
        return bool(await session.send(Transfer(Timestamp.now(), Priority.NOMINAL, tid, [memoryview(payload)]),
                                       loop.time() + timeout))

    def close(self) -> None:
        session, self.session, self._sock = self.session, None, None
        if session is not None:
            try:
                session.close()
            except Exception as ex:
                _log.debug("closing %s: %s", session, ex)
