"""The picture's state panels, from /diagnostics and /abort (issue 30): the abort and each node's state, each
device's health as the bridge saw its heartbeats, and the bridge's drop counters.

- One colour per state in every panel (plot_support: OK, WARN, ERROR, STALE, the abort, a managed bridge inactive),
  one legend under the panels.
- Names are the spec's: a namespaced run's statuses without the namespace, another vehicle's left out
  (sam_runtime.common.run_names.spec_status_name).
- Drops: each mapping's ``dropped`` count over time (cumulative, as the bridge reports it), those that dropped
  anything by name with their reasons at the end; the bridge's total when none did, so an empty panel says "0".
"""

from __future__ import annotations

from typing import Any

from sam_runtime.common.run_names import spec_status_name
from sam_runtime.report.plot_support import (
    ABORT_COLOUR,
    INACTIVE_COLOUR,
    LEVELS,
    STYLES,
    Run,
    not_recorded,
    shade_aborts,
)
from sam_runtime.report.recording import Recording

__all__ = ["INACTIVE", "device_states", "draw_devices", "draw_drops", "draw_states", "drops", "held_spans",
           "node_states", "state_legend"]

INACTIVE = -1  # a managed bridge's status while it is not active (its level is OK: drawn in its own colour)
_DEVICE = "/device/"
_MAPPING = "/mapping/"


def _level(status: Any) -> int:
    return status.level[0] if isinstance(status.level, bytes | bytearray) else int(status.level)


def _statuses(rec: Recording) -> Any:
    """(t, the spec's name, status) of every status of the run's own (another vehicle's left out)."""
    for t, msg in rec.get("/diagnostics"):
        for status in msg.status:
            name = spec_status_name(rec.names, status.name)  # None: another vehicle's (shared /diagnostics)
            if name is not None:
                yield t, name, status


def node_states(rec: Recording) -> dict[str, list[tuple[float, int]]]:
    """Each node's (and the bridge's) levels over time from /diagnostics, by the spec's name: a namespaced run's
    statuses (sam1/controller) without the namespace, another vehicle's and the per-mapping statuses left out. A
    managed bridge that is not active is :data:`INACTIVE` (its ``active`` value False)."""
    rows: dict[str, list[tuple[float, int]]] = {}
    for t, name, status in _statuses(rec):
        if "/" not in name:  # the nodes and the bridge itself, not per-mapping or per-device statuses
            level = _level(status)
            if level == 0 and any(kv.key == "active" and kv.value == "False" for kv in status.values):
                level = INACTIVE
            rows.setdefault(name, []).append((t, level))
    return rows


def device_states(rec: Recording) -> dict[str, list[tuple[float, int]]]:
    """Each device's level over time as the bridge reports it (``<bridge>/device/<name>``: OK while its heartbeat
    is fresh and its health nominal, ERROR when lost or unhealthy, STALE never heard), by device name (with the
    bridge's name when a mixed layout's two bridges report)."""
    rows: dict[str, list[tuple[float, int]]] = {}
    bridges = set()
    found: list[tuple[float, str, str, int]] = []
    for t, name, status in _statuses(rec):
        if _DEVICE in name:
            bridge, device = name.split(_DEVICE, 1)
            bridges.add(bridge)
            found.append((t, bridge, device, _level(status)))
    for t, bridge, device, level in found:
        rows.setdefault(device if len(bridges) == 1 else f"{bridge}: {device}", []).append((t, level))
    return rows


def drops(rec: Recording) -> tuple[dict[str, list[tuple[float, int]]], dict[str, dict[str, int]],
                                   list[tuple[float, int]]]:
    """(each mapping's (t, dropped) samples, each mapping's last drops by reason, the bridges' (t, total))."""
    series: dict[str, list[tuple[float, int]]] = {}
    reasons: dict[str, dict[str, int]] = {}
    total: dict[float, int] = {}
    for t, name, status in _statuses(rec):
        values = {kv.key: kv.value for kv in status.values}
        try:
            if _MAPPING in name:
                mapping = name.split(_MAPPING, 1)[1]
                series.setdefault(mapping, []).append((t, int(values.get("dropped", 0))))
                reasons[mapping] = {k[len("dropped."):]: int(v) for k, v in values.items()
                                    if k.startswith("dropped.")}
            elif "/" not in name and "dropped_total" in values:
                total[t] = total.get(t, 0) + int(values["dropped_total"])
        except ValueError:  # a value that is no count: not this panel's business
            continue
    return series, reasons, sorted(total.items())


