"""The Cyphal/UDP loop receiver on real sockets (127.0.0.1, under the machine-wide Cyphal/UDP lock).

- a pycyphal publisher in another process reaches it: single- and multi-frame transfers, in order, with their
  transfer ids, the same that a pycyphal input session in this process receives beside it; the frames of the
  node itself and of subjects it did not subscribe are not delivered;
- more datagrams queued than one wake-up takes (:data:`BATCH`) all arrive, the loop getting control between
  batches; a receive buffer the sender overruns loses datagrams that the kernel counts and the receiver reports
  (``overflows``): received + overflows == sent;
- no thread is started, and closing it leaves the groups and the socket.
- yakut (in its own venv at /tmp/yakut-venv, or $SAM_YAKUT; skipped where absent): ``yakut pub`` reaches it.
"""

from __future__ import annotations

import asyncio
import fcntl
import json
import os
import shutil
import socket
import sys
import termios
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")

from helpers.runtime_support import cyphal_udp_lock

from sam_runtime.cyphal_io.udp_receiver import BATCH, CYPHAL_PORT, UDPLoopReceiver, subject_group

IFACE = "127.0.0.1"
LOCAL_NODE = 100
SINGLE, MULTI, UNSUBSCRIBED = 6101, 6102, 6103
N = 40

_PUBLISHER = r"""
import asyncio, json, sys
from pycyphal.transport import MessageDataSpecifier, OutputSessionSpecifier, PayloadMetadata, Priority, Timestamp
from pycyphal.transport import Transfer
from pycyphal.transport.udp import UDPTransport

SINGLE, MULTI, UNSUBSCRIBED, LOCAL, N = (int(x) for x in sys.argv[1:6])

async def main():
    sent = {"single": [], "multi": []}
    small = UDPTransport("127.0.0.1", 11)  # default MTU: single-frame transfers
    tiny = UDPTransport("127.0.0.1", 12, mtu=UDPTransport.MTU_MIN)  # multi-frame transfers
    me = UDPTransport("127.0.0.1", LOCAL)  # frames that claim to be the receiving node's own
    def out(tr, sid):
        return tr.get_output_session(OutputSessionSpecifier(MessageDataSpecifier(sid), None), PayloadMetadata(1024))
    s, m, u, own = out(small, SINGLE), out(tiny, MULTI), out(small, UNSUBSCRIBED), out(me, SINGLE)
    loop = asyncio.get_running_loop()
    for i in range(N):
        single = bytes([i]) * (1 + i % 20)
        multi = bytes((i + k) & 0xFF for k in range(100 + 7 * i))
        for sess, payload, key in ((s, single, "single"), (m, multi, "multi")):
            assert await sess.send(Transfer(Timestamp.now(), Priority.NOMINAL, 1000 + i, [memoryview(payload)]),
                                   loop.time() + 1.0)
            sent[key].append([1000 + i, payload.hex()])
        await u.send(Transfer(Timestamp.now(), Priority.NOMINAL, i, [memoryview(b"not subscribed")]), loop.time() + 1)
        await own.send(Transfer(Timestamp.now(), Priority.NOMINAL, i, [memoryview(b"own")]), loop.time() + 1)
    for tr in (small, tiny, me):
        tr.close()
    print(json.dumps(sent))

asyncio.run(main())
"""


async def _until(cond: Callable[[], bool], timeout: float = 20.0) -> None:
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while not cond():
        assert loop.time() < deadline, "timed out"
        await asyncio.sleep(0.01)


