"""DroneCAN transport groundwork (sam_runtime.dronecan_io): the loopback multicast driver, the frame gate, the
asyncio node loop, frame accounting and SLCAN lines, against dronecan's own code, in one process (the
cross-process tests are in test_dronecan_io_processes.py).

Every bus here is private to this test session (bus number and UDP port from the pid), so concurrent runs do not
see each other; dronecan's own ``mcast:`` driver is never created (its packing code is run with fake sockets).
"""

from __future__ import annotations

import asyncio
import importlib
import logging
import queue
import socket
import time
import types
from typing import Any

import pytest

dronecan = pytest.importorskip("dronecan")

from dronecan import transport  # noqa: E402
from dronecan.driver.common import CANFrame, DriverError  # noqa: E402
from helpers.dronecan_peer import imu_seq, raw_imu_fields, raw_imu_message, read_raw_imu  # noqa: E402
from helpers.dronecan_support import frames_of, private_iface, until  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from sam_runtime.dronecan_io import (  # noqa: E402
    MCAST_PORT,
    BusLoadMeter,
    DropKey,
    DropReason,
    FrameGate,
    IfaceError,
    LoopbackMulticastDriver,
    NodeLoop,
    group_for_bus,
    make_node,
    parse_iface,
    payload_length,
    transfer_cost,
)
from sam_runtime.dronecan_io.bus_load import transfer_frame_lengths  # noqa: E402
from sam_runtime.dronecan_io.mcast_packet import PacketError, decode_packet, encode_packet  # noqa: E402
from sam_runtime.dronecan_io.slcan import SlcanError, decode_line, encode_line  # noqa: E402

RAW_IMU = dronecan.uavcan.equipment.ahrs.RawIMU



# -- packet format: dronecan's mcast: driver's own code, with fake sockets ------------------------------------------

class _StockDone(BaseException):
    pass


def run_stock_mcast_io(url: str, to_send: list[CANFrame], to_receive: list[bytes]) -> tuple[list[bytes], list[Any],
                                                                                               list[Any]]:
    """Run dronecan's mcast io_process (its only packing code) on fake sockets: the datagrams it sends for
    ``to_send``, the frames it makes of ``to_receive`` datagrams, and where it bound."""
    stock = importlib.import_module("dronecan.driver.mcast")  # `dronecan.driver.mcast` is the class
    sent: list[bytes] = []
    binds: list[Any] = []
    inbox = list(to_receive)

    class FakeSocket:
        def __init__(self, *_: Any) -> None: ...
        def setsockopt(self, *_: Any) -> None: ...
        def setblocking(self, _: Any) -> None: ...
        def bind(self, addr: Any) -> None: binds.append(addr)
        def connect(self, addr: Any) -> None: binds.append(("connect", addr))
        def send(self, pkt: bytes) -> None: sent.append(bytes(pkt))
        def getsockname(self) -> tuple[str, int]: return ("127.0.0.1", 1)

        def recvfrom(self, n: int) -> tuple[bytes, tuple[str, int]]:
            if not inbox:
                raise _StockDone
            return inbox.pop(0)[:n], ("127.0.0.1", 2)

    fake_socket = types.SimpleNamespace(**{k: getattr(socket, k) for k in dir(socket) if k.isupper()},
                                        socket=FakeSocket, inet_aton=socket.inet_aton, error=OSError)
    tx: queue.Queue[Any] = queue.Queue()
    rx: queue.Queue[Any] = queue.Queue()
    for f in to_send:
        tx.put(f)
    saved = stock.socket, stock.select, stock.time
    stock.socket = fake_socket
    stock.select = types.SimpleNamespace(select=lambda *_: ([], [], []))
    stock.time = types.SimpleNamespace(sleep=lambda _: None)
    try:
        stock.io_process(url, tx, rx)
    except _StockDone:
        pass
    finally:
        stock.socket, stock.select, stock.time = saved
    return sent, [rx.get() for _ in range(rx.qsize())], binds


