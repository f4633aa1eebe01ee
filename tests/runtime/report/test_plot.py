"""`sam-codegen plot`: a recorded run as one picture, from a synthetic dive written with mcap_ros2 (rosbag2's
conventions); missing topics give "not recorded" panels, a damaged file plots what is readable or is a clear error.
Issue 30: attitude and speed from the transforms, currents, command against feedback with every series visible,
device health and the bridge's drops, a distinct colour per state (a managed bridge's inactive span too)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

pytest.importorskip("mcap_ros2")
pytest.importorskip("matplotlib")

from helpers.mcap_fixture import write_dive

from sam_codegen.cli import main as codegen_main
from sam_runtime.report.motion_panels import attitude, estimated_speed, odom_points, speeds
from sam_runtime.report.plot import TOPICS, limits_from_params, node_states, plot_run, track
from sam_runtime.report.plot_support import Run, poses
from sam_runtime.report.recording import RecordingError, read_recording
from sam_runtime.report.status_panels import INACTIVE, device_states, drops, held_spans

REPO = Path(__file__).resolve().parents[3]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def dive(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_dive(tmp_path_factory.mktemp("dive") / "dive.mcap", chunk_size=4096)


def test_the_recording_reads_back_per_topic_in_time_order(dive: Path) -> None:
    rec = read_recording(dive)
    assert not rec.problems and rec.end_s == pytest.approx(60.0)
    assert rec.types["/abort"] == "sam_msgs/msg/Abort" and len(rec.get("/nav_goal")) == 3
    times = [t for t, _ in rec.get("/tf")]
    assert times == sorted(times) and times[0] == 0.0


def test_the_track_composes_world_odom_and_odom_base_link(dive: Path) -> None:
    frame, points = track(read_recording(dive))
    assert frame == "world"
    t, x, y, depth = points[-1]
    # The fixture's odom -> base_link is (x - 0.5, y, -depth) and world -> odom (0.5, 0, 0): world (20, 5) at the end.
    assert (t, x, y, depth) == pytest.approx((60.0, 20.0, 5.0, 0.0))
    assert max(p[3] for p in points) == pytest.approx(3.0)


def test_a_namespaced_run_reads_as_the_plain_one(dive: Path, tmp_path: Path) -> None:
    """Issue 30: a run as /sam1 of a spec with relative names recorded /sam1/pressure, sam1/odom, sam1/controller;
    the reader finds the spec's topics through the recorded namespace and the picture is the plain run's."""
    namespaced = write_dive(tmp_path / "sam1.mcap", chunk_size=4096, namespace="/sam1")
    plain, rec = read_recording(dive, TOPICS), read_recording(namespaced, TOPICS)
    assert (rec.names.namespace, rec.names.frame_prefix) == ("/sam1", "sam1/")
    assert "/sam1/pressure" in rec.series and "/pressure" not in rec.series
    assert len([t for t in TOPICS if plain.get(t)]) >= 14  # the dive's topics (of the feedback, the thrusters')
    for topic in TOPICS:
        assert len(rec.get(topic)) == len(plain.get(topic)), topic
    assert track(rec) == track(plain)
    assert node_states(rec) == node_states(plain) and "controller" in node_states(rec)
    svg = plot_run(namespaced, tmp_path / "sam1.svg").read_text()
    assert "not recorded" not in svg and "performance_monitor" in svg


def test_the_state_panels_read_devices_drops_and_an_inactive_bridge(dive: Path) -> None:
    """Issue 30: each device's level as the bridge reports it, the bridge's drop counters per mapping with their
    reasons, and a managed bridge's inactive span as a state of its own (its level is OK)."""
    rec = read_recording(dive, TOPICS)
    devices = device_states(rec)
    assert sorted(devices) == ["gps", "imu", "thruster_1"]
    assert {level for t, level in devices["gps"] if t < 10} == {3} and devices["gps"][-1][1] == 0
    assert {level for t, level in devices["thruster_1"] if 20 <= t < 30} == {2}
    bridge = node_states(rec)["uavcan_ros_bridge"]
    assert {level for t, level in bridge if 20 <= t < 25} == {INACTIVE}
    assert {level for t, level in bridge if not 20 <= t < 25} == {0}
    series, reasons, total = drops(rec)
    assert series["imu"][-1][1] == 100 and reasons["imu"] == {"lost": 100}
    assert reasons["thruster_1_rpm"] == {"inactive": 50} and series["pressure"][-1][1] == 0
    assert total[-1][1] == 150


