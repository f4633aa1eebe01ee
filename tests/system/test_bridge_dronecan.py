"""The bridge on DroneCAN from SAM's spec (layout ``dronecan``), against plain ``dronecan`` nodes (the library
itself, not the project's receive path) on a private loopback bus, and a ROS probe, in one process:

- RawIMU broadcast as the IMU's node id reaches /imu with the right values; the same from another node id is dropped
  and counted (``unknown_source``);
- ROS commands reach a plain dronecan listener from the bridge's node id, with the right ESC index / actuator id and
  saturation (RPM 200000 -> int18 131071, 150 % -> 1.0 of the travel), dynamic arrays with exactly the declared
  elements;
- esc.Status of both ESCs routed by source node and ``esc_index``; a Status no mapping selects is counted
  (``unselected``), never silent;
- the node duties: a device's GetNodeInfo as the typed service uavcan_get_node_info (bridge.node_services), a
  restart_node to a device that does not answer RestartNode fails clearly, Panic both ways, the GlobalTimeSync
  master.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any

import pytest

dronecan = pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_peer import raw_imu_fields, raw_imu_message  # noqa: E402
from helpers.dronecan_support import PlainPeer, private_iface, until  # noqa: E402
from helpers.ros_probe import ThreadedProbe  # noqa: E402
from helpers.runtime_support import domain_id, generated_or_skip  # noqa: E402

pytestmark = [pytest.mark.ros, pytest.mark.slow]

BRIDGE_ID, IMU_ID, ESC1_ID, STRANGER = 100, 11, 21, 42
BRIDGE = "uavcan_ros_bridge"


class Probe(ThreadedProbe):
    node_name = "test_dronecan_probe"

    def setup(self) -> None:
        from std_msgs.msg import String

        self.messages: dict[str, list[Any]] = {}
        self.panics: list[str] = []
        self.node.create_subscription(String, f"/{BRIDGE}/panic_received", lambda m: self.panics.append(m.data), 10)
        self.panic_pub = self.node.create_publisher(String, f"/{BRIDGE}/panic", 10)

    def on_message(self, topic: str, msg: Any) -> None:
        self.messages.setdefault(topic, []).append(msg)


def _ready(pub_or_sub: Any) -> bool:
    return (pub_or_sub.get_subscription_count() if hasattr(pub_or_sub, "get_subscription_count")
            else pub_or_sub.get_publisher_count()) > 0


@pytest.fixture(scope="module", params=["codec", "object"])
def run(request: pytest.FixtureRequest) -> dict[str, Any]:
    """One bridge on a private bus, on the wire path (generated codecs) or the object path; the scenario's
    outcomes, measured."""
    gen = generated_or_skip()
    iface = private_iface()
    with pytest.MonkeyPatch.context() as mp:  # a private ROS domain: no other ROS graph on this machine joins in
        mp.setenv("ROS_DOMAIN_ID", domain_id(43))
        return asyncio.run(_scenario(gen, iface, request.param))


async def _scenario(gen: Any, iface: str, wire: str) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge

    out: dict[str, Any] = {"asked": wire}
    bridge = Bridge(gen, layout="dronecan", dronecan_iface=iface, diagnostics_period=0.5,
                    dronecan_options={"time_sync": True}, wire=wire)
    await bridge.start()
    out["wire"] = bridge.wire  # (start falls back to the object path when the package has no codecs)
    peers: list[PlainPeer] = []
    probe = None
    try:
        imu, stranger, esc1, listener = (PlainPeer(iface, n) for n in (IMU_ID, STRANGER, ESC1_ID, 60))
        peers += [imu, stranger, esc1, listener]
        probe = Probe(gen, ["/imu", "/thruster_1/feedback"],
                      ["/thruster_rpms", "/thruster_angles", "/buoyancy_piston_position"])
        subs = {t: probe.node.count_publishers(t) for t in ("/imu", "/thruster_1/feedback")}
        await until(lambda: all(probe.node.count_publishers(t) for t in subs), 15, "the bridge's ROS publishers")
        await until(lambda: all(_ready(p) for p in probe.pubs.values()), 15, "the bridge's command subscriptions")
        await until(lambda: bridge.stats()["devices"]["imu"].get("alive"), 10, "the IMU's NodeStatus")

        # UAVCAN -> ROS: 50 from the IMU's node id, 20 from a stranger.
        stamp0 = time.time_ns() // 1000
        for k in range(50):
            imu.broadcast(raw_imu_message(k, stamp0 + k * 10_000))
            if k < 20:
                stranger.broadcast(raw_imu_message(1000 + k, stamp0))
            await asyncio.sleep(0.01)
        # esc.Status: ESC index 0 from thruster 1's node (its mapping), index 1 from the same node (no mapping).
        status = dronecan.TYPENAMES["uavcan.equipment.esc.Status"]
        for k in range(5):
            esc1.broadcast(status(esc_index=0, rpm=1000 + k, current=1.5, temperature=300.0))
        esc1.broadcast(status(esc_index=1, rpm=7, temperature=300.0))
        await until(lambda: len(probe.messages.get("/imu", [])) >= 50, 15, "50 RawIMU on /imu")
        await until(lambda: bridge.stats()["mappings"]["imu"]["dropped"].get("unknown_source", 0) >= 20, 10,
                    "the stranger's drops")
        await until(lambda: len(probe.messages.get("/thruster_1/feedback", [])) >= 5, 10, "thruster 1 feedback")
        await until(lambda: bridge.stats()["mappings"]["thruster_1_feedback"]["dropped"].get("unselected"), 10,
                    "the unselected Status")

        # ROS -> UAVCAN.
        probe.publish("/thruster_rpms", {"thruster_1_rpm": 1000, "thruster_2_rpm": 200000})
        probe.publish("/thruster_angles", {"thruster_vertical_radians": 0.0625,  # inside the limits (+-0.12)
                                           "thruster_horizontal_radians": -0.09375})
        probe.publish("/buoyancy_piston_position", {"percent": 150.0})
        await until(lambda: listener.got("uavcan.equipment.esc.RPMCommand")
                    and len(listener.got("uavcan.equipment.actuator.ArrayCommand")) >= 2, 10, "the commands")

        # Duties.
        out["info"] = await asyncio.to_thread(probe.call_duty, "/uavcan_get_node_info", "UavcanGetNodeInfo", IMU_ID)
        out["restart"] = await asyncio.to_thread(probe.call_duty, "/uavcan_restart_node", "UavcanRestartNode", ESC1_ID)
        await until(lambda: _ready(probe.panic_pub), 10, "the bridge's panic subscription")
        probe.panic_pub.publish(__import__("std_msgs.msg", fromlist=["String"]).String(data="ROS-ABORT"))
        stranger.broadcast(dronecan.TYPENAMES["uavcan.protocol.Panic"](reason_text=b"LEAK"))
        await until(lambda: len([1 for src, _ in listener.got("uavcan.protocol.Panic") if src == BRIDGE_ID]) >= 3
                    and probe.panics, 10, "the panics")
        await until(lambda: any(m.previous_transmission_timestamp_usec for _, m in
                                listener.got("uavcan.protocol.GlobalTimeSync")), 10, "a time sync with a previous time")

        out["imu"] = [(m.angular_velocity.x, m.angular_velocity.y, m.linear_acceleration.x, m.linear_acceleration.z,
                       m.header.stamp.sec * 10**9 + m.header.stamp.nanosec, m.header.frame_id)
                      for m in probe.messages["/imu"]]
        out["feedback"] = [m.rpm for m in probe.messages["/thruster_1/feedback"]]
        out["rpm"] = [(src, list(m.rpm)) for src, m in listener.got("uavcan.equipment.esc.RPMCommand")]
        out["array"] = [(src, [(int(c.actuator_id), int(c.command_type), float(c.command_value)) for c in m.commands])
                        for src, m in listener.got("uavcan.equipment.actuator.ArrayCommand")]
        out["panic_bus"] = [(src, bytes(m.reason_text)) for src, m in listener.got("uavcan.protocol.Panic")]
        out["panic_ros"] = list(probe.panics)
        out["sync"] = [(src, int(m.previous_transmission_timestamp_usec))
                       for src, m in listener.got("uavcan.protocol.GlobalTimeSync")]
        out["stats"] = bridge.stats()
        out["stamp0_us"] = stamp0
    finally:
        for p in peers:
            p.close()
        if probe is not None:
            probe.close()
        await bridge.close()
    return out


def test_the_bridge_took_the_path_asked_for(run: dict[str, Any]) -> None:
    assert run["wire"] == run["asked"]


def test_raw_imu_of_the_imu_node_reaches_ros_with_its_values(run: dict[str, Any]) -> None:
    imu = run["imu"]
    assert len(imu) == 50
    for k, (gx, gy, ax, az, stamp_ns, frame) in enumerate(imu):
        f = raw_imu_fields(k)
        assert (gx, gy) == tuple(f["rate_gyro_latest"][:2]) and (ax, az) == (f["accelerometer_latest"][0],
                                                                             f["accelerometer_latest"][2])
        assert stamp_ns == (run["stamp0_us"] + k * 10_000) * 1000 and frame == "imu_link"
    st = run["stats"]["mappings"]["imu"]
    assert st["published"] == 50 and st["dropped"] == {"unknown_source": 20} and st["received"] == 70
    assert st["data_type_id"] == 1003 and st["dronecan"]["transfers"] == 70


def test_esc_status_routed_by_node_and_esc_index(run: dict[str, Any]) -> None:
    assert run["feedback"] == [1000, 1001, 1002, 1003, 1004]
    m = run["stats"]["mappings"]
    assert m["thruster_1_feedback"]["published"] == 5 and m["thruster_1_feedback"]["dropped"] == {"unselected": 1}
    assert m["thruster_2_feedback"]["received"] == 0  # node 21's messages are thruster 1's mapping's alone


def test_commands_reach_a_plain_listener_with_index_id_and_saturation(run: dict[str, Any]) -> None:
    assert run["rpm"] == [(BRIDGE_ID, [1000, 131071])]
    arrays = sorted(run["array"])
    assert arrays == [(BRIDGE_ID, [(0, 1, 0.0625), (1, 1, -0.09375)]), (BRIDGE_ID, [(5, 0, 1.0)])]
    m = run["stats"]["mappings"]
    assert m["thruster_rpms"]["saturated"] == {"thruster_rpms.rpm[1]": 1} and m["thruster_rpms"]["published"] == 1
    assert m["buoyancy_piston"]["saturated_total"] == 1 and m["buoyancy_piston"]["destination_node_ids"] == [26]


def test_node_duties(run: dict[str, Any]) -> None:
    info = run["info"]
    assert info.success and info.name == "org.test.peer11" and info.message == ""
    restart = run["restart"]  # the plain node does not serve RestartNode: a clear refusal, no hang
    assert not restart.success and "did not answer" in restart.message
    assert [p for p in run["panic_bus"] if p[0] == BRIDGE_ID] == [(BRIDGE_ID, b"ROS-ABO")] * 3
    assert run["panic_ros"] == [f"node {STRANGER}: LEAK"]
    sync = run["sync"]
    # GlobalTimeSync master: each carries the previous one's transmission time, increasing (0 for the first after open
    # and after a send whose time is not known well enough: sam_runtime.bridge.time_sync)
    times = [t for _, t in sync if t]
    assert all(src == BRIDGE_ID for src, _ in sync) and times and times == sorted(set(times)), sync