_frames = st.one_of(
    st.builds(lambda i, d: CANFrame(i, bytearray(d), True), st.integers(0, 0x1FFFFFFF), st.binary(max_size=8)),
    st.builds(lambda i, d: CANFrame(i, bytearray(d), False), st.integers(0, 0x7FF), st.binary(max_size=8)),
    st.builds(lambda i, n: CANFrame(i, bytearray(range(n)), True, canfd=True), st.integers(0, 0x1FFFFFFF),
              st.sampled_from([0, 5, 8, 12, 16, 20, 24, 32, 48, 64])),
)


@settings(max_examples=60, deadline=None)
@given(st.lists(_frames, min_size=1, max_size=6))
def test_packets_identical_to_dronecan_mcast(frames: list[CANFrame]) -> None:
    sent, received, _ = run_stock_mcast_io("3", frames, [encode_packet(f) for f in frames])
    assert sent == [encode_packet(f) for f in frames]
    ours = [decode_packet(p) for p in sent]
    for a, b, c in zip(frames, received, ours, strict=True):
        assert (a.id, bytes(a.data), a.extended, a.canfd) == (b.id, bytes(b.data), b.extended, b.canfd) == \
            (c.id, bytes(c.data), c.extended, c.canfd)


def test_bus_group_and_port_as_dronecan_mcast() -> None:
    for bus in (0, 7, 255):
        _, _, binds = run_stock_mcast_io(str(bus), [], [])
        assert binds[0] == (group_for_bus(bus), MCAST_PORT)
    _, _, binds = run_stock_mcast_io("", [], [])  # "mcast:" is bus 0, as our "mcast-lo:"
    default = parse_iface("mcast-lo:")
    assert binds[0] == (group_for_bus(default.bus), default.port)


@pytest.mark.parametrize("data, message, stock_delivers", [
    (b"\x34\x29\x00", "3 bytes, shorter than the 10-byte header", False),
    (b"\x35\x29" + bytes(8), "magic 0x2935, expected 0x2934", False),
    (encode_packet(CANFrame(1, bytearray(b"ab"), True))[:-1] + b"c", "packet CRC 0x", False),
    # dronecan's driver checks no lengths: it hands these to its node.
    (encode_packet(CANFrame(1, bytearray(9), True, canfd=True)), "9 data bytes in a CAN FD frame", True),
    (encode_packet(CANFrame(1, bytearray(12), True)), "12 data bytes in a classic CAN frame", True),
    (encode_packet(CANFrame(0x800, bytearray(1), False)), "11-bit frame with id 0x800", True),
])
def test_bad_packets_rejected(data: bytes, message: str, stock_delivers: bool) -> None:
    with pytest.raises(PacketError, match="^" + message):
        decode_packet(data)
    assert len(run_stock_mcast_io("0", [], [data])[1]) == int(stock_delivers)


# -- SLCAN lines: dronecan's SLCAN worker code, with fake serial ports --------------------------------------------

@settings(max_examples=60, deadline=None)
@given(_frames.filter(lambda f: f.extended))  # dronecan's TxWorker cannot send 11-bit frames (TypeError)
def test_slcan_lines_as_dronecan(frame: CANFrame) -> None:
    slcan = importlib.import_module("dronecan.driver.slcan")
    written: list[bytes] = []
    conn = types.SimpleNamespace(write=written.append, flush=lambda: None, timeout=0)
    slcan.TxWorker(conn, None, None, lambda: True)._send_frame(frame)
    # dronecan writes the data in lower case hex; adapters (and encode_line) in upper case: both parse the same.
    assert [w.upper() for w in written] == [encode_line(frame)]
    out: queue.Queue[Any] = queue.Queue()
    slcan.RxWorker(conn, out, None, None, lambda: True)._process_slcan_line(written[0], 1.0, 2.0)
    theirs, ours = out.get_nowait(), decode_line(written[0][:-1])
    assert (theirs.id, bytes(theirs.data), theirs.extended, theirs.canfd) == \
        (ours.id, bytes(ours.data), ours.extended, ours.canfd)


