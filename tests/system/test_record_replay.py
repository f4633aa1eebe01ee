"""Keep and replay what the vehicle did (issue 18): the main job with ``--record`` and a standalone recorder beside
it, then the readers, the offline decoding of the raw bus and the replays, all on one recorded demo run.

No verdict rests on a sleep: the run is stopped once its recording holds every bridged topic (read from the file as
it grows, chunk by chunk), the standalone recorder is killed once its file holds whole chunks."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("pycyphal")
pytest.importorskip("rclpy")
pytest.importorskip("mcap")
pytest.importorskip("mcap_ros2")

from helpers.runtime_support import (
    Proc,
    child_env,
    cyphal_udp_lock,
    domain_id,
    generated_or_skip,
    poll_until,
    ros_prefix_for,
    runtime_cmd,
)
from helpers.user_project import start_time, wait_gone
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from sam_runtime.main_job.job import CHILD_KILL_TIMEOUT_S, CHILD_STOP_TIMEOUT_S
from sam_runtime.recording.reading import read_recording, rosbag2_folder
from sam_runtime.recording.schemas import CYPHAL_TOPIC, TRANSFER_TYPE

pytestmark = [pytest.mark.ros, pytest.mark.slow]

START_TIMEOUT_S = 240.0  # four Python processes starting on a loaded 2-core machine, then discovery
STOP_BOUND_S = CHILD_STOP_TIMEOUT_S + CHILD_KILL_TIMEOUT_S + 20.0
PICTURE_BOUND_S = 300.0  # the report picture of a few minutes' recording, on a loaded 2-core machine
MIN_PER_TOPIC = 10  # messages of every bridged topic before the run is stopped (the slowest is 1 Hz)


@dataclass
class Recorded:
    run: Path  # the main job's recording (stopped cleanly)
    cut: Path  # the standalone recorder's, SIGKILLed
    cut_seen: int  # messages its file held before the kill
    gen: Any
    env: dict[str, str]
    tmp: Path
    run_output: str


def _bridged(tables: Any) -> set[str]:
    return {m.topic.name for m in tables.MAPPINGS if m.direction == "uavcan_to_ros"}


def _counts(path: Path) -> dict[str, int]:
    if not path.exists():
        return {}
    out: dict[str, int] = {}
    for m in read_recording(path).messages:
        out[m.topic] = out.get(m.topic, 0) + 1
    return out


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Recorded]:
    gen = generated_or_skip()
    prefix = ros_prefix_for(gen)
    tmp = tmp_path_factory.mktemp("record")
    env = child_env(prefix, domain_id(61))
    run_path, cut_path, logs = tmp / "run.mcap", tmp / "cut.mcap", tmp / "logs"
    bridged = _bridged(gen.tables())
    out_path = tmp / "run.out"
    with cyphal_udp_lock(), open(out_path, "w") as out:
        run = subprocess.Popen(
            runtime_cmd("run", "--no-build", "--generated", str(gen.root), "--plain", "--duration", "900",
                        "--record", str(run_path), "--log-dir", str(logs), "--ros-prefix", str(prefix)),
            env=env, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
        standalone: Proc | None = None
        try:
            def output() -> str:
                return out_path.read_text(errors="replace")

            def full() -> bool:
                assert run.poll() is None, f"the main job ended early ({run.returncode}):\n{output()[-3000:]}"
                counts = _counts(run_path)
                return all(counts.get(t, 0) >= MIN_PER_TOPIC for t in bridged) and counts.get(CYPHAL_TOPIC, 0) > 0

            poll_until(full, START_TIMEOUT_S, "every bridged topic in the main job's recording", interval=0.5)
            standalone = Proc("recorder", runtime_cmd("record", str(cut_path), "--generated", str(gen.root)), env,
                              tmp)
            standalone.wait_line("READY recorder", 120)
            def chunks() -> int:  # whole chunks of both sides in the file
                counts = _counts(cut_path)
                return sum(counts.values()) if counts.get("/imu", 0) >= 50 and counts.get(CYPHAL_TOPIC, 0) else 0

            cut_seen = poll_until(chunks, 120, "whole chunks in the standalone recorder's file", interval=0.2)
            standalone.proc.send_signal(signal.SIGKILL)
            assert standalone.proc.wait(timeout=10) == -signal.SIGKILL

            header = poll_until(lambda: [ln for ln in output().splitlines() if "recorder pid" in ln], 30,
                                "the main job's header")[-1]
            recorder_pid = int(header.split("recorder pid ")[1].split()[0])
            started = start_time(recorder_pid) or 0
            os.kill(run.pid, signal.SIGTERM)  # as Ctrl-C: a clean stop of every child
            # The children's stop is bounded; the report picture drawn after it takes time in proportion to the
            # recording (minutes of it here on a loaded machine), so it has a bound of its own.
            poll_until(lambda: any(ln.startswith("logs: ") for ln in output().splitlines()), STOP_BOUND_S,
                       "the main job's children to stop (its 'logs:' line)", interval=0.2)
            assert run.wait(timeout=PICTURE_BOUND_S) == 0, output()[-3000:]
            assert f"report: {run_path.with_suffix('.png')}" in output(), output()[-3000:]
            assert not wait_gone({recorder_pid: started}, 10.0), "the recorder outlived the main job"
            text = output()
        finally:
            if standalone is not None:
                standalone.stop(signal.SIGKILL)
            if run.poll() is None:
                os.killpg(run.pid, signal.SIGKILL)
                run.wait(timeout=10)
    yield Recorded(run_path, cut_path, cut_seen, gen, env, tmp, text)


def _ros_channels(path: Path) -> dict[str, str]:
    rec = read_recording(path)
    return {t: s for t, s in rec.topics().items() if s != TRANSFER_TYPE}


def test_the_recording_opens_with_the_mcap_library_and_rosbags(recorded: Recorded) -> None:
    tables = recorded.gen.tables()
    channels = _ros_channels(recorded.run)
    assert {t.name: t.ros_type for t in tables.TOPICS}.items() <= channels.items()  # every spec topic, its type
    assert channels["/diagnostics"] == "diagnostic_msgs/msg/DiagnosticArray"
    # the mcap library: a complete file with a summary; every ROS message decodes from its stored schema
    with open(recorded.run, "rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
        assert summary is not None and summary.statistics.message_count > 1000
        decoded: dict[str, int] = {}
        for _schema, channel, _msg, obj in reader.iter_decoded_messages(
                topics=[t for t in channels if t != CYPHAL_TOPIC]):
            decoded[channel.topic] = decoded.get(channel.topic, 0) + 1
            if channel.topic == "/imu":
                assert obj.header.frame_id == "imu_link"
    assert all(decoded.get(t, 0) >= MIN_PER_TOPIC for t in _bridged(tables)), decoded
    # rosbags: its rosbag2 reader on the folder layout it needs; types registered from the stored definitions
    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(rosbag2_folder(recorded.run, recorded.tmp / "bag")) as bag:
        types = {}
        for c in bag.connections:
            types.update(get_types_from_msg(c.msgdef.data, c.msgtype))
        store.register(types)
        counts = {c.topic: c.msgcount for c in bag.connections}
        assert all(counts[t] >= MIN_PER_TOPIC for t in _bridged(tables))
        n = 0
        for conn, _t, raw in bag.messages():
            store.deserialize_cdr(raw, conn.msgtype)
            n += 1
        assert n == sum(counts.values())


_DECODE = textwrap.dedent("""\
    # Decode every recorded Cyphal transfer with nothing but the file: its DSDL attachments compiled here.
    import importlib, json, sys, tempfile
    from pathlib import Path
    from mcap.reader import make_reader
    import pycyphal.dsdl
    from sam_runtime.recording.schemas import decode_transfer, CYPHAL_TOPIC
    path, out = Path(sys.argv[1]), Path(tempfile.mkdtemp())
    with open(path, "rb") as fh:
        reader = make_reader(fh)
        atts = {a.name: a.data for a in reader.iter_attachments()}
        msgs = [m.data for _, _, m in reader.iter_messages(topics=[CYPHAL_TOPIC])]
    src = out / "src"
    for name, data in atts.items():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_bytes(data)
    roots = sorted(p for p in (src / "dsdl").iterdir())
    for root in roots:
        pycyphal.dsdl.compile(root, [r for r in roots if r != root], out / "py")
    sys.path.insert(0, str(out / "py"))
    import pycyphal.dsdl as d
    decoded, failed, imu = 0, 0, {}
    for raw in msgs:
        t = decode_transfer(raw)
        *ns, short, major, minor = t.data_type.split(".")
        cls = getattr(importlib.import_module(".".join(ns)), f"{short}_{major}_{minor}")
        obj = d.deserialize(cls, [memoryview(t.payload)])
        if obj is None:
            failed += 1
            continue
        decoded += 1
        if short == "RawIMU":
            imu[str(obj.timestamp.microsecond)] = [float(x) for x in obj.rate_gyro_latest]
    print(json.dumps({"decoded": decoded, "failed": failed, "imu": imu}))
    """)


def test_the_raw_bus_decodes_offline_from_the_file_alone(recorded: Recorded) -> None:
    env = {k: v for k, v in recorded.env.items() if k not in ("SAM_GENERATED_DIR", "CYPHAL_PATH")}
    proc = subprocess.run([sys.executable, "-c", _DECODE, str(recorded.run)], capture_output=True, text=True,
                          env=env, timeout=300, cwd=recorded.tmp)
    assert proc.returncode == 0, proc.stderr[-3000:]
    got = json.loads(proc.stdout.splitlines()[-1])
    rec = read_recording(recorded.run)
    assert got["failed"] == 0 and got["decoded"] == len(rec.transfers())
    # the ROS side agrees: /imu's stamp is the RawIMU's timestamp, its angular velocity the float16 rate gyro
    store = get_typestore(Stores.ROS2_JAZZY)
    compared = 0
    for m in rec.by_topic()["/imu"]:
        imu = store.deserialize_cdr(m.data, "sensor_msgs/msg/Imu")
        key = str((imu.header.stamp.sec * 1_000_000_000 + imu.header.stamp.nanosec) // 1000)
        if key in got["imu"]:
            av = imu.angular_velocity
            assert [av.x, av.y, av.z] == got["imu"][key]
            compared += 1
    assert compared >= MIN_PER_TOPIC


def _replay(recorded: Recorded, *args: str) -> tuple[int, dict, str]:
    report = recorded.tmp / f"report{len(args)}.json"
    proc = subprocess.run(runtime_cmd("replay", str(recorded.run), "--generated", str(recorded.gen.root),
                                      "--report", str(report), *args),
                          capture_output=True, text=True, env=recorded.env, timeout=300)
    assert proc.returncode in (0, 3), proc.stdout + proc.stderr
    return proc.returncode, json.loads(report.read_text()), proc.stdout


def test_replay_through_the_same_spec_reproduces_the_recorded_topics(recorded: Recorded) -> None:
    out = recorded.tmp / "replayed.mcap"
    code, report, text = _replay(recorded, "--out", str(out))
    assert code == 0 and report["same"], text
    bridged = _bridged(recorded.gen.tables())
    assert set(report["topics"]) == bridged
    for topic, d in report["topics"].items():
        # (a message the recorder lost under load, counted from the publisher's sequence numbers, is replayed: extra)
        assert d["differing"] == d["missing"] == 0 and d["extra"] == d["lost_by_recorder"], (topic, d)
        assert d["identical"] + d["receive_time_only"] == d["recorded"] >= MIN_PER_TOPIC, (topic, d)
        # the only fields allowed to differ: the stamp the bridge takes from its own clock
        assert set(d["receive_time_fields"]) <= {"header.stamp.sec", "header.stamp.nanosec"}, (topic, d)
    # the other direction (issue 30): the controller's commands, converted again, are the bridge's transfers on
    # every command port (a transfer the listener lost under load is a counted gap, never a differing payload)
    assert len(report["commands"]) == 6, text
    for port, d in report["commands"].items():
        assert d["differing"] == 0 and d["identical"] >= 0.9 * d["replayed"] - d["outside_ros_recording"], (port, d)
    # device-stamped: the same bytes, but for what the IMU sent before its clock followed the bridge's time-sync
    # master (stamp 0, unknown: the bridge's receive time), at most its first seconds (100 Hz) after the bridge started
    imu = report["topics"]["/imu"]
    assert imu["recorded"] - 300 <= imu["identical"] <= imu["recorded"], imu
    new = read_recording(out)
    assert new.complete and set(new.topics()) >= bridged | {CYPHAL_TOPIC}
    assert len(new.transfers()) == report["transfers"]
    # the replayed file holds the recorded /imu CDR, byte for byte, within the bus's longer span
    # (after the first ones the IMU stamped 0 before it synchronised: those carry a receive time, which differs)
    unsynchronised = imu["recorded"] - imu["identical"]
    recorded_imu = [m.data for m in read_recording(recorded.run).by_topic()["/imu"]][unsynchronised:]
    replayed_imu = [m.data for m in new.by_topic()["/imu"]]
    assert recorded_imu, imu
    k = replayed_imu.index(recorded_imu[0])
    assert replayed_imu[k:k + len(recorded_imu)] == recorded_imu


def test_replay_through_a_changed_spec_shows_the_change(recorded: Recorded) -> None:
    spec = Path(__file__).resolve().parents[2] / "spec" / "interfaces.yaml"
    text = spec.read_text()
    old = 'magnetic_field.x: {from: "magnetic_field_ga[0]", scale: 1.0e-4}'
    assert old in text
    changed = recorded.tmp / "changed" / "spec" / "interfaces.yaml"
    changed.parent.mkdir(parents=True)
    changed.write_text(text.replace(old, old.replace("1.0e-4", "2.0e-4"), 1))  # the Cyphal mapping only
    code, report, out = _replay(recorded, "--spec", str(changed))
    assert code == 3 and not report["same"], out
    mag = report["topics"]["/magnetic_field"]
    assert mag["differing"] == mag["recorded"] >= MIN_PER_TOPIC
    assert set(mag["differing_fields"]) == {"magnetic_field.x"}
    assert all(d["differing"] == 0 for t, d in report["topics"].items() if t != "/magnetic_field")
    assert "magnetic_field.x" in out


def test_a_recorder_killed_mid_run_leaves_a_readable_file(recorded: Recorded) -> None:
    rec = read_recording(recorded.cut)
    assert not rec.complete
    assert len(rec.messages) >= recorded.cut_seen  # at least every message seen before the kill
    assert rec.transfers() and rec.by_topic().get("/imu")
    # the mcap library's streaming reader reads the same messages, then meets the cut
    decode = {s.id: DecoderFactory().decoder_for("cdr", s) for s in rec.schemas.values()}
    from mcap.records import Message
    from mcap.stream_reader import StreamReader

    n = 0
    with open(recorded.cut, "rb") as fh, pytest.raises(Exception):  # noqa: B017  (its error at the cut)
        for r in StreamReader(fh).records:
            if isinstance(r, Message):
                decode[rec.channels[r.channel_id].schema_id](r.data)
                n += 1
    assert n == len(rec.messages)
    with Reader(rosbag2_folder(recorded.cut, recorded.tmp / "cutbag")) as bag:
        assert sum(1 for _ in bag.messages()) == len(rec.messages)


def test_an_unwritable_path_is_a_clear_error_before_anything_starts(recorded: Recorded, tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    run = subprocess.run(runtime_cmd("run", "--no-build", "--generated", str(recorded.gen.root),
                                     "--duration", "5", "--record", "/proc/sys/x.mcap", "--log-dir", str(logs)),
                         capture_output=True, text=True, env=recorded.env, timeout=120)
    assert run.returncode == 1
    lines = run.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sam-run: cannot record to /proc/sys/x.mcap: /proc/sys is not "
                                                   "writable"), run.stdout
    assert "Traceback" not in run.stdout + run.stderr
    assert not logs.exists()  # no child was started
    rec = subprocess.run(runtime_cmd("record", str(tmp_path / "missing" / "x.mcap"), "--generated",
                                     str(recorded.gen.root)),
                         capture_output=True, text=True, env=recorded.env, timeout=120)
    assert rec.returncode == 1 and "Traceback" not in rec.stderr
    assert rec.stderr.strip() == f"sam-record: cannot record to {tmp_path / 'missing' / 'x.mcap'}: the folder " \
                                 f"{tmp_path / 'missing'} does not exist"
