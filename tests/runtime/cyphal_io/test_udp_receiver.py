"""The Cyphal/UDP receiver on the event loop (sam_runtime.cyphal_io.udp_receiver) against pycyphal 1.27 itself.

The same datagram sequences, with the same reception times, go to pycyphal's own UDP input session (its
``receive`` and ``TransferReassembler``, the datagrams parsed by ``UDPFrame.parse`` as its reader thread does) and
to a :class:`SubjectPort`; both must accept the same transfers (payload, source, transfer id, timestamp) and count
the same frames, errors and error kinds per source. The sequences are made with pycyphal's own serialization
(``UDPFrame.compile_header_and_payload``, ``serialize_transfer``) and broken on purpose: header CRC, version,
truncation, transfer CRC, duplicated / reordered / missing frames, transfer ids going back, the transfer-id
timeout, anonymous and interleaved sources, payloads beyond the extent, other subjects' and services' frames, the
node's own frames. The differences are deliberate and checked: a datagram that makes pycyphal's parser raise
(priority above 7; a service frame from an anonymous node), which pycyphal logs with a traceback from its reader
thread and counts nowhere, is one more error here, as are the datagrams pycyphal skips uncounted (another
subject's, anonymous multi-frame or broken ones); and where a hostile sender could steer pycyphal's state (issue
29: broken CRCs, transfer-id jumps, frames of other transfers, partial transfers from many node ids) this receiver
keeps the real device's stream, which the fuzz target at the end checks.
"""

from __future__ import annotations

import asyncio
import dataclasses
import socket
from collections.abc import Callable
from typing import Any

import pytest

pytest.importorskip("pycyphal")

from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from pycyphal.transport import (
    InputSessionSpecifier,
    MessageDataSpecifier,
    PayloadMetadata,
    Priority,
    ServiceDataSpecifier,
    Timestamp,
)
from pycyphal.transport.commons.crc import CRC16CCITT
from pycyphal.transport.commons.high_overhead_transport import TransferCRC, TransferReassembler, serialize_transfer
from pycyphal.transport.udp import PromiscuousUDPInputSession, PromiscuousUDPInputSessionStatistics, UDPFrame
from pycyphal.transport.udp._ip._endpoint_mapping import message_data_specifier_to_multicast_group

from sam_runtime.cyphal_io.crc32c import IMPLEMENTATION, crc32c_register, crc32c_register_python
from sam_runtime.cyphal_io.udp_receiver import (
    ANONYMOUS_INTEGRITY,
    ANONYMOUS_MULTIFRAME,
    FRAME_INDEX_LIMIT,
    MAX_ERROR_SOURCES,
    MAX_FRAME_INDEX,
    MAX_SLOTS,
    WRONG_SUBJECT,
    SubjectPort,
    single_frame_datagram,
    subject_group,
)

SUBJECT = 1234
OTHER_SUBJECT = 1235
LOCAL_NODE = 100
EXTENT = 40
T0_NS = 1_000_000_000_000  # the first datagram's monotonic time


@dataclasses.dataclass(frozen=True)
class Outcome:
    transfers: list[tuple[bytes, int | None, int, int]]  # payload, source, transfer id, timestamp (ns)
    stats: PromiscuousUDPInputSessionStatistics
    raised: int  # datagrams pycyphal's parser raised on (its reader thread logs them and counts nothing)


class _Receiver:
    """What the loop receiver needs of its owner: the node's own id (a SubjectPort takes it at creation)."""

    local_node_id = LOCAL_NODE

    def unsubscribe(self, port: SubjectPort) -> None:
        pass


