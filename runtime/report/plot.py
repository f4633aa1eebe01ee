"""One picture of a recorded run (`sam-codegen plot FILE.mcap`, and the main job at the end of a recorded run).

Panels: the track in the world frame (world -> odom -> base_link from /tf, as the nodes and the live view derive it)
with the goals (/nav_goal); depth (the same transform, and /pressure) and altitude (/altitude) over time with the
safe and critical limits; attitude and speed (motion_panels); each command against its device's feedback (thruster
RPMs, thrust vector and ballast angles, buoyancy piston (VBS) and longitudinal weight (LCG) positions); the battery
and the currents; the abort and each node's state, each device's health and the bridge's drops (status_panels).

Invariants:

- A topic the recording lacks gives its panel a "not recorded" note, never an error; a damaged file plots what is
  readable and the picture names the problems (see recording.py).
- Every time axis is seconds since the recording's first message; every axis says its unit.
- matplotlib (the `runtime` extra) is imported only when a picture is drawn, with the Agg backend (no display).
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from sam_runtime.physics.geo import depth_from_pressure
from sam_runtime.report.motion_panels import draw_attitude, draw_currents, draw_speed
from sam_runtime.report.plot_support import ABORT_COLOUR, Run, finish, lines, not_recorded, poses, shade_aborts
from sam_runtime.report.recording import Recording, RecordingError, read_recording
from sam_runtime.report.status_panels import draw_devices, draw_drops, draw_states, node_states, state_legend

__all__ = ["LIMITS", "TOPICS", "RecordingError", "limits_from_params", "node_states", "plot_run", "track"]

LIMITS = ("safe_depth", "critical_depth", "safe_altitude", "critical_altitude")
# What the picture shows: only these are decoded (a run's /imu and raw bus are most of its messages).
TOPICS = ("/tf", "/nav_goal", "/pressure", "/altitude", "/thruster_rpms", "/thruster_angles", "/ballast_angles",
          "/buoyancy_piston_position", "/longitudinal_weight_position", "/battery_state", "/abort", "/diagnostics",
          "/thruster_1/feedback", "/thruster_2/feedback", "/thrust_vector/feedback", "/buoyancy_piston/feedback",
          "/longitudinal_weight/feedback")
def limits_from_params(path: Path) -> dict[str, float]:
    """The depth and altitude limits of a --params-file (generated/params/<vehicle>.params.yaml): the values given to
    every node (`/**`) and, over them, any node's own."""
    data = yaml.safe_load(Path(path).read_text()) or {}
    found: dict[str, float] = {}
    for node in sorted(data, key=lambda n: n != "/**"):  # the wildcard first, nodes' own values over it
        params = (data[node] or {}).get("ros__parameters", {}) if isinstance(data[node], dict) else {}
        for name in LIMITS:
            if isinstance(params.get(name), int | float):
                found[name] = float(params[name])
    return found


def track(rec: Recording) -> tuple[str, list[tuple[float, float, float, float]]]:
    """(frame, [(t, x, y, depth)]): base_link in world (odom -> base_link after the latest world -> odom), or in odom
    when no world -> odom was recorded."""
    frame, found = poses(rec)
    return frame, [(t, *pose.translation[:2], -pose.translation[2]) for t, pose in found]


def _abort_spans(rec: Recording) -> list[tuple[float, float, str]]:
    spans: list[tuple[float, float, str]] = []
    start: tuple[float, str] | None = None
    for t, msg in rec.get("/abort"):
        if msg.active and start is None:
            start = (t, str(msg.reason))
        elif not msg.active and start is not None:
            spans.append((start[0], t, start[1]))
            start = None
    if start is not None:
        spans.append((start[0], rec.end_s, start[1]))
    return spans


def _limit_lines(ax: Any, limits: Mapping[str, float], names: tuple[str, str], top: float) -> None:
    """Horizontal limit lines inside the plotted range; the ones beyond it are named in the panel's title (a 60 m
    limit would flatten a 3 m dive to a line)."""
    styles = {names[0]: ("#f39c12", "--"), names[1]: ("#c0392b", "-.")}
    off_scale = []
    for name in names:
        if name not in limits:
            continue
        value = limits[name]
        colour, style = styles[name]
        if value <= top:
            ax.axhline(value, color=colour, ls=style, lw=1.3, label=f"{name} {value:g} m")
        else:
            off_scale.append(f"{name} {value:g} m")
    if off_scale:
        ax.set_title(f"{ax.get_title()}\n(beyond the plotted range: {', '.join(off_scale)})", fontsize=10)


