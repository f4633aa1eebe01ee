"""Cyphal/UDP message reception on the asyncio event loop: one socket, no thread per subscription (issue 26).

pycyphal 1.x's UDP transport gives every input session a socket and a reader thread that polls ``select`` every
0.1 s and hands each datagram to the event loop with ``call_soon_threadsafe``: with SAM's 27 subscriptions that is
most of the bridge's CPU, idle or not. :class:`UDPLoopReceiver` does the same reception on the loop itself:

- one non-blocking socket bound to the Cyphal/UDP port on every address, ``IP_MULTICAST_ALL`` off, joining each
  subscribed subject's multicast group on the transport's interface, watched with ``loop.add_reader``; every wake-up
  drains the queued datagrams (at most :data:`BATCH` of them, so the loop stays fair; the rest wake it again);
- ``IP_PKTINFO`` gives each datagram's destination group, which says whose it is, as pycyphal's per-group socket
  does; ``SO_RXQ_OVFL`` gives the datagrams the kernel dropped for a full receive buffer (pycyphal cannot see
  those): :attr:`UDPLoopReceiver.overflows`;
- each datagram is parsed as pycyphal 1.27 parses it (``pycyphal.transport.udp.UDPFrame.parse``: header version,
  header CRC) and goes through the same per-source state machine (``TransferReassembler``: transfer-id
  deduplication and timeout, multi-frame reassembly in any frame order, the transfer CRC), with the same counters
  (:class:`SubjectPort`: transfers, frames, errors, the reassembly errors per source node). A single-frame transfer
  takes a fast path (the state is two numbers), and the payload goes to the handler as bytes, with no frame or
  transfer object between.

Where pycyphal's state machine can be steered by a hostile sender with a device's node id, this one differs on
purpose (issue 29): only a transfer that passed its CRC moves the source's expected transfer id; a transfer id
further ahead than the time since the source's last one allows (sam_runtime.common.transfer_ids; unless the
kernel dropped datagrams meanwhile) is delivered without becoming the expected one (the bridge counts it as a
jump); each multi-frame transfer has a slot of its own (source, transfer id), which frames of other transfers do
not end and a contradicting frame does not spoil, at most :data:`SLOTS_PER_SOURCE` per source and :data:`MAX_SLOTS`
per subject (the oldest evicted), each expiring after the transfer-id timeout. Every datagram is counted: a frame,
or a refusal by kind (:attr:`SubjectPort.refused`), or the node's own; the receiver counts those to no subscribed
subject (:attr:`UDPLoopReceiver.not_subscribed`).

Where pycyphal raises instead of counting, the receiver counts: a header with a priority above 7 or a service
transfer from an anonymous node (pycyphal logs a traceback from its reader thread and counts nothing), and a frame
index past :data:`MAX_FRAME_INDEX` (pycyphal would grow its fragment list up to the index, 2**31 entries for a
hostile datagram); these are ``errors`` too, the last with its own kind (``FRAME_INDEX_LIMIT``).
Like pycyphal, the transport delivers the whole payload: the extent's implicit truncation is the deserializer's.

Also here: :func:`loop_udp_transport`, pycyphal's UDPTransport that owns such a receiver (it lists the receiver's
subjects among its input sessions and closes it), and :func:`single_frame_datagram`, a one-frame transfer's
datagram as pycyphal's output session makes it (the bridge's wire path sends with it).

The proof against the library is tests/runtime/cyphal_io/test_udp_receiver.py: the same datagram sequences,
malformed ones included, fed to pycyphal's UDP input session and to this give the same transfers and counters.
"""

from __future__ import annotations

import asyncio
import binascii
import functools
import logging
import socket
import struct
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

from sam_runtime.common.transfer_ids import JUMP_SLACK, MAX_PLAUSIBLE_RATE_HZ
from sam_runtime.cyphal_io.crc32c import RESIDUE as CRC32C_RESIDUE
from sam_runtime.cyphal_io.crc32c import crc32c_register
from sam_runtime.cyphal_io.multicast import (
    ANC_OVERFLOW_SIZE,
    ANC_PKTINFO_SIZE,
    CYPHAL_PORT,
    IP_PKTINFO,
    SO_RXQ_OVFL,
    join_group,
    leave_group,
    open_socket,
    stop_reading,
)