def _with_pycyphal(datagrams: list[tuple[bytes, int]], extent: int = EXTENT) -> Outcome:
    """pycyphal's PromiscuousUDPInputSession: each datagram parsed as its reader thread parses it and queued with its
    reception time as the thread queues it, then taken by ``receive`` as the transport's user does."""

    async def run() -> Outcome:
        spec = InputSessionSpecifier(MessageDataSpecifier(SUBJECT), None)
        stats = PromiscuousUDPInputSessionStatistics()
        dead = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        dead.close()  # its reader thread stops at once: the datagrams are handed in below, with chosen times
        session = PromiscuousUDPInputSession(spec, PayloadMetadata(extent), dead, lambda: None, LOCAL_NODE, stats)
        out, raised = [], 0
        try:
            for data, ns in datagrams:
                try:
                    frame = UDPFrame.parse(memoryview(data))
                except Exception:  # the reader thread: handle_internal_error() logs it, nothing is counted
                    raised += 1
                    continue
                session._put_into_queue(Timestamp(system_ns=ns, monotonic_ns=ns), frame)
                while (tr := await session.receive(0.0)) is not None:
                    out.append((b"".join(tr.fragmented_payload), tr.source_node_id, tr.transfer_id,
                                tr.timestamp.monotonic_ns))
        finally:
            session.close()
        return Outcome(out, session.sample_statistics(), raised)

    return asyncio.run(run())


def _with_port(datagrams: list[tuple[bytes, int]], extent: int = EXTENT) -> Outcome:
    out: list[tuple[bytes, int | None, int, int]] = []
    port = SubjectPort(_Receiver(), SUBJECT, extent,  # type: ignore[arg-type]
                       lambda payload, src, tid, stamp: out.append((payload, src, tid, round(stamp * 1e9))))
    for data, ns in datagrams:
        port.feed(data, ns)
    return Outcome(out, port.sample_statistics(), 0)


def _same(datagrams: list[tuple[bytes, int]], extent: int = EXTENT) -> tuple[Outcome, Outcome]:
    ref, got = _with_pycyphal(datagrams, extent), _with_port(datagrams, extent)
    # Timestamps: ours are float seconds at the handler (as the core takes them); equal within float rounding.
    assert [t[:3] for t in got.transfers] == [t[:3] for t in ref.transfers]
    assert all(abs(a[3] - b[3]) <= 1000 for a, b in zip(got.transfers, ref.transfers, strict=True))
    r, g = ref.stats, got.stats
    assert (g.transfers, g.frames, g.payload_bytes, g.drops) == (r.transfers, r.frames, r.payload_bytes, r.drops)
    # What pycyphal drops uncounted is an error here too (issue 29: every datagram counted).
    uncounted = sum(g.reassembly_errors.get(k, 0) for k in (WRONG_SUBJECT, ANONYMOUS_MULTIFRAME, ANONYMOUS_INTEGRITY))
    assert g.errors == r.errors + ref.raised + uncounted
    assert _per_source(g) == _per_source(r)
    return ref, got


def _per_source(stats: PromiscuousUDPInputSessionStatistics) -> dict[int, dict[Any, int]]:
    """The reassembly errors per source, without the sources of none (pycyphal lists every source it heard)."""
    return {src: errs for src, errs in stats.reassembly_errors_per_source_node_id.items() if any(errs.values())}


# ------------------------------------------------------------------------------------------------ datagrams
def _frame(payload: bytes, *, src: int | None = 11, tid: int = 0, index: int = 0, eot: bool = True,
           subject: int = SUBJECT, prio: Priority = Priority.NOMINAL, service: bool = False) -> bytes:
    ds = (ServiceDataSpecifier(subject % 512, ServiceDataSpecifier.Role.REQUEST) if service
          else MessageDataSpecifier(subject))
    header, body = UDPFrame(priority=prio, source_node_id=src, destination_node_id=None, data_specifier=ds,
                            transfer_id=tid, index=index, end_of_transfer=eot, user_data=0,
                            payload=memoryview(payload)).compile_header_and_payload()
    return bytes(header) + bytes(body)


def _transfer(payload: bytes, *, mtu: int = 1200, **kw: Any) -> list[bytes]:
    """The datagrams pycyphal's output session sends for ``payload`` (its serializer, its frames)."""
    frames = serialize_transfer([memoryview(payload)], mtu, lambda i, eot, p: (i, eot, bytes(p)))
    return [_frame(p, index=i, eot=eot, **kw) for i, eot, p in frames]


def _single(payload: bytes, **kw: Any) -> bytes:
    return _frame(payload + TransferCRC.new(payload).value_as_bytes, **kw)


def _with_header_crc(header22: bytes) -> bytes:
    return header22 + CRC16CCITT.new(header22).value.to_bytes(2, "big")


