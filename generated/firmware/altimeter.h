/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board altimeter of sam.
 * Altimeter looking down at the sea floor (an addition to the document).
 *
 * Protocols: cyphal, dronecan. Report SAM_ALTIMETER_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_ALTIMETER_H
#define SAM_ALTIMETER_H

#include <stdint.h>

#define SAM_ALTIMETER_NODE_ID 16u
#define SAM_ALTIMETER_INTERFACE_HASH UINT64_C(0xe33abf430944c2b4)  /* sam-interface-1: report it as it is */
#define SAM_ALTIMETER_INTERFACE_HASH_BYTES {0xe3u, 0x3au, 0xbfu, 0x43u, 0x09u, 0x44u, 0xc2u, 0xb4u}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_ALTIMETER_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_ALTIMETER_CYPHAL_PUB_SAM_SENSOR_ALTITUDE_SUBJECT_ID 1106u  /* sam.sensor.Altitude.0.1 at 10 Hz */
#define SAM_ALTIMETER_CYPHAL_PUB_SAM_SENSOR_ALTITUDE_TYPE "sam.sensor.Altitude.0.1"
#define SAM_ALTIMETER_DRONECAN_PUB_SAM_SENSOR_ALTITUDE_DATA_TYPE_ID 20103u  /* sam.sensor.Altitude at 10 Hz */
#define SAM_ALTIMETER_DRONECAN_PUB_SAM_SENSOR_ALTITUDE_SIGNATURE UINT64_C(0x48a1c8047b5312fa)
#define SAM_ALTIMETER_DRONECAN_PUB_SAM_SENSOR_ALTITUDE_TYPE "sam.sensor.Altitude"

#endif /* SAM_ALTIMETER_H */
