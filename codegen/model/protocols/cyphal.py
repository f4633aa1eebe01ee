"""Cyphal (UAVCAN v1) as the generator sees it."""

from __future__ import annotations

from sam_codegen.model.protocols.description import ProtocolDescription

__all__ = ["CYPHAL"]

CYPHAL = ProtocolDescription(
    name="cyphal", label="Cyphal", v0=False, mappings_key="mappings", mapping_noun="mapping",
    liveness_type="uavcan.node.Heartbeat.1.0", node_ids=range(0, 128), transfer_id_modulo=2**64,
    codec_package="codec", mappings_table="MAPPINGS", devices_table="DEVICES",
    device_stamped_table="DEVICE_STAMPED_MAPPINGS", layout_mappings_field="cyphal_mappings", can_fd=True,
    # uavcan.register.Access.1.0 / Name.1.0 (uint8[<256]) / Value.1.0's String.1.0 (uint8[<=256])
    setting_noun="register", setting_name_style="register", setting_name_max=255, setting_string_max=256)