__all__ = ["BATCH", "CYPHAL_PORT", "FRAME_INDEX_LIMIT", "MAX_FRAME_INDEX", "RCVBUF_BYTES", "TRANSFER_ID_TIMEOUT_S",
           "Handler", "SubjectPort", "UDPLoopReceiver", "loop_udp_transport", "loop_udp_transport_class",
           "single_frame_datagram", "subject_group"]

_log = logging.getLogger(__name__)

Handler = Callable[[bytes, "int | None", int, float], None]  # (payload, source node id, transfer id, monotonic s)

BATCH = 256  # datagrams per wake-up at most: a flood cannot hold the loop
# The receive buffer asked for (the kernel doubles it, capped at 2 * net.core.rmem_max): one socket queues every
# subject, so it holds more than one of pycyphal's sockets (rmem_default, 208 KiB) yet not so much that a flood on
# one subject holds the others for long: 2 MiB, ~2,700 small datagrams, about a second of the bridge's throughput.
RCVBUF_BYTES = 1 << 20
MAX_FRAME_INDEX = 4095  # 4096 frames: 4.9 MB at pycyphal's default MTU, far beyond any extent the bridge has
_READ_SIZE = 0xFFFF  # as pycyphal's reader: any UDP/IPv4 datagram fits
# Linux values; Python 3.11's socket module names none of them.
_ANC_SIZE = ANC_PKTINFO_SIZE + ANC_OVERFLOW_SIZE
_SOL_IP, _SOL_SOCKET = socket.IPPROTO_IP, socket.SOL_SOCKET

_HEADER = struct.Struct("<BBHHHQIH")  # pycyphal's UDPFrame header without its CRC (22 bytes)
_HEADER_SIZE = _HEADER.size + 2
_VERSION = 1
_ANONYMOUS = 0xFFFF
_SNM = 1 << 15
_EOT = 1 << 31
_INDEX_MASK = _EOT - 1
_CRC_SIZE = 4
TRANSFER_ID_TIMEOUT_S = 2.0  # pycyphal's UDPInputSession.DEFAULT_TRANSFER_ID_TIMEOUT

# The reassembly errors by the names of pycyphal's TransferReassembler.Error (its members in sample_statistics());
# pycyphal is imported only where it is used, so that importing this module (the transport module does) costs
# nothing on a DroneCAN-only vehicle.
_INTEGRITY = "INTEGRITY_ERROR"
_UNEXPECTED_TID = "UNEXPECTED_TRANSFER_ID"
_MISSING_FRAMES = "MULTIFRAME_MISSING_FRAMES"
_EMPTY_FRAME = "MULTIFRAME_EMPTY_FRAME"
_EOT_MISPLACED = "MULTIFRAME_EOT_MISPLACED"
_EOT_INCONSISTENT = "MULTIFRAME_EOT_INCONSISTENT"
FRAME_INDEX_LIMIT = "FRAME_INDEX_LIMIT"  # not pycyphal's (see the module's docstring)
# Not pycyphal's either (issue 29): partial transfers dropped for their age or for room; and the datagrams refused
# before a source can be trusted (``SubjectPort.refused``; pycyphal counts the first three as errors, the others not).
TRANSFER_EXPIRED = "TRANSFER_EXPIRED"
TRANSFER_EVICTED = "TRANSFER_EVICTED"
TRUNCATED = "TRUNCATED_HEADER"
HEADER_CRC = "HEADER_CRC"
HEADER_VERSION = "HEADER_VERSION"
BAD_PRIORITY = "BAD_PRIORITY"
ANONYMOUS_SERVICE = "ANONYMOUS_SERVICE"
WRONG_SUBJECT = "WRONG_SUBJECT"
ANONYMOUS_MULTIFRAME = "ANONYMOUS_MULTIFRAME"
ANONYMOUS_INTEGRITY = "ANONYMOUS_INTEGRITY"
NOT_SUBSCRIBED = "NOT_SUBSCRIBED"  # UDPLoopReceiver.refused: a datagram to a group no port subscribed (or unicast)
# Reassembly bounds: a source has one transfer in flight per subject (a few while frames are late); the slots of a
# subject, every source's, are capped so that partial transfers from many node ids cannot grow memory (each holds
# its fragments until it ends, expires after the transfer-id timeout, or is evicted, oldest first: all counted).
SLOTS_PER_SOURCE = 4
MAX_SLOTS = 64
# Sources whose errors are counted apart (pycyphal's per-source statistics); the errors of further ones are summed
# by kind (``SubjectPort.unattributed``), so that made-up node ids cannot grow the counters and the reports.
MAX_ERROR_SOURCES = 32
_NS_PER_PLAUSIBLE_TID = round(1e9 / MAX_PLAUSIBLE_RATE_HZ)


