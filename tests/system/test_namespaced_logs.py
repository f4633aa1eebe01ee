"""A namespaced run's logs (issue 30): SAM's devices simulated on DroneCAN (layout ``dronecan``, a private loopback
bus), its bridge run as vehicle ``/sam1`` (frame prefix ``sam1/``) and the recorder with the same namespace, in one
process, recorded until every bridged topic has a few messages; then the readers:

- the recording keeps the run's names (``ros.namespace``, ``ros.frame_prefix`` in its metadata) and its channels
  are the names as the run resolved them;
- the plot's reader finds the spec's topics in it and the bridge's own state on /diagnostics under its spec name
  (``sam1/uavcan_ros_bridge`` -> ``uavcan_ros_bridge``), and draws a picture;
- the replay, through the offline bridge given the recorded names, reproduces every topic, ``header.frame_id``
  included; the same replay without them differs exactly in the frame ids (what the issue saw).

Every wait polls with a deadline.
"""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")
pytest.importorskip("mcap_ros2")

from helpers.dronecan_support import private_iface, until
from helpers.runtime_support import domain_id, generated_or_skip

pytestmark = [pytest.mark.ros, pytest.mark.slow]

MIN_PER_TOPIC = 3
TIMEOUT_S = 60.0  # discovery and the slowest port (1 Hz) on a loaded machine


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    gen = generated_or_skip()
    iface = private_iface()
    path = tmp_path_factory.mktemp("nslogs") / "sam1.mcap"
    with pytest.MonkeyPatch.context() as mp:  # a private ROS domain: no other ROS graph on this machine joins in
        mp.setenv("ROS_DOMAIN_ID", domain_id(53))
        topics = asyncio.run(_scenario(gen, iface, path))
    return {"gen": gen, "path": path, "topics": topics}


async def _scenario(gen: Any, iface: str, path: Path) -> list[str]:
    from sam_runtime.bridge import Bridge
    from sam_runtime.common.ros_namespace import ros_namespace
    from sam_runtime.recording.recorder import Recorder, RecorderConfig
    from sam_runtime.sim.simulator import SimConfig, Simulator

    tables = gen.tables()
    layout = next(lay for lay in tables.LAYOUTS if lay.name == "dronecan")
    topics = sorted({m.topic.name for m in tables.DRONECAN_MAPPINGS
                     if m.name in layout.dronecan_mappings and m.direction == "uavcan_to_ros"})
    names = ros_namespace("/sam1")
    recorder = Recorder(gen, RecorderConfig(path, layout="dronecan", dronecan_iface=iface,
                                            namespace=names.node_namespace, frame_prefix=names.frame_prefix))
    bridge = Bridge(gen, layout="dronecan", dronecan_iface=iface, diagnostics_period=0.5, namespace=names)
    sim = Simulator(gen, SimConfig(layout="dronecan", dronecan_iface=iface))
    await recorder.start()
    try:
        await bridge.start()
        try:
            await sim.start(publish_now=True)
            try:
                def short() -> list[str]:
                    recorder.tick()
                    return [t for t in [*topics, "/diagnostics"] if recorder.counts.ros[t] < MIN_PER_TOPIC]

                await until(lambda: not short(), TIMEOUT_S, f"{MIN_PER_TOPIC} recorded messages per bridged topic")
            finally:
                await sim.close()
        finally:
            await bridge.close()
    finally:
        await recorder.close()
    return topics


def test_the_recording_keeps_the_runs_names(recorded: dict[str, Any]) -> None:
    from sam_runtime.recording.reading import read_recording
    from sam_runtime.recording.recorder import METADATA_NAME

    rec = read_recording(recorded["path"])
    meta = rec.metadata[METADATA_NAME]
    assert (meta["ros.namespace"], meta["ros.frame_prefix"]) == ("/sam1", "sam1/")
    channels = {c.topic for c in rec.channels.values()}
    assert set(recorded["topics"]) <= channels  # SAM's names are absolute: resolved, they stay as they are


def test_the_plot_reads_the_namespaced_run(recorded: dict[str, Any], tmp_path: Path) -> None:
    from sam_runtime.report.plot import TOPICS, node_states, plot_run
    from sam_runtime.report.recording import read_recording

    rec = read_recording(recorded["path"], TOPICS)
    assert (rec.names.namespace, rec.names.frame_prefix) == ("/sam1", "sam1/")
    for topic in ("/pressure", "/altitude", "/battery_state", "/diagnostics"):
        assert rec.get(topic), topic
    assert "uavcan_ros_bridge" in node_states(rec)  # its status is sam1/uavcan_ros_bridge on the shared topic
    out = plot_run(recorded["path"], tmp_path / "sam1.png")
    assert out.stat().st_size > 10_000


def test_replay_with_the_recorded_names_reproduces_every_topic(recorded: dict[str, Any]) -> None:
    from sam_runtime.bridge.offline import OfflineBridge
    from sam_runtime.common.run_names import run_names
    from sam_runtime.recording.reading import read_recording
    from sam_runtime.recording.recorder import METADATA_NAME
    from sam_runtime.recording.replay import replay

    rec = read_recording(recorded["path"])
    names = run_names(rec.metadata[METADATA_NAME])
    report = replay(recorded["path"], [OfflineBridge(recorded["gen"], layout="dronecan", namespace=names)],
                    recording=rec)
    assert set(recorded["topics"]) <= set(report.topics)
    assert report.same, "\n".join(report.lines())
    assert all(report.topics[t].identical + report.topics[t].receive_time >= MIN_PER_TOPIC - 1
               for t in recorded["topics"]), "\n".join(report.lines())

    plain = replay(recorded["path"], [OfflineBridge(recorded["gen"], layout="dronecan")], recording=rec)
    framed = [t for t, d in plain.topics.items() if d.differing]
    assert framed and all(set(plain.topics[t].fields) <= {"header.frame_id"} for t in framed), \
        "\n".join(plain.lines())