def _draw_track(ax_track: Any, run: Run) -> None:
    frame, points, goals, spans = run.frame, run.points, run.goals, run.spans
    ax_track.set_title(f"Track in {frame} (world -> odom -> base_link from /tf) and goals")
    if points:
        xs, ys = [p[1] for p in points], [p[2] for p in points]
        ax_track.plot(xs, ys, color="#1f77b4", lw=1.6, label="base_link")
        ax_track.plot(xs[0], ys[0], "o", color="#2e8b57", ms=8, label="start", zorder=5)  # over a goal at the start
        ax_track.plot(xs[-1], ys[-1], "s", color="#34495e", ms=7, label="end", zorder=5)
        for a, _, _ in spans:
            at = min(points, key=lambda p: abs(p[0] - a))
            ax_track.plot(at[1], at[2], "X", color=ABORT_COLOUR, ms=11, label=f"abort at {a:.0f} s")
    # A mission sends a goal again until the planner has it: one star per distinct goal, with when it came first.
    distinct: dict[tuple[float, float, float], float] = {}
    for t, p in goals:
        distinct.setdefault((round(p.x, 2), round(p.y, 2), round(p.z, 2)), t)
    labels: dict[tuple[float, float], list[str]] = {}  # goals at one place (down, then up) share a star
    for k, ((x, y, z), t) in enumerate(distinct.items(), 1):
        where = "surface" if z == 0 else f"depth {-z:g} m" if z < 0 else f"altitude {z:g} m"
        labels.setdefault((x, y), []).append(f"goal {k}: {where}, from {t:.0f} s")
    xs_all = [x for x, _ in labels] + [p[1] for p in points]
    middle = (min(xs_all) + max(xs_all)) / 2 if xs_all else 0.0
    for k, ((x, y), texts) in enumerate(labels.items()):
        ax_track.plot(x, y, "*", color="#8e44ad", ms=15, label="goal (/nav_goal)" if k == 0 else None)
        right = x <= middle  # the text toward the middle of the picture, below-beside the star and the end marker
        ax_track.annotate("\n".join(texts), (x, y), textcoords="offset points", xytext=(12 if right else -12, -10),
                          ha="left" if right else "right", va="top", fontsize=8, color="#8e44ad",
                          bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
                          zorder=1)  # under the track: a label never hides the line
    if points or goals:
        ax_track.set_xlabel(f"x (east) in {frame} [m]")
        ax_track.set_ylabel(f"y (north) in {frame} [m]")
        ax_track.margins(0.15)  # room for the goals' labels at the edges
        ax_track.set_aspect("equal", adjustable="datalim")
        ax_track.grid(alpha=0.3)
        ax_track.legend(loc="best", fontsize=8)
    else:
        not_recorded(ax_track, "/tf (odom -> base_link) and /nav_goal")


def _draw_depth(ax_depth: Any, run: Run) -> None:
    rec, spans, end, limits, points, goals = run.rec, run.spans, run.end, run.limits, run.points, run.goals
    ax_depth.set_title("Depth")
    depth_top = 0.0
    if points:
        ax_depth.plot([p[0] for p in points], [p[3] for p in points], color="#1f77b4", lw=1.4,
                      label="estimate (world -> base_link)")
        depth_top = max(depth_top, max(p[3] for p in points))
    pressure = rec.get("/pressure")
    if pressure:
        d = [depth_from_pressure(float(m.fluid_pressure)) for _, m in pressure]
        # dashed: the estimate follows the pressure closely, and must show under it
        ax_depth.plot([t for t, _ in pressure], d, color="#17becf", lw=1.0, ls=(0, (6, 3)), label="from /pressure")
        depth_top = max(depth_top, max(d))
    depth_goals = [(t, -p.z) for t, p in goals if p.z <= 0]
    if depth_goals:
        ax_depth.step([t for t, _ in depth_goals] + [end], [d for _, d in depth_goals] + [depth_goals[-1][1]],
                      where="post", color="#8e44ad", lw=1.0, ls=":", label="goal depth")
        depth_top = max(depth_top, max(d for _, d in depth_goals))
    if points or pressure:
        top = depth_top * 1.25 + 0.5
        _limit_lines(ax_depth, limits, ("safe_depth", "critical_depth"), top)
        ax_depth.set_ylim(top, min(-0.2, -0.05 * top))  # depth grows downward
        ax_depth.set_ylabel("depth [m]")
        ax_depth.grid(alpha=0.3)
        ax_depth.legend(loc="best", fontsize=8)
        shade_aborts(ax_depth, spans)
    else:
        not_recorded(ax_depth, "/tf and /pressure")