def _reheader(data: bytes, **fields: int) -> bytes:
    """``data`` with header fields replaced and a valid header CRC (to reach the checks after the CRC)."""
    names = ("version", "prio", "src", "dst", "dsn", "tid", "index_eot", "user")
    values = dict(zip(names, UDPFrame._HEADER_FORMAT_NO_CRC.unpack_from(data), strict=True))
    values.update(fields)
    return _with_header_crc(UDPFrame._HEADER_FORMAT_NO_CRC.pack(*values.values())) + data[24:]


def _timed(datagrams: list[bytes], gaps_s: list[float] | None = None) -> list[tuple[bytes, int]]:
    ns, out = T0_NS, []
    for i, d in enumerate(datagrams):
        ns += round((gaps_s[i] if gaps_s else 0.001) * 1e9)
        out.append((d, ns))
    return out


# ------------------------------------------------------------------------------------------------ fixed cases
def test_group_is_pycyphals() -> None:
    for sid in (0, 1, 255, 256, 1234, 7509, 8191):
        assert subject_group(sid) == message_data_specifier_to_multicast_group(MessageDataSpecifier(sid)).packed


def test_valid_transfers_single_and_multi_frame_from_interleaved_sources() -> None:
    a, b = bytes(range(30)), bytes(range(100, 200)) * 3
    dgs = [_single(a, src=11, tid=5), *_transfer(b, mtu=64, src=12, tid=7)]
    dgs.insert(2, _single(a[:7], src=13, tid=0))  # another source between the frames of one
    dgs.append(_single(b"", src=11, tid=6))  # an empty single-frame transfer is valid
    _, got = _same(_timed(dgs))
    assert [(p, s, t) for p, s, t, _ in got.transfers] == [(a, 11, 5), (a[:7], 13, 0), (b, 12, 7), (b"", 11, 6)]
    assert got.stats.errors == 0


def test_multi_frame_timestamp_is_the_first_frames() -> None:
    payload = bytes(range(200))
    dgs = _transfer(payload, mtu=64, tid=3)
    _, got = _same(_timed([dgs[2], dgs[0], dgs[3], dgs[1]], [0.0, 0.5, 0.1, 0.1]))
    assert got.transfers == [(payload, 11, 3, T0_NS + round(0.5e9))]


def test_malformed_headers_are_errors() -> None:
    good = _single(b"hello", tid=1)
    broken_crc = good[:23] + bytes([good[23] ^ 1]) + good[24:]
    dgs = [b"", b"\x01" * 10, good[:21], good[:22], good[:23], _single(b"hello", tid=0)[:24], broken_crc,
           _reheader(good, version=2), bytes([2]) + good[1:], good]
    ref, got = _same(_timed(dgs))
    # Every datagram is one error but the last; the header-only one (transfer id 0) is a frame without room for
    # its transfer CRC: an INTEGRITY_ERROR of its source.
    assert got.stats.errors == 9 and ref.stats.errors == 9
    assert got.stats.reassembly_errors_per_source_node_id == {11: {TransferReassembler.Error.INTEGRITY_ERROR: 1}}
    assert [t[:3] for t in got.transfers] == [(b"hello", 11, 1)]


def test_what_pycyphals_parser_raises_on_is_an_error_here() -> None:
    good = _single(b"hello", tid=1)
    dgs = [_reheader(good, prio=8), _reheader(good, prio=255), _reheader(good, src=0xFFFF, dsn=(1 << 15) | 5), good]
    ref, got = _same(_timed(dgs))
    assert ref.raised == 3 and ref.stats.errors == 0 and got.stats.errors == 3
    assert [t[:3] for t in got.transfers] == [(b"hello", 11, 1)]


def test_frames_not_for_the_subject_are_counted() -> None:
    """Another subject's frame in this subject's group and a service frame are refused (pycyphal skips them
    uncounted); the node's own looped-back frame is counted apart, as no error."""
    dgs = [_single(b"x", subject=OTHER_SUBJECT), _single(b"y", service=True), _single(b"z", src=LOCAL_NODE),
           _single(b"w", src=12)]
    _, got = _same(_timed(dgs))
    assert got.stats.frames == 1 and got.stats.errors == 2 and [t[0] for t in got.transfers] == [b"w"]
    assert got.stats.reassembly_errors == {WRONG_SUBJECT: 2}


