/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board battery of sam.
 * Battery management system.
 *
 * Protocols: cyphal, dronecan. Report SAM_BATTERY_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_BATTERY_H
#define SAM_BATTERY_H

#include <stdint.h>

#define SAM_BATTERY_NODE_ID 15u
#define SAM_BATTERY_INTERFACE_HASH UINT64_C(0xdd92abd4cbac74ed)  /* sam-interface-1: report it as it is */
#define SAM_BATTERY_INTERFACE_HASH_BYTES {0xddu, 0x92u, 0xabu, 0xd4u, 0xcbu, 0xacu, 0x74u, 0xedu}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_BATTERY_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_BATTERY_CYPHAL_PUB_SAM_POWER_BATTERYINFO_SUBJECT_ID 1104u  /* sam.power.BatteryInfo.0.1 at 1 Hz */
#define SAM_BATTERY_CYPHAL_PUB_SAM_POWER_BATTERYINFO_TYPE "sam.power.BatteryInfo.0.1"
#define SAM_BATTERY_DRONECAN_PUB_UAVCAN_EQUIPMENT_POWER_BATTERYINFO_DATA_TYPE_ID 1092u  /* uavcan.equipment.power.BatteryInfo at 1 Hz */
#define SAM_BATTERY_DRONECAN_PUB_UAVCAN_EQUIPMENT_POWER_BATTERYINFO_SIGNATURE UINT64_C(0x249c26548a711966)
#define SAM_BATTERY_DRONECAN_PUB_UAVCAN_EQUIPMENT_POWER_BATTERYINFO_TYPE "uavcan.equipment.power.BatteryInfo"

#endif /* SAM_BATTERY_H */