@pytest.mark.parametrize("line, message", [
    (b"", "not a frame line"), (b"x123", "not a frame line"), (b"T1234567G0", "bad id or length"),
    (b"T12345678201", "2 data bytes announced"), (b"t8000", "id out of range"), (b"T123456781ZZ", "bad data"),
])
def test_slcan_bad_lines(line: bytes, message: str) -> None:
    with pytest.raises(SlcanError, match=message):
        decode_line(line)


# -- interface URIs ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("uri, message", [
    ("mcast:", "dronecan's mcast: driver sends out of the machine; use mcast-lo:"),
    ("can0", "expected one of mcast-lo:..., slcan:..., socketcan:..."),
    ("/dev/ttyACM0", "expected one of"),
    ("slcan:", "slcan: needs a device name"),
    ("socketcan:", "socketcan: needs an interface name"),
    ("mcast-lo:x", "expected mcast-lo:[<bus>[:<port>]] with decimal numbers"),
    ("mcast-lo:1:2:3", "expected mcast-lo:"),
    ("mcast-lo:1:70000", "port must be 1..65535"),
])
def test_bad_iface_uris(uri: str, message: str) -> None:
    with pytest.raises(IfaceError) as info:
        parse_iface(uri)
    assert str(info.value).startswith(f"{uri!r}: {message}")


def test_make_node_rejects_bad_node_id() -> None:
    with pytest.raises(ValueError, match=r"node id must be 1\.\.127"):
        make_node(private_iface(), 128)


# -- frame accounting -------------------------------------------------------------------------------------------

def test_frame_lengths_as_dronecan_splits_transfers() -> None:
    for n in range(0, 300):
        t = transport.Transfer(source_node_id=10, transfer_id=3)
        t.payload, t.data_type_id, t.data_type_crc = bytes(n), 1003, 0xFFFF
        assert [len(f.bytes) for f in t.to_frames()] == transfer_frame_lengths(n), n
    for seq, size, frames in ((0, 47, 7), (1, 49, 8), (3, 53, 8)):  # seq % 4 covariance entries
        assert payload_length(raw_imu_message(seq, 123)) == size
        assert transfer_cost(size).frames == frames


# -- the frame gate, with a scripted driver -----------------------------------------------------------------------

class ScriptedDriver:
    def __init__(self, frames: list[CANFrame]) -> None:
        self.frames = list(frames)

    def receive(self, timeout: float | None = None) -> CANFrame | None:
        return self.frames.pop(0) if self.frames else None

    def close(self) -> None: ...


class _TimedDriver:
    """Frames with the times (s) they are read at: the gate's clock (``now``) follows."""

    def __init__(self, frames: list[tuple[float, CANFrame]], now: list[float]) -> None:
        self.frames, self.now = list(frames), now

    def receive(self, timeout: float | None = None) -> CANFrame | None:
        if not self.frames:
            return None
        self.now[0], frame = self.frames.pop(0)
        return frame

    def close(self) -> None: ...


def _frame(can_id: int, tail: int, body: bytes = b"\x00", extended: bool = True) -> CANFrame:
    return CANFrame(can_id, bytearray(body + bytes([tail])), extended)


def _drain(gate: FrameGate) -> list[CANFrame]:
    out = []
    while (f := gate.receive(0)) is not None:
        out.append(f)
    return out


def test_frame_gate_classifies_and_holds_transfers() -> None:
    now = [0.0]
    imu = frames_of(raw_imu_message(1, 5), 42, 4)
    v1_id = (4 << 26) | (3 << 21) | (1234 << 8) | 42
    script = [
        imu[0], _frame(0x100, 0xC0, extended=False), CANFrame(0x1403EB2A, bytearray(), True),
        _frame(v1_id, 0xE1), _frame(v1_id, 0xA2), _frame(v1_id, 0x02), _frame(v1_id, 0x62),  # v1: 1 + 3 frames
        _frame(0x1403EB2A, 0x07),  # continuation of nothing
        *imu[1:],
        *frames_of(raw_imu_message(2, 5), 42, 5)[:3],  # never ends
    ]
    gate = FrameGate(ScriptedDriver(script), clock=lambda: now[0], transfer_timeout=2.0)
    got = _drain(gate)
    assert [bytes(f.data) for f in got] == [bytes(f.data) for f in imu]  # held, then passed on whole and in order
    assert gate.partial_transfers == 1
    now[0] = 1.9
    gate.sweep()
    assert DropReason.INCOMPLETE_TRANSFER.value not in gate.drops.snapshot()
    now[0] = 2.1
    gate.sweep()
    assert gate.drops.snapshot() == {"cyphal_v1_frame": 4, "empty_frame": 1, "incomplete_transfer": 1,
                                     "not_extended_id": 1, "orphan_frame": 1}
    assert gate.drops.detailed()[DropKey(DropReason.INCOMPLETE_TRANSFER, 1003, 42)] == 1
    assert gate.partial_transfers == 0


