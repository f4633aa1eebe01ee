"""pycyphal's Cyphal/UDP input sessions on the event loop (sam_runtime.cyphal_io.udp_sessions) against pycyphal 1.27.

- The same datagram sequences, with the same reception times, go to pycyphal's own input sessions (promiscuous: a
  service server's requests, a subject; selective: a client's responses from one server) and to a
  :class:`LoopInputSession` of the same specifier: the same transfers (payload, source, transfer id, timestamp) and
  the same statistics (pycyphal's classes, compared whole). Fixed cases and random sequences (hypothesis) of service
  and message frames: other services, the other role, other and own and anonymous sources, multi-frame transfers cut,
  repeated and reordered, broken bytes, truncation, the transfer-id timeout. The one deliberate difference: a datagram
  pycyphal's parser raises on (priority above 7, a service frame from an anonymous node) is one more error here.
- receive(): waits for a datagram without polling, returns None at its deadline, and a close wakes it.
- On real sockets (127.0.0.1): a node on the loop transport answers a plain pycyphal node's GetInfo and register
  calls, its own client gets the peer's answer, its heartbeat publisher hears the peer, and no reader thread is
  started; closing leaves every group and closes the socket. yakut (its own venv, skipped where absent) calls it.
"""

from __future__ import annotations

import asyncio
import socket
import subprocess
import threading
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")

from helpers.runtime_support import cyphal_udp_lock
from helpers.yakut_tool import yakut_env, yakut_exe, yakut_lock
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pycyphal.transport import (
    InputSessionSpecifier,
    MessageDataSpecifier,
    PayloadMetadata,
    Priority,
    ServiceDataSpecifier,
    Timestamp,
)
from pycyphal.transport.commons.high_overhead_transport import TransferCRC, serialize_transfer
from pycyphal.transport.udp import (
    PromiscuousUDPInputSession,
    PromiscuousUDPInputSessionStatistics,
    SelectiveUDPInputSession,
    SelectiveUDPInputSessionStatistics,
    UDPFrame,
)
from pycyphal.transport.udp._ip._endpoint_mapping import service_node_id_to_multicast_group

from sam_runtime.cyphal_io.udp_sessions import (
    LoopInputSession,
    parse_datagram,
    service_group,
)

LOCAL = 100
SERVER = 11  # the selective session's remote node
SERVICE = 430
SUBJECT = 7509
EXTENT = 64
T0_NS = 1_000_000_000_000
REQ, RESP = ServiceDataSpecifier.Role.REQUEST, ServiceDataSpecifier.Role.RESPONSE

SPECS = {
    "server": InputSessionSpecifier(ServiceDataSpecifier(SERVICE, REQ), None),
    "client": InputSessionSpecifier(ServiceDataSpecifier(SERVICE, RESP), SERVER),
    "subject": InputSessionSpecifier(MessageDataSpecifier(SUBJECT), None),
}


# ------------------------------------------------------------------------------------------------ datagrams
def _frame(payload: bytes, *, src: int | None = SERVER, dst: int | None = LOCAL, tid: int = 0, index: int = 0,
           eot: bool = True, ds: Any = None, prio: Priority = Priority.NOMINAL) -> bytes:
    ds = ds if ds is not None else ServiceDataSpecifier(SERVICE, REQ)
    header, body = UDPFrame(priority=prio, source_node_id=src, destination_node_id=dst, data_specifier=ds,
                            transfer_id=tid, index=index, end_of_transfer=eot, user_data=0,
                            payload=memoryview(payload)).compile_header_and_payload()
    return bytes(header) + bytes(body)


def _transfer(payload: bytes, *, mtu: int = 1200, **kw: Any) -> list[bytes]:
    """The datagrams pycyphal's output session sends for ``payload``."""
    frames = serialize_transfer([memoryview(payload)], mtu, lambda i, eot, p: (i, eot, bytes(p)))
    return [_frame(p, index=i, eot=eot, **kw) for i, eot, p in frames]


def _single(payload: bytes, **kw: Any) -> bytes:
    return _frame(payload + TransferCRC.new(payload).value_as_bytes, **kw)


def _raw_header(data: bytes, **fields: int) -> bytes:
    """``data`` with header fields replaced and a valid header CRC (to reach what pycyphal's parser raises on)."""
    from pycyphal.transport.commons.crc import CRC16CCITT

    names = ("version", "prio", "src", "dst", "dsn", "tid", "index_eot", "user")
    values = dict(zip(names, UDPFrame._HEADER_FORMAT_NO_CRC.unpack_from(data), strict=True))
    values.update(fields)
    h = UDPFrame._HEADER_FORMAT_NO_CRC.pack(*values.values())
    return h + CRC16CCITT.new(h).value.to_bytes(2, "big") + data[24:]