def _draw_altitude(ax_alt: Any, run: Run) -> None:
    rec, spans, limits = run.rec, run.spans, run.limits
    ax_alt.set_title("Altitude above the sea floor (/altitude)")
    altitude = rec.get("/altitude")
    if altitude:
        values = [float(m.range) for _, m in altitude]
        ax_alt.plot([t for t, _ in altitude], values, color="#1f77b4", lw=1.3, label="altimeter")
        finite = [v for v in values if math.isfinite(v)]
        top = max([*finite, limits.get("safe_altitude", 0.0), limits.get("critical_altitude", 0.0), 1.0]) * 1.15
        _limit_lines(ax_alt, limits, ("safe_altitude", "critical_altitude"), top)
        if len(finite) < len(values):
            ax_alt.text(0.01, 0.95, f"{len(values) - len(finite)} samples without bottom lock (NaN)",
                        transform=ax_alt.transAxes, fontsize=8, va="top", color="#7f8c8d")
        ax_alt.set_ylim(0, top)
        ax_alt.set_ylabel("altitude [m]")
        ax_alt.grid(alpha=0.3)
        ax_alt.legend(loc="best", fontsize=8)
        shade_aborts(ax_alt, spans)
    else:
        not_recorded(ax_alt, "/altitude")


def _draw_commands(ax_rpm: Any, ax_ang: Any, ax_pct: Any, run: Run) -> None:
    """Each command with its device's feedback over it (feedback: thinner, markers); equal series stay visible."""
    rec, spans = run.rec, run.spans
    ax_rpm.set_title("Thrusters: command (/thruster_rpms) and feedback")
    if lines(ax_rpm, rec, "/thruster_rpms", [("thruster_1_rpm", "thruster 1"), ("thruster_2_rpm", "thruster 2")]):
        for k in (1, 2):
            lines(ax_rpm, rec, f"/thruster_{k}/feedback", [("rpm", f"thruster {k} feedback")], feedback=True)
        finish(ax_rpm, "speed [rpm]", spans)
    else:
        not_recorded(ax_rpm, "/thruster_rpms")
    ax_ang.set_title("Angles: commands (/thruster_angles, /ballast_angles) and feedback")
    drawn = lines(ax_ang, rec, "/thruster_angles", [("thruster_vertical_radians", "thrust vector vertical"),
                                                     ("thruster_horizontal_radians", "thrust vector horizontal")],
                  scale=180 / math.pi)
    drawn = lines(ax_ang, rec, "/ballast_angles", [("weight_1_offset_radians", "ballast weight 1"),
                                                    ("weight_2_offset_radians", "ballast weight 2")],
                  scale=180 / math.pi) or drawn
    if drawn:
        lines(ax_ang, rec, "/thrust_vector/feedback", [("vertical_mrad", "thrust vector vertical feedback"),
                                                        ("horizontal_mrad", "thrust vector horizontal feedback")],
              scale=0.001 * 180 / math.pi, feedback=True)
        finish(ax_ang, "angle [deg]", spans, ncol=2)
    else:
        not_recorded(ax_ang, "/thruster_angles and /ballast_angles")
    ax_pct.set_title("Buoyancy (VBS) and trim (LCG): commands and feedback")
    drawn = lines(ax_pct, rec, "/buoyancy_piston_position", [("percent", "buoyancy piston (VBS)")])
    drawn = lines(ax_pct, rec, "/longitudinal_weight_position", [("percent", "longitudinal weight (LCG)")]) or drawn
    if drawn:
        lines(ax_pct, rec, "/buoyancy_piston/feedback", [("percent", "VBS feedback")], feedback=True)
        lines(ax_pct, rec, "/longitudinal_weight/feedback", [("percent", "LCG feedback")], feedback=True)
        ax_pct.set_ylim(-5, 105)
        finish(ax_pct, "position [%]", spans)
    else:
        not_recorded(ax_pct, "/buoyancy_piston_position and /longitudinal_weight_position")