def test_frame_gate_restart_cap_and_batch_limit() -> None:
    a = frames_of(raw_imu_message(1, 5), 42, 9)
    b = frames_of(raw_imu_message(2, 5), 42, 9)
    now = [0.0]
    gate = FrameGate(_TimedDriver([(0.0, f) for f in a[:2]] + [(0.2, f) for f in b], now), clock=lambda: now[0],
                     max_partial_transfers=2)
    assert [bytes(f.data) for f in _drain(gate)] == [bytes(f.data) for f in b]
    assert gate.drops.snapshot() == {"incomplete_transfer": 1}  # restarted by b's first frame, a's sender gone quiet

    starts = [_frame(0x1403EB00 | src, 0x80) for src in (1, 2, 3)]
    gate = FrameGate(ScriptedDriver(starts), max_partial_transfers=2)
    assert _drain(gate) == [] and gate.partial_transfers == 2
    assert gate.drops.detailed() == {DropKey(DropReason.INCOMPLETE_TRANSFER, 1003, 1): 1}

    singles = [_frame(0x1403EB2A, 0xC0 | i) for i in range(10)]
    gate = FrameGate(ScriptedDriver(singles))
    gate.limit_batch(3)
    assert len(_drain(gate)) == 3
    gate.limit_batch(None)
    assert len(_drain(gate)) == 7


def test_frame_gate_frames_of_another_sender_with_the_devices_id_do_not_spoil_its_transfer() -> None:
    """Issue 29 item 2: a first frame under the key of the device's live transfer, and frames with the wrong toggle
    bit for it, are dropped alone (counted): the device's transfer still comes out whole."""
    real = frames_of(raw_imu_message(1, 5), 42, 9)
    junk_first = _frame(real[0].id, 0x80 | 9, b"\xAA" * 7)  # a first frame, the device's key
    junk_toggle = _frame(real[0].id, 0x00 | 9, b"\xBB" * 7)  # the second frame's position needs the toggle set
    gate = FrameGate(ScriptedDriver([real[0], junk_first, junk_toggle, *real[1:]]))
    assert [bytes(f.data) for f in _drain(gate)] == [bytes(f.data) for f in real]
    assert gate.drops.snapshot() == {"frame_sequence_error": 1, "toggle_error": 1}
    assert gate.frames_dropped == 2


_GATE_IDS = st.sampled_from([0x1403EB29, 0x1403EB2B, 0x1404072A, 0x100, 0x7FF, 0x1FFFFFFF])  # not node 42's RawIMU


@st.composite
def _gate_junk(draw: Any) -> list[tuple[float, CANFrame]]:
    """A frame of anything (any id, 0-8 data bytes, any tail), or a whole v0 transfer of another node."""
    if draw(st.integers(0, 4)) == 0:
        return [(0.001, f) for f in frames_of(raw_imu_message(draw(st.integers(0, 3)), 5), draw(st.integers(1, 40)),
                                             draw(st.integers(0, 31)))]
    can_id = draw(_GATE_IDS)
    data = bytearray(draw(st.binary(max_size=8)))
    return [(draw(st.sampled_from([0.0, 0.001, 0.5, 2.5])), CANFrame(can_id, data, can_id > 0x7FF and
                                                                      draw(st.booleans())))]


