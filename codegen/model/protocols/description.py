"""What the generator and the runtime know of one protocol: a frozen description, data only (standard library).

Every place that used to compare a protocol's name (``== "dronecan"``) asks its entry instead, so a protocol is one
entry in registry.py. The runtime's part of an entry (backend, simulated devices, recording) is
sam_runtime.protocols; the names of the generated tables here are the contract of templates/python/tables.py.j2.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ProtocolDescription"]


@dataclass(frozen=True)
class ProtocolDescription:
    """One protocol, as the spec, the validation, the generated tables and the docs see it."""

    name: str  # the spec's spelling: a device's `protocol`, a layout's, a service mapping's
    label: str  # for people: "Cyphal", "DroneCAN"
    v0: bool  # UAVCAN v0 (DroneCAN): data types without subject ids, DSDL v0 signatures, classic CAN frames only
    mappings_key: str  # the bridge section's key of its topic mappings
    mapping_noun: str  # what a diagnostic calls one of them: "mapping", "DroneCAN mapping"
    liveness_type: str  # the message every node sends once a second (its heartbeat)
    node_ids: range  # the node ids a device may take
    transfer_id_modulo: int  # transfer ids count modulo this
    codec_package: str  # the generated package's wire codec module
    mappings_table: str  # the generated tables.py's names: the topic mappings,
    devices_table: str  # the devices' firmware on this protocol,
    device_stamped_table: str  # the mappings whose stamps come from the device's clock,
    layout_mappings_field: str  # and the LayoutInfo field of the layout's mappings on this protocol
    can_fd: bool  # its frames use CAN FD's data phase when the bus has one
    # A board's settings (model.device_params): what one is called ("register", "parameter"), how its name is
    # checked and derived from the spec's name ("register": uavcan.register naming, the spec's name as it is;
    # "upper": printable ASCII, the spec's name upper-cased), the longest name and string value the protocol carries.
    setting_noun: str = "parameter"
    setting_name_style: str = "register"
    setting_name_max: int = 255
    setting_string_max: int = 256
