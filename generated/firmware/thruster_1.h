/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board thruster_1 of sam.
 * Thruster 1 motor controller.
 *
 * Protocols: cyphal, dronecan. Report SAM_THRUSTER_1_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_THRUSTER_1_H
#define SAM_THRUSTER_1_H

#include <stdint.h>

#define SAM_THRUSTER_1_NODE_ID 21u
#define SAM_THRUSTER_1_INTERFACE_HASH UINT64_C(0xe8aa5843e87f68fc)  /* sam-interface-1: report it as it is */
#define SAM_THRUSTER_1_INTERFACE_HASH_BYTES {0xe8u, 0xaau, 0x58u, 0x43u, 0xe8u, 0x7fu, 0x68u, 0xfcu}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_THRUSTER_1_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_THRUSTER_1_CYPHAL_PUB_SAM_ACTUATOR_THRUSTERFEEDBACK_SUBJECT_ID 1300u  /* sam.actuator.ThrusterFeedback.0.1 at 10 Hz */
#define SAM_THRUSTER_1_CYPHAL_PUB_SAM_ACTUATOR_THRUSTERFEEDBACK_TYPE "sam.actuator.ThrusterFeedback.0.1"
#define SAM_THRUSTER_1_CYPHAL_SUB_SAM_ACTUATOR_THRUSTERRPM_SUBJECT_ID 1200u  /* sam.actuator.ThrusterRPM.0.1 at 10 Hz */
#define SAM_THRUSTER_1_CYPHAL_SUB_SAM_ACTUATOR_THRUSTERRPM_TYPE "sam.actuator.ThrusterRPM.0.1"
#define SAM_THRUSTER_1_DRONECAN_PUB_UAVCAN_EQUIPMENT_ESC_STATUS_DATA_TYPE_ID 1034u  /* uavcan.equipment.esc.Status at 10 Hz */
#define SAM_THRUSTER_1_DRONECAN_PUB_UAVCAN_EQUIPMENT_ESC_STATUS_SIGNATURE UINT64_C(0xa9af28aea2fbb254)
#define SAM_THRUSTER_1_DRONECAN_PUB_UAVCAN_EQUIPMENT_ESC_STATUS_TYPE "uavcan.equipment.esc.Status"
#define SAM_THRUSTER_1_DRONECAN_SUB_UAVCAN_EQUIPMENT_ESC_RPMCOMMAND_DATA_TYPE_ID 1031u  /* uavcan.equipment.esc.RPMCommand at 10 Hz */
#define SAM_THRUSTER_1_DRONECAN_SUB_UAVCAN_EQUIPMENT_ESC_RPMCOMMAND_SIGNATURE UINT64_C(0xce0f9f621cf7e70b)
#define SAM_THRUSTER_1_DRONECAN_SUB_UAVCAN_EQUIPMENT_ESC_RPMCOMMAND_TYPE "uavcan.equipment.esc.RPMCommand"
#define SAM_THRUSTER_1_PARAM_ESC_INDEX_CYPHAL_NAME "esc.index"  /* integer, restart: Its index in uavcan.equipment.esc.RPMCommand. */
#define SAM_THRUSTER_1_PARAM_ESC_INDEX_DRONECAN_NAME "ESC_INDEX"
#define SAM_THRUSTER_1_PARAM_ESC_INDEX_DEFAULT INT64_C(0)
#define SAM_THRUSTER_1_PARAM_ESC_INDEX_MIN INT64_C(0)
#define SAM_THRUSTER_1_PARAM_ESC_INDEX_MAX INT64_C(19)
#define SAM_THRUSTER_1_PARAM_MOTOR_DIRECTION_CYPHAL_NAME "motor.direction"  /* enum: Propeller sense (the two thrusters counter-rotate). */
#define SAM_THRUSTER_1_PARAM_MOTOR_DIRECTION_DRONECAN_NAME "MOTOR_DIRECTION"
#define SAM_THRUSTER_1_PARAM_MOTOR_DIRECTION_DEFAULT INT64_C(1)
#define SAM_THRUSTER_1_PARAM_MOTOR_DIRECTION_FORWARD INT64_C(1)
#define SAM_THRUSTER_1_PARAM_MOTOR_DIRECTION_REVERSE INT64_C(-1)
#define SAM_THRUSTER_1_PARAM_MOTOR_POLE_COUNT_CYPHAL_NAME "motor.pole_count"  /* integer, restart: Magnet poles of the motor. */
#define SAM_THRUSTER_1_PARAM_MOTOR_POLE_COUNT_DRONECAN_NAME "MOTOR_POLE_COUNT"
#define SAM_THRUSTER_1_PARAM_MOTOR_POLE_COUNT_DEFAULT INT64_C(14)
#define SAM_THRUSTER_1_PARAM_MOTOR_POLE_COUNT_MIN INT64_C(2)
#define SAM_THRUSTER_1_PARAM_MOTOR_POLE_COUNT_MAX INT64_C(48)

#endif /* SAM_THRUSTER_1_H */