@given(st.lists(st.tuples(_gate_junk(), st.booleans()), max_size=30))
@settings(max_examples=150, deadline=None, derandomize=True)
def test_fuzz_frame_gate_junk_beside_a_real_device(steps: list[tuple[list[tuple[float, CANFrame]], bool]]) -> None:
    """The frame gate's fuzz target (issue 29), derandomized: junk frames between a real device's transfers (node
    42, multi-frame, none of the junk under its CAN id). Never raises; every frame read is passed on, held, or
    counted as dropped; the device's transfers all come out whole; the held transfers stay within the cap; after
    the transfer timeout a good transfer from any node passes."""
    script: list[tuple[float, CANFrame]] = []
    t, sent, tid = 0.0, [], 0
    for junk, real_now in steps:
        if real_now:
            frames = frames_of(raw_imu_message(tid, 5), 42, tid % 32)
            sent.append([bytes(f.data) for f in frames])
            script += [(t, f) for f in frames]
            tid += 1
        for dt, f in junk:
            t += dt
            script.append((t, f))
    now = [0.0]
    gate = FrameGate(_TimedDriver(script, now), clock=lambda: now[0], max_partial_transfers=8)
    out = []
    while (f := gate.receive(0)) is not None or gate.has_ready_frames():
        if f is not None:
            out.append(f)
        gate.sweep()
        assert gate.partial_transfers <= 8
    held = sum(len(p.frames) for p in gate._partial.values())
    assert len(out) + gate.frames_dropped + held == len(script)
    assert gate.drops.total >= 0 and sum(gate.drops.snapshot().values()) == gate.drops.total
    real_id = frames_of(raw_imu_message(0, 5), 42, 0)[0].id
    real_out = [bytes(f.data) for f in out if f.id == real_id and f.extended]
    assert real_out == [d for tr in sent for d in tr]
    now[0] = t + 3.0
    gate.sweep()
    good = frames_of(raw_imu_message(99, 5), 7, 3)
    gate.inner.frames = [(t + 3.0, f) for f in good]
    assert [bytes(f.data) for f in _drain(gate)] == [bytes(f.data) for f in good]


# -- the loopback driver, in one process ----------------------------------------------------------------------------

def _driver_pair() -> tuple[LoopbackMulticastDriver, LoopbackMulticastDriver]:
    spec = parse_iface(private_iface())
    return LoopbackMulticastDriver(spec.bus, spec.port), LoopbackMulticastDriver(spec.bus, spec.port)


def test_loopback_acceptance_filter_takes_only_its_services_and_data_types() -> None:
    """A node that listens to little (a simulated device): the kernel passes the service frames addressed to it and
    the broadcasts of its data types, and drops the rest before it takes buffer space or wakes the process."""
    from sam_runtime.dronecan_io import Acceptance

    spec = parse_iface(private_iface())
    sender = LoopbackMulticastDriver(spec.bus, spec.port)
    picky = LoopbackMulticastDriver(spec.bus, spec.port, accept=Acceptance(21, frozenset({1031, 20101})))
    deaf = LoopbackMulticastDriver(spec.bus, spec.port, accept=Acceptance(None))
    with sender, picky, deaf:
        assert picky.kernel_self_filter and deaf.kernel_self_filter
        ids = [0x1403EB0A,  # RawIMU (1003) from node 10: not taken
               0x1404071F,  # RPMCommand (1031) from node 31: taken
               0x1401958B,  # a request to node 21: taken
               0x1401968B,  # a request to node 22: not taken
               0x14040700,  # RPMCommand bits from an anonymous node: not taken
               0x144E851F]  # data type 20101 from node 31: taken
        for can_id in ids:
            sender.send(can_id, b"\x01\xc0", extended=True)
        picky.send(0x1404071F, b"\x02\xc1", extended=True)  # its own: never back
        got = []
        deadline = time.monotonic() + 5
        while len(got) < 3 and time.monotonic() < deadline:
            frame = picky.receive(0.1)
            if frame is not None:
                got.append(frame.id)
        assert got == [0x1404071F, 0x1401958B, 0x144E851F] and picky.receive(0.2) is None
        assert deaf.receive(0.2) is None


