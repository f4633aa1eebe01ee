/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board pressure of sam.
 * Water pressure sensor.
 *
 * Protocols: cyphal, dronecan. Report SAM_PRESSURE_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_PRESSURE_H
#define SAM_PRESSURE_H

#include <stdint.h>

#define SAM_PRESSURE_NODE_ID 14u
#define SAM_PRESSURE_INTERFACE_HASH UINT64_C(0x536d8a2339c45079)  /* sam-interface-1: report it as it is */
#define SAM_PRESSURE_INTERFACE_HASH_BYTES {0x53u, 0x6du, 0x8au, 0x23u, 0x39u, 0xc4u, 0x50u, 0x79u}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_PRESSURE_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_PRESSURE_CYPHAL_PUB_SAM_SENSOR_STATICPRESSURE_SUBJECT_ID 1103u  /* sam.sensor.StaticPressure.0.1 at 20 Hz */
#define SAM_PRESSURE_CYPHAL_PUB_SAM_SENSOR_STATICPRESSURE_TYPE "sam.sensor.StaticPressure.0.1"
#define SAM_PRESSURE_DRONECAN_PUB_UAVCAN_EQUIPMENT_AIR_DATA_STATICPRESSURE_DATA_TYPE_ID 1028u  /* uavcan.equipment.air_data.StaticPressure at 20 Hz */
#define SAM_PRESSURE_DRONECAN_PUB_UAVCAN_EQUIPMENT_AIR_DATA_STATICPRESSURE_SIGNATURE UINT64_C(0xcdc7c43412bdc89a)
#define SAM_PRESSURE_DRONECAN_PUB_UAVCAN_EQUIPMENT_AIR_DATA_STATICPRESSURE_TYPE "uavcan.equipment.air_data.StaticPressure"

#endif /* SAM_PRESSURE_H */
