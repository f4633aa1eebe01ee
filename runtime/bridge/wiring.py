"""From the generated tables and converters to the bridge's run-time mappings: each mapping's converter, its ROS
message class and DSDL class; the UAVCAN -> ROS mappings grouped by port (one subscription per port, named after
its first mapping: sam_runtime.cyphal_ports.subscription_names); the ROS -> UAVCAN destinations checked against the
devices."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from sam_runtime.cyphal_ports import subscription_names

from .backend import BridgeConfigError
from .counters import MappingStats, log
from .inbound import InMapping, PortGroup
from .loss import TransferLoss
from .outbound import OutMapping

__all__ = ["check_destinations", "find_converter", "in_groups", "nominal_rates", "out_mappings"]


def find_converter(convert: Any, m: Any, which: int) -> Callable[..., Any]:
    """The generated converter of mapping ``m``: ``which`` 0 = to ROS, 1 = to UAVCAN."""
    fname = m.to_ros if which == 0 else m.to_uavcan
    fn = getattr(convert, fname, None) if fname else None
    converters = getattr(convert, "CONVERTERS", {})
    if fn is None and m.name in converters:
        fn = converters[m.name][which]
    if fn is None:
        raise BridgeConfigError(f"the generated converters have no {fname or m.name!r} for mapping {m.name}")
    return fn


def check_destinations(tables: Any) -> None:
    """Warn about a ROS -> UAVCAN mapping whose destination is no device, or does not subscribe to its subject."""
    devices = {d.node_id: d for d in tables.DEVICES}
    for m in tables.MAPPINGS:
        if m.direction == "ros_to_uavcan" and m.destination_node_id is not None:
            dev = devices.get(m.destination_node_id)
            if dev is None:
                log.warning("mapping %s: destination node %s is no device of the spec", m.name, m.destination_node_id)
            elif all(p.subject_id != m.port.subject_id for p in dev.subscribes):
                log.warning("mapping %s: destination %s (node %d) does not subscribe to subject %d",
                            m.name, dev.name, dev.node_id, m.port.subject_id)


def nominal_rates(tables: Any) -> dict[tuple[int, int], float]:
    """(device node id, subject id) -> the spec's nominal rate of what the device publishes."""
    return {(d.node_id, p.subject_id): float(p.rate_hz) for d in tables.DEVICES for p in d.publishes
            if getattr(p, "rate_hz", None)}


def _has_header(ros_cls: Any) -> bool:
    return "header" in getattr(ros_cls, "get_fields_and_field_types", dict)()


def in_groups(gen: Any, convert: Any, counters: Mapping[str, MappingStats],
              make_loss: Callable[[int], TransferLoss]) -> list[PortGroup]:
    """The UAVCAN -> ROS mappings, one group per port, in the tables' order."""
    tables = gen.tables()
    names = subscription_names(tables.MAPPINGS)
    groups: dict[int, PortGroup] = {}
    for m in tables.MAPPINGS:
        if m.direction not in ("uavcan_to_ros", "ros_to_uavcan"):
            raise BridgeConfigError(f"mapping {m.name}: unknown direction {m.direction!r}")
        if m.direction != "uavcan_to_ros":
            continue
        dtype = gen.dsdl_class(m.port)
        sid = m.port.subject_id
        group = groups.get(sid)
        if group is None:
            group = groups[sid] = PortGroup(sid, names[sid], dtype, [], make_loss(sid))
        elif group.dtype is not dtype:
            raise BridgeConfigError(f"subject {sid} has two types: {group.dtype} and {m.port.dsdl_type}")
        ros_cls = gen.ros_class(m.topic)
        group.mappings.append(InMapping(m, find_converter(convert, m, 0), counters[m.name], ros_cls,
                                        has_header=_has_header(ros_cls)))
    return list(groups.values())


def out_mappings(gen: Any, convert: Any, counters: Mapping[str, MappingStats]) -> list[OutMapping]:
    """The ROS -> UAVCAN mappings, in the tables' order."""
    return [OutMapping(m, find_converter(convert, m, 1), counters[m.name], gen.ros_class(m.topic),
                       gen.dsdl_class(m.port)) for m in gen.tables().MAPPINGS if m.direction == "ros_to_uavcan"]
