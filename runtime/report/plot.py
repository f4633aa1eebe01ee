"""One picture of a recorded run (`sam-codegen plot FILE.mcap`, and the main job at the end of a recorded run).

Panels: the track in the world frame (world -> odom -> base_link from /tf, as the nodes and the live view derive it)
with the goals (/nav_goal); depth (the same transform, and /pressure) and altitude (/altitude) over time with the
safe and critical limits; the commands (thruster RPMs, thrust vector and ballast angles, buoyancy piston (VBS) and
longitudinal weight (LCG) positions); the battery; the abort (/abort) and each node's state (/diagnostics levels).

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
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from sam_runtime.common.run_names import spec_frame, spec_status_name
from sam_runtime.physics.geo import depth_from_pressure
from sam_runtime.report.recording import Recording, RecordingError, read_recording
from sam_runtime.tf_buffer import Transform

__all__ = ["LIMITS", "TOPICS", "RecordingError", "limits_from_params", "node_states", "plot_run", "track"]

LIMITS = ("safe_depth", "critical_depth", "safe_altitude", "critical_altitude")
# What the picture shows: only these are decoded (a run's /imu and raw bus are most of its messages).
TOPICS = ("/tf", "/nav_goal", "/pressure", "/altitude", "/thruster_rpms", "/thruster_angles", "/ballast_angles",
          "/buoyancy_piston_position", "/longitudinal_weight_position", "/battery_state", "/abort", "/diagnostics",
          "/thruster_1/feedback", "/thruster_2/feedback", "/thrust_vector/feedback", "/buoyancy_piston/feedback",
          "/longitudinal_weight/feedback")
LEVELS = {0: ("OK", "#2e8b57"), 1: ("WARN", "#f39c12"), 2: ("ERROR", "#c0392b"), 3: ("STALE", "#95a5a6")}
ABORT_COLOUR = "#6c3483"  # not ERROR's red: an abort and a node in ERROR are different facts
# Series of one panel may be equal (both thrusters commanded alike): each its own dash pattern and width, the
# later ones thinner and drawn over the earlier, so that none hides another.
_STYLES = (("-", 2.4), ((0, (6, 3)), 1.6), ((0, (2, 2)), 1.2), ((0, (6, 2, 1, 2)), 1.0))


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


def _stamp_ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def track(rec: Recording) -> tuple[str, list[tuple[float, float, float, float]]]:
    """(frame, [(t, x, y, depth)]): base_link in world (odom -> base_link after the latest world -> odom), or in odom
    when no world -> odom was recorded."""
    odom_base: list[tuple[float, Transform]] = []
    world_odom: list[tuple[float, Transform]] = []
    for t, msg in rec.get("/tf"):
        for ts in msg.transforms:
            tr, rot = ts.transform.translation, ts.transform.rotation
            # a namespaced run's frames carry its prefix (sam1/odom): the spec's names again
            edge = Transform(spec_frame(rec.names, ts.header.frame_id), spec_frame(rec.names, ts.child_frame_id),
                             _stamp_ns(ts.header.stamp), (tr.x, tr.y, tr.z), (rot.x, rot.y, rot.z, rot.w))
            if (edge.parent, edge.child) == ("odom", "base_link"):
                odom_base.append((t, edge))
            elif (edge.parent, edge.child) == ("world", "odom"):
                world_odom.append((t, edge))
    frame = "world" if world_odom else "odom"
    points = []
    k = -1
    for t, edge in odom_base:
        while k + 1 < len(world_odom) and world_odom[k + 1][0] <= t:
            k += 1
        if world_odom and k < 0:
            continue  # before the first world -> odom: no world position yet
        pose = world_odom[k][1].compose(edge) if world_odom else edge
        x, y, z = pose.translation
        points.append((t, x, y, -z))
    return frame, points


def _not_recorded(ax: Any, what: str) -> None:
    ax.text(0.5, 0.5, f"{what}\nnot recorded", ha="center", va="center", transform=ax.transAxes, color="#7f8c8d",
            fontsize=11)
    ax.set_xticks([])
    ax.set_yticks([])


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


def _shade_aborts(ax: Any, spans: list[tuple[float, float, str]]) -> None:
    for a, b, _ in spans:
        ax.axvspan(a, b, color=ABORT_COLOUR, alpha=0.08, lw=0)


def _lines(ax: Any, rec: Recording, topic: str, fields: list[tuple[str, str]], *, scale: float = 1.0,
           feedback: bool = False) -> bool:
    """One line per field of ``topic``; ``feedback``: a device's report, drawn with markers beside the commands."""
    items = rec.get(topic)
    if not items:
        return False
    t = [s for s, _ in items]
    for attr, label in fields:
        values = [float(getattr(m, attr)) * scale for _, m in items]
        if feedback:
            ax.plot(t, values, label=label, lw=0.8, marker=".", ms=3, alpha=0.85)
        else:
            style, width = _STYLES[len(ax.get_lines()) % len(_STYLES)]
            ax.plot(t, values, label=label, ls=style, lw=width)
    return True


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


