"""The picture's vehicle panels beside the track and depth (issue 30): attitude, speed, and the electric currents.

- Attitude: roll, pitch and heading of base_link in the track's frame (world -> odom -> base_link from /tf, the
  estimate the nodes use), in degrees; the heading on its own axis (it spans -180..180, roll and pitch a few degrees).
- Speed: from odom -> base_link (horizontal, and the depth rate, positive when descending), each over a sliding
  window of :data:`SPEED_WINDOW_S` (the track is 25 Hz: differences of single samples are noise); odom, not world:
  world -> odom jumps when a GPS fix at the surface corrects it, odom is continuous (REP 105), so a speed from it
  has no spikes that the vehicle never had. With the dead reckoning's own speed estimate when /diagnostics has it
  (the ``speed`` value of its status).
- Currents: the battery's (/battery_state, negative while discharging as sensor_msgs/BatteryState says) and each
  thruster's from its feedback, on one axis in amperes.
"""

from __future__ import annotations

import math
from typing import Any

from sam_runtime.common.run_names import spec_frame, spec_status_name
from sam_runtime.report.plot_support import Run, finish, lines, not_recorded
from sam_runtime.report.recording import Recording

__all__ = ["SPEED_WINDOW_S", "attitude", "draw_attitude", "draw_currents", "draw_speed", "estimated_speed",
           "odom_points", "speeds"]

SPEED_WINDOW_S = 1.0
_ESTIMATOR = "dead_reckoning"  # the node whose /diagnostics status carries its speed estimate


def attitude(run: Run) -> list[tuple[float, float, float, float]]:
    """(t, roll, pitch, yaw) in degrees of each pose."""
    out = []
    for t, pose in run.poses:
        roll, pitch, yaw = pose.rpy()
        out.append((t, math.degrees(roll), math.degrees(pitch), math.degrees(yaw)))
    return out


def speeds(points: list[tuple[float, float, float, float]],
           window_s: float = SPEED_WINDOW_S) -> list[tuple[float, float, float]]:
    """(t, horizontal speed, depth rate) in m/s from the track's (t, x, y, depth) points, each over the window that
    ends at t (from the latest point at least ``window_s`` older)."""
    out = []
    j = 0
    for i, (t, x, y, depth) in enumerate(points):
        while j + 1 < i and points[j + 1][0] <= t - window_s:
            j += 1
        t0, x0, y0, d0 = points[j]
        if t - t0 < window_s:
            continue
        dt = t - t0
        out.append((t, math.hypot(x - x0, y - y0) / dt, (depth - d0) / dt))
    return out


def odom_points(rec: Recording) -> list[tuple[float, float, float, float]]:
    """(t, x, y, depth) of base_link in odom (odom -> base_link from /tf)."""
    out = []
    for t, msg in rec.get("/tf"):
        for ts in msg.transforms:
            parent = spec_frame(rec.names, ts.header.frame_id)
            if (parent, spec_frame(rec.names, ts.child_frame_id)) == ("odom", "base_link"):
                tr = ts.transform.translation
                out.append((t, float(tr.x), float(tr.y), -float(tr.z)))
    return out


def estimated_speed(rec: Recording) -> list[tuple[float, float]]:
    """(t, speed) of the dead reckoning's /diagnostics status (its estimate through the water), where it has one."""
    out = []
    for t, msg in rec.get("/diagnostics"):
        for status in msg.status:
            if spec_status_name(rec.names, status.name) != _ESTIMATOR:
                continue
            for kv in status.values:
                if kv.key == "speed":
                    try:
                        out.append((t, float(kv.value)))
                    except ValueError:
                        pass
    return out


def draw_attitude(ax: Any, run: Run) -> None:
    ax.set_title(f"Attitude of base_link in {run.frame} (/tf)")
    rows = attitude(run)
    if not rows:
        not_recorded(ax, "/tf (odom -> base_link)")
        return
    times = [r[0] for r in rows]
    ax.plot(times, [r[1] for r in rows], color="#1f77b4", lw=1.6, label="roll")
    ax.plot(times, [r[2] for r in rows], color="#d35400", lw=1.2, ls=(0, (6, 3)), label="pitch")
    heading = ax.twinx()
    heading.plot(times, [r[3] for r in rows], color="#7f8c8d", lw=1.0, ls=(0, (2, 2)), label="yaw (heading)")
    heading.set_ylabel("yaw [deg]")
    heading.set_ylim(-185, 185)
    handles, labels = [], []
    for a in (ax, heading):
        h, lab = a.get_legend_handles_labels()
        handles += h
        labels += lab
    finish(ax, "roll, pitch [deg]", run.spans)
    ax.legend(handles, labels, loc="best", fontsize=8, framealpha=0.8)


def draw_speed(ax: Any, run: Run) -> None:
    ax.set_title("Speed: from odom -> base_link (/tf), and the dead reckoning's estimate")
    rows = speeds(odom_points(run.rec))
    estimate = estimated_speed(run.rec)
    if not rows and not estimate:
        not_recorded(ax, "/tf (odom -> base_link)")
        return
    if rows:
        times = [r[0] for r in rows]
        ax.plot(times, [r[1] for r in rows], color="#1f77b4", lw=1.6, label=f"horizontal (over {SPEED_WINDOW_S:g} s)")
        ax.plot(times, [r[2] for r in rows], color="#17becf", lw=1.1, ls=(0, (6, 3)),
                label="depth rate (+ descending)")
    if estimate:
        ax.plot([t for t, _ in estimate], [v for _, v in estimate], color="#8e44ad", lw=1.0, ls=(0, (2, 2)),
                marker="o", ms=3, markevery=max(1, len(estimate) // 40), label="dead reckoning estimate")
    ax.axhline(0.0, color="#7f8c8d", lw=0.6)
    finish(ax, "speed [m/s]", run.spans)


def draw_currents(ax: Any, run: Run) -> None:
    ax.set_title("Currents: battery (/battery_state) and thrusters (feedback)")
    drawn = lines(ax, run.rec, "/battery_state", [("current", "battery (negative: discharging)")])
    for k in (1, 2):
        drawn = lines(ax, run.rec, f"/thruster_{k}/feedback", [("current", f"thruster {k}")], feedback=True) or drawn
    if drawn:
        finish(ax, "current [A]", run.spans)
    else:
        not_recorded(ax, "/battery_state and the thrusters' feedback")
