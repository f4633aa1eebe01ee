"""The bridge's wire path without a bus or a ROS node: payload bytes in, CDR bytes out, and the DroneCAN framing.

- inbound on raw ports: the same accounting as the object path (sources, losses, stamps, rejections), and a payload
  the codec refuses counted below the bridge like the protocol library's own refusals: not converted, not counted
  as received, and a transfer-id gap before the next one, as when the library drops it before the handler;
- DroneCAN: payload bytes broadcast by :func:`broadcast_payload` go out in the very frames dronecan's
  ``node.broadcast`` sends for the message they encode, and :class:`TransferTaps` gives the payload back from
  them, counting what dronecan would refuse (toggle bits, CRC) under the NodeLoop's reasons.
"""

from __future__ import annotations

import logging
import threading
from types import SimpleNamespace as NS
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sam_runtime.bridge.backend import BelowBridge
from sam_runtime.bridge.counters import MappingStats
from sam_runtime.bridge.lifetime import Lifetime
from sam_runtime.bridge.loss import TransferLoss
from sam_runtime.common.rate_log import RateLimitedLog


class _Inlet:
    def __init__(self) -> None:
        self.below = BelowBridge()
        self.refused: list[tuple[int | None, str]] = []

    def malformed(self, src: int | None, detail: str) -> None:
        self.refused.append((src, detail))
        self.below.count("deserialization_failures", 1, True)


def _codec(payload: bytes, receive_ns: int, stats: Any) -> Any:
    kind, _, value = payload.partition(b":")
    if kind == b"bad":
        raise ValueError("array length prefix 9 > capacity 3")
    if kind == b"reject":
        stats.reject("imu.x")
        return None
    stamp = int(value) or receive_ns
    return b"CDR" + value, stamp


def _inbound(matches: Any = None) -> tuple[Any, Any, list[Any], Any, _Inlet]:
    from sam_runtime.bridge.inbound import Inbound, InMapping, PortGroup

    lt = Lifetime("t", RateLimitedLog(logging.getLogger("test_bridge_wire_path")))
    info = NS(name="imu", source_node_ids=(11,), frame_id="imu_link", topic=NS(name="/imu"))
    im = InMapping(info, _codec, MappingStats(threading.Lock(), "imu"), has_header=True, matches=matches, raw=True)
    loss = TransferLoss(7, {}, lambda: 2**64, lambda nid: None, lambda: [], lambda nid: None)
    group = PortGroup(1100, "imu", object, [im], loss)
    published: list[Any] = []
    ros = NS(receive_ns=lambda: 5_000_000_000, publisher=lambda topic, cls: NS(publish=published.append))
    inbound = Inbound(lt, [group], ros, backend=None)  # type: ignore[arg-type]
    im.ros_publisher = ros.publisher(info.topic, None)
    group.inlet = inlet = _Inlet()
    return inbound, inbound.handler(group), published, im, inlet


def test_raw_inbound_accounts_like_the_object_path() -> None:
    inbound, on_transfer, published, im, inlet = _inbound()
    assert inbound.groups[1100].raw
    on_transfer(b"ok:3000000000", 11, 0, 1.0)
    on_transfer(b"ok:4000000000", 11, 3, 1.1)  # 2 lost before it
    on_transfer(b"ok:1", 42, 0, 1.2)  # a spoofer
    on_transfer(b"ok:0", 11, 4, 1.3)  # unknown stamp: the codec gives the receive time
    on_transfer(b"ok:2000000000", 11, 5, 1.4)  # older than the previous: published anyway, counted
    on_transfer(b"reject:", 11, 6, 1.5)
    st = im.stats.snapshot()
    assert st["dropped"] == {"lost": 2, "unknown_source": 1, "rejected": 1}
    assert st["received"] == 6 and st["published"] == 4 and st["out_of_order"] == 1
    assert published == [b"CDR3000000000", b"CDR4000000000", b"CDR0", b"CDR2000000000"]  # bytes: rclpy publishes raw
    assert inlet.refused == []


