"""From the generated tables and converters to the bridge's run-time mappings: each mapping's converter, its ROS
message class and DSDL class; the UAVCAN -> ROS mappings grouped by port (one subscription per port, named after
its first mapping: sam_runtime.cyphal_io.ports.subscription_names); the ROS -> UAVCAN destinations checked against the
devices."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from sam_codegen.model.spec import DIRECTIONS, ROS_TO_UAVCAN, UAVCAN_TO_ROS
from sam_runtime.bridge.backend import BridgeConfigError
from sam_runtime.bridge.counters import MappingStats, log
from sam_runtime.bridge.inbound import InMapping, PortGroup
from sam_runtime.bridge.layout import destinations_of, port_id_of
from sam_runtime.bridge.loss import TransferLoss
from sam_runtime.bridge.outbound import OutMapping
from sam_runtime.cyphal_io.ports import subscription_names

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule

__all__ = ["check_destinations", "codec_gaps", "find_converter", "in_groups", "missing_codecs", "nominal_rates",
           "out_mappings", "writes_header"]


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


def check_destinations(tables: TablesModule, mappings: Sequence[Any] | None = None,
                       devices: Sequence[Any] | None = None) -> None:
    """Warn about a ROS -> UAVCAN mapping whose destination is no device, or does not subscribe to its port (the
    subject, or the DroneCAN data type)."""
    by_id = {d.node_id: d for d in (tables.DEVICES if devices is None else devices)}
    for m in tables.MAPPINGS if mappings is None else mappings:
        if m.direction != ROS_TO_UAVCAN:
            continue
        port, what = (m.data_type.name, "data type") if hasattr(m, "data_type") else (m.port.subject_id, "subject")
        for nid in destinations_of(m):
            dev = by_id.get(nid)
            if dev is None:
                log.warning("mapping %s: destination node %s is no device of the spec", m.name, nid)
            elif all(_port_key(p) != port for p in dev.subscribes):
                log.warning("mapping %s: destination %s (node %d) does not subscribe to %s %s",
                            m.name, dev.name, dev.node_id, what, port)


def _port_key(p: Any) -> Any:
    return p.data_type.name if hasattr(p, "data_type") else p.subject_id


def _port_id(p: Any) -> int:
    return int(p.data_type.data_type_id) if hasattr(p, "data_type") else int(p.subject_id)


def nominal_rates(tables: TablesModule, devices: Sequence[Any] | None = None) -> dict[tuple[int, int], float]:
    """(device node id, port id) -> the spec's nominal rate of what the device publishes (port id: the subject id,
    or the DroneCAN data type id)."""
    return {(d.node_id, _port_id(p)): float(p.rate_hz) for d in (tables.DEVICES if devices is None else devices)
            for p in d.publishes if getattr(p, "rate_hz", None)}


def writes_header(ros_cls: Any, m: Any = None) -> bool:
    """Whether the bridge stamps and frames the message's header. Not when the spec leaves it at its default
    (`ros_defaults: [header]`, issue 27: zero stamp, empty frame id, as the C++ it replaces): the one way a
    UAVCAN -> ROS mapping into a message with a header has no frame_id (validation refuses any other; an empty
    frame id is '')."""
    if m is not None and getattr(m, "frame_id", "") is None:
        return False
    return "header" in getattr(ros_cls, "get_fields_and_field_types", dict)()


def _dtype(gen: Any, m: Any) -> Any:
    """The port's type: the pycyphal class, or the DroneCAN type's full name (the backend looks it up at every open:
    dronecan.load_dsdl replaces the type objects)."""
    return m.data_type.name if hasattr(m, "data_type") else gen.dsdl_class(m.port)


def missing_codecs(codec: Any, mappings: Sequence[Any]) -> list[str]:
    """The mappings the generated codec module has no codecs for (all of them when there is no module)."""
    have = getattr(codec, "CODECS", {})
    return [m.name for m in mappings if m.name not in have]


def in_groups(gen: Any, convert: Any, counters: Mapping[str, MappingStats],
              make_loss: Callable[[int], TransferLoss], mappings: Sequence[Any] | None = None, codec: Any = None
              ) -> list[PortGroup]:
    """The UAVCAN -> ROS mappings, one group per port, in the tables' order; with ``codec`` (the generated wire
    codecs) on the wire path."""
    tables = gen.tables()
    mappings = tables.MAPPINGS if mappings is None else mappings
    names = subscription_names(mappings)
    matches = getattr(convert, "MATCHES", {})
    wire_matches = getattr(codec, "WIRE_MATCHES", {})
    groups: dict[int, PortGroup] = {}
    for m in mappings:
        if m.direction not in DIRECTIONS:
            raise BridgeConfigError(f"mapping {m.name}: unknown direction {m.direction!r}")
        if m.direction != UAVCAN_TO_ROS:
            continue
        dtype = _dtype(gen, m)
        pid = port_id_of(m)
        group = groups.get(pid)
        if group is None:
            group = groups[pid] = PortGroup(pid, names[pid], dtype, [], make_loss(pid))
        elif group.dtype is not dtype and group.dtype != dtype:
            raise BridgeConfigError(f"port {pid} has two types: {group.dtype} and {dtype}")
        ros_cls = gen.ros_class(m.topic)
        if codec is not None:
            group.mappings.append(InMapping(m, codec.CODECS[m.name][0], counters[m.name], ros_cls,
                                            has_header=writes_header(ros_cls, m), matches=wire_matches.get(m.name),
                                            raw=True))
            continue
        match = matches.get(m.name)
        group.mappings.append(InMapping(m, find_converter(convert, m, 0), counters[m.name], ros_cls,
                                        has_header=writes_header(ros_cls, m),
                                        matches=None if match is None or match.__name__ == "_always" else match))
    return list(groups.values())


def out_mappings(gen: Any, convert: Any, counters: Mapping[str, MappingStats],
                 mappings: Sequence[Any] | None = None, codec: Any = None) -> list[OutMapping]:
    """The ROS -> UAVCAN mappings, in the tables' order; with ``codec`` (the generated wire codecs) on the wire
    path."""
    return [OutMapping(m, codec.CODECS[m.name][1] if codec is not None else find_converter(convert, m, 1),
                       counters[m.name], gen.ros_class(m.topic), _dtype(gen, m), raw=codec is not None)
            for m in (gen.tables().MAPPINGS if mappings is None else mappings) if m.direction == ROS_TO_UAVCAN]


def codec_gaps(codec: Any, missing: Sequence[str]) -> str:
    """Why the codec module has no codecs for `missing`: the reasons it gives (OBJECT_ONLY: constructs the wire
    codecs do not render yet), else an older build."""
    reasons = getattr(codec, "OBJECT_ONLY", {})
    known = [f"{name} ({reasons[name]})" for name in missing if name in reasons]
    stale = [name for name in missing if name not in reasons]
    parts = []
    if known:
        parts.append("; ".join(known))
    if stale or codec is None:
        parts.append(("any mapping" if codec is None else ", ".join(stale))
                     + " (built by an older sam-codegen? run `sam-codegen build`)")
    return "; ".join(parts)
