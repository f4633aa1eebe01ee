/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board gps of sam.
 * GPS receiver, usable at the surface.
 *
 * Protocols: cyphal, dronecan. Report SAM_GPS_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_GPS_H
#define SAM_GPS_H

#include <stdint.h>

#define SAM_GPS_NODE_ID 13u
#define SAM_GPS_INTERFACE_HASH UINT64_C(0xe085da2eaaafb1f9)  /* sam-interface-1: report it as it is */
#define SAM_GPS_INTERFACE_HASH_BYTES {0xe0u, 0x85u, 0xdau, 0x2eu, 0xaau, 0xafu, 0xb1u, 0xf9u}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_GPS_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_GPS_CYPHAL_PUB_SAM_SENSOR_GNSSFIX_SUBJECT_ID 1102u  /* sam.sensor.GNSSFix.0.1 at 5 Hz */
#define SAM_GPS_CYPHAL_PUB_SAM_SENSOR_GNSSFIX_TYPE "sam.sensor.GNSSFix.0.1"
#define SAM_GPS_DRONECAN_PUB_UAVCAN_EQUIPMENT_GNSS_FIX2_DATA_TYPE_ID 1063u  /* uavcan.equipment.gnss.Fix2 at 5 Hz */
#define SAM_GPS_DRONECAN_PUB_UAVCAN_EQUIPMENT_GNSS_FIX2_SIGNATURE UINT64_C(0xca41e7000f37435f)
#define SAM_GPS_DRONECAN_PUB_UAVCAN_EQUIPMENT_GNSS_FIX2_TYPE "uavcan.equipment.gnss.Fix2"

#endif /* SAM_GPS_H */