def test_transfer_crc_missing_frames_duplicates_and_transfer_ids() -> None:
    """The errors pycyphal counts, counted as pycyphal does, but for what this receiver does differently on
    purpose (issue 29): a transfer whose last frame is missing keeps its slot until the transfer-id timeout (a new
    transfer id does not end it: it may be a hostile sender's), and a frame that contradicts its slot's frames is
    dropped, not its slot."""
    payload = bytes(range(150))
    frames = _transfer(payload, mtu=64, tid=10)
    bad_crc = _single(b"abc", tid=20)
    bad_crc = bad_crc[:-1] + bytes([bad_crc[-1] ^ 0xFF])
    dgs = [frames[0], frames[1], *_transfer(payload, mtu=64, tid=11)]  # 10 misses its last frame; 11 is whole
    dgs += [_single(b"dup", tid=12), _single(b"dup", tid=12), _single(b"old", tid=3)]  # a duplicate, one back
    dgs += [bad_crc, _single(b"", tid=21)[:24]]  # broken transfer CRC; no room for a CRC at all
    dgs += [_frame(b"", tid=30, index=1, eot=False)]  # an empty frame of a multi-frame transfer
    dgs += [_frame(b"p", tid=31, index=2, eot=True), _frame(b"q", tid=31, index=3, eot=False)]  # EOT misplaced
    dgs += [_frame(b"p", tid=32, index=2, eot=True), _frame(b"q", tid=32, index=3, eot=True)]  # EOT inconsistent
    got = _with_port(_timed(dgs))
    errs = got.stats.reassembly_errors_per_source_node_id[11]
    assert {e.name: n for e, n in errs.items()} == {
        "MULTIFRAME_MISSING_FRAMES": 1, "UNEXPECTED_TRANSFER_ID": 2, "INTEGRITY_ERROR": 2,
        "MULTIFRAME_EMPTY_FRAME": 1, "MULTIFRAME_EOT_MISPLACED": 1, "MULTIFRAME_EOT_INCONSISTENT": 1}
    assert [t[:3] for t in got.transfers] == [(payload, 11, 11), (b"dup", 11, 12)]
    # (10's slot ended when 11 was taken.) The two unfinished ones (31, 32) end after the transfer-id timeout
    timed = _timed(dgs)
    got = _with_port([*timed, (_frame(b"x", tid=40, index=0, eot=False), timed[-1][1] + 3_000_000_000)])
    errs = got.stats.reassembly_errors_per_source_node_id[11]
    assert errs["TRANSFER_EXPIRED"] == 2


def test_a_spoofed_frame_of_a_transfer_in_flight_spoils_that_transfer_alone() -> None:
    """What the receive path cannot prevent (README, issue 29 d): a header-valid frame with the device's node id,
    its in-flight transfer id and an index the device also sends takes that index's place (before or after the
    device's frame: the later is kept), so the transfer fails its CRC. Nothing more: counted as one INTEGRITY_ERROR,
    the device's next transfers delivered, its expected transfer id untouched."""
    payload = bytes(range(150))
    real = _transfer(payload, mtu=64, tid=10)
    assert len(real) == 3
    spoof = _frame(b"x" * 64, tid=10, index=1, eot=False)
    # (the spoofed frame after the device's: the transfer is lost; before it: the device's frame wins)
    for dgs, spoiled in (([real[0], real[1], spoof, real[2]], True), ([real[0], spoof, real[1], real[2]], False)):
        got = _with_port(_timed([*dgs, *_transfer(payload, mtu=64, tid=11), _single(b"next", tid=12)]))
        assert [t[:3] for t in got.transfers] == [*([] if spoiled else [(payload, 11, 10)]),
                                                 (payload, 11, 11), (b"next", 11, 12)]
        errs = got.stats.reassembly_errors_per_source_node_id.get(11, {})
        assert {getattr(e, "name", e): n for e, n in errs.items()} == ({"INTEGRITY_ERROR": 1} if spoiled else {})


def test_transfer_id_timeout() -> None:
    """A transfer id that went back is refused within pycyphal's 2 s transfer-id timeout, accepted after it."""
    dgs = [_single(b"a", tid=50), _single(b"b", tid=5), _single(b"c", tid=5), _single(b"d", tid=6)]
    _, got = _same(_timed(dgs, [0.0, 1.9, 0.2, 0.0]))
    assert [t[:3] for t in got.transfers] == [(b"a", 11, 50), (b"c", 11, 5), (b"d", 11, 6)]


