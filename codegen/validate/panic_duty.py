"""`bridge.panic_duty`: who handles `uavcan.protocol.Panic` on DroneCAN, the bridge's built-in duty or the spec's own
mappings of it, or both.

The built-in duty (sam_runtime.bridge.backends.dronecan_duties) publishes every Panic of the bus on
`/<bridge>/panic_received` and broadcasts a message of `/<bridge>/panic` as Panic three times. A dronecan mapping of
Panic is an ordinary mapping onto topics the spec names. Invariant: a spec with a mapping of Panic says which of the
two handle it (`mappings`: the built-in duty is off; `both`), so that nothing changes silently when such a mapping is
added; `mappings` without any mapping of Panic, and a mapping on one of the built-in duty's own topics beside it, are
errors.
"""

from __future__ import annotations

from sam_codegen.model.diagnostics import Diagnostics
from sam_codegen.model.spec import Spec

__all__ = ["BOTH", "BUILTIN", "MAPPINGS", "PANIC", "PANIC_DUTIES", "builtin_topics", "check_panic_duty", "panic_duty"]

PANIC = "uavcan.protocol.Panic"
BUILTIN, MAPPINGS, BOTH = "builtin", "mappings", "both"
PANIC_DUTIES = (BUILTIN, MAPPINGS, BOTH)


def builtin_topics(bridge_name: str) -> tuple[str, ...]:
    """The topics of the built-in duty: its ROS node is the bridge's name (`<name>_dronecan` in a mixed layout).

    >>> builtin_topics("br")
    ('/br/panic', '/br/panic_received', '/br_dronecan/panic', '/br_dronecan/panic_received')
    """
    return tuple(f"/{node}/{topic}" for node in (bridge_name, f"{bridge_name}_dronecan")
                 for topic in ("panic", "panic_received"))


def panic_duty(spec: Spec) -> str:
    """Who handles Panic in a valid spec: the declared `panic_duty`, else the built-in duty."""
    declared = spec.bridge.panic_duty if spec.bridge is not None else None
    return declared if declared is not None and declared in PANIC_DUTIES else BUILTIN


def check_panic_duty(spec: Spec, diag: Diagnostics) -> None:
    bridge = spec.bridge
    if bridge is None:
        return
    duty = bridge.panic_duty
    mappings = [m for m in bridge.dronecan_mappings if m.data_type == PANIC]
    topics = builtin_topics(bridge.name)
    shown = f"/{bridge.name}/panic, /{bridge.name}/panic_received"
    if duty is not None and duty not in PANIC_DUTIES:
        diag.error(bridge.panic_duty_pos, f"panic_duty {duty!r} of the bridge is unknown",
                   "builtin (the bridge's built-in Panic duty), mappings (the spec's mappings of "
                   f"{PANIC} instead) or both")
        return
    if duty is None:
        for m in mappings[:1]:  # one error says it
            diag.error(m.pos, f"DroneCAN mapping {m.name!r} maps {PANIC}, which the bridge's built-in Panic duty "
                       f"({shown}) handles too: the spec must say which handles it",
                       "`panic_duty: mappings` in bridge (the mappings instead of the built-in duty) or "
                       "`panic_duty: both`")
    elif duty == BUILTIN and mappings:
        diag.error(bridge.panic_duty_pos, f"panic_duty builtin leaves {PANIC} to the bridge's built-in duty, but "
                   f"DroneCAN mapping {mappings[0].name!r} maps it", "`panic_duty: mappings` or `panic_duty: both`")
    elif duty == MAPPINGS and not mappings:
        diag.error(bridge.panic_duty_pos, f"panic_duty mappings turns the bridge's built-in Panic duty off, but no "
                   f"DroneCAN mapping maps {PANIC}: nothing would send or receive Panic",
                   f"a dronecan_mappings entry with `data_type: {PANIC}`, or `panic_duty: builtin`")
    if duty == BOTH:
        for m in mappings:
            if m.topic in topics:
                diag.error(m.pos, f"DroneCAN mapping {m.name!r} uses topic {m.topic}, one of the bridge's built-in "
                           "Panic duty", "a topic of its own, or `panic_duty: mappings` (the built-in duty off)")
