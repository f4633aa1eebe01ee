"""The bridges' /diagnostics as the main job's table shows them: one name space for mappings and devices, a status
line per bridge (a mixed layout runs two: ``<bridge>_cyphal`` and ``<bridge>_dronecan``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

__all__ = ["PROTOCOL_SUFFIXES", "bridge_lines", "interface_line", "status_key"]

PROTOCOL_SUFFIXES = ("cyphal", "dronecan")


def status_key(name: str, bridge: str) -> str:
    """Where a status is kept: a mapping's or device's under ``<bridge>/`` whichever bridge reported it (each one
    belongs to one bridge of a layout); a bridge's own status under its own name, so both bridges keep a line.

    >>> status_key("uavcan_ros_bridge_dronecan/device/battery", "uavcan_ros_bridge")
    'uavcan_ros_bridge/device/battery'
    >>> status_key("uavcan_ros_bridge_cyphal", "uavcan_ros_bridge")
    'uavcan_ros_bridge_cyphal'
    >>> status_key("uavcan_ros_bridge/mapping/imu", "uavcan_ros_bridge")
    'uavcan_ros_bridge/mapping/imu'
    >>> status_key("other_node/x", "uavcan_ros_bridge")
    'other_node/x'
    """
    head, sep, rest = name.partition("/")
    if sep and head in {f"{bridge}_{p}" for p in PROTOCOL_SUFFIXES}:
        return bridge + sep + rest
    return name


def bridge_lines(diagnostics: Mapping[str, Mapping[str, Any]], bridge: str) -> list[str]:
    """The bridges' status lines: ``bridge: ...`` for one bridge, ``bridge <protocol>: ...`` per bridge of a mixed
    layout.

    >>> bridge_lines({"b": {"message": "18 mappings, 0 dropped"}}, "b")
    ['bridge: 18 mappings, 0 dropped']
    >>> bridge_lines({"b_dronecan": {"message": "13 mappings, 2 dropped"}, "b/device/gps": {"message": "ok"},
    ...               "b_cyphal": {"message": "5 mappings, 0 dropped"}}, "b")
    ['bridge cyphal: 5 mappings, 0 dropped', 'bridge dronecan: 13 mappings, 2 dropped']
    >>> bridge_lines({}, "b")
    ['bridge: no /diagnostics yet']
    """
    lines = [f"bridge: {diagnostics[bridge]['message']}"] if bridge in diagnostics else []
    lines += [f"bridge {p}: {diagnostics[f'{bridge}_{p}']['message']}" for p in PROTOCOL_SUFFIXES
              if f"{bridge}_{p}" in diagnostics]
    return lines or ["bridge: no /diagnostics yet"]


def interface_line(diagnostics: Mapping[str, Mapping[str, Any]], bridge: str, devices: list[str]) -> str | None:
    """The boards' firmware interface versions (issue 28: the bridge's interface check, in each device's status
    values) in one line; None before any board was checked.

    >>> d = {"b/device/imu": {"values": {"interface": "mismatch", "interface_mismatches": "2"}},
    ...      "b/device/gps": {"values": {"interface": "match"}}, "b/device/dvl": {"values": {}}}
    >>> interface_line(d, "b", ["imu", "gps", "dvl"])
    'firmware interface: 2 boards checked, 1 match, 1 mismatch (imu: 2 seen)'
    >>> interface_line({}, "b", ["imu"]) is None
    True
    """
    values = {name: diagnostics.get(f"{bridge}/device/{name}", {}).get("values", {}) for name in devices}
    verdicts = {name: v.get("interface") for name, v in values.items()}
    checked = [n for n, verdict in verdicts.items() if verdict in ("match", "mismatch", "unknown")]
    if not checked:
        return None
    counts = [f"{sum(verdicts[n] == kind for n in checked)} {kind}" for kind in ("match", "mismatch", "unknown")
              if any(verdicts[n] == kind for n in checked)]
    bad = [f"{n}: {values[n].get('interface_mismatches', '?')} seen" for n in checked if verdicts[n] == "mismatch"]
    return (f"firmware interface: {len(checked)} boards checked, {', '.join(counts)}"
            + (f" ({'; '.join(bad)})" if bad else ""))
