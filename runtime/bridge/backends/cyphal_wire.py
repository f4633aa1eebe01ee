"""The Cyphal backend's wire path: ports at pycyphal's transport layer, carrying payload bytes.

The presentation layer deserializes every transfer into a numpy-backed object and serializes every object it sends;
the generated codecs do both straight from and to the bytes, so the wire path skips it:

- :class:`RawReceiver`: one transport input session per subject (extent: the DSDL type's) and one task that hands
  every transfer's payload to the core's handler, with its source node id, transfer id and timestamp, as
  pycyphal's own subscriber task does (no queue: the handler is quick and never raises);
- :class:`RawSender`: one transport output session per subject and a transfer-id counter that lives across
  reopenings of the transport (pycyphal keeps it per presentation; a reopened node would start again at 0).

The sessions are the transport's, so pycyphal's node still lists the ports in ``uavcan.node.port.List``, and the
transport counts frames, transfers, errors and drops per session exactly as under a presentation-layer port.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable
from typing import Any

__all__ = ["RawReceiver", "RawSender"]

_log = logging.getLogger(__name__)
_RECEIVE_TIMEOUT_S = 1.0  # pycyphal's subscriber task wakes up as often; the task is cancelled on close anyway


def _extent_bytes(dtype: Any) -> int:
    import nunavut_support

    return int(nunavut_support.get_extent_bytes(dtype))


class RawReceiver:
    """Receives the transfers of one subject as payload bytes until closed."""

    def __init__(self, transport: Any, subject_id: int, dtype: Any,
                 handler: Callable[[bytes, int | None, int, float], None]) -> None:
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

    def reopen(self, transport: Any, subject_id: int, dtype: Any) -> None:
        from pycyphal.transport import MessageDataSpecifier, OutputSessionSpecifier, PayloadMetadata

        self.session = transport.get_output_session(
            OutputSessionSpecifier(MessageDataSpecifier(subject_id), None), PayloadMetadata(_extent_bytes(dtype)))

    async def send(self, payload: bytes, timeout: float) -> bool:
        from pycyphal.transport import Priority, Timestamp, Transfer

        session = self.session
        tid = self._next_transfer_id
        self._next_transfer_id = tid + 1  # the transport takes it modulo its own transfer-id modulo
        loop = asyncio.get_running_loop()
        return bool(await session.send(Transfer(Timestamp.now(), Priority.NOMINAL, tid, [memoryview(payload)]),
                                       loop.time() + timeout))

    def close(self) -> None:
        session, self.session = self.session, None
        if session is not None:
            try:
                session.close()
            except Exception as ex:
                _log.debug("closing %s: %s", session, ex)
