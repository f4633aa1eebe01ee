"""Missions: a sequence of goals for the motion planner, each advanced on arrival. Pure (no ROS).

A mission file (YAML) is a list of goals, or a mapping with ``goals:``; every goal is in world (ENU metres
around the first GPS fix) with the document's z convention (z < 0 a depth, z > 0 an altitude above the sea floor,
0 the surface)::

    goals:
      - {x: 15, y: 0, z: -3}                     # a pose goal: reached within 2 m horizontally and 1 m of depth
      - {x: 30, y: 15, z: -3, tolerance: 3.0, depth_tolerance: 0.5}
      - {heading_deg: 90, z: -4, duration: 30}   # a heading goal: held for 30 s, then the next goal
      - {x: 30, y: 15, z: 0}                     # back up to the surface

A pose goal is reached when world -> base_link is within ``tolerance`` metres of it horizontally and (for a depth
or surface goal) within ``depth_tolerance`` of its depth; an altitude goal is judged horizontally only. A heading
goal never arrives: it is held for ``duration`` seconds (without one, for ever). After the last goal the mission is
complete and its goal stays (the vehicle holds it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["DEMO_MISSION", "MissionError", "MissionGoal", "arrived", "load_mission", "parse_mission", "single_goal"]

DEFAULT_TOLERANCE_M = 2.0
DEFAULT_DEPTH_TOLERANCE_M = 1.0
_POSE_KEYS = {"x", "y", "z", "tolerance", "depth_tolerance"}
_HEADING_KEYS = {"heading_deg", "heading", "z", "duration"}


class MissionError(ValueError):
    """A mission file or goal that cannot be flown: every problem, one per line."""


@dataclass(frozen=True)
class MissionGoal:
    kind: str  # "pose" or "heading"
    z: float  # the document's convention
    x: float = math.nan
    y: float = math.nan
    heading: float = math.nan  # [rad], ENU yaw (counter-clockwise from east)
    tolerance: float = DEFAULT_TOLERANCE_M  # [m] horizontal (pose goals)
    depth_tolerance: float = DEFAULT_DEPTH_TOLERANCE_M  # [m] (pose goals at a depth or the surface)
    duration: float | None = None  # [s] how long a heading goal is held (None: for ever)

    def describe(self) -> str:
        """
        >>> MissionGoal("pose", -3.0, 15.0, 0.0).describe()
        'pose (15.0, 0.0) at depth 3.0 m'
        >>> MissionGoal("heading", 4.0, heading=math.pi / 2, duration=30.0).describe()
        'heading 90 deg at altitude 4.0 m for 30 s'
        """
        where = "at the surface" if self.z == 0 else (f"at depth {-self.z:.1f} m" if self.z < 0
                                                      else f"at altitude {self.z:.1f} m")
        if self.kind == "pose":
            return f"pose ({self.x:.1f}, {self.y:.1f}) {where}"
        held = "" if self.duration is None else f" for {self.duration:g} s"
        return f"heading {math.degrees(self.heading):.0f} deg {where}{held}"


# Dive to a depth, go to a point, come back up (the main job's default): about 40 m and a minute at 1.25 m/s.
DEMO_MISSION: tuple[MissionGoal, ...] = (
    MissionGoal("pose", -3.0, 15.0, 0.0),
    MissionGoal("pose", -3.0, 30.0, 15.0),
    MissionGoal("pose", 0.0, 30.0, 15.0, depth_tolerance=0.3),
)


def _number(value: Any, where: str, problems: list[str], *, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        problems.append(f"{where}: expected a finite number, got {value!r}")
        return math.nan
    if positive and value <= 0:
        problems.append(f"{where}: must be > 0, got {value!r}")
    return float(value)


def _goal(item: Any, where: str, problems: list[str]) -> MissionGoal | None:
    if not isinstance(item, dict):
        problems.append(f"{where}: expected a mapping such as {{x: 10, y: 0, z: -3}}, got {item!r}")
        return None
    keys = set(item)
    heading = bool(keys & {"heading_deg", "heading"})
    allowed = _HEADING_KEYS if heading else _POSE_KEYS
    unknown = sorted(str(k) for k in keys - allowed)
    if unknown:
        problems.append(f"{where}: unknown key(s) {unknown} for a {'heading' if heading else 'pose'} goal "
                        f"(allowed: {sorted(allowed)})")
    missing = sorted(k for k in ({"z"} if heading else {"x", "y", "z"}) if k not in item)
    if heading and {"heading_deg", "heading"} <= keys:
        problems.append(f"{where}: give heading_deg or heading (radians), not both")
    if missing:
        problems.append(f"{where}: missing {missing}")
        return None
    n = len(problems)
    if heading:
        h = (math.radians(_number(item["heading_deg"], f"{where}.heading_deg", problems)) if "heading_deg" in item
             else _number(item["heading"], f"{where}.heading", problems))
        z = _number(item["z"], f"{where}.z", problems)
        duration = (_number(item["duration"], f"{where}.duration", problems, positive=True) if "duration" in item
                    else None)
        goal = MissionGoal("heading", z, heading=h, duration=duration)
    else:
        x, y = _number(item["x"], f"{where}.x", problems), _number(item["y"], f"{where}.y", problems)
        goal = MissionGoal(
            "pose", _number(item["z"], f"{where}.z", problems), x, y,
            tolerance=_number(item.get("tolerance", DEFAULT_TOLERANCE_M), f"{where}.tolerance", problems,
                              positive=True),
            depth_tolerance=_number(item.get("depth_tolerance", DEFAULT_DEPTH_TOLERANCE_M),
                                    f"{where}.depth_tolerance", problems, positive=True))
    return goal if len(problems) == n else None


def parse_mission(data: Any, source: str = "mission") -> tuple[MissionGoal, ...]:
    """The goals of a loaded mission document; MissionError lists every problem.

    >>> parse_mission({"goals": [{"x": 10, "y": 0, "z": -2}, {"heading_deg": 90, "z": -3, "duration": 5}]})[1]
    MissionGoal(kind='heading', z=-3.0, x=nan, y=nan, heading=1.5707963267948966, tolerance=2.0, \
depth_tolerance=1.0, duration=5.0)
    >>> parse_mission([{"x": 1, "z": "deep"}])
    Traceback (most recent call last):
    ...
    sam_runtime.nav.mission.MissionError: mission: goal 1: missing ['y']
    """
    items = data.get("goals") if isinstance(data, dict) else data
    if isinstance(data, dict) and set(data) - {"goals"}:
        raise MissionError(f"{source}: unknown key(s) {sorted(map(str, set(data) - {'goals'}))} (expected 'goals')")
    if not isinstance(items, list) or not items:
        raise MissionError(f"{source}: expected a non-empty list of goals (or a mapping with 'goals:'), got "
                           f"{items!r}")
    problems: list[str] = []
    goals = [_goal(item, f"goal {i}", problems) for i, item in enumerate(items, 1)]
    if problems:
        raise MissionError("\n".join(f"{source}: {p}" for p in problems))
    return tuple(g for g in goals if g is not None)


def load_mission(path: Path) -> tuple[MissionGoal, ...]:
    """A mission file (YAML, read with the safe loader)."""
    import yaml

    try:
        data = yaml.safe_load(Path(path).read_text())
    except OSError as ex:
        raise MissionError(f"{path}: cannot read: {ex.strerror or ex}") from None
    except yaml.YAMLError as ex:
        raise MissionError(f"{path}: not valid YAML: {ex}") from None
    return parse_mission(data, str(path))


def single_goal(x: float, y: float, z: float) -> tuple[MissionGoal, ...]:
    """``--goal X Y Z``: one pose goal.

    >>> single_goal(10, 0, -2)[0].describe()
    'pose (10.0, 0.0) at depth 2.0 m'
    """
    return parse_mission([{"x": x, "y": y, "z": z}], "--goal")


def arrived(goal: MissionGoal, x: float, y: float, depth: float, held_s: float) -> bool:
    """Whether the vehicle at (x, y) [world] and ``depth`` has reached ``goal`` (current for ``held_s`` seconds).

    >>> g = MissionGoal("pose", -3.0, 10.0, 0.0)
    >>> arrived(g, 8.5, 0.5, 2.5, 0.0), arrived(g, 7.0, 0.0, 3.0, 0.0), arrived(g, 10.0, 0.0, 1.5, 0.0)
    (True, False, False)
    >>> arrived(MissionGoal("heading", -3.0, heading=0.0, duration=10.0), 0, 0, 3, 9.9)
    False
    """
    if goal.kind == "heading":
        return goal.duration is not None and held_s >= goal.duration
    if math.hypot(goal.x - x, goal.y - y) > goal.tolerance:
        return False
    return goal.z > 0 or abs(depth - max(0.0, -goal.z)) <= goal.depth_tolerance
