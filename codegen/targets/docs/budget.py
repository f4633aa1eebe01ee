"""The CAN bus budget part of the interface reference: each layout's predicted frames/s and load per node and for the
whole bus (the figures of sam_codegen.validate.bus_budget, which `build` also prints and checks).

Invariants: every figure is computed from the resolved spec alone (same spec, same text); the section is left out for
a spec without devices; loads are rounded to 0.1 %, rates to 0.1 frame/s.
"""

from __future__ import annotations

from sam_codegen.validate.bus_budget import (
    DEFAULT_FD_DATA_BITRATE,
    LayoutBudget,
    Transfer,
    classic_frame_bits,
    layout_budgets,
)
from sam_codegen.validate.resolve import Resolved

__all__ = ["budget_context", "resolved_budgets"]


def resolved_budgets(resolved: Resolved, *, fd: bool | None = None) -> list[LayoutBudget]:
    """The budget of every layout of a resolved spec, on its bus (``fd``: see layout_budgets)."""
    v0 = resolved.dronecan
    return layout_budgets(resolved.spec, resolved.layouts,
                          {"cyphal": resolved.mappings, "dronecan": resolved.dronecan_mappings},
                          resolved.dsdl.get, v0.get if v0 is not None else lambda _: None, fd=fd)


def _rate(value: float) -> str:
    return f"{value:,.1f}".removesuffix(".0")


def _percent(fraction: float) -> str:
    return f"{100 * fraction:.1f} %"


def _message(t: Transfer, budget: LayoutBudget) -> str:
    frames = t.frame_count(budget.bus)
    hz = f"{t.rate_hz:g} Hz"
    return f"{t.type} at {hz}: {t.payload_bytes} B, {frames} frame{'s' if frames != 1 else ''}"


def budget_context(resolved: Resolved) -> dict[str, object]:
    if not resolved.spec.devices:
        return {"bus_budget": None}
    declared = resolved_budgets(resolved)
    if not declared:  # `bus: none`
        return {"bus_budget": None}
    other = resolved_budgets(resolved, fd=not any(b.bus.fd for b in declared))
    layouts = []
    for budget, alternative in zip(declared, other, strict=True):
        layouts.append({
            "name": budget.layout, "bus": budget.bus.describe(), "frames": _rate(budget.frames_per_s),
            "load": _percent(budget.load), "worst": _percent(budget.load_worst_case), "verdict": budget.verdict,
            "alternative": f"{_rate(alternative.frames_per_s)} frames/s, {_percent(alternative.load)} "
                           f"({_percent(alternative.load_worst_case)}) on {alternative.bus.describe()}",
            "nodes": [{"name": n.name, "node_id": n.node_id, "protocol": n.protocol,
                       "messages": [_message(t, budget) for t in n.transfers],
                       "frames": _rate(n.frames_per_s(budget.bus)), "load": _percent(n.load(budget.bus))}
                      for n in budget.nodes],
        })
    return {"bus_budget": {
        "layouts": layouts, "warning_percent": f"{declared[0].bus.warning_percent:g}",
        "fd_default": f"{DEFAULT_FD_DATA_BITRATE / 1e6:g} Mbit/s",
        "frame_bits": classic_frame_bits(8), "frame_bits_worst": classic_frame_bits(8, worst_case=True),
        "frames_1m": f"{1e6 / classic_frame_bits(8):,.0f}",
        "frames_1m_worst": f"{1e6 / classic_frame_bits(8, worst_case=True):,.0f}",
    }}