def test_loopback_driver_delivers_to_others_only() -> None:
    a, b = _driver_pair()
    with a, b:
        assert a.receive_buffer_size >= 1 << 20
        a.send(0x1403EB0A, b"\x01\xc0", extended=True)
        got = b.receive(5.0)
        assert got is not None and (got.id, bytes(got.data), got.extended) == (0x1403EB0A, b"\x01\xc0", True)
        b.send(0x1403EB0B, b"\x02\xc1", extended=True)
        # a's own frame was queued on a's socket before b's: a must skip it and see b's.
        got = a.receive(5.0)
        assert got is not None and got.id == 0x1403EB0B
        assert a.receive(0) is None
        # On Linux the kernel drops a driver's own datagrams before they take space in its receive buffer.
        assert a.kernel_self_filter and b.kernel_self_filter
        assert a.own_frames_skipped == b.own_frames_skipped == 0

        # A blocking receive sleeps in poll: no busy wait.
        cpu, wall = time.process_time(), time.monotonic()
        assert a.receive(0.5) is None
        assert time.monotonic() - wall >= 0.5
        assert time.process_time() - cpu < 0.1

        # A datagram that is not a frame is counted and skipped.
        raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        raw.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        raw.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        raw.sendto(b"garbage", (a.group, a.port))
        raw.close()
        b.send(0x1403EB0B, b"\x03\xc2", extended=True)
        got = a.receive(5.0)
        assert got is not None and bytes(got.data) == b"\x03\xc2"
        deadline = time.monotonic() + 10.0
        while not a.drops.snapshot() and time.monotonic() < deadline:  # (two senders: no order between them)
            assert a.receive(0.05) is None
        assert a.drops.snapshot() == {"bad_packet": 1}
    with pytest.raises(DriverError, match="is closed"):
        a.receive(0)


def test_loopback_driver_counts_receive_buffer_overflow() -> None:
    a, b = _driver_pair()
    frame = CANFrame(0x1403EB0A, bytearray(8), True)
    with a, b:
        total = b.receive_buffer_size // 256  # far more datagrams than fit (each takes ~800 bytes)
        for i in range(total):
            (b if i % 10 == 0 else a).send_frame(frame)  # b's own frames are filtered: not an overflow
        from_a, from_b = total - len(range(0, total, 10)), len(range(0, total, 10))

        def drain(drv: LoopbackMulticastDriver, expected: int) -> int:
            got, deadline = 0, time.monotonic() + 20.0
            while got + drv.drops.snapshot().get("rx_overflow", 0) < expected and time.monotonic() < deadline:
                got += drv.receive(0.1) is not None
            return got

        delivered = drain(b, from_a)
        overflow = b.drops.snapshot().get("rx_overflow", 0)
        assert overflow > 0 and delivered + overflow == from_a
        assert drain(a, from_b) == from_b and a.receive(0) is None and a.drops.snapshot() == {}  # all fitted


# -- the node loop: bad input on the bus, in one process ------------------------------------------------------------

