/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board longitudinal_weight of sam.
 * Longitudinal trim weight.
 *
 * Protocols: cyphal, dronecan. Report SAM_LONGITUDINAL_WEIGHT_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_LONGITUDINAL_WEIGHT_H
#define SAM_LONGITUDINAL_WEIGHT_H

#include <stdint.h>

#define SAM_LONGITUDINAL_WEIGHT_NODE_ID 25u
#define SAM_LONGITUDINAL_WEIGHT_INTERFACE_HASH UINT64_C(0xe0f208d469bd0b99)  /* sam-interface-1: report it as it is */
#define SAM_LONGITUDINAL_WEIGHT_INTERFACE_HASH_BYTES {0xe0u, 0xf2u, 0x08u, 0xd4u, 0x69u, 0xbdu, 0x0bu, 0x99u}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_LONGITUDINAL_WEIGHT_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_LONGITUDINAL_WEIGHT_CYPHAL_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_SUBJECT_ID 1304u  /* sam.actuator.PositionFeedback.0.1 at 10 Hz */
#define SAM_LONGITUDINAL_WEIGHT_CYPHAL_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_TYPE "sam.actuator.PositionFeedback.0.1"
#define SAM_LONGITUDINAL_WEIGHT_CYPHAL_SUB_SAM_ACTUATOR_PERCENTCOMMAND_SUBJECT_ID 1204u  /* sam.actuator.PercentCommand.0.1 at 10 Hz */
#define SAM_LONGITUDINAL_WEIGHT_CYPHAL_SUB_SAM_ACTUATOR_PERCENTCOMMAND_TYPE "sam.actuator.PercentCommand.0.1"
#define SAM_LONGITUDINAL_WEIGHT_DRONECAN_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_DATA_TYPE_ID 20102u  /* sam.actuator.PositionFeedback at 10 Hz */
#define SAM_LONGITUDINAL_WEIGHT_DRONECAN_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_SIGNATURE UINT64_C(0x4f9415770af42bd6)
#define SAM_LONGITUDINAL_WEIGHT_DRONECAN_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_TYPE "sam.actuator.PositionFeedback"
#define SAM_LONGITUDINAL_WEIGHT_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_DATA_TYPE_ID 1010u  /* uavcan.equipment.actuator.ArrayCommand at 10 Hz */
#define SAM_LONGITUDINAL_WEIGHT_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_SIGNATURE UINT64_C(0xd8a7486238ec3af3)
#define SAM_LONGITUDINAL_WEIGHT_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_TYPE "uavcan.equipment.actuator.ArrayCommand"

#endif /* SAM_LONGITUDINAL_WEIGHT_H */
