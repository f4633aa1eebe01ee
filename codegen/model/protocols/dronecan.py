"""DroneCAN (UAVCAN v0) as the generator sees it."""

from __future__ import annotations

from sam_codegen.model.protocols.description import ProtocolDescription

__all__ = ["DRONECAN"]

DRONECAN = ProtocolDescription(
    name="dronecan", label="DroneCAN", v0=True, mappings_key="dronecan_mappings", mapping_noun="DroneCAN mapping",
    # 0 is anonymous, 126 and 127 are kept for maintenance tools
    liveness_type="uavcan.protocol.NodeStatus", node_ids=range(1, 126), transfer_id_modulo=32,
    codec_package="codec_v0", mappings_table="DRONECAN_MAPPINGS", devices_table="DRONECAN_DEVICES",
    device_stamped_table="DRONECAN_DEVICE_STAMPED_MAPPINGS", layout_mappings_field="dronecan_mappings", can_fd=False,
    # uavcan.protocol.param.GetSet: name uint8[<=92], Value.string_value uint8[<=128]
    setting_noun="parameter", setting_name_style="upper", setting_name_max=92, setting_string_max=128)