def test_raw_inbound_a_refused_payload_is_counted_below_and_leaves_no_gap() -> None:
    _, on_transfer, published, im, inlet = _inbound()
    on_transfer(b"ok:1000000000", 11, 0, 1.0)
    on_transfer(b"bad:", 11, 1, 1.1)
    on_transfer(b"ok:2000000000", 11, 2, 1.2)
    st = im.stats.snapshot()
    # pycyphal / dronecan drop such a transfer before the bridge, so the next one shows a gap: one lost. The wire
    # path counts exactly the same (the "same counted drops"), plus the refusal below the bridge.
    assert st["dropped"] == {"lost": 1} and st["received"] == 2 and st["published"] == 2
    assert inlet.refused == [(11, "ValueError: array length prefix 9 > capacity 3")]
    assert inlet.below.snapshot()[0] == {"deserialization_failures": 1}
    assert len(published) == 2


_KIND = st.sampled_from([b"ok:0", b"ok:3000000000", b"ok:1000000000", b"bad:", b"reject:", b"boom:"])


@settings(max_examples=120, deadline=None)
@given(transfers=st.lists(st.tuples(_KIND, st.sampled_from([11, 11, 11, 42, None]), st.integers(0, 40),
                                    st.booleans(), st.booleans()), max_size=30))
def test_one_mapping_fast_path_accounts_as_the_general_path(transfers: list[tuple[bytes, Any, int, bool, bool]]
                                                            ) -> None:
    """A port's one mapping that takes every transfer runs Inbound's one-mapping path (no takers' list); the same
    transfers through the general path give the same counters, publications, refusals and logs: sources, losses,
    stamps, rejections, codec and publish failures, a disabled mapping. Both count each transfer that reached the
    bridge once, as published or as one drop (received + published under one lock when it is published)."""
    runs = []
    for fast in (True, False):
        inbound, on_transfer, published, im, inlet = _inbound()
        group = inbound.groups[1100]
        assert group.single is im
        if not fast:
            group.single = None
        pub_fail = [False]

        def publish(out: Any, pub_fail: list[bool] = pub_fail, published: list[Any] = published) -> None:
            if pub_fail[0]:
                raise RuntimeError("rmw")
            published.append(out)

        im.ros_publisher = NS(publish=publish)
        to_ros = im.to_ros

        def convert(payload: bytes, receive_ns: int, stats: Any, to_ros: Any = to_ros) -> Any:
            if payload.startswith(b"boom"):
                raise KeyError("a converter bug")
            return to_ros(payload, receive_ns, stats)

        im.to_ros = convert
        t = 0.0
        for payload, src, tid, enabled, fail in transfers:
            t += 0.01
            im.switch.enabled = enabled or payload.startswith(b"ok:1")
            pub_fail[0] = fail and payload.endswith(b"0")
            on_transfer(payload, src, tid, t)
        snap = im.stats.snapshot()
        snap.pop("last_drop_age_s")  # (a time)
        # every transfer that reached the bridge is published or dropped, once (the losses came before it)
        drops = snap["dropped"]
        assert snap["received"] == snap["published"] + sum(drops.values()) - drops.get("lost", 0)
        assert snap["received"] + len(inlet.refused) == len(transfers) and snap["published"] == len(published)
        runs.append((snap, published, inlet.refused, dict(inbound.lifetime.rlog.lines)))
    assert runs[0] == runs[1]


def test_raw_inbound_selection_by_payload() -> None:
    _, on_transfer, published, im, _ = _inbound(matches=lambda payload: not payload.endswith(b"7"))
    on_transfer(b"ok:1000000000", 11, 0, 1.0)
    on_transfer(b"ok:1000000007", 11, 1, 1.1)  # no mapping of the port selects it
    st = im.stats.snapshot()
    assert st["dropped"] == {"unselected": 1} and st["published"] == 1 and published == [b"CDR1000000000"]