@pytest.mark.system  # the holder / the publisher is another process
def test_a_pycyphal_publisher_in_another_process_reaches_the_receiver() -> None:
    from pycyphal.transport import InputSessionSpecifier, MessageDataSpecifier, PayloadMetadata
    from pycyphal.transport.udp import UDPTransport

    async def go() -> dict[str, Any]:
        got: dict[str, list[tuple[int, bytes, int | None]]] = {"single": [], "multi": []}
        threads_before = threading.active_count()
        rx = UDPLoopReceiver(IFACE, LOCAL_NODE)
        ports = {key: rx.subscribe(sid, 1024, lambda p, src, tid, t, key=key: got[key].append((tid, p, src)))
                 for key, sid in (("single", SINGLE), ("multi", MULTI))}
        threads_rx = threading.active_count()
        # pycyphal beside it, on the same subject: what the library receives from the same datagrams
        ref_tr = UDPTransport(IFACE, LOCAL_NODE)
        ref = ref_tr.get_input_session(InputSessionSpecifier(MessageDataSpecifier(SINGLE), None),
                                       PayloadMetadata(1024))
        ref_got: list[tuple[int, bytes, int | None]] = []

        async def take() -> None:
            while len(ref_got) < N:
                tr = await ref.receive(asyncio.get_running_loop().time() + 1.0)
                if tr is not None:
                    ref_got.append((tr.transfer_id, b"".join(tr.fragmented_payload), tr.source_node_id))

        taker = asyncio.create_task(take())
        proc = await asyncio.create_subprocess_exec(
            sys.executable, "-c", _PUBLISHER, *map(str, (SINGLE, MULTI, UNSUBSCRIBED, LOCAL_NODE, N)),
            stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
        out, err = await asyncio.wait_for(proc.communicate(), 60)
        assert proc.returncode == 0, err.decode()[-3000:]
        sent = json.loads(out)
        await _until(lambda: len(got["single"]) >= N and len(got["multi"]) >= N)
        await asyncio.wait_for(taker, 20)
        stats = {k: p.sample_statistics() for k, p in ports.items()}
        rx.close()
        ref_tr.close()
        return {"got": got, "ref": ref_got, "sent": sent, "stats": stats,
                "threads": (threads_before, threads_rx)}

    with cyphal_udp_lock():
        r = asyncio.run(go())
    for key, src in (("single", 11), ("multi", 12)):
        assert r["got"][key] == [(tid, bytes.fromhex(p), src) for tid, p in r["sent"][key]]
        s = r["stats"][key]
        assert (s.transfers, s.errors) == (N, 0)
    assert r["stats"]["multi"].frames > 2 * N  # multi-frame indeed
    assert r["stats"]["single"].frames == N  # the node's own frames skipped, uncounted, as pycyphal does
    assert r["got"]["single"] == r["ref"]
    assert r["threads"][1] == r["threads"][0]  # no thread of its own


def _send_all(datagrams: list[bytes], group: bytes) -> None:
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(IFACE))
    try:
        for d in datagrams:
            tx.sendto(d, (socket.inet_ntoa(group), CYPHAL_PORT))
    finally:
        tx.close()


def _datagrams(n: int, src: int = 11) -> list[bytes]:
    from pycyphal.transport import MessageDataSpecifier, Priority
    from pycyphal.transport.commons.high_overhead_transport import TransferCRC
    from pycyphal.transport.udp import UDPFrame

    out = []
    for tid in range(n):
        payload = tid.to_bytes(4, "little")
        h, p = UDPFrame(priority=Priority.NOMINAL, source_node_id=src, destination_node_id=None,
                        data_specifier=MessageDataSpecifier(SINGLE), transfer_id=tid, index=0, end_of_transfer=True,
                        user_data=0, payload=memoryview(payload + TransferCRC.new(payload).value_as_bytes)
                        ).compile_header_and_payload()
        out.append(bytes(h) + bytes(p))
    return out


def _queued(sock: socket.socket) -> int:
    return int.from_bytes(fcntl.ioctl(sock.fileno(), termios.FIONREAD, b"\0" * 4), sys.byteorder)


def test_batches_and_counted_kernel_overflows() -> None:
    async def go(n: int, rcvbuf: int) -> dict[str, Any]:
        got: list[int] = []
        wakeups = [0]
        rx = UDPLoopReceiver(IFACE, LOCAL_NODE, rcvbuf_bytes=rcvbuf)
        port = rx.subscribe(SINGLE, 64, lambda p, src, tid, t: got.append(tid))
        reader = rx._on_readable

        def counting() -> None:
            wakeups[0] += 1
            reader()

        loop = asyncio.get_running_loop()
        loop.remove_reader(rx._sock.fileno())  # type: ignore[union-attr]
        loop.add_reader(rx._sock.fileno(), counting)  # type: ignore[union-attr]
        dgs = _datagrams(n + 1)
        _send_all(dgs[:n], subject_group(SINGLE))  # the loop does not run meanwhile: all queued at once
        # The kernel's drop count comes with the next datagram queued after the drops: a trailing one, once the
        # queue has been drained.
        await _until(lambda: _queued(rx._sock) == 0)  # type: ignore[arg-type]
        _send_all(dgs[n:], subject_group(SINGLE))
        await _until(lambda: bool(got) and got[-1] == n)
        result = {"got": got, "overflows": rx.overflows, "wakeups": wakeups[0], "transfers": port.transfers}
        rx.close()
        return result

    with cyphal_udp_lock():
        fits = asyncio.run(go(3 * BATCH, 4 << 20))
        overrun = asyncio.run(go(3000, 4096))
    assert fits["got"] == list(range(3 * BATCH + 1)) and fits["overflows"] == 0
    assert fits["wakeups"] >= 3  # at most BATCH per wake-up: the loop ran between the batches
    assert overrun["overflows"] > 0 and overrun["transfers"] + overrun["overflows"] == 3000 + 1
    assert overrun["got"] == sorted(overrun["got"])