def test_anonymous_transfers() -> None:
    dgs = [_single(b"anon", src=None, tid=3), _single(b"anon", src=None, tid=3),  # no deduplication: stateless
           _single(b"", src=None), _frame(b"abcdef", src=None, eot=False),  # no empty one; no multi-frame
           _single(b"x", src=None)[:-1] + b"\x00"]  # broken CRC: dropped (pycyphal counts no error; here one)
    _, got = _same(_timed(dgs))
    assert [t[:3] for t in got.transfers] == [(b"anon", None, 3)] * 2
    assert got.stats.frames == 5 and got.stats.errors == 3
    assert got.stats.reassembly_errors == {ANONYMOUS_INTEGRITY: 2, ANONYMOUS_MULTIFRAME: 1}


def test_payload_beyond_the_extent_is_delivered_whole() -> None:
    """pycyphal's transport does not truncate (its reassembler says so): the deserializer applies the extent."""
    big = bytes(range(256)) * 2
    _, got = _same(_timed([*_transfer(big, mtu=100, tid=1), _single(big[:300], tid=2)]), extent=8)
    assert [t[0] for t in got.transfers] == [big, big[:300]]


def test_a_frame_index_past_the_limit_is_refused_and_counted() -> None:
    """pycyphal would grow its fragment list to the index (2**31 entries: it hangs): here an error of its own."""
    dgs = _timed([_frame(b"x", tid=1, index=MAX_FRAME_INDEX + 1, eot=False),
                  _frame(b"x", tid=1, index=(1 << 31) - 1, eot=True), _single(b"ok", tid=2)])
    got = _with_port(dgs)
    assert got.stats.errors == 2 and [t[0] for t in got.transfers] == [b"ok"]
    assert got.stats.reassembly_errors_per_source_node_id == {11: {FRAME_INDEX_LIMIT: 2}}


# ------------------------------------------------------------------------------------------------ property test
_SOURCES = st.sampled_from([11, 12, 13, None, LOCAL_NODE])
_GAPS = st.sampled_from([0.0, 0.001, 0.3, 1.0, 2.5])


@st.composite
def _episode(draw: Callable[..., Any], hostile: bool = True) -> list[bytes]:
    """A few datagrams: a transfer (maybe multi-frame, maybe mangled) or a broken datagram. Not ``hostile``:
    whole transfers only, their frames in order, transfer ids that do not jump (where this receiver is
    pycyphal; the hostile cases are the fuzz target's, below)."""
    kind = draw(st.sampled_from(["transfer", "transfer", "transfer", "frame", "garbage", "mangled"])
                if hostile else st.just("transfer"))
    src = draw(_SOURCES)
    tid = draw(st.one_of(st.integers(0, 8), st.integers(2**32, 2**32 + 3), st.just(2**64 - 1))
               if hostile else st.integers(0, 8))
    if kind == "transfer":
        payload = draw(st.binary(max_size=120))
        mtu = draw(st.sampled_from([16, 40, 1200]))
        dgs = _transfer(payload, mtu=mtu, src=src, tid=tid)
        if not hostile:  # (in order: pycyphal refuses a later frame that comes first after the timeout, and
            return dgs    # then the whole transfer; here the transfer is taken whole)
        if draw(st.booleans()):  # lose, repeat and reorder some frames
            dgs = draw(st.lists(st.sampled_from(dgs), max_size=len(dgs) + 2)) if len(dgs) > 1 else dgs * 2
            dgs = draw(st.permutations(dgs))
        if draw(st.integers(0, 5)) == 0 and dgs:  # break the transfer CRC (its last byte)
            i = draw(st.integers(0, len(dgs) - 1))
            dgs[i] = dgs[i][:-1] + bytes([dgs[i][-1] ^ 0x5A]) if len(dgs[i]) > 24 else dgs[i]
        return list(dgs)
    if kind == "frame":  # any header with any payload
        return [_frame(draw(st.binary(max_size=12)), src=src, tid=tid, index=draw(st.integers(0, 6)),
                       eot=draw(st.booleans()), subject=draw(st.sampled_from([SUBJECT, OTHER_SUBJECT])),
                       service=src is not None and draw(st.integers(0, 9)) == 0)]
    if kind == "garbage":
        return [draw(st.binary(max_size=40))]
    good = _single(draw(st.binary(max_size=10)), src=src, tid=tid)
    how = draw(st.sampled_from(["truncate", "flip", "version", "prio"]))
    if how == "truncate":
        return [good[: draw(st.integers(0, len(good) - 1))]]
    if how == "flip":
        i = draw(st.integers(0, len(good) - 1))
        return [good[:i] + bytes([good[i] ^ draw(st.integers(1, 255))]) + good[i + 1:]]
    if how == "version":
        return [_reheader(good, version=draw(st.sampled_from([0, 2, 255])))]
    return [_reheader(good, prio=draw(st.integers(8, 255)))]


