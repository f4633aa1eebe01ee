"""QoS as REP 2003 asks (issue 30): the bridge publishes every sensor topic reliably (keep last), so a subscriber
with rclpy's default settings (reliable, what most nodes, scripts and loggers create), a best-effort one (rclpy's
``qos_profile_sensor_data``, what the spec's subscribers use) and an explicitly reliable one all match and
receive it, with no incompatible-QoS event on any of them.

SAM's devices simulated on DroneCAN (layout ``dronecan``, a private loopback bus) and the bridge in one process,
with one rclpy probe node that subscribes each UAVCAN->ROS topic three ways. Every wait polls with a deadline.
"""

from __future__ import annotations

import asyncio
import threading
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_support import private_iface, until
from helpers.ros_probe import SpunNode
from helpers.runtime_support import domain_id, generated_or_skip

pytestmark = [pytest.mark.ros, pytest.mark.slow]

KINDS = ("default", "best_effort", "reliable")
COUNT = 3  # messages per topic and subscriber: each subscription delivers, not just matches
TIMEOUT_S = 40.0  # the slowest sensor port (1 Hz) on a loaded machine, after discovery


class QosProbe(SpunNode):
    """Each topic subscribed with rclpy's default QoS (depth 10), sensor-data QoS and explicit reliable QoS; the
    messages and the incompatible-QoS events per (topic, kind)."""

    def __init__(self, gen: Any, topics: dict[str, Any]) -> None:
        from rclpy.event_handler import SubscriptionEventCallbacks
        from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data

        super().__init__("test_qos_probe")
        self.lock = threading.Lock()
        self.got: dict[tuple[str, str], int] = {}
        self.incompatible: dict[tuple[str, str], int] = {}
        profiles = {"default": 10, "best_effort": qos_profile_sensor_data,
                    "reliable": QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)}
        self.subs = []
        for name, topic in topics.items():
            for kind in KINDS:
                key = (name, kind)
                events = SubscriptionEventCallbacks(incompatible_qos=lambda _e, key=key: self._count(
                    self.incompatible, key))
                self.subs.append(self.node.create_subscription(
                    gen.ros_class(topic), name, lambda _m, key=key: self._count(self.got, key), profiles[kind],
                    event_callbacks=events))
        self.start_spinning("qos-probe")

    def _count(self, counts: dict[tuple[str, str], int], key: tuple[str, str]) -> None:
        with self.lock:
            counts[key] = counts.get(key, 0) + 1

    def missing(self, topics: list[str]) -> list[tuple[str, str]]:
        with self.lock:
            return [(t, k) for t in topics for k in KINDS if self.got.get((t, k), 0) < COUNT]


@pytest.fixture(scope="module")
def run() -> dict[str, Any]:
    gen = generated_or_skip()
    iface = private_iface()
    with pytest.MonkeyPatch.context() as mp:  # a private ROS domain: no other ROS graph on this machine joins in
        mp.setenv("ROS_DOMAIN_ID", domain_id(47))
        return asyncio.run(_scenario(gen, iface))


async def _scenario(gen: Any, iface: str) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge
    from sam_runtime.sim.simulator import SimConfig, Simulator

    tables = gen.tables()
    layout = next(lay for lay in tables.LAYOUTS if lay.name == "dronecan")
    mappings = [m for m in tables.DRONECAN_MAPPINGS if m.name in layout.dronecan_mappings]
    topics = {m.topic.name: m.topic for m in mappings if m.direction == "uavcan_to_ros"}
    bridge = Bridge(gen, layout="dronecan", dronecan_iface=iface, diagnostics_period=0.5)
    sim = Simulator(gen, SimConfig(layout="dronecan", dronecan_iface=iface))
    probe = None
    await bridge.start()
    try:
        await sim.start(publish_now=True)
        probe = QosProbe(gen, topics)
        names = sorted(topics)
        try:
            await until(lambda: not probe.missing(names), TIMEOUT_S, f"{COUNT} messages on every sensor topic, "
                        "each subscription kind")
        except AssertionError as e:
            raise AssertionError(f"{e}; missing: {probe.missing(names)}; incompatible: {probe.incompatible}") from e
        with probe.lock:
            return {"topics": names, "got": dict(probe.got), "incompatible": dict(probe.incompatible),
                    "qos": {n: (t.qos.reliability, t.subscriber_qos.reliability) for n, t in topics.items()}}
    finally:
        if probe is not None:
            probe.close()
        await sim.close()
        await bridge.close()


def test_every_sensor_topic_reaches_default_best_effort_and_reliable_subscribers(run: dict[str, Any]) -> None:
    assert len(run["topics"]) >= 10  # SAM's sensors and feedback: the scenario saw the whole layout
    assert all(run["got"][(t, k)] >= COUNT for t in run["topics"] for k in KINDS)
    assert run["incompatible"] == {}


def test_the_bridge_publishes_sensor_data_reliably_for_best_effort_subscribers(run: dict[str, Any]) -> None:
    """The tables' two sides, as the bridge used them (REP 2003)."""
    assert set(run["qos"].values()) == {("reliable", "best_effort")}
