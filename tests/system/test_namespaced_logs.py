"""A namespaced run's logs (issue 30): SAM's devices simulated on DroneCAN (layout ``dronecan``, a private loopback
bus), its bridge run as vehicle ``/sam1`` (frame prefix ``sam1/``) and the recorder with the same namespace, in one
process, recorded until every bridged topic has a few messages; then the readers:

- the recording keeps the run's names (``ros.namespace``, ``ros.frame_prefix`` in its metadata) and its channels
  are the names as the run resolved them;
- the plot's reader finds the spec's topics in it and the bridge's own state on /diagnostics under its spec name
  (``sam1/uavcan_ros_bridge`` -> ``uavcan_ros_bridge``), and draws a picture;
- the replay, through the offline bridge given the recorded names, reproduces every topic, ``header.frame_id``
  included; the same replay without them differs exactly in the frame ids (what the issue saw);
- the other direction: the thruster commands a ROS node sent during the run, recorded, converted again by the
  offline bridge, are the payloads of the bridge's recorded transfers; a changed spec conversion shows its first
  differing payloads.

Every wait polls with a deadline.
"""

from __future__ import annotations

import asyncio
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")
pytest.importorskip("mcap_ros2")

from helpers.dronecan_support import private_iface, until
from helpers.ros_probe import ThreadedProbe
from helpers.runtime_support import child_env, domain_id, generated_or_skip, ros_prefix_for, runtime_cmd

pytestmark = [pytest.mark.ros, pytest.mark.slow]

MIN_PER_TOPIC = 3
COMMANDS = 8  # /thruster_rpms commands the test's node sends


class Commander(ThreadedProbe):
    node_name = "test_nslogs_commander"

    def on_message(self, topic: str, msg: Any) -> None:
        pass
TIMEOUT_S = 60.0  # discovery and the slowest port (1 Hz) on a loaded machine


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    gen = generated_or_skip()
    iface = private_iface()
    path = tmp_path_factory.mktemp("nslogs") / "sam1" / "sam1_0.mcap"  # recorded inside a rosbag2 folder
    path.parent.mkdir()
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
    commander = None
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
                # commands, once both the bridge and the recorder subscribe (3 ROS subscriptions: the bridge's, the
                # recorder's... and none other), each waited for in the recording before the next
                commander = Commander(gen, [], ["/thruster_rpms"])
                pub = commander.pubs["/thruster_rpms"]
                await until(lambda: pub.get_subscription_count() >= 2, TIMEOUT_S, "the bridge's and the recorder's "
                            "/thruster_rpms subscriptions")
                for k in range(COMMANDS):  # each in the recording and sent by the bridge before the next
                    commander.publish("/thruster_rpms", {"thruster_1_rpm": 100 * k, "thruster_2_rpm": -50 * k})
                    await until(lambda k=k: (recorder.tick(), recorder.counts.ros["/thruster_rpms"] > k)[1],
                                TIMEOUT_S, f"command {k} in the recording")
                    await until(lambda k=k: bridge.stats()["mappings"]["thruster_rpms"]["published"] > k, TIMEOUT_S,
                                f"the bridge's transfer of command {k}")
            finally:
                if commander is not None:
                    commander.close()
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


