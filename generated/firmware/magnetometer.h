/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board magnetometer of sam.
 * Three-axis magnetometer.
 *
 * Protocols: cyphal, dronecan. Report SAM_MAGNETOMETER_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_MAGNETOMETER_H
#define SAM_MAGNETOMETER_H

#include <stdint.h>

#define SAM_MAGNETOMETER_NODE_ID 12u
#define SAM_MAGNETOMETER_INTERFACE_HASH UINT64_C(0x91845a90d6c01c77)  /* sam-interface-1: report it as it is */
#define SAM_MAGNETOMETER_INTERFACE_HASH_BYTES {0x91u, 0x84u, 0x5au, 0x90u, 0xd6u, 0xc0u, 0x1cu, 0x77u}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_MAGNETOMETER_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_MAGNETOMETER_CYPHAL_PUB_SAM_SENSOR_MAGNETICFIELDSTRENGTH_SUBJECT_ID 1101u  /* sam.sensor.MagneticFieldStrength.0.1 at 50 Hz */
#define SAM_MAGNETOMETER_CYPHAL_PUB_SAM_SENSOR_MAGNETICFIELDSTRENGTH_TYPE "sam.sensor.MagneticFieldStrength.0.1"
#define SAM_MAGNETOMETER_DRONECAN_PUB_UAVCAN_EQUIPMENT_AHRS_MAGNETICFIELDSTRENGTH_DATA_TYPE_ID 1001u  /* uavcan.equipment.ahrs.MagneticFieldStrength at 50 Hz */
#define SAM_MAGNETOMETER_DRONECAN_PUB_UAVCAN_EQUIPMENT_AHRS_MAGNETICFIELDSTRENGTH_SIGNATURE UINT64_C(0xe2a7d4a9460bc2f2)
#define SAM_MAGNETOMETER_DRONECAN_PUB_UAVCAN_EQUIPMENT_AHRS_MAGNETICFIELDSTRENGTH_TYPE "uavcan.equipment.ahrs.MagneticFieldStrength"

#endif /* SAM_MAGNETOMETER_H */