def subject_group(subject_id: int) -> bytes:
    """The subject's multicast group, packed (pycyphal's ``message_data_specifier_to_multicast_group``).

    >>> socket.inet_ntoa(subject_group(7509))
    '239.0.29.85'
    """
    return bytes((239, 0, (subject_id >> 8) & 0x7F, subject_id & 0xFF))


def single_frame_datagram(source_node_id: int | None, subject_id: int, transfer_id: int, payload: bytes,
                          priority: int = 4) -> bytes:
    """The datagram of a single-frame message transfer, as pycyphal's UDP output session makes it (header with its
    CRC, payload, transfer CRC); the caller checks that it fits the MTU (``len(payload) + 4 <= mtu``).
    ``priority``: 4 = NOMINAL."""
    header = _HEADER.pack(_VERSION, priority, _ANONYMOUS if source_node_id is None else source_node_id, _ANONYMOUS,
                          subject_id, transfer_id & 0xFFFFFFFFFFFFFFFF, _EOT, 0)
    crc = crc32c_register(payload) ^ 0xFFFFFFFF
    return b"".join((header, binascii.crc_hqx(header, 0xFFFF).to_bytes(2, "big"), payload, crc.to_bytes(4, "little")))


class _Source:
    """One source node's accepted state: ``tid`` the transfer id expected next (the last accepted one + 1),
    ``ts_ns`` the monotonic time of the last accepted transfer (the reference of the transfer-id timeout and of
    the plausible jump), ``slots`` its transfers being reassembled (oldest first, at most :data:`SLOTS_PER_SOURCE`).
    Only a transfer that passed its CRC changes ``tid`` and ``ts_ns`` (issue 29)."""

    __slots__ = ("slots", "tid", "ts_ns")

    def __init__(self) -> None:
        self.tid = -1  # nothing accepted yet: any transfer id is taken
        self.ts_ns = 0
        self.slots: list[_Slot] = []


class _Slot:
    """One multi-frame transfer being reassembled: its fragments (empty bytes: not received yet), the index of its
    last frame once known, the time of its first frame (the transfer's timestamp) and of its creation (expiry)."""

    __slots__ = ("born_ns", "key", "max_index", "payloads", "src", "tid", "ts_ns")

    def __init__(self, src: int, tid: int, now_ns: int) -> None:
        self.src, self.tid, self.key = src, tid, (src, tid)
        self.payloads: list[bytes] = []
        self.max_index: int | None = None
        self.ts_ns = self.born_ns = now_ns