def test_bad_input_counted_and_node_keeps_working(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="sam_runtime.dronecan_io")
    iface = private_iface()
    spec = parse_iface(iface)

    async def scenario() -> None:
        loop_errors: list[Any] = []
        asyncio.get_running_loop().set_exception_handler(lambda _loop, ctx: loop_errors.append(ctx))
        node = make_node(iface, 10, transfer_timeout=0.5)
        nl = NodeLoop(node, log_interval=600.0)
        received: list[dict[str, Any]] = []
        nl.add_handler(RAW_IMU, lambda e: received.append(read_raw_imu(e.message)))
        nl.add_handler(dronecan.uavcan.equipment.ahrs.MagneticFieldStrength, lambda e: 1 / 0)
        bus = LoopbackMulticastDriver(spec.bus, spec.port)
        sent_ok = 0

        def send(frames: list[CANFrame]) -> None:
            for f in frames:
                bus.send_frame(f)

        async def expect(counts: dict[str, int], what: str) -> None:
            await until(lambda: nl.snapshot() == counts, 10.0, f"{what}: {counts}, have {nl.snapshot()}")

        async with nl:
            counts: dict[str, int] = {}
            imu = frames_of(raw_imu_message(3, 77), 42, 1)
            unknown = CANFrame((20 << 24) | (4242 << 8) | 42, bytearray(b"\x01\x02\xc0"), True)
            assert (4242, 0) not in dronecan.DATATYPES
            corrupted = [CANFrame(f.id, bytearray(f.data), True) for f in imu]
            corrupted[2].data[1] ^= 0x10
            toggled = [CANFrame(f.id, bytearray(f.data), True) for f in frames_of(raw_imu_message(4, 1), 42, 2)]
            toggled[3].data[-1] ^= 0x20
            short = CANFrame(0x1403EB2A, bytearray(b"\x01\x02\x03\xc3"), True)
            v1_id = (4 << 26) | (3 << 21) | (1234 << 8) | 42
            v1 = [_frame(v1_id, 0xE4), _frame(v1_id, 0xA5, bytes(7)), _frame(v1_id, 0x05, bytes(7)),
                  _frame(v1_id, 0x65)]
            steps: list[tuple[str, list[CANFrame], dict[str, int]]] = [
                ("unknown data type", [unknown], {"unknown_data_type": 1}),
                ("corrupted multi-frame transfer", corrupted, {"crc_mismatch": 1}),
                # The frame gate drops a frame with the wrong toggle bit alone (issue 29: it may be another
                # sender's): frames 3 and 4 here; the rest, one frame short, fails dronecan's CRC.
                ("broken toggle sequence", toggled, {"toggle_error": 2, "crc_mismatch": 1}),
                ("short payload", [short], {"malformed_payload": 1}),
                ("Cyphal v1 single and multi-frame", v1, {"cyphal_v1_frame": 4}),
                ("continuation without a start", [_frame(0x1403EB2A, 0x07)], {"orphan_frame": 1}),
                ("11-bit frame", [_frame(0x55, 0xC0, extended=False)], {"not_extended_id": 1}),
                ("handler raising", frames_of(dronecan.uavcan.equipment.ahrs.MagneticFieldStrength(), 42, 1),
                 {"handler_error": 1}),
                ("transfer that never ends", imu[:4], {"incomplete_transfer": 1}),
            ]
            for what, frames, more in steps:
                send(frames)
                for reason, n in more.items():
                    counts[reason] = counts.get(reason, 0) + n
                await expect(counts, what)
            node.defer(0.0, lambda: {}["scheduled"])
            nl.wake()
            counts["scheduled_callback_error"] = 1
            await expect(counts, "a scheduled callback raising")
            for i in range(20):  # a burst of the same error: one log line at once, one summary later
                bad = [CANFrame(f.id, bytearray(f.data), True) for f in frames_of(raw_imu_message(i, 1), 42, i)]
                bad[1].data[0] ^= 1
                send(bad)
            counts["crc_mismatch"] += 20
            await expect(counts, "a burst of corrupted transfers")

            send(frames_of(raw_imu_message(7, 99), 42, 30))
            sent_ok += 1
            await until(lambda: len(received) == sent_ok, 10.0, "a valid RawIMU after the bad input")
            assert received == [raw_imu_fields(7, 99)]
            assert nl.drops.detailed()[DropKey(DropReason.CRC_MISMATCH, 1003, 42)] == 22
            assert nl.drops.detailed()[DropKey(DropReason.UNKNOWN_DATA_TYPE, 4242, 42)] == 1
        bus.close()
        node.close()
        assert loop_errors == []

    asyncio.run(scenario())
    lines = [r.getMessage() for r in caplog.records]
    crc = [ln for ln in lines if "crc_mismatch" in ln]
    # (the first at once; then the burst's 20 and the broken toggle sequence's, one frame short)
    assert len(crc) == 2 and crc[1].startswith("dronecan drop crc_mismatch: 21 more in the last"), crc
    for reason in ("unknown_data_type", "toggle_error", "cyphal_v1_frame", "incomplete_transfer", "handler_error"):
        assert sum(f"drop {reason}" in ln for ln in lines) >= 1, reason
    assert not any(r.exc_info for r in caplog.records)


