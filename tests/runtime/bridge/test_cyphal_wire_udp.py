"""The wire path on Cyphal/UDP (sam_runtime.bridge.backends.cyphal_wire), on real sockets (127.0.0.1, under the
machine-wide Cyphal/UDP lock): what it sends, pycyphal receives."""

from __future__ import annotations

import asyncio

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