class SubjectPort:
    """One subscribed subject: its handler, its per-source states and pycyphal's counters of an input session.

    ``specifier`` and ``payload_metadata`` as a pycyphal input session's (so the node's ``uavcan.node.port.List``
    lists the subject); :meth:`sample_statistics` gives pycyphal's ``PromiscuousUDPInputSessionStatistics``, with
    ``reassembly_errors`` (kind -> count) added for the datagrams refused before any source could be trusted.

    Every datagram fed is counted once: ``frames`` (it reached a source's state machine: anonymous ones too), a
    kind of :attr:`refused` (also in ``errors``), or ``own_frames`` (this node's own, looped back)."""

    def __init__(self, receiver: UDPLoopReceiver, subject_id: int, extent_bytes: int, handler: Handler) -> None:
        from pycyphal.transport import InputSessionSpecifier, MessageDataSpecifier, PayloadMetadata

        self.subject_id = int(subject_id)
        self.specifier = InputSessionSpecifier(MessageDataSpecifier(self.subject_id), None)
        self.payload_metadata = PayloadMetadata(int(extent_bytes))
        self.handler = handler
        self.transfer_id_timeout_ns = round(TRANSFER_ID_TIMEOUT_S * 1e9)
        self.transfers = self.frames = self.errors = self.payload_bytes = 0
        self.own_frames = 0
        self.refused: dict[str, int] = {}  # datagrams no source is blamed for, by kind (in ``errors`` too)
        # errors of sources beyond the first MAX_ERROR_SOURCES with errors, by kind (in ``errors`` too)
        self.unattributed: dict[str, int] = {}
        self.errors_per_source: dict[int, dict[str, int]] = {}
        self.handler_failures = 0
        self._sources: dict[int, _Source] = {}
        self._slots: dict[tuple[int, int], _Slot] = {}  # every source's, oldest first (expiry, the cap)
        self._receiver: UDPLoopReceiver | None = receiver
        self._local_node_id = receiver.local_node_id

    @property
    def transfer_id_timeout(self) -> float:
        return self.transfer_id_timeout_ns * 1e-9

    @transfer_id_timeout.setter
    def transfer_id_timeout(self, value: float) -> None:
        if not value > 0:
            raise ValueError(f"Invalid value for transfer-ID timeout [second]: {value}")
        self.transfer_id_timeout_ns = round(value * 1e9)

    @property
    def partial_transfers(self) -> int:
        """Multi-frame transfers being reassembled now (at most :data:`MAX_SLOTS`)."""
        return len(self._slots)

    def sample_statistics(self) -> Any:
        """pycyphal's PromiscuousUDPInputSessionStatistics, its error kinds TransferReassembler.Error members
        (or this module's names for the kinds pycyphal has not), plus ``reassembly_errors``."""
        from pycyphal.transport.commons.high_overhead_transport import TransferReassembler

        kinds = TransferReassembler.Error.__members__
        # Copies built from atomic dict copies: another thread may sample while the loop counts.
        per_src: dict[int, dict[Any, int]] = {src: {kinds.get(k, k): n for k, n in list(errs.items())}
                                              for src, errs in list(self.errors_per_source.items())}
        out = _statistics_class()(
            transfers=self.transfers, frames=self.frames, payload_bytes=self.payload_bytes, errors=self.errors,
            drops=0, reassembly_errors_per_source_node_id=per_src)
        out.reassembly_errors = dict(list(self.refused.items()))
        for kind, n in list(self.unattributed.items()):
            out.reassembly_errors[kind] = out.reassembly_errors.get(kind, 0) + n
        return out

    def close(self) -> None:
        receiver, self._receiver = self._receiver, None
        if receiver is not None:
            receiver.unsubscribe(self)

    # ------------------------------------------------------------------------------------------ the hot path
    def feed(self, data: bytes, now_ns: int) -> None:
        """One datagram that came to this subject's group (pycyphal: ``UDPFrame.parse`` in the reader thread,
        then ``UDPInputSession.receive`` on the loop)."""
        if len(data) < _HEADER.size:
            self._refuse(TRUNCATED)  # pycyphal: parse() -> None, counted by receive()
            return
        version, prio, src, _dst, dsn, tid, index_eot, _user = _HEADER.unpack_from(data)
        # The header CRC: CRC-16/CCITT-FALSE (pycyphal's CRC16CCITT) is binascii's CRC-CCITT from 0xFFFF; the
        # residue of a header with its big-endian CRC is 0 (over what there is of the 24 bytes, as pycyphal).
        if binascii.crc_hqx(data[:_HEADER_SIZE], 0xFFFF):
            self._refuse(HEADER_CRC)
            return
        if version != _VERSION:
            self._refuse(HEADER_VERSION)
            return
        if prio > 7:
            self._refuse(BAD_PRIORITY)  # pycyphal raises in parse() (Priority()): see the module's docstring
            return
        if dsn != self.subject_id:  # a service frame, or another subject's (pycyphal: skipped, not counted)
            self._refuse(ANONYMOUS_SERVICE if dsn & _SNM and src == _ANONYMOUS else WRONG_SUBJECT)
            return
        if src == self._local_node_id:  # our own publication looped back (pycyphal: skipped, not counted)
            self.own_frames += 1
            return
        self.frames += 1
        index = index_eot & _INDEX_MASK
        if src == _ANONYMOUS:  # TransferReassembler.construct_anonymous_transfer: stateless
            if index == 0 and index_eot >= _EOT and len(data) > _HEADER_SIZE + _CRC_SIZE and \
                    crc32c_register(data[_HEADER_SIZE:]) == CRC32C_RESIDUE:
                self._deliver(data[_HEADER_SIZE:-_CRC_SIZE], None, tid, now_ns)
            else:  # pycyphal drops these uncounted
                self._refuse(ANONYMOUS_MULTIFRAME if index or index_eot < _EOT else ANONYMOUS_INTEGRITY)
            return
        if index == 0 and index_eot >= _EOT:
            # A single-frame transfer: its CRC first, so that a broken one changes nothing (issue 29).
            if len(data) < _HEADER_SIZE + _CRC_SIZE or crc32c_register(data[_HEADER_SIZE:]) != CRC32C_RESIDUE:
                self._error(src, _INTEGRITY)
                return
            st = self._sources.get(src)
            if st is None:
                st = self._sources[src] = _Source()
            if tid == st.tid:  # the next one
                st.tid = tid + 1
                st.ts_ns = now_ns
            elif not self._take(st, tid, now_ns):
                self._error(src, _UNEXPECTED_TID)
                return
            if st.slots and st.tid == tid + 1:
                self._superseded(st, tid)
            self._deliver(data[_HEADER_SIZE:-_CRC_SIZE], src, tid, now_ns)
            return
        self._reassemble(src, tid, index, index_eot >= _EOT, data[_HEADER_SIZE:], now_ns)

    def _take(self, st: _Source, tid: int, now_ns: int) -> bool:
        """Whether a whole transfer ``tid`` from the source of ``st`` is delivered (a duplicate or an old one is
        not, within the transfer-id timeout); its id becomes the source's expected one unless it jumped further
        ahead than the time since the last one allows (:func:`sam_runtime.common.transfer_ids.plausible_gap`):
        that one is delivered (the bridge counts it as a jump) and the real device's next transfer still taken."""
        elapsed = now_ns - st.ts_ns
        if tid >= st.tid:
            if tid - st.tid > JUMP_SLACK and tid - st.tid > JUMP_SLACK + elapsed // _NS_PER_PLAUSIBLE_TID and \
                    elapsed <= self.transfer_id_timeout_ns and \
                    getattr(self._receiver, "last_overflow_ns", 0) < st.ts_ns:  # (a kernel drop explains a gap)
                return True  # delivered, the state kept
        elif elapsed <= self.transfer_id_timeout_ns:
            return False  # a duplicate, or a transfer id that went back (pycyphal: UNEXPECTED_TRANSFER_ID)
        st.tid = tid + 1
        st.ts_ns = now_ns
        return True

    def _reassemble(self, src: int, tid: int, index: int, eot: bool, payload: bytes, now_ns: int) -> None:
        """A frame of a multi-frame transfer: into the slot of (source, transfer id). A slot is a transfer's own:
        frames of other transfer ids (a hostile sender's) neither restart nor end it, and only a whole transfer
        that passed its CRC moves the source's expected transfer id."""
        if not payload:
            self._error(src, _EMPTY_FRAME)
            return
        if index > MAX_FRAME_INDEX:
            self._error(src, FRAME_INDEX_LIMIT)
            return
        st = self._sources.get(src)
        if st is None:
            st = self._sources[src] = _Source()
        elif tid < st.tid and now_ns - st.ts_ns <= self.transfer_id_timeout_ns:
            self._error(src, _UNEXPECTED_TID)  # of a transfer taken already, or older
            return
        slots = self._slots
        slot = slots.get((src, tid))
        if slot is None:
            # Expiry, oldest first, when a slot is made: a transfer whose frames stopped is dropped after the
            # transfer-id timeout.
            while slots:
                oldest = next(iter(slots.values()))
                if now_ns - oldest.born_ns <= self.transfer_id_timeout_ns:
                    break
                self._discard(oldest, TRANSFER_EXPIRED)
            if len(st.slots) >= SLOTS_PER_SOURCE:  # pycyphal: a new transfer id restarts its one slot
                self._discard(st.slots[0], _MISSING_FRAMES)
            if len(slots) >= MAX_SLOTS:
                self._discard(next(iter(slots.values())), TRANSFER_EVICTED)
            slot = slots[(src, tid)] = _Slot(src, tid, now_ns)
            st.slots.append(slot)
            self._sources[src] = st  # (again: the discards above may have forgotten a source never taken)
        payloads = slot.payloads
        # A frame that contradicts the slot's frames is counted and dropped, the slot kept: it may be a hostile
        # sender's (pycyphal drops the transfer).
        if eot:
            if slot.max_index is not None and slot.max_index != index:
                self._error(src, _EOT_INCONSISTENT)
                return
            if len(payloads) - 1 > index:
                self._error(src, _EOT_MISPLACED)
                return
            slot.max_index = index
        elif slot.max_index is not None and index >= slot.max_index:
            self._error(src, _EOT_MISPLACED)
            return
        if index == 0:
            slot.ts_ns = now_ns
        while len(payloads) <= index:
            payloads.append(b"")
        payloads[index] = payload
        if slot.max_index is None or not all(payloads):
            return
        whole = b"".join(payloads)
        del slots[slot.key]
        st.slots.remove(slot)
        if len(whole) <= _CRC_SIZE or crc32c_register(whole) != CRC32C_RESIDUE:
            if not st.slots and st.tid < 0:  # a source never taken leaves nothing behind
                del self._sources[src]
            self._error(src, _INTEGRITY)  # and the source's state stays as it was
            return
        if tid == st.tid:
            st.tid = tid + 1
            st.ts_ns = slot.ts_ns
        elif not self._take(st, tid, slot.ts_ns):
            self._error(src, _UNEXPECTED_TID)
            return
        if st.slots and st.tid == tid + 1:
            self._superseded(st, tid)
        self._deliver(whole[:-_CRC_SIZE], src, tid, slot.ts_ns)

    def _superseded(self, st: _Source, tid: int) -> None:
        """The source's transfer ``tid`` was taken: its unfinished older ones can no longer be (pycyphal counts
        them as missing frames when the next transfer starts)."""
        for slot in [s for s in st.slots if s.tid < tid]:
            self._discard(slot, _MISSING_FRAMES)

    def _discard(self, slot: _Slot, error: str | None) -> None:
        del self._slots[slot.key]
        st = self._sources[slot.src]
        st.slots.remove(slot)
        if not st.slots and st.tid < 0:  # a source never taken leaves nothing behind (many made-up node ids)
            del self._sources[slot.src]
        if error is not None:
            self._error(slot.src, error)

    def _refuse(self, kind: str) -> None:
        self.errors += 1
        self.refused[kind] = self.refused.get(kind, 0) + 1

    def _error(self, src: int, error: str) -> None:
        self.errors += 1
        errs = self.errors_per_source.get(src)
        if errs is None:
            if len(self.errors_per_source) >= MAX_ERROR_SOURCES:  # node ids made up by the thousand: not kept
                self.unattributed[error] = self.unattributed.get(error, 0) + 1
                return
            errs = self.errors_per_source[src] = {}
        errs[error] = errs.get(error, 0) + 1

    def _deliver(self, payload: bytes, src: int | None, tid: int, stamp_ns: int) -> None:
        self.transfers += 1
        self.payload_bytes += len(payload)
        try:
            self.handler(payload, src, tid, stamp_ns * 1e-9)
        except Exception as ex:  # the handlers never raise; if one did, the other subjects go on
            self.handler_failures += 1
            if self.handler_failures == 1 or not self.handler_failures & (self.handler_failures - 1):
                _log.error("subject %d: the handler failed (%d times): %s: %s", self.subject_id,
                           self.handler_failures, type(ex).__name__, ex)


