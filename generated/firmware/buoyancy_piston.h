/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board buoyancy_piston of sam.
 * Variable buoyancy piston.
 *
 * Protocols: cyphal, dronecan. Report SAM_BUOYANCY_PISTON_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_BUOYANCY_PISTON_H
#define SAM_BUOYANCY_PISTON_H

#include <stdint.h>

#define SAM_BUOYANCY_PISTON_NODE_ID 26u
#define SAM_BUOYANCY_PISTON_INTERFACE_HASH UINT64_C(0xaff974292348d87e)  /* sam-interface-1: report it as it is */
#define SAM_BUOYANCY_PISTON_INTERFACE_HASH_BYTES {0xafu, 0xf9u, 0x74u, 0x29u, 0x23u, 0x48u, 0xd8u, 0x7eu}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_BUOYANCY_PISTON_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_BUOYANCY_PISTON_CYPHAL_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_SUBJECT_ID 1305u  /* sam.actuator.PositionFeedback.0.1 at 10 Hz */
#define SAM_BUOYANCY_PISTON_CYPHAL_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_TYPE "sam.actuator.PositionFeedback.0.1"
#define SAM_BUOYANCY_PISTON_CYPHAL_SUB_SAM_ACTUATOR_PERCENTCOMMAND_SUBJECT_ID 1205u  /* sam.actuator.PercentCommand.0.1 at 10 Hz */
#define SAM_BUOYANCY_PISTON_CYPHAL_SUB_SAM_ACTUATOR_PERCENTCOMMAND_TYPE "sam.actuator.PercentCommand.0.1"
#define SAM_BUOYANCY_PISTON_DRONECAN_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_DATA_TYPE_ID 20102u  /* sam.actuator.PositionFeedback at 10 Hz */
#define SAM_BUOYANCY_PISTON_DRONECAN_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_SIGNATURE UINT64_C(0x4f9415770af42bd6)
#define SAM_BUOYANCY_PISTON_DRONECAN_PUB_SAM_ACTUATOR_POSITIONFEEDBACK_TYPE "sam.actuator.PositionFeedback"
#define SAM_BUOYANCY_PISTON_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_DATA_TYPE_ID 1010u  /* uavcan.equipment.actuator.ArrayCommand at 10 Hz */
#define SAM_BUOYANCY_PISTON_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_SIGNATURE UINT64_C(0xd8a7486238ec3af3)
#define SAM_BUOYANCY_PISTON_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_TYPE "uavcan.equipment.actuator.ArrayCommand"
#define SAM_BUOYANCY_PISTON_PARAM_PID_KD_CYPHAL_NAME "pid.kd"  /* real: Derivative gain. */
#define SAM_BUOYANCY_PISTON_PARAM_PID_KD_DRONECAN_NAME "PID_KD"
#define SAM_BUOYANCY_PISTON_PARAM_PID_KD_DEFAULT 0.05f  /* [s] */
#define SAM_BUOYANCY_PISTON_PARAM_PID_KD_MIN 0.0f
#define SAM_BUOYANCY_PISTON_PARAM_PID_KD_MAX 5.0f
#define SAM_BUOYANCY_PISTON_PARAM_PID_KI_CYPHAL_NAME "pid.ki"  /* real: Integral gain. */
#define SAM_BUOYANCY_PISTON_PARAM_PID_KI_DRONECAN_NAME "PID_KI"
#define SAM_BUOYANCY_PISTON_PARAM_PID_KI_DEFAULT 0.5f  /* [1/s] */
#define SAM_BUOYANCY_PISTON_PARAM_PID_KI_MIN 0.0f
#define SAM_BUOYANCY_PISTON_PARAM_PID_KI_MAX 10.0f
#define SAM_BUOYANCY_PISTON_PARAM_PID_KP_CYPHAL_NAME "pid.kp"  /* real: Proportional gain of the piston's position loop (motor duty per unit of position error). */
#define SAM_BUOYANCY_PISTON_PARAM_PID_KP_DRONECAN_NAME "PID_KP"
#define SAM_BUOYANCY_PISTON_PARAM_PID_KP_DEFAULT 4.0f  /* [1] */
#define SAM_BUOYANCY_PISTON_PARAM_PID_KP_MIN 0.0f
#define SAM_BUOYANCY_PISTON_PARAM_PID_KP_MAX 50.0f

#endif /* SAM_BUOYANCY_PISTON_H */