@dataclass(frozen=True)
class _Run:
    """What every panel draws from: the recording, its abort spans, its length and the parameter limits; the track
    (frame, (t, x, y, depth) points) and the goals (t, position) that the track and depth panels share."""

    rec: Recording
    spans: list[tuple[float, float, str]]
    end: float
    limits: Mapping[str, float]
    frame: str
    points: list[tuple[float, float, float, float]]
    goals: list[tuple[float, Any]]


def _draw_track(ax_track: Any, run: _Run) -> None:
    frame, points, goals, spans = run.frame, run.points, run.goals, run.spans
    ax_track.set_title(f"Track in {frame} (world -> odom -> base_link from /tf) and goals")
    if points:
        xs, ys = [p[1] for p in points], [p[2] for p in points]
        ax_track.plot(xs, ys, color="#1f77b4", lw=1.6, label="base_link")
        ax_track.plot(xs[0], ys[0], "o", color="#2e8b57", ms=8, label="start")
        ax_track.plot(xs[-1], ys[-1], "s", color="#34495e", ms=7, label="end")
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
    for k, ((x, y), lines) in enumerate(labels.items()):
        ax_track.plot(x, y, "*", color="#8e44ad", ms=15, label="goal (/nav_goal)" if k == 0 else None)
        right = x <= middle  # the text toward the middle of the picture, below-beside the star and the end marker
        ax_track.annotate("\n".join(lines), (x, y), textcoords="offset points", xytext=(12 if right else -12, -10),
                          ha="left" if right else "right", va="top", fontsize=8, color="#8e44ad",
                          bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85})
    if points or goals:
        ax_track.set_xlabel(f"x (east) in {frame} [m]")
        ax_track.set_ylabel(f"y (north) in {frame} [m]")
        ax_track.margins(0.15)  # room for the goals' labels at the edges
        ax_track.set_aspect("equal", adjustable="datalim")
        ax_track.grid(alpha=0.3)
        ax_track.legend(loc="best", fontsize=8)
    else:
        _not_recorded(ax_track, "/tf (odom -> base_link) and /nav_goal")


def _draw_depth(ax_depth: Any, run: _Run) -> None:
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
        ax_depth.plot([t for t, _ in pressure], d, color="#17becf", lw=1.0, alpha=0.9, label="from /pressure")
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
        _shade_aborts(ax_depth, spans)
    else:
        _not_recorded(ax_depth, "/tf and /pressure")


def _draw_altitude(ax_alt: Any, run: _Run) -> None:
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
        _shade_aborts(ax_alt, spans)
    else:
        _not_recorded(ax_alt, "/altitude")