class UDPLoopReceiver:
    """The subscribed subjects of one Cyphal/UDP node, received on the running loop through one socket.

    :param local_ip: the transport's interface address (its multicast memberships are made there).
    :param local_node_id: the node's own id (its looped-back frames are skipped, as pycyphal does) or None.
    :param rcvbuf_bytes: the socket's receive buffer to ask for (pycyphal's sockets keep the default, one each).
    Create, subscribe and close it in the loop's thread."""

    def __init__(self, local_ip: str, local_node_id: int | None, rcvbuf_bytes: int = RCVBUF_BYTES) -> None:
        self.local_ip = str(local_ip)
        self.local_node_id = local_node_id
        self.overflows = 0  # datagrams the kernel dropped (receive buffer full): SO_RXQ_OVFL
        self.not_subscribed = 0  # datagrams read for no subscribed subject (the ports count the rest)
        # When the kernel last dropped datagrams (monotonic ns; 0: never): a gap in a source's transfer ids across
        # it is a loss, however far ahead (SubjectPort._take)
        self.last_overflow_ns = 0
        self.failure: str | None = None  # why the socket stopped (the link supervisor reopens the transport)
        self._loop = asyncio.get_running_loop()
        self._ports: dict[bytes, SubjectPort] = {}
        self._iface = socket.inet_aton(self.local_ip)
        self._kernel_drops = 0
        sock = open_socket(rcvbuf_bytes=rcvbuf_bytes, overflow_counter=True)
        self._sock: socket.socket | None = sock
        self._loop.add_reader(sock.fileno(), self._on_readable)

    @property
    def ports(self) -> list[SubjectPort]:
        return list(self._ports.values())

    def subscribe(self, subject_id: int, extent_bytes: int, handler: Handler) -> SubjectPort:
        """A port for ``subject_id`` (one per subject) whose transfers go to ``handler``."""
        sock = self._sock
        if sock is None:
            raise OSError(f"the Cyphal/UDP receiver on {self.local_ip} is closed")
        group = subject_group(subject_id)
        if group in self._ports:
            raise ValueError(f"subject {subject_id} is subscribed already")
        join_group(sock, group, self._iface)
        port = self._ports[group] = SubjectPort(self, subject_id, extent_bytes, handler)
        return port

    def unsubscribe(self, port: SubjectPort) -> None:
        group = subject_group(port.subject_id)
        if self._ports.get(group) is not port:
            return
        del self._ports[group]
        if self._sock is not None:
            leave_group(self._sock, group, self._iface)

    def close(self) -> None:
        sock, self._sock = self._sock, None
        self._ports.clear()
        stop_reading(self._loop, sock, close=True)

    def _on_readable(self) -> None:
        sock = self._sock
        if sock is None:
            return
        recvmsg, ports, clock = sock.recvmsg, self._ports, time.monotonic_ns
        for _ in range(BATCH):
            try:
                data, ancdata, _flags, _addr = recvmsg(_READ_SIZE, _ANC_SIZE)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as ex:
                self._fail(ex)
                return
            now = clock()
            group = b""
            for level, kind, cdata in ancdata:
                if kind == IP_PKTINFO and level == _SOL_IP:
                    group = cdata[8:12]  # in_pktinfo.ipi_addr: the datagram's destination
                elif kind == SO_RXQ_OVFL and level == _SOL_SOCKET:
                    self._note_kernel_drops(int.from_bytes(cdata[:4], sys.byteorder))
            port = ports.get(group)
            if port is not None:
                port.feed(data, now)
            else:  # not a subscribed group (a unicast datagram to the port, a late one): counted, not read further
                self.not_subscribed += 1

    def _note_kernel_drops(self, total: int) -> None:
        # The counter is the socket's total so far (32 bits, wrapping): count what it grew by.
        grew = (total - self._kernel_drops) & 0xFFFFFFFF
        if grew:
            self._kernel_drops = total
            self.overflows += grew
            self.last_overflow_ns = time.monotonic_ns()

    def _fail(self, ex: OSError) -> None:
        self.failure = f"Cyphal/UDP receive on {self.local_ip}: {type(ex).__name__}: {ex}"
        _log.warning("%s", self.failure)
        stop_reading(self._loop, self._sock)  # the reopen replaces it

    def __repr__(self) -> str:
        subjects = sorted(p.subject_id for p in self._ports.values())
        return f"UDPLoopReceiver({self.local_ip!r}, local_node_id={self.local_node_id}, subjects={subjects})"



