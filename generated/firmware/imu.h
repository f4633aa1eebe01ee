/* Generated from interfaces.yaml by sam-codegen; do not edit. */
/* The firmware interface of board imu of sam.
 * Inertial measurement unit.
 *
 * Protocols: cyphal, dronecan. Report SAM_IMU_INTERFACE_HASH as the software's revision:
 * Cyphal uavcan.node.GetInfo software_vcs_revision_id; DroneCAN uavcan.protocol.GetNodeInfo
 * software_version.image_crc with optional_field_flags' OPTIONAL_FIELD_FLAG_IMAGE_CRC set. The bridge compares it
 * with its spec's on first contact and after every restart.
 */
#ifndef SAM_IMU_H
#define SAM_IMU_H

#include <stdint.h>

#define SAM_IMU_NODE_ID 11u
#define SAM_IMU_INTERFACE_HASH UINT64_C(0xd637a59eaf89905f)  /* sam-interface-1: report it as it is */
#define SAM_IMU_INTERFACE_HASH_BYTES {0xd6u, 0x37u, 0xa5u, 0x9eu, 0xafu, 0x89u, 0x90u, 0x5fu}  /* big-endian: the SHA-256's first 8 bytes */
#define SAM_IMU_SPEC_INTERFACE_HASH UINT64_C(0x23669fe96266cb3c)  /* the whole spec's */
#define SAM_IMU_CYPHAL_PUB_SAM_SENSOR_RAWIMU_SUBJECT_ID 1100u  /* sam.sensor.RawIMU.0.1 at 100 Hz */
#define SAM_IMU_CYPHAL_PUB_SAM_SENSOR_RAWIMU_TYPE "sam.sensor.RawIMU.0.1"
#define SAM_IMU_DRONECAN_PUB_UAVCAN_EQUIPMENT_AHRS_RAWIMU_DATA_TYPE_ID 1003u  /* uavcan.equipment.ahrs.RawIMU at 100 Hz */
#define SAM_IMU_DRONECAN_PUB_UAVCAN_EQUIPMENT_AHRS_RAWIMU_SIGNATURE UINT64_C(0x8280632c40e574b5)
#define SAM_IMU_DRONECAN_PUB_UAVCAN_EQUIPMENT_AHRS_RAWIMU_TYPE "uavcan.equipment.ahrs.RawIMU"
#define SAM_IMU_PARAM_IMU_GYRO_RANGE_CYPHAL_NAME "imu.gyro_range"  /* enum, restart: Gyroscope full scale in degrees per second. */
#define SAM_IMU_PARAM_IMU_GYRO_RANGE_DRONECAN_NAME "IMU_GYRO_RANGE"
#define SAM_IMU_PARAM_IMU_GYRO_RANGE_DEFAULT INT64_C(500)
#define SAM_IMU_PARAM_IMU_GYRO_RANGE_DPS250 INT64_C(250)
#define SAM_IMU_PARAM_IMU_GYRO_RANGE_DPS500 INT64_C(500)
#define SAM_IMU_PARAM_IMU_GYRO_RANGE_DPS1000 INT64_C(1000)
#define SAM_IMU_PARAM_IMU_GYRO_RANGE_DPS2000 INT64_C(2000)
#define SAM_IMU_PARAM_IMU_RATE_HZ_CYPHAL_NAME "imu.rate_hz"  /* integer: Output rate. */
#define SAM_IMU_PARAM_IMU_RATE_HZ_DRONECAN_NAME "IMU_RATE_HZ"
#define SAM_IMU_PARAM_IMU_RATE_HZ_DEFAULT INT64_C(100)  /* [Hz] */
#define SAM_IMU_PARAM_IMU_RATE_HZ_MIN INT64_C(10)
#define SAM_IMU_PARAM_IMU_RATE_HZ_MAX INT64_C(400)

#endif /* SAM_IMU_H */
