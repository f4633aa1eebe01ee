"""The wire path on Cyphal/UDP (sam_runtime.bridge.backends.cyphal_wire), on real sockets (127.0.0.1, under the
machine-wide Cyphal/UDP lock): what it sends, pycyphal receives."""

from __future__ import annotations

import asyncio
import socket
from typing import Any

import pytest

pytest.importorskip("pycyphal")

from helpers.runtime_support import cyphal_udp_lock, generated_or_skip

IFACE = "127.0.0.1"
LOCAL_NODE = 100
SINGLE = 6101


def test_the_wire_paths_sender_on_udp_reaches_pycyphal() -> None:
    """RawSender on Cyphal/UDP: one-frame transfers sent straight on the socket, longer ones by pycyphal; a pycyphal
    input session takes them all, in order, with their transfer ids; the bridge's own receiver skips them."""
    from pycyphal.transport import InputSessionSpecifier, MessageDataSpecifier, PayloadMetadata
    from pycyphal.transport.udp import UDPTransport

    from sam_runtime.bridge.backends.cyphal_wire import RawSender
    from sam_runtime.cyphal_io.transport import make_transport

    generated_or_skip().compile_dsdl()  # uavcan.* importable
    import uavcan.primitive

    payloads = [bytes([i]) * (1 + 3 * i) for i in range(30)] + [bytes(range(256)) * 6]  # the last: 2 frames

    async def go() -> tuple[list[tuple[int, bytes, int | None]], list[bytes]]:
        tx = make_transport("udp", node_id=LOCAL_NODE, iface=IFACE, loop_rx=True)
        own: list[bytes] = []
        tx.loop_receiver.subscribe(SINGLE, 2048, lambda p, src, tid, t: own.append(p))  # type: ignore[attr-defined]
        rx = UDPTransport(IFACE, 11)
        session = rx.get_input_session(InputSessionSpecifier(MessageDataSpecifier(SINGLE), None),
                                       PayloadMetadata(2048))
        sender = RawSender()
        sender.reopen(tx, SINGLE, uavcan.primitive.Unstructured_1_0)
        for p in payloads:
            assert await sender.send(p, 1.0)
        got: list[tuple[int, bytes, int | None]] = []
        while len(got) < len(payloads):
            tr = await session.receive(asyncio.get_running_loop().time() + 5.0)
            assert tr is not None, got
            got.append((tr.transfer_id, b"".join(tr.fragmented_payload), tr.source_node_id))
        sender.close()
        tx.close()
        rx.close()
        return got, own

    with cyphal_udp_lock():
        got, own = asyncio.run(go())
    assert got == [(i, p, LOCAL_NODE) for i, p in enumerate(payloads)]
    assert own == []  # the node's own frames: skipped by its receiver, as pycyphal skips them


def test_the_backend_on_udp_receives_on_its_loop() -> None:
    """CyphalBackend on Cyphal/UDP: its wire-path subscriptions and the devices' heartbeats come through the loop
    receiver (no thread per subscription: eight subscriptions start no thread), uavcan.node.port.List's source
    (the transport's input sessions) names them, and the counters reach the subscription's BelowBridge."""
    import collections
    import logging
    import threading

    import pycyphal.application
    from pycyphal.transport import (
        MessageDataSpecifier,
        OutputSessionSpecifier,
        PayloadMetadata,
        Priority,
        Timestamp,
        Transfer,
    )
    from pycyphal.transport.udp import UDPTransport

    from sam_runtime.bridge.backends.cyphal import CyphalBackend, TransportConfig
    from sam_runtime.common.rate_log import RateLimitedLog
    from sam_runtime.cyphal_io.transport import aclose, make_node
    from sam_runtime.cyphal_io.udp_receiver import CYPHAL_PORT, single_frame_datagram, subject_group

    generated_or_skip().compile_dsdl()
    import uavcan.primitive

    subjects = [SINGLE + i for i in range(8)]

    def backend_errors(sub: Any) -> int:
        return int(sub.below.snapshot()[0].get("errors", 0))

    async def go() -> dict[str, Any]:
        got: list[tuple[int, bytes, int | None, int]] = []
        statuses: list[Any] = []
        backend = CyphalBackend("org.test.udprx", LOCAL_NODE, TransportConfig("udp", IFACE),
                                rlog=RateLimitedLog(logging.getLogger("test_udprx")), errors=collections.Counter())
        subs = [backend.subscribe(f"s{sid}", sid, uavcan.primitive.Unstructured_1_0,
                                  lambda p, src, tid, t, sid=sid: got.append((sid, p, src, tid)), raw=True)
                for sid in subjects]
        backend.on_device_status(statuses.append)
        before = threading.active_count()
        await backend.open()
        after = threading.active_count()
        listed = {s.specifier.data_specifier.subject_id for s in backend.node.presentation.transport.input_sessions
                  if isinstance(s.specifier.data_specifier, MessageDataSpecifier)}
        device = make_node("org.test.device", 21, iface=IFACE)  # heartbeats at 1 Hz (the first at once)
        tx = UDPTransport(IFACE, 21)
        loop = asyncio.get_running_loop()
        for i, sid in enumerate(subjects):
            out = tx.get_output_session(OutputSessionSpecifier(MessageDataSpecifier(sid), None), PayloadMetadata(64))
            assert await out.send(Transfer(Timestamp.now(), Priority.NOMINAL, 5, [memoryview(bytes([1, i]))]),
                                  loop.time() + 1)
        bad = single_frame_datagram(21, subjects[0], 6, b"broken")  # its transfer CRC broken: an error of node 21
        raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        raw.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(IFACE))
        raw.sendto(bad[:-1] + bytes([bad[-1] ^ 1]), (socket.inet_ntoa(subject_group(subjects[0])), CYPHAL_PORT))
        raw.close()
        deadline = loop.time() + 20
        while (len(got) < len(subjects) or not statuses or not backend_errors(subs[0])) and loop.time() < deadline:
            await asyncio.sleep(0.01)
            backend.poll_statistics()
        below = [s.below.snapshot() for s in subs]
        tx.close()
        await aclose(device)
        await backend.close()
        assert isinstance(device, pycyphal.application.Node)
        return {"got": got, "statuses": statuses, "threads": (before, after), "listed": listed, "below": below}

    with cyphal_udp_lock():
        r = asyncio.run(go())
    assert sorted(r["got"]) == [(sid, bytes([1, i]), 21, 5) for i, sid in enumerate(subjects)]
    assert r["statuses"] and r["statuses"][0].node_id == 21 and r["statuses"][0].health == "NOMINAL"
    assert set(subjects) | {7509} <= r["listed"]
    # pycyphal's node itself starts threads for its own services (GetInfo, registers): a handful, not one per
    # subscription.
    assert r["threads"][1] - r["threads"][0] < len(subjects)
    assert all(totals.get("transfers") == 1 for totals, _, _ in r["below"]), r["below"]
    assert r["below"][0][0].get("errors") == 1 and r["below"][0][1] == {"INTEGRITY_ERROR.node21": 1}, r["below"]