# ============================================================================================ DroneCAN framing
class _CaptureDriver:
    """A dronecan driver that keeps what is sent."""

    def __init__(self) -> None:
        self.sent: list[tuple[int, bytes]] = []

    def send(self, can_id: int, data: Any, extended: bool = False, canfd: bool = False) -> None:
        self.sent.append((can_id, bytes(data)))

    def receive(self, timeout: float | None = None) -> None:
        return None

    def close(self) -> None:
        pass


@pytest.fixture(scope="module")
def dronecan_mod() -> Any:
    return pytest.importorskip("dronecan")


def _node(dronecan: Any, driver: _CaptureDriver, node_id: int = 10) -> Any:
    return dronecan.node.Node(driver, node_id=node_id)


def _messages(dronecan: Any) -> list[Any]:
    t = dronecan.TYPENAMES
    imu = t["uavcan.equipment.ahrs.RawIMU"](timestamp=t["uavcan.Timestamp"](usec=123456789),
                                            rate_gyro_latest=[0.5, -1.25, 2.0],
                                            accelerometer_latest=[0.0, 9.81, -3.5])
    cmd = t["uavcan.equipment.actuator.ArrayCommand"](commands=[
        t["uavcan.equipment.actuator.Command"](actuator_id=i, command_type=1, command_value=0.25 * i)
        for i in range(3)])
    rpm = t["uavcan.equipment.esc.RPMCommand"](rpm=[1000, -2000])
    return [imu, cmd, rpm, t["uavcan.equipment.esc.RPMCommand"](rpm=[])]


def test_broadcast_payload_sends_the_frames_dronecan_sends(dronecan_mod: Any) -> None:
    from dronecan import transport

    from sam_runtime.dronecan_io.wire import broadcast_payload

    for msg in _messages(dronecan_mod):
        dtype = dronecan_mod.get_dronecan_data_type(msg)
        theirs, ours = _CaptureDriver(), _CaptureDriver()
        a, b = _node(dronecan_mod, theirs), _node(dronecan_mod, ours)
        for _ in range(3):  # the transfer ids advance alike
            a.broadcast(msg)
            broadcast_payload(b, dtype.default_dtid, dtype.base_crc, bytes(transport.Transfer(payload=msg).payload))
        assert ours.sent == theirs.sent, dtype.full_name
        assert len(theirs.sent) >= 3


def _frames(sent: list[tuple[int, bytes]]) -> list[Any]:
    from dronecan.driver.common import CANFrame

    return [CANFrame(can_id, bytearray(data), True) for can_id, data in sent]


def test_taps_give_back_the_payload_and_count_what_dronecan_refuses(dronecan_mod: Any) -> None:
    from dronecan import transport

    from sam_runtime.dronecan_io import DropCounter
    from sam_runtime.dronecan_io.wire import TransferTaps

    drops = DropCounter()
    taps = TransferTaps(drops)
    got: list[tuple[bytes, int, int]] = []
    imu = _messages(dronecan_mod)[0]
    dtype = dronecan_mod.get_dronecan_data_type(imu)
    taps.add(dtype.default_dtid, dtype.base_crc, lambda payload, src, tid, ts: got.append((payload, src, tid)))
    driver = _CaptureDriver()
    node = _node(dronecan_mod, driver, 11)
    for _ in range(2):
        node.broadcast(imu)
    frames = _frames(driver.sent)
    half = len(frames) // 2
    assert half > 1  # a multi-frame transfer: its CRC is checked
    assert taps.take(frames[:half]) and taps.take(frames[half:])
    payload = bytes(transport.Transfer(payload=imu).payload)
    assert got == [(payload, 11, 0), (payload, 11, 1)]

    bad_crc = _frames(driver.sent[:half])
    bad_crc[0].data[0] ^= 0xFF
    assert taps.take(bad_crc)
    bad_toggle = _frames(driver.sent[:half])
    bad_toggle[1].data[-1] ^= 0x20
    assert taps.take(bad_toggle)
    assert len(got) == 2
    reasons = {(k.reason.value, k.data_type_id, k.source_node_id): n for k, n in drops.detailed().items()}
    assert reasons == {("crc_mismatch", dtype.default_dtid, 11): 1, ("toggle_error", dtype.default_dtid, 11): 1}

    other = _CaptureDriver()  # another data type, and a service: dronecan's, untouched
    _node(dronecan_mod, other, 11).broadcast(_messages(dronecan_mod)[2])
    assert not taps.take(_frames(other.sent))


