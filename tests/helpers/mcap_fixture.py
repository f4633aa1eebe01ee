"""A synthetic recorded dive as an MCAP with rosbag2's conventions (ros2msg schemas with their dependencies, CDR
messages), written with mcap_ros2's writer: the report's test input until a real recording is at hand.

The dive: 60 s, down to 3 m along x toward a goal at (20, 5, -3), back up; /tf world->odom (2 Hz) and
odom->base_link (25 Hz), /nav_goal, /pressure, /altitude, the command topics, both thrusters' feedback (alike),
/battery_state, /abort (an abort at 45 s) and /diagnostics of the nodes (the controller WARN from 30 to 35 s, the
dead reckoning's speed) and of the bridge (deactivated 20-25 s, a device lost, one never heard, drops: see
_bridge_statuses).
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
_SHARE = [REPO / "generated" / "ros", Path(sys.prefix) / "share"]
_BUILTIN = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
            "int64", "uint64", "string", "wstring"}


def _msg_file(full: str) -> Path:
    package, name = full.split("/")[0], full.split("/")[-1]
    for share in _SHARE:
        path = share / package / "msg" / f"{name}.msg"
        if path.is_file():
            return path
    raise FileNotFoundError(full)


def msgdef(full: str) -> str:
    """The concatenated definition rosbag2 stores for ``pkg/msg/Name`` (or ``pkg/Name``)."""
    main = full.replace("/msg/", "/")
    seen: list[str] = []
    order: list[str] = []

    def deps(name: str) -> None:
        package = name.split("/")[0]
        for line in _msg_file(name).read_text().splitlines():
            line = line.split("#", 1)[0].strip()
            if not line or "=" in line.split()[1] if len(line.split()) > 1 else True:
                continue
            base = re.sub(r"\[.*\]$", "", line.split()[0])
            base = re.sub(r"<=\d+$", "", base)
            if base in _BUILTIN:
                continue
            dep = "std_msgs/Header" if base == "Header" else base if "/" in base else f"{package}/{base}"
            if dep not in seen:
                seen.append(dep)
                deps(dep)
                order.append(dep)

    deps(main)
    text = _msg_file(main).read_text()
    for dep in order:
        text += "\n" + "=" * 80 + f"\nMSG: {dep}\n" + _msg_file(dep).read_text()
    return text


TYPES = {
    "/tf": "tf2_msgs/msg/TFMessage", "/nav_goal": "geometry_msgs/msg/PoseStamped",
    "/pressure": "sensor_msgs/msg/FluidPressure", "/altitude": "sensor_msgs/msg/Range",
    "/thruster_rpms": "sam_msgs/msg/ThrusterRPMs", "/thruster_angles": "sam_msgs/msg/ThrusterAngles",
    "/ballast_angles": "sam_msgs/msg/BallastAngles", "/buoyancy_piston_position": "sam_msgs/msg/PercentStamped",
    "/longitudinal_weight_position": "sam_msgs/msg/PercentStamped", "/battery_state": "sensor_msgs/msg/BatteryState",
    "/abort": "sam_msgs/msg/Abort", "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
    "/thruster_1/feedback": "sam_msgs/msg/ThrusterFeedback", "/thruster_2/feedback": "sam_msgs/msg/ThrusterFeedback",
}
T0_NS = 1_764_000_000_000_000_000


def _stamp(t: float) -> dict[str, int]:
    ns = T0_NS + int(t * 1e9)
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _header(t: float, frame: str = "") -> dict[str, Any]:
    return {"stamp": _stamp(t), "frame_id": frame}


def _tf(t: float, parent: str, child: str, xyz: tuple[float, float, float], yaw: float) -> dict[str, Any]:
    return {"transforms": [{"header": _header(t, parent), "child_frame_id": child,
                            "transform": {"translation": dict(zip("xyz", xyz, strict=True)),
                                          "rotation": {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2),
                                                       "w": math.cos(yaw / 2)}}}]}


def _namespaced(msg: Any, prefix: str) -> Any:
    """A message as a run with frame prefix ``prefix`` writes it: every non-empty frame id (header, child) and
    status name prefixed."""
    if isinstance(msg, list):
        return [_namespaced(m, prefix) for m in msg]
    if not isinstance(msg, dict):
        return msg
    out = {k: _namespaced(v, prefix) for k, v in msg.items()}
    for key in ("frame_id", "child_frame_id"):
        if out.get(key):
            out[key] = prefix + out[key]
    if "level" in out and out.get("name"):
        out["name"] = prefix + out["name"]
    return out


def _kv(values: dict[str, Any]) -> list[dict[str, str]]:
    return [{"key": k, "value": str(v)} for k, v in values.items()]


def _bridge_statuses(t: float) -> list[dict[str, Any]]:
    """The bridge's statuses at ``t``: deactivated by its lifecycle manager from 20 to 25 s (commands dropped as
    inactive), thruster_1 lost from 20 to 30 s (ERROR), the GPS never heard before 10 s (STALE), the IMU losing
    transfers from 10 s on."""
    active = not 20 <= t < 25
    lost = max(0, int(2 * (t - 10))) if t >= 10 else 0
    inactive = 0 if t < 20 else min(50, int(10 * (t - 20)))
    out = [{"level": 0, "name": "uavcan_ros_bridge", "hardware_id": "",
            "message": ("" if active else "inactive (lifecycle): commands dropped; ") + "3 mappings",
            "values": _kv({"dropped_total": lost + inactive, "active": active})}]
    for device, level in (("imu", 0), ("thruster_1", 2 if 20 <= t < 30 else 0), ("gps", 3 if t < 10 else 0)):
        out.append({"level": level, "name": f"uavcan_ros_bridge/device/{device}", "message": "", "hardware_id": "",
                    "values": _kv({"alive": level == 0})})
    for mapping, drops in (("imu", {"lost": lost}), ("thruster_1_rpm", {"inactive": inactive}), ("pressure", {})):
        out.append({"level": 0, "name": f"uavcan_ros_bridge/mapping/{mapping}", "message": "", "hardware_id": "",
                    "values": _kv({"dropped": sum(drops.values()),
                                   **{f"dropped.{k}": v for k, v in drops.items()}})})
    return out


def dive_depth(t: float) -> float:
    return 3.0 * min(1.0, t / 15.0) if t < 40 else max(0.0, 3.0 * (1 - (t - 40) / 15.0))


def write_dive(path: Path, *, seconds: float = 60.0, skip: tuple[str, ...] = (), chunk_size: int = 1 << 20,
               namespace: str = "") -> Path:
    """Write the synthetic dive to ``path``; ``skip`` leaves topics out (for the "not recorded" panels); small chunks
    make a file that a cut leaves partly readable. ``namespace`` (``/sam1``): the dive as a namespaced run of a spec
    with relative topic names records it: channels under the namespace (but the global /tf and /diagnostics), frame
    ids with its prefix, status names with the namespace, and the recorder's metadata saying so."""
    prefix = namespace[1:] + "/" if namespace else ""
    from mcap_ros2.writer import Writer

    events: list[tuple[float, str, dict[str, Any]]] = []

    def add(t: float, topic: str, msg: dict[str, Any]) -> None:
        if topic not in skip and t <= seconds:
            events.append((t, topic, msg))

    steps = int(seconds * 25)
    for k in range(steps + 1):
        t = k / 25
        x, y = min(20.0, 0.6 * t), min(5.0, 0.15 * t)
        depth = dive_depth(t)
        add(t, "/tf", _tf(t, "odom", "base_link", (x - 0.5, y, -depth), math.atan2(5, 20)))
        if k % 12 == 0:
            add(t, "/tf", _tf(t, "world", "odom", (0.5, 0.0, 0.0), 0.0))
        if k % 5 == 0:
            add(t, "/pressure", {"header": _header(t, "pressure_link"), "fluid_pressure": 101325 + 10052 * depth,
                                 "variance": 0.0})
            add(t, "/altitude", {"header": _header(t, "altimeter_link"), "radiation_type": 0, "field_of_view": 0.1,
                                 "min_range": 0.2, "max_range": 50.0, "range": 12.0 - depth})
            ascent = t >= 40
            add(t, "/thruster_rpms", {"header": _header(t), "thruster_1_rpm": 0 if t >= 45 else 1200,
                                      "thruster_2_rpm": 0 if t >= 45 else 1200})
            add(t, "/thruster_angles", {"header": _header(t), "thruster_vertical_radians": 0.1 * math.sin(t / 5),
                                        "thruster_horizontal_radians": -0.05})
            add(t, "/ballast_angles", {"header": _header(t), "weight_1_offset_radians": 0.0,
                                       "weight_2_offset_radians": 0.0})
            add(t, "/buoyancy_piston_position", {"header": _header(t), "percent": 100.0 if ascent else 30.0})
            add(t, "/longitudinal_weight_position", {"header": _header(t), "percent": 50.0 + 10 * math.sin(t / 8)})
            for n in (1, 2):  # both thrusters alike: equal series, each must stay visible
                add(t, f"/thruster_{n}/feedback", {"header": _header(t), "rpm": 0 if t >= 46 else 1180,
                                                    "current": 0.2 if t >= 46 else 2.5, "temperature_c": 20})
        if k % 25 == 0:
            add(t, "/battery_state", {"header": _header(t), "voltage": 16.0, "temperature": 20.0, "current": -3.0,
                                      "charge": math.nan, "capacity": math.nan, "design_capacity": math.nan,
                                      "percentage": 0.9 - 0.002 * t, "power_supply_status": 2,
                                      "power_supply_health": 1, "power_supply_technology": 2, "present": True,
                                      "cell_voltage": [], "cell_temperature": [], "location": "",
                                      "serial_number": ""})
            statuses = []
            for name in ("dead_reckoning", "slam", "motion_planner", "controller", "performance_monitor"):
                level = 1 if name == "controller" and 30 <= t < 35 else 2 if name == "performance_monitor" \
                    and t >= 45 else 0
                values = [{"key": "speed", "value": f"{0.6 if t < 45 else 0.0:.3g}"}] if name == "dead_reckoning" \
                    else []
                statuses.append({"level": level, "name": name, "message": "ok", "hardware_id": "",
                                 "values": values})
            statuses += _bridge_statuses(t)
            add(t, "/diagnostics", {"header": _header(t), "status": statuses})
    for t in (0.5, 1.0):  # sent again, as the mission does until the planner has it
        add(t, "/nav_goal", {"header": _header(t, "world"),
                             "pose": {"position": {"x": 20.0, "y": 5.0, "z": -3.0},
                                      "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}})
    add(38.0, "/nav_goal", {"header": _header(38.0, "world"),
                            "pose": {"position": {"x": 0.0, "y": 0.0, "z": 0.0},
                                     "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}})
    add(0.0, "/abort", {"header": _header(0.0), "active": False, "reason": ""})
    add(45.0, "/abort", {"header": _header(45.0), "active": True, "reason": "battery below min_battery_percent"})
    events.sort(key=lambda e: e[0])
    if namespace:
        events = [(t, topic if topic in ("/tf", "/diagnostics") else namespace + topic, _namespaced(msg, prefix))
                  for t, topic, msg in events]
    with open(path, "wb") as f:
        writer = Writer(f, chunk_size=chunk_size)
        if namespace:
            writer.add_metadata("sam_codegen.recording", {"format": "sam-recording/1", "ros.namespace": namespace,
                                                          "ros.frame_prefix": prefix})
        schemas = {topic: writer.register_msgdef(TYPES[topic], msgdef(TYPES[topic])) for topic in TYPES}
        for seq, (t, topic, msg) in enumerate(events):
            ns = T0_NS + int(t * 1e9)
            schema = schemas[topic[len(namespace):] if namespace and topic.startswith(namespace + "/") else topic]
            writer.write_message(topic, schema, msg, log_time=ns, publish_time=ns, sequence=seq)
        writer.finish()
    return path