def test_the_recording_reads_as_a_rosbag2_folder_and_bare(recorded: dict[str, Any]) -> None:
    """rosbags 0.11 reads the bare MCAP and the rosbag2 folder made in place around it (metadata.yaml beside it,
    the file itself untouched), with the same messages; the metadata counts them as rosbag2 does."""
    import json

    from rosbags.rosbag2 import Reader

    from sam_runtime.recording.reading import rosbag2_folder

    path = recorded["path"]
    before = path.read_bytes()
    folder = rosbag2_folder(path, path.parent)
    assert path.read_bytes() == before and not path.is_symlink()
    info = json.loads((folder / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["relative_file_paths"] == [path.name] and info["files"][0]["path"] == path.name
    counts = []
    for where in (path, folder):
        with Reader(where) as bag:
            counts.append({c.topic: c.msgcount for c in bag.connections})
    assert counts[0] == counts[1] and counts[0]["/imu"] >= MIN_PER_TOPIC
    assert info["message_count"] == sum(counts[0].values())


def test_record_writes_a_rosbag2_folder(recorded: dict[str, Any], tmp_path: Path) -> None:
    """`sam-codegen record BAG --rosbag2`: a new folder with BAG_0.mcap and, at the end, its metadata.yaml."""
    import json
    import subprocess

    gen = recorded["gen"]
    bag = tmp_path / "bag"
    env = child_env(ros_prefix_for(gen), domain_id(54))
    done = subprocess.run(runtime_cmd("record", str(bag), "--rosbag2", "--no-bus", "--duration", "1",
                                      "--generated", str(gen.root)), env=env, capture_output=True, text=True,
                          timeout=180)
    assert done.returncode == 0, done.stderr[-2000:]
    assert sorted(p.name for p in bag.iterdir()) == ["bag_0.mcap", "metadata.yaml"]
    info = json.loads((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["storage_identifier"] == "mcap" and "/imu" in {t["topic_metadata"]["name"]
                                                                for t in info["topics_with_message_count"]}
    again = subprocess.run(runtime_cmd("record", str(bag), "--rosbag2", "--no-bus", "--generated", str(gen.root)),
                           env=env, capture_output=True, text=True, timeout=180)
    assert again.returncode == 1 and "it exists and is not an empty folder" in again.stderr


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

    commands = report.commands
    assert len(commands) == 1, "\n".join(report.lines())
    (rpm,) = commands.values()
    assert "thruster_rpms" in next(iter(commands))
    assert (rpm.identical, rpm.differing, rpm.missing, rpm.extra) == (COMMANDS, 0, 0, 0), "\n".join(report.lines())

    # a conversion that changed (here: the last payload byte flipped) is named with its first values and the count
    changed = OfflineBridge(recorded["gen"], layout="dronecan", namespace=names)
    convert = changed.command
    changed.command = lambda topic, cdr: [  # type: ignore[method-assign]
        replace(c, payload=c.payload[:-1] + bytes([c.payload[-1] ^ 0xFF])) for c in convert(topic, cdr)]
    other = replay(recorded["path"], [changed], recording=rec)
    (rpm,) = other.commands.values()
    assert (rpm.differing, rpm.fields["payload"]) == (COMMANDS, COMMANDS) and not other.same
    _, old, new = rpm.first_values["payload"]
    assert old != new and old[:-3] == new[:-3], (old, new)  # hex: the last byte differs

    plain = replay(recorded["path"], [OfflineBridge(recorded["gen"], layout="dronecan")], recording=rec)
    framed = [t for t, d in plain.topics.items() if d.differing]
    assert framed and all(set(plain.topics[t].fields) <= {"header.frame_id"} for t in framed), \
        "\n".join(plain.lines())
    # the first differing values, old and new, with the count
    imu = plain.topics["/imu"]
    assert imu.fields["header.frame_id"] == imu.differing > 0
    assert imu.first_values["header.frame_id"][1:] == ("'sam1/imu_link'", "'imu_link'")
    assert any("header.frame_id" in line and "recorded 'sam1/imu_link', replayed 'imu_link'" in line
               for line in plain.lines())


def test_cyphal_service_transfers_are_recorded(tmp_path: Path) -> None:
    """Cyphal/UDP service transfers go to the destination node's multicast group: the recorder listens as every
    node that takes part and records a GetInfo request (bridge -> IMU) and its response (IMU -> bridge) with their
    kind and destination, beside the messages (raw pycyphal transports play the two nodes)."""
    from helpers.runtime_support import cyphal_udp_lock

    gen = generated_or_skip()
    imu = next(d.node_id for d in gen.tables().DEVICES if d.name == "imu")
    bridge_id = int(gen.tables().BRIDGE_NODE_ID)
    path = tmp_path / "services.mcap"
    with cyphal_udp_lock():
        asyncio.run(_service_scenario(gen, path, bridge_id, imu))

    from sam_runtime.recording.reading import read_recording
    from sam_runtime.recording.schemas import KIND_REQUEST, KIND_RESPONSE

    rec = read_recording(path)
    got = [(tr.port_id, tr.kind, tr.source_node_id, tr.destination_node_id, tr.payload, tr.data_type)
           for _, tr in rec.transfers() if tr.kind != 0]
    assert (430, KIND_REQUEST, bridge_id, imu, b"", "uavcan.node.GetInfo.1.0") in got
    assert (430, KIND_RESPONSE, imu, bridge_id, b"info", "uavcan.node.GetInfo.1.0") in got


async def _service_scenario(gen: Any, path: Path, bridge_id: int, imu: int) -> None:
    from pycyphal.transport import (
        InputSessionSpecifier,
        OutputSessionSpecifier,
        PayloadMetadata,
        Priority,
        ServiceDataSpecifier,
        Timestamp,
        Transfer,
    )

    from sam_runtime.cyphal_io.transport import make_transport
    from sam_runtime.recording.recorder import Recorder, RecorderConfig
    from sam_runtime.recording.schemas import KIND_REQUEST, KIND_RESPONSE

    recorder = Recorder(gen, RecorderConfig(path, layout="default", ros=False))
    await recorder.start()
    a = make_transport("udp", node_id=bridge_id, iface="127.0.0.1")
    b = make_transport("udp", node_id=imu, iface="127.0.0.1")
    try:
        loop = asyncio.get_running_loop()
        req = ServiceDataSpecifier(430, ServiceDataSpecifier.Role.REQUEST)
        res = ServiceDataSpecifier(430, ServiceDataSpecifier.Role.RESPONSE)
        server = b.get_input_session(InputSessionSpecifier(req, None), PayloadMetadata(1024))
        client = a.get_input_session(InputSessionSpecifier(res, imu), PayloadMetadata(1024))
        ask = a.get_output_session(OutputSessionSpecifier(req, imu), PayloadMetadata(1024))
        answer = b.get_output_session(OutputSessionSpecifier(res, bridge_id), PayloadMetadata(1024))

        def recorded() -> bool:  # a request and a response (the response's listener may lag the request's)
            recorder.tick()
            return recorder.counts.services[KIND_REQUEST] >= 1 and recorder.counts.services[KIND_RESPONSE] >= 1

        for tid in range(3):  # the recorder's sessions may join their groups a moment after start
            await ask.send(Transfer(Timestamp.now(), Priority.NOMINAL, tid, [memoryview(b"")]), loop.time() + 2)
            got = await server.receive(loop.time() + 10)
            assert got is not None, "the IMU's transport got no request"
            await answer.send(Transfer(Timestamp.now(), Priority.NOMINAL, tid, [memoryview(b"info")]),
                              loop.time() + 2)
            assert await client.receive(loop.time() + 10) is not None, "the bridge's transport got no response"
            if recorded():
                break
        await until(recorded, 10, "the request and the response in the recording")
    finally:
        for t in (a, b):
            t.close()
        await recorder.close()