def test_a_shared_tap_hands_the_transfer_to_the_node_too(dronecan_mod: Any) -> None:
    """The bridge's built-in Panic duty beside a mapping of Panic on the wire path (`panic_duty: both`): the tap's
    handler has the transfer, then the node too; one that fails its checks is counted once, by the tap."""
    from sam_runtime.dronecan_io import DropCounter
    from sam_runtime.dronecan_io.wire import TransferTaps

    drops = DropCounter()
    taps = TransferTaps(drops)
    panic = dronecan_mod.TYPENAMES["uavcan.protocol.Panic"]
    got: list[bytes] = []
    taps.add(panic.default_dtid, panic.base_crc, lambda payload, src, tid, ts: got.append(payload))
    driver = _CaptureDriver()
    _node(dronecan_mod, driver, 12).broadcast(panic(reason_text=b"LEAK"))
    assert taps.take(_frames(driver.sent)) and got == [b"LEAK"]  # not shared: the tap's alone
    taps.share(panic.default_dtid)
    assert not taps.take(_frames(driver.sent)) and got == [b"LEAK", b"LEAK"]  # shared: the node's as well
    long = _CaptureDriver()
    imu = _messages(dronecan_mod)[0]
    imu_type = dronecan_mod.get_dronecan_data_type(imu)
    taps.add(imu_type.default_dtid, imu_type.base_crc, lambda payload, src, tid, ts: got.append(payload))
    taps.share(imu_type.default_dtid)
    _node(dronecan_mod, long, 12).broadcast(imu)
    bad = _frames(long.sent)
    bad[0].data[0] ^= 0xFF
    assert taps.take(bad) and len(got) == 2  # a bad CRC: counted here, never handed on
    assert sum(drops.detailed().values()) == 1


def test_a_transfer_id_jump_is_no_loss_and_does_not_move_the_stream() -> None:
    """Issue 29 item 1: one valid transfer with the device's node id and a transfer id 2**40 ahead added
    1,099,511,627,775 to ``lost``. A jump beyond what the time since the previous transfer allows is counted as
    ``transfer_id_jump``, not published, and the real device's next transfers are taken as if it never came; a
    real restart with another counter (two transfers in sequence after the jump) starts the new sequence, and a
    real gap (after a second, 30 missing at 100 Hz) is still ``lost``."""
    _, on_transfer, published, im, _ = _inbound()
    for i in range(5):
        on_transfer(b"ok:1", 11, 100 + i, 1.0 + 0.01 * i)
    on_transfer(b"ok:1", 11, 2**40, 1.045)  # the spoof
    for i in range(5, 10):
        on_transfer(b"ok:1", 11, 100 + i, 1.0 + 0.01 * i)
    st = im.stats.snapshot()
    assert st["dropped"] == {"transfer_id_jump": 1} and st["published"] == 10
    on_transfer(b"ok:1", 11, 5000, 1.2)  # a restart with another counter: its first transfer is a jump ...
    on_transfer(b"ok:1", 11, 5001, 1.21)  # ... its second starts the new sequence
    on_transfer(b"ok:1", 11, 5032, 2.21)  # a real gap: 30 lost in a second
    st = im.stats.snapshot()
    assert st["dropped"] == {"transfer_id_jump": 2, "lost": 30} and st["published"] == 12
    assert len(published) == 12