def _draw_battery(ax_bat: Any, run: Run) -> None:
    """Charge and voltage (the current is in the currents panel, beside the thrusters' that draw it)."""
    rec, spans = run.rec, run.spans
    ax_bat.set_title("Battery (/battery_state): charge and voltage")
    battery = rec.get("/battery_state")
    if battery:
        times = [s for s, _ in battery]
        ax_bat.plot(times, [100 * float(m.percentage) for _, m in battery], color="#2e8b57", lw=1.6, label="charge")
        ax_bat.set_ylim(0, 105)
        volts = ax_bat.twinx()
        volts.plot(times, [float(m.voltage) for _, m in battery], color="#7d3c98", lw=1.0, ls=(0, (6, 3)),
                   label="voltage")
        volts.set_ylabel("voltage [V]")
        handles, labels = [], []
        for ax in (ax_bat, volts):
            h, lab = ax.get_legend_handles_labels()
            handles += h
            labels += lab
        finish(ax_bat, "charge [%]", spans)
        ax_bat.legend(handles, labels, loc="best", fontsize=8, framealpha=0.8)
    else:
        not_recorded(ax_bat, "/battery_state")


def plot_run(mcap: Path, out: Path, *, limits: Mapping[str, float] | None = None, title: str | None = None) -> Path:
    """Draw the run recorded in ``mcap`` into ``out`` (.png or .svg); returns ``out``. Raises RecordingError for a
    file that is not a recording, ValueError for an output format other than PNG or SVG."""
    import matplotlib

    matplotlib.use("Agg")  # no display: a file is all we write
    import matplotlib.pyplot as plt

    out = Path(out)
    if out.suffix.lower() not in (".png", ".svg"):
        raise ValueError(f"{out}: the report is a .png or .svg picture")
    rec = read_recording(Path(mcap), TOPICS)
    limits = dict(limits or {})
    spans = _abort_spans(rec)
    end = max(rec.end_s, 1.0)

    fig = plt.figure(figsize=(15, 25), dpi=100)
    grid = fig.add_gridspec(7, 2, height_ratios=[1.15, 1.15, 1, 1, 1, 1, 1.15], hspace=0.5, wspace=0.32,
                            left=0.12, right=0.9, top=0.955, bottom=0.06)
    ax_track = fig.add_subplot(grid[0:2, 0])
    ax_depth = fig.add_subplot(grid[0, 1])
    time_axes = {"alt": (1, 1), "attitude": (2, 0), "speed": (2, 1), "rpm": (3, 0), "ang": (3, 1), "pct": (4, 0),
                 "bat": (4, 1), "currents": (5, 0), "drops": (5, 1), "state": (6, 0), "devices": (6, 1)}
    axes = {name: fig.add_subplot(grid[r, c], sharex=ax_depth) for name, (r, c) in time_axes.items()}
    heading = title or f"Run {Path(mcap).name}"
    fig.suptitle(f"{heading}  ({end:.0f} s recorded)", fontsize=15)
    if rec.problems:
        note = textwrap.shorten("Recording: " + "; ".join(rec.problems), 200, placeholder=" ...")
        fig.text(0.5, 0.967, note, ha="center", fontsize=9, color=ABORT_COLOUR)

    frame, found = poses(rec)
    points = [(t, *pose.translation[:2], -pose.translation[2]) for t, pose in found]
    run = Run(rec, spans, end, limits, frame, points, [(t, m.pose.position) for t, m in rec.get("/nav_goal")], found)
    _draw_track(ax_track, run)
    _draw_depth(ax_depth, run)
    _draw_altitude(axes["alt"], run)
    draw_attitude(axes["attitude"], run)
    draw_speed(axes["speed"], run)
    _draw_commands(axes["rpm"], axes["ang"], axes["pct"], run)
    _draw_battery(axes["bat"], run)
    draw_currents(axes["currents"], run)
    draw_drops(axes["drops"], run)
    draw_states(axes["state"], run)
    draw_devices(axes["devices"], run)
    state_legend(fig, 0.018)
    for name, ax in [("depth", ax_depth), *axes.items()]:
        if ax.has_data():
            ax.set_xlabel("time since the recording began [s]" if name in ("state", "devices") else "time [s]")
            ax.set_xlim(0, end)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    plt.close(fig)
    return out