class NoFdDriver:
    """The loopback driver without fileno(), as dronecan's SLCAN driver: the NodeLoop has to poll it."""

    def __init__(self, inner: LoopbackMulticastDriver) -> None:
        self._inner = inner
        self.drops = inner.drops

    def receive(self, timeout: float | None = None) -> CANFrame | None:
        return self._inner.receive(timeout)

    def send_frame(self, frame: CANFrame) -> None:
        self._inner.send_frame(frame)

    def close(self) -> None:
        self._inner.close()


def test_two_node_loops_in_one_process_one_polled() -> None:
    spec = parse_iface(private_iface())

    async def scenario() -> None:
        watched = dronecan.node.Node(FrameGate(LoopbackMulticastDriver(spec.bus, spec.port)), node_id=10)
        polled = dronecan.node.Node(FrameGate(NoFdDriver(LoopbackMulticastDriver(spec.bus, spec.port))),
                                    node_id=11)
        got: dict[int, list[int]] = {10: [], 11: []}
        loops = [NodeLoop(watched), NodeLoop(polled, poll_interval=0.005)]
        loops[0].add_handler(RAW_IMU, lambda e: got[10].append(imu_seq(e.message)))
        loops[1].add_handler(RAW_IMU, lambda e: got[11].append(imu_seq(e.message)))
        async with loops[0], loops[1]:
            for i in range(50):
                watched.broadcast(raw_imu_message(i, 1))
                polled.broadcast(raw_imu_message(i, 1))
                await asyncio.sleep(0.002)
            await until(lambda: len(got[10]) == len(got[11]) == 50, 20.0, f"50 RawIMU each way, have {got}")
        assert got == {10: list(range(50)), 11: list(range(50))}
        assert loops[0].snapshot() == loops[1].snapshot() == {}
        assert loops[1].stats.wakeups > 0
        watched.close()
        polled.close()

    asyncio.run(scenario())


def test_node_loop_runs_the_scheduler_at_its_deadlines() -> None:
    """With max_idle at 60 s only the timer at dronecan's next scheduler deadline can run a 50 ms periodic
    callback 10 times within 30 s (nominally 0.5 s)."""

    async def scenario() -> None:
        node = make_node(private_iface(), 10)
        calls: list[float] = []
        async with NodeLoop(node, max_idle=60.0) as nl:
            node.periodic(0.05, lambda: calls.append(time.monotonic()))
            nl.wake()  # the periodic was added from outside the node's callbacks
            await until(lambda: len(calls) >= 10, 30.0, f"10 periodic calls, have {len(calls)}")
        node.close()

    asyncio.run(scenario())


def test_node_loop_reads_the_earliest_deadline_from_the_schedulers_heap() -> None:
    """The timer's deadline is read from the scheduler's heap (not its sorted copy): the earliest event's, whatever
    the order the events were added in."""

    async def scenario() -> None:
        node = make_node(private_iface(), 10)
        nl = NodeLoop(node, max_idle=60.0)
        for delay in (30.0, 0.7, 5.0, 0.3, 12.0):
            node.defer(delay, lambda: None)
        earliest = node._scheduler.queue[0].time  # the stdlib's sorted view
        assert nl._next_scheduler_deadline() == earliest
        assert earliest <= time.monotonic() + 0.3
        node.close()

    asyncio.run(scenario())


def test_bus_load_meter_counts_frames_on_the_wire() -> None:
    a, b = _driver_pair()
    meter = BusLoadMeter()
    b.add_io_hook(meter.on_frame)
    with a, b:
        for f in frames_of(raw_imu_message(0, 1), 42, 0):  # 47 bytes: 7 frames
            a.send_frame(f)
        for _ in range(7):
            assert b.receive(5.0) is not None
    snap = meter.snapshot()
    assert snap["rx"] == {"frames": 7, "bits": 917, "bits_worst_case": 1120} and snap["tx"]["frames"] == 0
    assert meter.bus_fraction(0.01) == pytest.approx(0.0917)