def test_a_state_held_over_many_samples_is_one_span() -> None:
    """A long run's state rows hold thousands of samples (ten a second): one bar each made the picture take
    longer than the run's stop. A stretch of one level is one span; each sample holds until the next."""
    samples = [(t / 10, 0) for t in range(3000)] + [(300.0, 2), (300.5, 2), (301.0, 0)]
    assert held_spans(samples, 310.0) == [(0.0, 300.0, 0), (300.0, 301.0, 2), (301.0, 310.0, 0)]
    assert held_spans([], 5.0) == [] and held_spans([(1.0, 3)], 5.0) == [(1.0, 5.0, 3)]


def test_attitude_and_speed_come_from_the_transforms(dive: Path) -> None:
    """The fixture's base_link heads atan2(5, 20) in odom (world -> odom has no rotation) at 0.6 m/s east and
    0.15 m/s north until x reaches 20 m (33.3 s), descending at 0.2 m/s for the first 15 s."""
    rec = read_recording(dive, TOPICS)
    frame, found = poses(rec)
    points = [(t, *p.translation[:2], -p.translation[2]) for t, p in found]
    run = Run(rec, [], rec.end_s, {}, frame, points, [], found)
    rows = attitude(run)
    assert all(r[1] == pytest.approx(0.0, abs=1e-9) and r[2] == pytest.approx(0.0, abs=1e-9) for r in rows)
    assert rows[-1][3] == pytest.approx(math.degrees(math.atan2(5, 20)))
    fast = [(t, h, v) for t, h, v in speeds(odom_points(rec)) if 2 < t < 14]
    assert fast and all(h == pytest.approx(math.hypot(0.6, 0.15), rel=1e-3) for _, h, _ in fast)
    assert all(v == pytest.approx(0.2, rel=1e-3) for _, _, v in fast)
    assert all(h == pytest.approx(0.0, abs=1e-9) for t, h, _ in speeds(odom_points(rec)) if t > 35)
    assert estimated_speed(rec)[0] == (0.0, 0.6)


