"""Missions (sam_runtime.nav.mission): the file format, its refusals (every problem at once, naming the goal
and the key) and the arrival rule the mission node advances on. Pure: no ROS."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from sam_runtime.nav.mission import (
    DEMO_MISSION,
    MissionError,
    MissionGoal,
    arrived,
    load_mission,
    parse_mission,
    single_goal,
)


def test_a_mission_file(tmp_path: Path) -> None:
    path = tmp_path / "m.yaml"
    path.write_text("# comment\ngoals:\n  - {x: 15, y: 0, z: -3}\n  - {x: 30, y: 15, z: 5, tolerance: 3}\n"
                    "  - {heading: 1.5, z: -4, duration: 30}\n  - {heading_deg: -90, z: 0}\n")
    goals = load_mission(path)
    assert goals == (MissionGoal("pose", -3.0, 15.0, 0.0), MissionGoal("pose", 5.0, 30.0, 15.0, tolerance=3.0),
                     MissionGoal("heading", -4.0, heading=1.5, duration=30.0),
                     MissionGoal("heading", 0.0, heading=-math.pi / 2))
    assert [g.describe() for g in goals] == [
        "pose (15.0, 0.0) at depth 3.0 m", "pose (30.0, 15.0) at altitude 5.0 m", "heading 86 deg at depth 4.0 m "
        "for 30 s", "heading -90 deg at the surface"]
    assert load_mission(path) == parse_mission([{"x": 15, "y": 0, "z": -3}, {"x": 30, "y": 15, "z": 5,
                                                                               "tolerance": 3},
                                                {"heading": 1.5, "z": -4, "duration": 30},
                                                {"heading_deg": -90, "z": 0}])


@pytest.mark.parametrize(("data", "message"), [
    ([], "m: expected a non-empty list of goals (or a mapping with 'goals:'), got []"),
    ({"goal": []}, "m: unknown key(s) ['goal'] (expected 'goals')"),
    ("dive", "m: expected a non-empty list of goals (or a mapping with 'goals:'), got 'dive'"),
    ([{"x": 1, "y": 2}], "m: goal 1: missing ['z']"),
    ([{"x": True, "y": 2, "z": -1}], "m: goal 1.x: expected a finite number, got True"),
    ([{"x": 1, "y": 2, "z": -1, "tolerance": 0}], "m: goal 1.tolerance: must be > 0, got 0"),
    ([{"heading_deg": 10, "heading": 0.1, "z": -1}], "m: goal 1: give heading_deg or heading (radians), not both"),
    ([{"x": 1, "y": 2, "z": -1, "frame": "map"}],
     "m: goal 1: unknown key(s) ['frame'] for a pose goal (allowed: ['depth_tolerance', 'tolerance', 'x', 'y', 'z'])"),
    ([{"heading_deg": 10, "z": -1, "duration": -5}, {"x": "a", "y": 1, "z": math.inf}],
     "m: goal 1.duration: must be > 0, got -5\nm: goal 2.x: expected a finite number, got 'a'\n"
     "m: goal 2.z: expected a finite number, got inf"),
], ids=["empty", "unknown-top-key", "not-a-list", "missing-z", "bool", "zero-tolerance", "two-headings",
        "unknown-key", "several"])
def test_refusals_name_the_goal_and_key(data: object, message: str) -> None:
    with pytest.raises(MissionError) as ex:
        parse_mission(data, "m")
    assert str(ex.value) == message


def test_unreadable_and_invalid_files(tmp_path: Path) -> None:
    with pytest.raises(MissionError, match=r"missing\.yaml: cannot read: No such file or directory"):
        load_mission(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("goals: [ {x: 1\n")
    with pytest.raises(MissionError, match=r"bad\.yaml: not valid YAML"):
        load_mission(bad)
    tagged = tmp_path / "tagged.yaml"
    tagged.write_text("goals: !!python/object:os.system {}\n")  # the safe loader: no tags, never evaluated
    with pytest.raises(MissionError, match="not valid YAML"):
        load_mission(tagged)


def test_the_goal_option() -> None:
    assert single_goal(10, -5, 4) == (MissionGoal("pose", 4.0, 10.0, -5.0),)
    with pytest.raises(MissionError, match=r"--goal: goal 1.z: expected a finite number, got nan"):
        single_goal(1, 2, math.nan)


def test_arrival() -> None:
    depth_goal = MissionGoal("pose", -3.0, 10.0, 0.0, tolerance=2.0, depth_tolerance=0.5)
    assert arrived(depth_goal, 9.0, 1.0, 3.4, 0.0)
    assert not arrived(depth_goal, 9.0, 1.0, 2.4, 0.0)  # there, but not yet at depth
    assert not arrived(depth_goal, 7.9, 0.0, 3.0, 100.0)  # at depth, 2.1 m away
    surface = MissionGoal("pose", 0.0, 0.0, 0.0, depth_tolerance=0.3)
    assert arrived(surface, 0.0, 0.0, 0.25, 0.0) and not arrived(surface, 0.0, 0.0, 0.35, 0.0)
    altitude = MissionGoal("pose", 4.0, 0.0, 0.0)  # the depth of an altitude goal is not known here
    assert arrived(altitude, 1.0, 0.0, 17.0, 0.0)
    assert not arrived(MissionGoal("heading", -2.0, heading=0.0), 0, 0, 2, 1e6)  # held for ever
    assert arrived(MissionGoal("heading", -2.0, heading=0.0, duration=30.0), 0, 0, 2, 30.0)


def test_the_demo_mission_dives_goes_and_comes_back_up() -> None:
    dive, go, up = DEMO_MISSION
    assert dive.kind == go.kind == up.kind == "pose"
    assert dive.z < 0 and go.z < 0 and up.z == 0.0
    assert (go.x, go.y) == (up.x, up.y) and math.hypot(go.x - dive.x, go.y - dive.y) > 10.0