# ------------------------------------------------------------------------------------------------ the two sides
Got = tuple[list[tuple[bytes, int | None, int, int]], Any, int]  # transfers, statistics, datagrams pycyphal raised on


def _drain(session: Any) -> Any:
    async def take() -> list[tuple[bytes, int | None, int, int]]:
        out = []
        while (tr := await session.receive(0.0)) is not None:
            out.append((b"".join(tr.fragmented_payload), tr.source_node_id, tr.transfer_id, tr.timestamp.monotonic_ns))
        return out
    return take()


def _stats(spec: InputSessionSpecifier) -> Any:
    return PromiscuousUDPInputSessionStatistics() if spec.is_promiscuous else SelectiveUDPInputSessionStatistics()


def _with_pycyphal(spec: InputSessionSpecifier, datagrams: list[tuple[bytes, int]]) -> Got:
    """pycyphal's session: each datagram parsed as its reader thread parses it, queued with its time, received."""

    async def run() -> Got:
        dead = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        dead.close()  # its reader thread stops at once: the datagrams are handed in below, with chosen times
        cls = PromiscuousUDPInputSession if spec.is_promiscuous else SelectiveUDPInputSession
        session = cls(spec, PayloadMetadata(EXTENT), dead, lambda: None, LOCAL, _stats(spec))
        out, raised = [], 0
        try:
            for data, ns in datagrams:
                try:
                    frame = UDPFrame.parse(memoryview(data))
                except Exception:  # its reader thread logs it (handle_internal_error) and counts nothing
                    raised += 1
                    continue
                session._put_into_queue(Timestamp(system_ns=ns, monotonic_ns=ns), frame)
                out += await _drain(session)
        finally:
            session.close()
        return out, session.sample_statistics(), raised

    return asyncio.run(run())


def _with_loop_session(spec: InputSessionSpecifier, datagrams: list[tuple[bytes, int]]) -> Got:
    async def run() -> Got:
        session = LoopInputSession(spec, PayloadMetadata(EXTENT), None, b"", lambda: None, LOCAL, _stats(spec))
        out = []
        for data, ns in datagrams:
            session.push(Timestamp(system_ns=ns, monotonic_ns=ns), parse_datagram(data))
            out += await _drain(session)
        session.close()
        return out, session.sample_statistics(), 0

    return asyncio.run(run())


def _same(kind: str, datagrams: list[tuple[bytes, int]]) -> tuple[Got, Got]:
    spec = SPECS[kind]
    ref, got = _with_pycyphal(spec, datagrams), _with_loop_session(spec, datagrams)
    assert got[0] == ref[0]
    expected = ref[1]
    expected.errors += ref[2]  # the deliberate difference (module doc)
    assert got[1] == expected
    return ref, got


def _timed(datagrams: list[bytes], gaps_s: list[float] | None = None) -> list[tuple[bytes, int]]:
    ns, out = T0_NS, []
    for i, d in enumerate(datagrams):
        ns += round((gaps_s[i] if gaps_s else 0.001) * 1e9)
        out.append((d, ns))
    return out


# ------------------------------------------------------------------------------------------------ fixed cases
def test_service_group_is_pycyphals() -> None:
    for nid in (0, 1, 100, 255, 256, 456, 65534):
        assert service_group(nid) == service_node_id_to_multicast_group(nid).packed


def test_a_server_session_takes_its_requests_only() -> None:
    a, b = bytes(range(30)), bytes(range(100, 200)) * 3
    dgs = [_single(a, tid=5), *_transfer(b, mtu=64, src=12, tid=7),
           _single(b"other service", ds=ServiceDataSpecifier(SERVICE + 1, REQ)),
           _single(b"a response", ds=ServiceDataSpecifier(SERVICE, RESP)),
           _single(b"own", src=LOCAL), _single(b"a message", ds=MessageDataSpecifier(SUBJECT), dst=None),
           _single(b"dup", tid=5), _single(b"", src=13, tid=1)]
    _, got = _same("server", _timed(dgs))
    assert [t[:3] for t in got[0]] == [(a, SERVER, 5), (b, 12, 7), (b"", 13, 1)]
    assert got[1].reassembly_errors_per_source_node_id[SERVER]  # the duplicate: an unexpected transfer id


def test_a_client_session_takes_its_servers_responses_only() -> None:
    resp = ServiceDataSpecifier(SERVICE, RESP)
    dgs = [_single(b"answer", ds=resp, tid=1), _single(b"from another", ds=resp, src=12, tid=1),
           _single(b"a request", tid=2), *_transfer(bytes(300), mtu=100, ds=resp, tid=2),
           _single(b"late", ds=resp, tid=1)]
    _, got = _same("client", _timed(dgs))
    assert [t[:3] for t in got[0]] == [(b"answer", SERVER, 1), (bytes(300), SERVER, 2)]