def _bars(ax: Any, rows: dict[str, list[tuple[float, int]]], names: list[str], end: float) -> None:
    """One row of coloured spans per name. A state held over many samples is one span, and a row's spans of one
    colour are one call: a long run has thousands of samples, and one call each made the picture take minutes."""
    colours = {**{level: colour for level, (_, colour) in LEVELS.items()}, INACTIVE: INACTIVE_COLOUR}
    for k, name in enumerate(names):
        spans: dict[str, list[tuple[float, float]]] = {}
        for a, b, level in held_spans(rows[name], end):
            spans.setdefault(colours.get(level, "#000000"), []).append((a, max(b - a, 0.01)))
        for colour, xranges in spans.items():
            ax.broken_barh(xranges, (k - 0.4, 0.8), color=colour, lw=0)


def held_spans(samples: list[tuple[float, int]], end: float) -> list[tuple[float, float, int]]:
    """(from, to, level) for each stretch of one level: each sample holds until the next, the last until end."""
    held: list[tuple[float, float, int]] = []
    ends = [t for t, _ in samples[1:]] + [end] if samples else []
    for (a, level), b in zip(samples, ends, strict=True):
        if held and held[-1][2] == level:  # the stretch before ends where this sample starts: extend it
            held[-1] = (held[-1][0], b, level)
        else:
            held.append((a, b, level))
    return held


def state_legend(fig: Any, y: float) -> None:
    """One legend of the states' colours for the state panels, centred under them at figure height ``y``."""
    from matplotlib.patches import Patch

    handles = [Patch(color=c, label=n) for n, c in LEVELS.values()]
    handles += [Patch(color=ABORT_COLOUR, label="abort active"),
                Patch(color=INACTIVE_COLOUR, label="bridge inactive (lifecycle)")]
    fig.legend(handles=handles, loc="center", bbox_to_anchor=(0.5, y), ncol=len(handles), fontsize=9,
               frameon=False)


def draw_states(ax: Any, run: Run) -> None:
    rec, spans, end = run.rec, run.spans, run.end
    ax.set_title("Abort (/abort) and node states (/diagnostics)")
    rows = node_states(rec)
    names = sorted(rows)
    if not rows and not rec.get("/abort"):
        not_recorded(ax, "/abort and /diagnostics")
        return
    _bars(ax, rows, names, end)
    k = len(names)
    if rec.get("/abort"):
        for a, b, reason in spans:
            ax.broken_barh([(a, max(b - a, 0.01))], (k - 0.4, 0.8), color=ABORT_COLOUR, lw=0)
            ax.text(a, k + 0.45, f" {reason}"[:90], fontsize=8, va="bottom", color=ABORT_COLOUR)
        if not spans:
            ax.text(0.0, k, "  no abort", va="center", fontsize=8, color="#2e8b57")
    else:
        ax.text(0.0, k, "  /abort not recorded", va="center", fontsize=8, color="#7f8c8d")
    if not names:
        ax.text(0.5, 0.5, "/diagnostics not recorded", transform=ax.transAxes, ha="center", color="#7f8c8d")
    ax.set_yticks(range(k + 1), [*names, "abort"], fontsize=9)
    ax.set_ylim(-0.7, k + 1.2)
    ax.set_xlim(0, end)
    ax.grid(axis="x", alpha=0.3)


def draw_devices(ax: Any, run: Run) -> None:
    ax.set_title("Device health (the bridge's /diagnostics: heartbeats)")
    rows = device_states(run.rec)
    if not rows:
        not_recorded(ax, "the bridge's device statuses (/diagnostics)")
        return
    names = sorted(rows)
    _bars(ax, rows, names, run.end)
    ax.set_yticks(range(len(names)), names, fontsize=8)
    ax.set_ylim(-0.7, len(names) - 0.3)
    ax.set_xlim(0, run.end)
    ax.grid(axis="x", alpha=0.3)


def draw_drops(ax: Any, run: Run) -> None:
    ax.set_title("Bridge drops per mapping (/diagnostics, cumulative)")
    series, reasons, total = drops(run.rec)
    if not series and not total:
        not_recorded(ax, "the bridge's statuses (/diagnostics)")
        return
    dropping = sorted((m for m, s in series.items() if s and s[-1][1] > 0), key=lambda m: -series[m][-1][1])
    for k, mapping in enumerate(dropping):
        samples = series[mapping]
        why = ", ".join(f"{r} {n}" for r, n in sorted(reasons.get(mapping, {}).items(), key=lambda i: -i[1]) if n)
        style, width = STYLES[k % len(STYLES)]
        ax.step([t for t, _ in samples], [n for _, n in samples], where="post", ls=style, lw=width,
                label=f"{mapping}: {samples[-1][1]}" + (f" ({why})" if why else ""))
    if not dropping:
        if total:
            ax.step([t for t, _ in total], [n for _, n in total], where="post", color="#2e8b57", lw=1.6,
                    label="all mappings")
        ax.text(0.5, 0.6, f"no drops in {len(series)} mappings", transform=ax.transAxes, ha="center",
                color="#2e8b57", fontsize=11)
        ax.set_ylim(-0.5, 5)
    ax.set_ylabel("messages dropped")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.8)
    shade_aborts(ax, run.spans)