@functools.cache
def _statistics_class() -> type:
    from pycyphal.transport.udp import PromiscuousUDPInputSessionStatistics

    class Statistics(PromiscuousUDPInputSessionStatistics):
        """pycyphal's statistics with ``reassembly_errors``: the errors no source can be blamed for (kind ->
        count, e.g. a bad header CRC), which the bridge reports as it reports pycyphal's."""

        reassembly_errors: dict[str, int]

    return Statistics


def loop_udp_transport(local_ip_address: str, local_node_id: int | None, **kwargs: Any) -> Any:
    """pycyphal's UDPTransport whose message subscriptions may be received on the loop (its ``loop_receiver``).

    The receiver's subjects are listed among the transport's input sessions (so the node's
    ``uavcan.node.port.List`` still names them) and it closes with the transport; publications, services and any
    pycyphal input session stay pycyphal's. ``kwargs``: UDPTransport's (mtu, service_transfer_multiplier)."""
    return _loop_udp_transport_class()(local_ip_address, local_node_id, **kwargs)


def loop_udp_transport_class() -> type:
    """The class :func:`loop_udp_transport` makes (pycyphal imported on the first call), for a subclass
    (sam_runtime.cyphal_io.udp_sessions: pycyphal's input sessions on the loop too)."""
    return _loop_udp_transport_class()


