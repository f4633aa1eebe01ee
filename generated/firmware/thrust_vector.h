/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board thrust_vector of sam.
 * Thrust vectoring nozzle servos.
 *
 * Protocols: cyphal, dronecan. Report SAM_THRUST_VECTOR_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_THRUST_VECTOR_H
#define SAM_THRUST_VECTOR_H

#include <stdint.h>

#define SAM_THRUST_VECTOR_NODE_ID 23u
#define SAM_THRUST_VECTOR_INTERFACE_HASH UINT64_C(0x4bd8faffe39569c2)  /* sam-interface-1: report it as it is */
#define SAM_THRUST_VECTOR_INTERFACE_HASH_BYTES {0x4bu, 0xd8u, 0xfau, 0xffu, 0xe3u, 0x95u, 0x69u, 0xc2u}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_THRUST_VECTOR_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_THRUST_VECTOR_CYPHAL_PUB_SAM_ACTUATOR_THRUSTVECTORFEEDBACK_SUBJECT_ID 1302u  /* sam.actuator.ThrustVectorFeedback.0.1 at 10 Hz */
#define SAM_THRUST_VECTOR_CYPHAL_PUB_SAM_ACTUATOR_THRUSTVECTORFEEDBACK_TYPE "sam.actuator.ThrustVectorFeedback.0.1"
#define SAM_THRUST_VECTOR_CYPHAL_SUB_SAM_ACTUATOR_THRUSTVECTOR_SUBJECT_ID 1202u  /* sam.actuator.ThrustVector.0.1 at 10 Hz */
#define SAM_THRUST_VECTOR_CYPHAL_SUB_SAM_ACTUATOR_THRUSTVECTOR_TYPE "sam.actuator.ThrustVector.0.1"
#define SAM_THRUST_VECTOR_DRONECAN_PUB_SAM_ACTUATOR_THRUSTVECTORFEEDBACK_DATA_TYPE_ID 20101u  /* sam.actuator.ThrustVectorFeedback at 10 Hz */
#define SAM_THRUST_VECTOR_DRONECAN_PUB_SAM_ACTUATOR_THRUSTVECTORFEEDBACK_SIGNATURE UINT64_C(0x05fd0d1cc24f4b59)
#define SAM_THRUST_VECTOR_DRONECAN_PUB_SAM_ACTUATOR_THRUSTVECTORFEEDBACK_TYPE "sam.actuator.ThrustVectorFeedback"
#define SAM_THRUST_VECTOR_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_DATA_TYPE_ID 1010u  /* uavcan.equipment.actuator.ArrayCommand at 10 Hz */
#define SAM_THRUST_VECTOR_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_SIGNATURE UINT64_C(0xd8a7486238ec3af3)
#define SAM_THRUST_VECTOR_DRONECAN_SUB_UAVCAN_EQUIPMENT_ACTUATOR_ARRAYCOMMAND_TYPE "uavcan.equipment.actuator.ArrayCommand"
#define SAM_THRUST_VECTOR_PARAM_SERVO_HORIZONTAL_TRIM_CYPHAL_NAME "servo.horizontal.trim"  /* real: Added to every horizontal command. */
#define SAM_THRUST_VECTOR_PARAM_SERVO_HORIZONTAL_TRIM_DRONECAN_NAME "SERVO_HORIZONTAL_TRIM"
#define SAM_THRUST_VECTOR_PARAM_SERVO_HORIZONTAL_TRIM_DEFAULT 0.0f  /* [rad] */
#define SAM_THRUST_VECTOR_PARAM_SERVO_HORIZONTAL_TRIM_MIN -0.1f
#define SAM_THRUST_VECTOR_PARAM_SERVO_HORIZONTAL_TRIM_MAX 0.1f
#define SAM_THRUST_VECTOR_PARAM_SERVO_LIMIT_CYPHAL_NAME "servo.limit"  /* real: The largest deflection either servo is driven to. */
#define SAM_THRUST_VECTOR_PARAM_SERVO_LIMIT_DRONECAN_NAME "SERVO_LIMIT"
#define SAM_THRUST_VECTOR_PARAM_SERVO_LIMIT_DEFAULT 0.12f  /* [rad] */
#define SAM_THRUST_VECTOR_PARAM_SERVO_LIMIT_MIN 0.02f
#define SAM_THRUST_VECTOR_PARAM_SERVO_LIMIT_MAX 0.2f
#define SAM_THRUST_VECTOR_PARAM_SERVO_VERTICAL_TRIM_CYPHAL_NAME "servo.vertical.trim"  /* real: Added to every vertical command (the nozzle's mechanical zero). */
#define SAM_THRUST_VECTOR_PARAM_SERVO_VERTICAL_TRIM_DRONECAN_NAME "SERVO_VERTICAL_TRIM"
#define SAM_THRUST_VECTOR_PARAM_SERVO_VERTICAL_TRIM_DEFAULT 0.0f  /* [rad] */
#define SAM_THRUST_VECTOR_PARAM_SERVO_VERTICAL_TRIM_MIN -0.1f
#define SAM_THRUST_VECTOR_PARAM_SERVO_VERTICAL_TRIM_MAX 0.1f

#endif /* SAM_THRUST_VECTOR_H */