@given(st.lists(st.tuples(_episode(hostile=False), _GAPS), max_size=14), st.sampled_from([0, 8, 200]))
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_same_as_pycyphal_on_any_datagram_sequence(episodes: list[tuple[list[bytes], float]], extent: int) -> None:
    datagrams, gaps = [], []
    for dgs, gap in episodes:
        datagrams += dgs
        gaps += [gap] + [0.0] * (len(dgs) - 1)
    ref, got = _same(_timed(datagrams, gaps), extent)
    # What the examples cover (pytest --hypothesis-show-statistics): accepted transfers and each kind of refusal.
    event("accepted" if got.transfers else "none accepted")
    for errs in got.stats.reassembly_errors_per_source_node_id.values():
        for kind in errs:
            event(f"error {kind.name}")
    if got.stats.errors > sum(sum(e.values()) for e in got.stats.reassembly_errors_per_source_node_id.values()):
        event("unparsable datagram")
    if ref.raised:
        event("pycyphal's parser raised")


@given(st.one_of(st.none(), st.integers(0, 0xFFFE)), st.integers(0, 8191), st.integers(0, 2**64 - 1),
       st.binary(max_size=80), st.integers(0, 7))
@settings(max_examples=200, deadline=None)
def test_the_single_frame_datagram_is_pycyphals(src: int | None, subject: int, tid: int, payload: bytes,
                                                 prio: int) -> None:
    ref = _frame(payload + TransferCRC.new(payload).value_as_bytes, src=src, tid=tid, subject=subject,
                 prio=Priority(prio))
    assert single_frame_datagram(src, subject, tid, payload, prio) == ref


@given(st.binary(max_size=300), st.integers(0, 2**32 - 1))
@settings(max_examples=300, deadline=None)
def test_crc32c_is_pycyphals_transfer_crc(data: bytes, start: int) -> None:
    from pycyphal.transport.commons.crc import CRC32C

    ref = CRC32C()
    ref._value = start  # pycyphal's register, from any state: the word steps must agree with its byte steps
    ref.add(data)
    assert crc32c_register(data, start) == crc32c_register_python(data, start) == ref._value


def test_the_crc_is_computed_in_c_where_the_runtime_is_installed() -> None:
    # google_crc32c is a runtime dependency with wheels for x86-64 and aarch64: the Python fallback here would
    # mean the dependency went missing (a silent ~12 % more CPU on a Cyphal bridge)
    assert IMPLEMENTATION == "c"


def test_the_transfer_id_timeout_is_pycyphals() -> None:
    from pycyphal.transport.udp import UDPInputSession

    from sam_runtime.cyphal_io.udp_receiver import TRANSFER_ID_TIMEOUT_S

    assert TRANSFER_ID_TIMEOUT_S == UDPInputSession.DEFAULT_TRANSFER_ID_TIMEOUT


# ------------------------------------------------------------------------------------------------ the fuzz target
# Issue 29: the receive path under hostile datagrams, in-process (no socket), derandomized. A real device (node 21)
# sends its transfers, single- and multi-frame, one every 10 ms; between them come hostile datagrams: anything of
# the property test's episodes (any node, garbage, mangled headers, partial transfers), and aimed at the device:
# its node id with a broken transfer CRC (also with the id it sends next), valid transfers whose id jumped far
# ahead or went back, partial transfers from many node ids. Never raises; every datagram is counted once; the
# device loses nothing; the reassembly slots stay bounded; after the junk and a transfer-id timeout every source's
# good transfers are taken again.
_DEVICE = 21