def test_equal_series_each_keep_a_visible_style() -> None:
    """Both thrusters commanded alike and reporting alike: no two lines of a panel share a style, and each device's
    feedback has markers of its own shape."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sam_runtime.report.plot_support import lines
    from sam_runtime.report.recording import Recording

    msg = type("M", (), {"a": 1.0, "b": 1.0})()
    rec = Recording(Path("x.mcap"), series={"/cmd": [(0.0, msg), (1.0, msg)], "/fb1": [(0.0, msg), (1.0, msg)],
                                            "/fb2": [(0.0, msg), (1.0, msg)]})
    fig, ax = plt.subplots()
    try:
        assert lines(ax, rec, "/cmd", [("a", "1"), ("b", "2")])
        lines(ax, rec, "/fb1", [("a", "1 feedback")], feedback=True)
        lines(ax, rec, "/fb2", [("a", "2 feedback")], feedback=True)
        drawn = ax.get_lines()
        styles = {(str(line.get_linestyle()), str(line.get_dashes() if hasattr(line, "get_dashes") else ""),
                   line.get_linewidth(), line.get_marker()) for line in drawn}
        assert len(drawn) == 4 and len(styles) == 4
        assert drawn[2].get_marker() != drawn[3].get_marker()
        assert not lines(ax, rec, "/missing", [("a", "x")])
    finally:
        plt.close(fig)


def test_limits_come_from_the_generated_parameters() -> None:
    limits = limits_from_params(REPO / "generated" / "params" / "sam.params.yaml")
    assert limits == {"safe_depth": 50.0, "critical_depth": 60.0, "safe_altitude": 5.0, "critical_altitude": 2.0}


def test_a_node_own_value_overrides_the_wildcard(tmp_path: Path) -> None:
    params = tmp_path / "p.yaml"
    params.write_text("/**:\n  ros__parameters: {safe_depth: 10.0}\n"
                      "performance_monitor:\n  ros__parameters: {safe_depth: 12, critical_depth: 20.0}\n")
    assert limits_from_params(params) == {"safe_depth": 12.0, "critical_depth": 20.0}


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_plot_writes_the_picture(dive: Path, tmp_path: Path, suffix: str) -> None:
    out = plot_run(dive, tmp_path / f"run{suffix}", limits={"safe_depth": 2.5, "critical_depth": 60.0})
    data = out.read_bytes()
    assert data.startswith(PNG_MAGIC) if suffix == ".png" else b"<svg" in data[:2000]
    if suffix == ".svg":  # the panels and what they say are in the picture
        text = data.decode()
        for words in ("safe_depth 2.5 m", "beyond the plotted range: critical_depth 60 m",
                      "battery below min_battery_percent", "depth [m]", "speed [rpm]", "charge [%]",
                      "performance_monitor", "goal 1: depth 3 m, from 0 s", "goal 2: surface, from 38 s",
                      # issue 30: attitude, speed, currents, command against feedback, device health and drops
                      "Attitude of base_link in world", "yaw [deg]", "speed [m/s]", "dead reckoning estimate",
                      "current [A]", "battery (negative: discharging)", "thruster 2 feedback",
                      "Device health", "thruster_1", "imu: 100 (lost 100)", "thruster_1_rpm: 50 (inactive 50)",
                      "bridge inactive (lifecycle)", "abort active", "STALE"):
            assert words in text, words
        assert "not recorded" not in text
        assert "goal 3" not in text  # a goal sent again is one goal


def test_missing_topics_are_not_recorded_panels(tmp_path: Path) -> None:
    mcap = write_dive(tmp_path / "few.mcap", skip=("/altitude", "/battery_state", "/thruster_rpms", "/diagnostics"))
    svg = plot_run(mcap, tmp_path / "few.svg").read_text()
    # altitude, battery, RPMs, and from /diagnostics the node states (the abort is there), device health and drops
    assert svg.count("not recorded") == 6


def test_a_cut_recording_plots_what_was_read(tmp_path: Path) -> None:
    whole = write_dive(tmp_path / "whole.mcap", chunk_size=4096).read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole[: len(whole) // 2])  # a run killed mid-recording: no summary, a torn last chunk
    rec = read_recording(cut)
    assert rec.problems and 5 < rec.end_s < 55
    svg = plot_run(cut, tmp_path / "cut.svg").read_text()
    assert "cut short or damaged" in svg


def test_not_an_mcap_or_nothing_readable_is_a_clear_error(tmp_path: Path, dive: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.mcap"
    bad.write_text("not a recording")
    with pytest.raises(RecordingError, match="not an MCAP file"):
        read_recording(bad)
    stub = tmp_path / "stub.mcap"
    stub.write_bytes(dive.read_bytes()[:100])
    with pytest.raises(RecordingError, match="no message"):
        read_recording(stub)
    assert codegen_main(["plot", str(bad), "-o", str(tmp_path / "x.png")]) == 1
    assert "not an MCAP file" in capsys.readouterr().err and not (tmp_path / "x.png").exists()


def test_the_command_writes_beside_the_recording_with_the_projects_limits(dive: Path, tmp_path: Path,
                                                                          capsys: pytest.CaptureFixture[str]) -> None:
    mcap = tmp_path / "run.mcap"
    mcap.write_bytes(dive.read_bytes())
    assert codegen_main(["plot", str(mcap), "--params-file", str(REPO / "generated/params/sam.params.yaml")]) == 0
    assert (tmp_path / "run.png").read_bytes().startswith(PNG_MAGIC)
    assert "limits from" in capsys.readouterr().out
    assert codegen_main(["plot", str(mcap), "-o", str(tmp_path / "run.pdf")]) == 1


def test_a_recorded_run_ends_with_its_picture_beside_the_recording(dive: Path, tmp_path: Path) -> None:
    from sam_runtime.main_job.job import report_picture

    said: list[str] = []
    mcap = tmp_path / "run.mcap"
    mcap.write_bytes(dive.read_bytes())
    out = report_picture(mcap, REPO / "generated", said.append)
    assert out == tmp_path / "run.png" and out.read_bytes().startswith(PNG_MAGIC) and said == [f"report: {out}"]
    bad = tmp_path / "bad.mcap"
    bad.write_text("not a recording")
    said.clear()
    assert report_picture(bad, REPO / "generated", said.append) is None  # said, never raised: the run is over
    assert said and said[0].startswith(f"sam-run: no report picture of {bad}: RecordingError")