def _draw_commands(ax_rpm: Any, ax_ang: Any, ax_pct: Any, run: _Run) -> None:
    rec, spans = run.rec, run.spans
    ax_rpm.set_title("Thrusters: command (/thruster_rpms) and feedback")
    if _lines(ax_rpm, rec, "/thruster_rpms", [("thruster_1_rpm", "thruster 1"), ("thruster_2_rpm", "thruster 2")]):
        for k in (1, 2):
            _lines(ax_rpm, rec, f"/thruster_{k}/feedback", [("rpm", f"thruster {k} feedback")], feedback=True)
        ax_rpm.set_ylabel("speed [rpm]")
        ax_rpm.grid(alpha=0.3)
        ax_rpm.legend(loc="best", fontsize=8)
        _shade_aborts(ax_rpm, spans)
    else:
        _not_recorded(ax_rpm, "/thruster_rpms")
    ax_ang.set_title("Angle commands (/thruster_angles, /ballast_angles)")
    drawn = _lines(ax_ang, rec, "/thruster_angles", [("thruster_vertical_radians", "thrust vector vertical"),
                                                      ("thruster_horizontal_radians", "thrust vector horizontal")],
                   scale=180 / math.pi)
    drawn = _lines(ax_ang, rec, "/ballast_angles", [("weight_1_offset_radians", "ballast weight 1"),
                                                     ("weight_2_offset_radians", "ballast weight 2")],
                   scale=180 / math.pi) or drawn
    if drawn:
        _lines(ax_ang, rec, "/thrust_vector/feedback", [("vertical_mrad", "thrust vector vertical feedback"),
                                                         ("horizontal_mrad", "thrust vector horizontal feedback")],
               scale=0.001 * 180 / math.pi, feedback=True)
    if drawn:
        ax_ang.set_ylabel("angle [deg]")
        ax_ang.grid(alpha=0.3)
        ax_ang.legend(loc="best", fontsize=8, ncol=2)
        _shade_aborts(ax_ang, spans)
    else:
        _not_recorded(ax_ang, "/thruster_angles and /ballast_angles")
    ax_pct.set_title("Buoyancy (VBS) and trim (LCG) commands")
    drawn = _lines(ax_pct, rec, "/buoyancy_piston_position", [("percent", "buoyancy piston (VBS)")])
    drawn = _lines(ax_pct, rec, "/longitudinal_weight_position", [("percent", "longitudinal weight (LCG)")]) or drawn
    if drawn:
        _lines(ax_pct, rec, "/buoyancy_piston/feedback", [("percent", "VBS feedback")], feedback=True)
        _lines(ax_pct, rec, "/longitudinal_weight/feedback", [("percent", "LCG feedback")], feedback=True)
        ax_pct.set_ylabel("position [%]")
        ax_pct.set_ylim(-5, 105)
        ax_pct.grid(alpha=0.3)
        ax_pct.legend(loc="best", fontsize=8)
        _shade_aborts(ax_pct, spans)
    else:
        _not_recorded(ax_pct, "/buoyancy_piston_position and /longitudinal_weight_position")


def _draw_battery(ax_bat: Any, run: _Run) -> None:
    rec, spans = run.rec, run.spans
    ax_bat.set_title("Battery (/battery_state)")
    battery = rec.get("/battery_state")
    if battery:
        times = [s for s, _ in battery]
        ax_bat.plot(times, [100 * float(m.percentage) for _, m in battery], color="#2e8b57", lw=1.4, label="charge")
        ax_bat.set_ylabel("charge [%]")
        ax_bat.set_ylim(0, 105)
        ax_bat.grid(alpha=0.3)
        volts = ax_bat.twinx()
        volts.plot(times, [float(m.voltage) for _, m in battery], color="#7d3c98", lw=1.0, ls="--", label="voltage")
        volts.set_ylabel("voltage [V]")
        amps = ax_bat.twinx()  # a third axis, its spine moved out: the current has its own unit
        amps.spines["right"].set_position(("axes", 1.17))
        amps.plot(times, [float(m.current) for _, m in battery], color="#1f618d", lw=1.0, ls=":", label="current")
        amps.set_ylabel("current [A]")
        handles, labels = [], []
        for ax in (ax_bat, volts, amps):
            h, lab = ax.get_legend_handles_labels()
            handles += h
            labels += lab
        ax_bat.legend(handles, labels, loc="best", fontsize=8)
        _shade_aborts(ax_bat, spans)
    else:
        _not_recorded(ax_bat, "/battery_state")


def node_states(rec: Recording) -> dict[str, list[tuple[float, int]]]:
    """Each node's (and the bridge's) levels over time from /diagnostics, by the spec's name: a namespaced run's
    statuses (sam1/controller) without the namespace, another vehicle's and the per-mapping statuses left out."""
    rows: dict[str, list[tuple[float, int]]] = {}
    for t, msg in rec.get("/diagnostics"):
        for status in msg.status:
            name = spec_status_name(rec.names, status.name)  # None: another vehicle's (shared /diagnostics)
            if name is not None and "/" not in name:  # the nodes and the bridge itself, not per-mapping statuses
                level = status.level[0] if isinstance(status.level, bytes | bytearray) else int(status.level)
                rows.setdefault(name, []).append((t, level))
    return rows


