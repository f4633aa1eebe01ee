/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board ballast of sam.
 * The two ballast weights.
 *
 * Protocols: cyphal, dronecan. Report SAM_BALLAST_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_BALLAST_H
#define SAM_BALLAST_H

#include <stdint.h>

#define SAM_BALLAST_NODE_ID 24u
#define SAM_BALLAST_INTERFACE_HASH UINT64_C(0x6f1b373e3940c462)  /* sam-interface-1: report it as it is */
#define SAM_BALLAST_INTERFACE_HASH_BYTES {0x6fu, 0x1bu, 0x37u, 0x3eu, 0x39u, 0x40u, 0xc4u, 0x62u}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_BALLAST_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_BALLAST_CYPHAL_SUB_SAM_ACTUATOR_BALLASTANGLES_SUBJECT_ID 1203u  /* sam.actuator.BallastAngles.0.1 at 10 Hz */
#define SAM_BALLAST_CYPHAL_SUB_SAM_ACTUATOR_BALLASTANGLES_TYPE "sam.actuator.BallastAngles.0.1"
#define SAM_BALLAST_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_DATA_TYPE_ID 1010u  /* uavcan.equipment.actuator.ArrayCommand at 10 Hz */
#define SAM_BALLAST_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_SIGNATURE UINT64_C(0xd8a7486238ec3af3)
#define SAM_BALLAST_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_TYPE "uavcan.equipment.actuator.ArrayCommand"

#endif /* SAM_BALLAST_H */