def test_closing_leaves_the_groups() -> None:
    async def go() -> tuple[list[int], socket.socket]:
        rx = UDPLoopReceiver(IFACE, LOCAL_NODE)
        got: list[int] = []
        port = rx.subscribe(SINGLE, 64, lambda p, src, tid, t: got.append(tid))
        _send_all(_datagrams(1), subject_group(SINGLE))
        await _until(lambda: len(got) == 1)
        port.close()
        _send_all(_datagrams(2)[1:], subject_group(SINGLE))  # after leaving: not delivered (no port either)
        again = rx.subscribe(SINGLE, 64, lambda p, src, tid, t: got.append(tid))
        _send_all(_datagrams(3)[2:], subject_group(SINGLE))
        await _until(lambda: again.transfers == 1)
        sock = rx._sock
        assert sock is not None
        rx.close()
        with pytest.raises(OSError):
            rx.subscribe(SINGLE, 64, lambda p, src, tid, t: None)
        return got, sock

    with cyphal_udp_lock():
        got, sock = asyncio.run(go())
    assert got == [0, 2]
    assert sock.fileno() == -1


def _yakut() -> str | None:
    exe = os.environ.get("SAM_YAKUT") or "/tmp/yakut-venv/bin/yakut"
    return exe if Path(exe).exists() else shutil.which("yakut")


@pytest.mark.system  # the holder / the publisher is another process
def test_yakut_pub_reaches_the_receiver() -> None:
    """yakut (its own venv: it pins pycyphal itself) publishes uavcan.primitive.scalar.Natural32 on a subject."""
    exe = _yakut()
    if exe is None:
        pytest.skip("yakut is not installed (python -m venv /tmp/yakut-venv && /tmp/yakut-venv/bin/pip install yakut)")
    from sam_codegen.project.cyphal_path import default_search_dirs

    dsdl = [str(d) for d in default_search_dirs() if (Path(d) / "uavcan").is_dir()]
    if not dsdl:
        pytest.skip("no uavcan DSDL for yakut")

    async def go() -> list[tuple[bytes, int | None, int]]:
        got: list[tuple[bytes, int | None, int]] = []
        rx = UDPLoopReceiver(IFACE, LOCAL_NODE)
        rx.subscribe(SINGLE, 64, lambda p, src, tid, t: got.append((p, src, tid)))
        env = dict(os.environ, UAVCAN__UDP__IFACE=IFACE, UAVCAN__NODE__ID="42", CYPHAL_PATH=":".join(dsdl),
                   YAKUT_PATH=str(Path(os.environ.get("TMPDIR", "/tmp")) / "yakut-compiled"))
        proc = await asyncio.create_subprocess_exec(
            exe, "pub", "--count", "3", "--period", "0.1", f"{SINGLE}:uavcan.primitive.scalar.Natural32", "123456",
            env=env, stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
        _out, err = await asyncio.wait_for(proc.communicate(), 300)  # the first run compiles the DSDL
        assert proc.returncode == 0, err.decode()[-3000:]
        await _until(lambda: len(got) >= 3)
        rx.close()
        return got

    with cyphal_udp_lock():
        got = asyncio.run(go())
    assert [(p, src) for p, src, _ in got] == [((123456).to_bytes(4, "little"), 42)] * 3
    assert [tid for _, _, tid in got] == sorted(tid for _, _, tid in got)