@functools.cache
def _loop_udp_transport_class() -> type:
    from pycyphal.transport import ResourceClosedError
    from pycyphal.transport.udp import UDPTransport

    class LoopUDPTransport(UDPTransport):
        __doc__ = loop_udp_transport.__doc__

        def __init__(self, local_ip_address: str, local_node_id: int | None, **kw: Any) -> None:
            super().__init__(local_ip_address, local_node_id, **kw)
            self._loop_receiver: UDPLoopReceiver | None = None
            self._loop_receiver_closed = False

        @property
        def loop_receiver(self) -> UDPLoopReceiver:
            """The receiver (made on first use, in the running loop)."""
            if self._loop_receiver_closed:
                raise ResourceClosedError(f"{self!r} is closed")
            if self._loop_receiver is None:
                self._loop_receiver = UDPLoopReceiver(str(self.local_ip_address), self.local_node_id)
            return self._loop_receiver

        @property
        def input_sessions(self) -> Sequence[Any]:
            receiver = self._loop_receiver
            return [*super().input_sessions, *(receiver.ports if receiver is not None else ())]

        def close(self) -> None:
            self._loop_receiver_closed = True
            super().close()
            receiver, self._loop_receiver = self._loop_receiver, None
            if receiver is not None:
                receiver.close()

    return LoopUDPTransport