@st.composite
def _aimed(draw: Callable[..., Any], next_tid: int) -> list[bytes]:
    kind = draw(st.sampled_from(["bad_crc", "bad_crc_multi", "jump", "back", "partials", "header_crc"]))
    if kind == "bad_crc":
        tid = draw(st.sampled_from([next_tid, next_tid + 1, next_tid + 7, 2**40]))
        good = _single(draw(st.binary(max_size=20)), src=_DEVICE, tid=tid)
        return [good[:-1] + bytes([good[-1] ^ draw(st.integers(1, 255))])]
    if kind == "bad_crc_multi":  # a whole multi-frame transfer with a broken CRC, of another transfer id
        tid = draw(st.sampled_from([next_tid + 1, next_tid + 5, 2**40]))
        dgs = _transfer(draw(st.binary(min_size=50, max_size=90)), mtu=40, src=_DEVICE, tid=tid)
        dgs[-1] = dgs[-1][:-1] + bytes([dgs[-1][-1] ^ 0x33])
        return dgs
    if kind == "jump":
        return [_single(b"spoof", src=_DEVICE, tid=next_tid + draw(st.sampled_from([2**40, 2**63, 10**6])))]
    if kind == "back":
        return [_single(b"old", src=_DEVICE, tid=max(0, next_tid - draw(st.integers(1, 50))))]
    if kind == "partials":  # first frames of transfers that never end, from many node ids
        first = draw(st.integers(200, 60000))
        return [_transfer(bytes(80), mtu=40, src=first + i, tid=i)[0] for i in range(draw(st.integers(1, 90)))]
    good = _single(b"x", src=_DEVICE, tid=next_tid)
    return [good[:22] + bytes([good[22] ^ 0x01]) + good[23:]]  # the header CRC broken


@st.composite
def _hostile_run(draw: Callable[..., Any]) -> tuple[list[tuple[bytes, int]], list[int]]:
    """The datagrams with their times, and the transfer ids the device sent."""
    out, sent, ns, tid = [], [], T0_NS, 5000
    for _ in range(draw(st.integers(1, 12))):
        payload = draw(st.binary(max_size=100))
        for d in _transfer(payload, mtu=draw(st.sampled_from([40, 1200])), src=_DEVICE, tid=tid):
            out.append((d, ns))
        sent.append(tid)
        tid += 1
        junk = draw(st.one_of(_episode(), _aimed(tid)))
        for d in junk:
            ns += 100_000
            out.append((d, ns))
        ns += 10_000_000
    return out, sent


@given(_hostile_run())
@settings(max_examples=150, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
def test_fuzz_hostile_datagrams_beside_a_real_device(run: tuple[list[tuple[bytes, int]], list[int]]) -> None:
    datagrams, sent = run
    got: list[tuple[int | None, int]] = []
    port = SubjectPort(_Receiver(), SUBJECT, EXTENT,  # type: ignore[arg-type]
                       lambda payload, src, tid, stamp: got.append((src, tid)))
    for data, ns in datagrams:
        port.feed(data, ns)
        assert port.partial_transfers <= MAX_SLOTS
    assert [tid for src, tid in got if src == _DEVICE and tid in sent] == sent  # nothing of the device lost
    # every datagram counted once: a frame (anonymous ones too: their refusals are counted on top), own, or refused
    refused = sum(n for k, n in port.refused.items() if k not in (ANONYMOUS_MULTIFRAME, ANONYMOUS_INTEGRITY))
    assert port.frames + port.own_frames + refused == len(datagrams)
    assert port.errors == sum(port.refused.values()) + sum(port.unattributed.values()) + sum(
        sum(e.values()) for e in port.errors_per_source.values())
    assert len(port.errors_per_source) <= MAX_ERROR_SOURCES
    # after the junk and a transfer-id timeout, good transfers from every source are taken again
    ns = datagrams[-1][1] + 2_500_000_000
    got.clear()
    for i, src in enumerate((11, 12, 13, _DEVICE)):
        for d in _transfer(bytes(range(60)), mtu=40 if i % 2 else 1200, src=src, tid=i):
            port.feed(d, ns)
    assert got == [(11, 0), (12, 1), (13, 2), (_DEVICE, 3)]