def _draw_states(ax_state: Any, run: _Run) -> None:
    from matplotlib.patches import Patch

    rec, spans, end = run.rec, run.spans, run.end
    ax_state.set_title("Abort (/abort) and node states (/diagnostics)")
    rows = node_states(rec)
    names = sorted(rows)
    if rows or rec.get("/abort"):
        rows_shown = [*names, "abort"]
        for k, name in enumerate(names):
            samples = rows[name]
            for (a, level), (b, _) in zip(samples, [*samples[1:], (end, 0)], strict=True):
                ax_state.broken_barh([(a, max(b - a, 0.01))], (k - 0.4, 0.8),
                                     color=LEVELS.get(level, ("?", "#000000"))[1], lw=0)
        k = len(names)
        if rec.get("/abort"):
            for a, b, reason in spans:
                ax_state.broken_barh([(a, max(b - a, 0.01))], (k - 0.4, 0.8), color=ABORT_COLOUR, lw=0)
                ax_state.text(a, k + 0.45, f" {reason}"[:90], fontsize=8, va="bottom", color=ABORT_COLOUR)
            if not spans:
                ax_state.text(0.0, k, "  no abort", va="center", fontsize=8, color="#2e8b57")
        else:
            ax_state.text(0.0, k, "  /abort not recorded", va="center", fontsize=8, color="#7f8c8d")
        if not names:
            ax_state.text(0.5, 0.5, "/diagnostics not recorded", transform=ax_state.transAxes, ha="center",
                          color="#7f8c8d")
        ax_state.set_yticks(range(len(rows_shown)), rows_shown, fontsize=9)
        ax_state.set_ylim(-0.7, len(rows_shown) + 0.2)
        ax_state.set_xlim(0, end)
        ax_state.legend(handles=[Patch(color=c, label=n) for n, c in LEVELS.values()]
                        + [Patch(color=ABORT_COLOUR, label="abort active")],
                        loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=5, fontsize=8, frameon=False)
        ax_state.grid(axis="x", alpha=0.3)
    else:
        _not_recorded(ax_state, "/abort and /diagnostics")


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

    fig = plt.figure(figsize=(15, 19), dpi=100)
    grid = fig.add_gridspec(5, 2, height_ratios=[1.15, 1.15, 1, 1, 1.05], hspace=0.42, wspace=0.2,
                            left=0.12, right=0.88, top=0.94, bottom=0.05)
    ax_track = fig.add_subplot(grid[0:2, 0])
    ax_depth = fig.add_subplot(grid[0, 1])
    ax_alt = fig.add_subplot(grid[1, 1], sharex=ax_depth)
    ax_rpm = fig.add_subplot(grid[2, 0], sharex=ax_depth)
    ax_ang = fig.add_subplot(grid[2, 1], sharex=ax_depth)
    ax_pct = fig.add_subplot(grid[3, 0], sharex=ax_depth)
    ax_bat = fig.add_subplot(grid[3, 1], sharex=ax_depth)
    ax_state = fig.add_subplot(grid[4, :], sharex=ax_depth)
    heading = title or f"Run {Path(mcap).name}"
    fig.suptitle(f"{heading}  ({end:.0f} s recorded)", fontsize=15)
    if rec.problems:
        note = textwrap.shorten("Recording: " + "; ".join(rec.problems), 200, placeholder=" ...")
        fig.text(0.5, 0.955, note, ha="center", fontsize=9, color=ABORT_COLOUR)

    frame, points = track(rec)
    run = _Run(rec, spans, end, limits, frame, points, [(t, m.pose.position) for t, m in rec.get("/nav_goal")])
    _draw_track(ax_track, run)
    _draw_depth(ax_depth, run)
    _draw_altitude(ax_alt, run)
    _draw_commands(ax_rpm, ax_ang, ax_pct, run)
    _draw_battery(ax_bat, run)
    _draw_states(ax_state, run)
    ax_state.set_xlabel("time since the recording began [s]")
    for ax in (ax_depth, ax_alt, ax_rpm, ax_ang, ax_pct, ax_bat):
        if ax.has_data():
            ax.set_xlabel("time [s]")
            ax.set_xlim(0, end)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    plt.close(fig)
    return out
