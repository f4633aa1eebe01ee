"""The `bridge.time_sync:` key: the bridge as the bus's time-synchronisation master, on both protocols (Cyphal
``uavcan.time.Synchronization.1.0`` on its fixed subject 7168, DroneCAN ``uavcan.protocol.GlobalTimeSync``).

    bridge:
      time_sync: {enabled: true, period_s: 0.5}   # the default when the key is absent
      time_sync: false                            # no master (devices stamp 0, "unknown", unless another node is one)

Invariants: absent means enabled at DEFAULT_PERIOD_S; ``true``/``false`` is short for ``{enabled: ...}``; the period is
a number of seconds within both protocols' limits, [MIN_PERIOD_S, MAX_PERIOD_S] (GlobalTimeSync's
MIN_BROADCASTING_PERIOD_MS 40 and Synchronization's MAX_PUBLICATION_PERIOD 1 s); a value out of range is an error
at its key. The default period leaves a slave's 1 s limit between two messages room for the master's jitter.
"""

from __future__ import annotations

from sam_codegen.frontend.reading import Reader, kind_of
from sam_codegen.frontend.yaml_source import YNode, YScalar
from sam_codegen.model.diagnostics import Diagnostics
from sam_codegen.model.spec import TimeSync

__all__ = ["DEFAULT_PERIOD_S", "MAX_PERIOD_S", "MIN_PERIOD_S", "TIME_SYNC_KEYS", "parse_time_sync"]

TIME_SYNC_KEYS = ("enabled", "period_s")
MIN_PERIOD_S, MAX_PERIOD_S = 0.04, 1.0
DEFAULT_PERIOD_S = 0.5


def parse_time_sync(node: YNode | None, what: str, diag: Diagnostics) -> TimeSync:
    """The time-sync settings of ``node`` (the default when absent or wrong; the errors are in ``diag``)."""
    if node is None:
        return TimeSync(True, DEFAULT_PERIOD_S)
    if isinstance(node, YScalar):
        if isinstance(node.value, bool):
            return TimeSync(node.value, DEFAULT_PERIOD_S, node.pos)
        diag.error(node.pos, f"{what} must be a mapping, true or false, found {kind_of(node)}",
                   "{enabled: true, period_s: 0.5}, true or false")
        return TimeSync(True, DEFAULT_PERIOD_S, node.pos)
    r = Reader(node, what, diag, TIME_SYNC_KEYS)
    enabled = r.get("enabled", bool, True)
    period = r.get("period_s", (int, float), DEFAULT_PERIOD_S)
    if period is not None and not MIN_PERIOD_S <= period <= MAX_PERIOD_S:
        diag.error(r.key_pos("period_s"), f"period_s {period} of {what} is out of range",
                   f"{MIN_PERIOD_S}..{MAX_PERIOD_S} s: DroneCAN GlobalTimeSync 40..1100 ms, Cyphal "
                   f"uavcan.time.Synchronization at most 1 s")
        period = None
    return TimeSync(True if enabled is None else bool(enabled), DEFAULT_PERIOD_S if period is None else float(period),
                    r.pos)