def test_malformed_datagrams_and_what_pycyphals_parser_raises_on() -> None:
    good = _single(b"hello", tid=1)
    broken = good[:23] + bytes([good[23] ^ 1]) + good[24:]
    dgs = [b"", b"\x01" * 10, good[:23], broken, _raw_header(good, version=2), _raw_header(good, prio=8),
           _raw_header(good, src=0xFFFF), good, good[:-1] + bytes([good[-1] ^ 0xFF])]
    ref, got = _same("server", _timed(dgs))
    assert ref[2] == 2  # priority 8, an anonymous service frame: pycyphal raised, nothing counted
    assert got[1].errors == ref[1].errors == 5 + 2 + 1  # five unparsable, two raised, the broken transfer CRC
    assert [t[:3] for t in got[0]] == [(b"hello", SERVER, 1)]


def test_transfer_id_timeout_and_multi_frame_time() -> None:
    dgs = [_single(b"a", tid=50), _single(b"b", tid=5), _single(b"c", tid=5)]
    parts = _transfer(bytes(range(200)), mtu=64, tid=6)
    _, got = _same("server", _timed([*dgs, parts[2], parts[0], parts[1], parts[3]], [0, 1.9, 0.2, 0, 0.5, 0, 0]))
    assert [t[:3] for t in got[0]] == [(b"a", SERVER, 50), (b"c", SERVER, 5), (bytes(range(200)), SERVER, 6)]


def test_a_subject_session_takes_anonymous_messages() -> None:
    msg = MessageDataSpecifier(SUBJECT)
    dgs = [_single(b"hb", ds=msg, dst=None, tid=3), _single(b"anon", ds=msg, src=None, dst=None),
           _single(b"req", tid=1)]
    _, got = _same("subject", _timed(dgs))
    assert [t[:2] for t in got[0]] == [(b"hb", SERVER), (b"anon", None)]


@st.composite
def _sequences(draw: st.DrawFn) -> list[tuple[bytes, int]]:
    ds_choices = [ServiceDataSpecifier(SERVICE, REQ), ServiceDataSpecifier(SERVICE, RESP),
                  ServiceDataSpecifier(SERVICE + 1, RESP), MessageDataSpecifier(SUBJECT)]
    dgs: list[bytes] = []
    for _ in range(draw(st.integers(1, 12))):
        ds = draw(st.sampled_from(ds_choices))
        src = draw(st.sampled_from([SERVER, SERVER, 12, LOCAL] + ([None] if isinstance(ds, MessageDataSpecifier)
                                                                   else [])))
        kw = {"ds": ds, "src": src, "dst": None if isinstance(ds, MessageDataSpecifier) else LOCAL,
              "tid": draw(st.integers(0, 6))}
        payload = draw(st.binary(max_size=150))
        frames = _transfer(payload, mtu=draw(st.sampled_from([64, 1200])), **kw)
        if len(frames) > 1 and draw(st.booleans()):  # cut, repeated or reordered
            frames = draw(st.permutations(frames))[: draw(st.integers(1, len(frames)))] + frames[:1]
        for f in frames:
            mutate = draw(st.integers(0, 9))
            if mutate == 0:  # a broken byte anywhere
                i = draw(st.integers(0, len(f) - 1))
                f = f[:i] + bytes([f[i] ^ (1 << draw(st.integers(0, 7)))]) + f[i + 1:]
            elif mutate == 1:
                f = f[: draw(st.integers(0, len(f)))]
            elif mutate == 2:  # what pycyphal's parser raises on
                f = _raw_header(f, prio=9) if draw(st.booleans()) else _raw_header(f, src=0xFFFF, dsn=0xC000 | SERVICE)
            dgs.append(f)
    gaps = [draw(st.sampled_from([0.0, 0.001, 0.5, 2.5])) for _ in dgs]
    return _timed(dgs, gaps)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seq=_sequences(), kind=st.sampled_from(sorted(SPECS)))
def test_random_sequences_same_as_pycyphal(seq: list[tuple[bytes, int]], kind: str) -> None:
    _same(kind, seq)


