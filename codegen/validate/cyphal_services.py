"""A service mapping on Cyphal (`bridge.service_mappings` with `protocol: cyphal`): a ROS service the bridge serves
by a Cyphal request to one device.

Its service type is a spec `dsdl_types` entry with `request` and `response`, or a standard one of CYPHAL_PATH
(e.g. uavcan.node.GetInfo.1.0); its service id is the mapping's `service_id` (0..511), else the standard type's
fixed port id; the device is one with Cyphal ports (or a request field names the node). The field lines are
checked as on DroneCAN (validate.services); every error has its position and nothing follows from a reported one.
"""

from __future__ import annotations

from typing import Any

from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.spec import ServiceMapping
from sam_codegen.model.types import RosType

__all__ = ["CYPHAL_SERVICE_IDS", "resolve_cyphal_mapping"]

CYPHAL_SERVICE_IDS = range(0, 512)


def resolve_cyphal_mapping(v: Any, m: ServiceMapping, what: str) -> tuple[Any, list[Any], list[Any], int] | None:
    """`v`: the ServiceValidator (spec, dsdl, error, bad, links). Returns the srv, the request and response links
    and the service id, or None after reporting why."""
    s = v.spec
    srv = s.services.get(m.type)
    if srv is None:
        v.error(m.pos, f"unknown service type {m.type!r} of {what}",
                "a type of `services` or `external_services` (pkg/Name)")
    found = v.dsdl.service(m.data_type)
    service_id = m.service_id
    if found is None:
        message = ("is a message type" if v.dsdl.get(m.data_type) is not None
                   else "is not a Cyphal service type of dsdl_types or CYPHAL_PATH")
        v.error(m.pos, f"Cyphal type {m.data_type!r} of {what} {message}",
                "a service type by its versioned name, e.g. uavcan.node.GetInfo.1.0")
    else:
        if service_id is None:
            service_id = found[2]
        if service_id is None:
            v.error(m.pos, f"{what} needs a `service_id`: {m.data_type} has no fixed port id",
                    f"a service id, {CYPHAL_SERVICE_IDS.start}..{CYPHAL_SERVICE_IDS.stop - 1}")
        elif service_id not in CYPHAL_SERVICE_IDS:
            v.error(m.pos, f"service id {service_id} of {what} is not a Cyphal service id",
                    f"{CYPHAL_SERVICE_IDS.start}..{CYPHAL_SERVICE_IDS.stop - 1}")
            service_id = None
    if m.destination_field is not None:
        dest = next((f for f in srv.request if f.name == m.destination_field), None) if srv is not None else None
        if srv is not None and (dest is None or not isinstance(dest.type, RosType)
                                or dest.type.array or dest.type.base not in ("uint8", "uint16", "int32", "int64",
                                                                             "uint32", "uint64", "int16")):
            v.error(m.pos, f"destination_node_id {m.destination_field!r} of {what} is not an integer field of "
                    f"the srv request", "a node id, or the name of an integer field of the request")
            return None
    else:
        device = s.devices_by_node_id().get(m.destination_node_id)
        if device is None or CYPHAL.name not in device.protocols:
            v.error(m.pos, f"destination node id {m.destination_node_id} of {what} is not a Cyphal device",
                    "the node id of a device with Cyphal ports")
    if srv is None or found is None or service_id is None or srv.full_name in v.bad:
        return None
    request, response, _ = found
    links = v.links(m, what, srv, request.fields, response.fields, m.data_type)
    if links is None:
        return None
    return srv, links[0], links[1], service_id
