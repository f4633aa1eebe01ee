"""A namespaced bridge (issue 26): SAM's bridge on DroneCAN (layout ``dronecan``) run as vehicle ``/sam1`` (frame
prefix ``sam1/``) stays on the wire path, the generated codecs bound to the prefix at start, and writes what the
object path writes: against a plain ``dronecan`` node on a private loopback bus and a ROS probe, in one process.

- the bridge reports ``"wire": "codec"`` in its stats (a namespaced run took the object path before: the codecs
  held the spec's frame ids in their constant bytes);
- RawIMU broadcast as the IMU's node id reaches /imu (SAM's topics are absolute: they stay global) with its
  values, its stamp and the frame id ``sam1/imu_link`` (the prefix's length, 5, shifts the float64 fields after the
  frame id by 3 bytes of padding: the property tests of tests/codegen/test_codec_v0.py cover every length);
- the same scenario on the object path (``wire="object"``) gives the same messages.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_peer import raw_imu_fields, raw_imu_message
from helpers.dronecan_support import PlainPeer, private_iface, until
from helpers.ros_probe import ThreadedProbe
from helpers.runtime_support import domain_id, generated_or_skip

pytestmark = [pytest.mark.ros, pytest.mark.slow]

IMU_ID = 11
COUNT = 30


class Probe(ThreadedProbe):
    node_name = "test_namespaced_probe"

    def setup(self) -> None:
        self.messages: dict[str, list[Any]] = {}

    def on_message(self, topic: str, msg: Any) -> None:
        self.messages.setdefault(topic, []).append(msg)


@pytest.fixture(scope="module", params=["codec", "object"])
def run(request: pytest.FixtureRequest) -> dict[str, Any]:
    """One bridge as /sam1 on a private bus, on the path asked for; what reached ROS."""
    gen = generated_or_skip()
    iface = private_iface()
    with pytest.MonkeyPatch.context() as mp:  # a private ROS domain: no other ROS graph on this machine joins in
        mp.setenv("ROS_DOMAIN_ID", domain_id(25))
        return asyncio.run(_scenario(gen, iface, request.param))


async def _scenario(gen: Any, iface: str, wire: str) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge
    from sam_runtime.common.ros_namespace import ros_namespace

    bridge = Bridge(gen, layout="dronecan", dronecan_iface=iface, diagnostics_period=0.5, wire=wire,
                    namespace=ros_namespace("/sam1"))
    await bridge.start()
    imu = probe = None
    try:
        imu = PlainPeer(iface, IMU_ID)
        probe = Probe(gen, ["/imu"], [])
        await until(lambda: probe.node.count_publishers("/imu"), 15, "the bridge's /imu publisher")
        stamp0 = time.time_ns() // 1000
        for k in range(COUNT):
            imu.broadcast(raw_imu_message(k, stamp0 + k * 10_000))
            await asyncio.sleep(0.01)
        await until(lambda: len(probe.messages.get("/imu", [])) >= COUNT, 15, f"{COUNT} RawIMU on /imu")
        return {
            "asked": wire,
            "stats": bridge.stats(),
            "stamp0_us": stamp0,
            "imu": [(m.header.frame_id, m.header.stamp.sec * 10**9 + m.header.stamp.nanosec,
                     m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z, m.linear_acceleration.x,
                     m.linear_acceleration.y, m.linear_acceleration.z, m.orientation_covariance[0])
                    for m in probe.messages["/imu"]],
        }
    finally:
        if imu is not None:
            imu.close()
        if probe is not None:
            probe.close()
        await bridge.close()


def test_a_namespaced_bridge_runs_the_path_asked_for(run: dict[str, Any]) -> None:
    """The codec path when asked (the default), not a fall back to the object path."""
    assert run["stats"]["wire"] == run["asked"]


def test_raw_imu_reaches_ros_with_the_prefixed_frame_and_its_values(run: dict[str, Any]) -> None:
    imu = run["imu"]
    assert len(imu) == COUNT
    for k, (frame, stamp_ns, *values) in enumerate(imu):
        f = raw_imu_fields(k)
        assert frame == "sam1/imu_link"
        assert stamp_ns == (run["stamp0_us"] + k * 10_000) * 1000
        assert values == [*f["rate_gyro_latest"], *f["accelerometer_latest"], -1.0]
    assert run["stats"]["mappings"]["imu"]["published"] == COUNT