# ------------------------------------------------------------------------------------------------ receive()
def test_receive_waits_for_a_datagram_returns_none_at_the_deadline_and_wakes_on_close() -> None:
    async def go() -> None:
        loop = asyncio.get_running_loop()
        closed: list[int] = []
        session = LoopInputSession(SPECS["server"], PayloadMetadata(EXTENT), None, b"", lambda: closed.append(1),
                                   LOCAL, PromiscuousUDPInputSessionStatistics())
        t0 = loop.time()
        assert await session.receive(t0 + 0.05) is None
        assert loop.time() >= t0 + 0.05
        waiting = asyncio.ensure_future(session.receive(loop.time() + 60))
        await asyncio.sleep(0)
        session.push(Timestamp.now(), parse_datagram(_single(b"x", tid=1)))
        tr = await asyncio.wait_for(waiting, 5)  # woken by the datagram, not by a poll
        assert tr is not None and bytes(tr.fragmented_payload[0]) == b"x"
        waiting = asyncio.ensure_future(session.receive(loop.time() + 60))
        await asyncio.sleep(0)
        session.close()
        with pytest.raises(Exception, match="closed"):  # pycyphal's ResourceClosedError, at once
            await asyncio.wait_for(waiting, 5)
        assert closed == [1]
        with pytest.raises(Exception, match="closed"):
            await session.receive(loop.time() + 1)

    asyncio.run(go())


# ------------------------------------------------------------------------------------------------ real sockets
async def _until(cond: Any, timeout: float = 20.0) -> None:
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while not cond():
        assert loop.time() < deadline, "timed out"
        await asyncio.sleep(0.02)


def _reader_threads() -> list[str]:
    return [t.name for t in threading.enumerate() if "InputSession" in t.name]


def test_services_and_heartbeats_on_the_loop_with_a_plain_pycyphal_peer() -> None:
    from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled
    from sam_runtime.cyphal_io.transport import make_node, make_transport

    # The standard types on the path here, not left to an earlier test of the worker (alone, or first in the unit
    # tier, `import uavcan` found nothing).
    ensure_compiled([], Path(__file__).resolve().parents[3] / ".cache" / "dsdl")

    async def go() -> None:
        import uavcan.node
        import uavcan.register

        before = set(_reader_threads())
        tr = make_transport("udp", node_id=LOCAL, iface="127.0.0.1", loop_rx=True)
        me = make_node("org.sam.test.loop", LOCAL, transport=tr)
        peer = make_node("org.sam.test.peer", 101, "udp", iface="127.0.0.1")  # pycyphal's own sessions
        try:
            sock = tr.session_socket
            assert sock is not None and all(isinstance(s, LoopInputSession) for s in tr.input_sessions)
            assert set(_reader_threads()) - before == {str(s) for s in peer.presentation.transport.input_sessions}
            # the peer asks the loop node (its requests reach the loop's server sessions)
            info = peer.make_client(uavcan.node.GetInfo_1, LOCAL)
            got = await info.call(uavcan.node.GetInfo_1.Request())
            assert got is not None and bytes(got[0].name).decode() == "org.sam.test.loop"
            regs = peer.make_client(uavcan.register.List_1, LOCAL)
            got = await regs.call(uavcan.register.List_1.Request(index=0))
            assert got is not None and bytes(got[0].name.name).decode()
            # the loop node asks the peer (the response reaches the loop's selective client session)
            mine = me.make_client(uavcan.node.GetInfo_1, 101)
            got = await mine.call(uavcan.node.GetInfo_1.Request())
            assert got is not None and bytes(got[0].name).decode() == "org.sam.test.peer"
            # the heartbeat publisher's own subscription hears the peer
            hb = next(s for s in tr.input_sessions if s.specifier.data_specifier == MessageDataSpecifier(SUBJECT))
            await _until(lambda: hb.sample_statistics().transfers >= 1)
            assert sock.groups == sorted({"239.0.29.85", socket.inet_ntoa(service_group(LOCAL))})
            for c in (info, regs, mine):
                c.close()
        finally:
            peer.close()
            me.close()
        assert sock.groups == [] and sock._sock is None
        await asyncio.sleep(0)

    with cyphal_udp_lock():
        asyncio.run(go())


@pytest.mark.system  # yakut is another process
def test_yakut_calls_a_node_on_the_loop_transport() -> None:
    exe = yakut_exe()
    if exe is None:
        pytest.skip("yakut is not installed (nox -s tests installs it; or /tmp/yakut-venv, SAM_YAKUT)")
    from sam_runtime.cyphal_io.transport import make_node, make_transport

    env = yakut_env(42)

    async def go() -> str:
        node = make_node("org.sam.test.yakut", LOCAL,
                         transport=make_transport("udp", node_id=LOCAL, iface="127.0.0.1", loop_rx=True))
        try:
            proc = await asyncio.create_subprocess_exec(
                exe, "--format", "json", "call", "--timeout", "5", str(LOCAL), "uavcan.node.getinfo", "{}",
                env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            out, err = await asyncio.wait_for(proc.communicate(), 300)  # the first run compiles the DSDL
            assert proc.returncode == 0, err.decode()[-3000:]
            return out.decode()
        finally:
            node.close()

    with cyphal_udp_lock(), yakut_lock():
        out = asyncio.run(go())
    assert "org.sam.test.yakut" in out
