"""What the picture's panels share (sam_runtime.report.plot and its panel modules): the run every panel draws from,
the colours of the states, the line styles that keep equal series visible, the "not recorded" note, the abort
shading, and the vehicle's poses from /tf.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from sam_runtime.common.run_names import spec_frame
from sam_runtime.report.recording import Recording
from sam_runtime.tf_buffer import Transform

__all__ = ["ABORT_COLOUR", "INACTIVE_COLOUR", "LEVELS", "STYLES", "Run", "finish", "lines", "not_recorded", "poses",
           "shade_aborts"]

# The diagnostic levels' colours; the abort's and a managed bridge's inactive state have their own, none shared.
LEVELS = {0: ("OK", "#2e8b57"), 1: ("WARN", "#f39c12"), 2: ("ERROR", "#c0392b"), 3: ("STALE", "#95a5a6")}
ABORT_COLOUR = "#6c3483"  # not ERROR's red: an abort and a node in ERROR are different facts
INACTIVE_COLOUR = "#5dade2"  # a managed bridge not active (commands dropped): not OK's green, though its level is OK
# Series of one panel may be equal (both thrusters commanded alike, their feedback alike): each its own dash pattern
# and width, the later ones thinner and drawn over the earlier, so that none hides another; a device's feedback also
# has sparse markers of its own shape.
STYLES = (("-", 2.4), ((0, (6, 3)), 1.6), ((0, (2, 2)), 1.2), ((0, (6, 2, 1, 2)), 1.0))
_MARKERS = ("o", "x", "^", "+", "s")
_MARKS_PER_SERIES = 40


@dataclass(frozen=True)
class Run:
    """What every panel draws from: the recording, its abort spans, its length and the parameter limits; the track
    (frame, (t, x, y, depth) points) and the goals (t, position) that the track and depth panels share; the poses
    (t, base_link in the track's frame) the attitude panel reads."""

    rec: Recording
    spans: list[tuple[float, float, str]]
    end: float
    limits: Mapping[str, float]
    frame: str
    points: list[tuple[float, float, float, float]]
    goals: list[tuple[float, Any]]
    poses: list[tuple[float, Transform]]


def _stamp_ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def poses(rec: Recording) -> tuple[str, list[tuple[float, Transform]]]:
    """(frame, [(t, pose)]): base_link in world (odom -> base_link after the latest world -> odom), or in odom when no
    world -> odom was recorded."""
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
    out = []
    k = -1
    for t, edge in odom_base:
        while k + 1 < len(world_odom) and world_odom[k + 1][0] <= t:
            k += 1
        if world_odom and k < 0:
            continue  # before the first world -> odom: no world position yet
        out.append((t, world_odom[k][1].compose(edge) if world_odom else edge))
    return frame, out


def not_recorded(ax: Any, what: str) -> None:
    ax.text(0.5, 0.5, f"{what}\nnot recorded", ha="center", va="center", transform=ax.transAxes, color="#7f8c8d",
            fontsize=11)
    ax.set_xticks([])
    ax.set_yticks([])


def shade_aborts(ax: Any, spans: list[tuple[float, float, str]]) -> None:
    for a, b, _ in spans:
        ax.axvspan(a, b, color=ABORT_COLOUR, alpha=0.08, lw=0)


def lines(ax: Any, rec: Recording, topic: str, fields: list[tuple[str, str]], *, scale: float = 1.0,
          feedback: bool = False) -> bool:
    """One line per field of ``topic``, each in the panel's next style (:data:`STYLES`); ``feedback``: a device's
    report, thinner, with sparse markers of the next shape, drawn over the commands."""
    items = rec.get(topic)
    if not items:
        return False
    t = [s for s, _ in items]
    for attr, label in fields:
        values = [float(getattr(m, attr)) * scale for _, m in items]
        k = len(ax.get_lines())
        style, width = STYLES[k % len(STYLES)]
        if feedback:
            marks = sum(1 for line in ax.get_lines() if line.get_marker() not in (None, "None", ""))
            ax.plot(t, values, label=label, ls=style, lw=min(width, 1.2), marker=_MARKERS[marks % len(_MARKERS)],
                    ms=4, markevery=max(1, len(values) // _MARKS_PER_SERIES), alpha=0.9)
        else:
            ax.plot(t, values, label=label, ls=style, lw=width)
    return True


def finish(ax: Any, ylabel: str, spans: list[tuple[float, float, str]], *, ncol: int = 1) -> None:
    """A drawn time panel's label, grid, legend and abort shading."""
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8, ncol=ncol, framealpha=0.8)
    shade_aborts(ax, spans)
