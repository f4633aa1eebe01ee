# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The bridge's service mappings: a ROS service each, answered by a UAVCAN request to one device.

Standard library only. A link writes `target` from `source` (None: the constant `value`): numbers as
target = (source - offset) / scale towards UAVCAN and source * scale + offset back, an integer rounded half
to even and saturated to [lo, hi]; bools as bools; "text" a ROS string <-> a UAVCAN uint8 array of at most
`hi` bytes; "bytes" a uint8 array as is; "ok_if_zero" a bool, true when the source is 0 (a status code).
"""

from __future__ import annotations

from dataclasses import dataclass

_INF = float("inf")
_F32_MAX = 3.4028234663852886e38


@dataclass(frozen=True)
class ServiceLinkInfo:
    target: str
    source: str | None
    kind: str  # "int" | "float" | "bool" | "text" | "bytes" | "ok_if_zero"
    value: bool | int | float | str | None
    scale: float | None
    offset: float | None
    lo: float
    hi: float


@dataclass(frozen=True)
class ServiceMappingInfo:
    name: str
    service: str  # the ROS service name
    ros_module: str  # e.g. "lolo_msgs.srv"
    ros_class: str
    ros_type: str
    data_type: str  # the service type, e.g. "lolo.power.UpdateBattery" (Cyphal: "lolo.power.SetChargeLimits.1.0")
    data_type_id: int  # DroneCAN: the data type id; Cyphal: the service id
    signature: int  # DroneCAN's; 0 on Cyphal
    destination_node_id: int  # 0 when destination_field gives it
    device: str  # "" when destination_field gives the node
    destination_field: str | None  # the ROS request field that names the node to ask, at each call
    timeout_s: float
    request: tuple[ServiceLinkInfo, ...]  # every field of the UAVCAN request
    response: tuple[ServiceLinkInfo, ...]  # the ROS response fields set from the UAVCAN response
    success_field: str | None  # a bool of the ROS response set False when the call fails (timeout, link down)
    message_field: str | None  # a string of the ROS response that gets the reason of a failure
    protocol: str = "dronecan"  # "dronecan" or "cyphal"
    # a device duty of bridge.node_services ("get_node_info", "restart_node", "get_transport_stats"): its node id
    # must be a device of the bridge's protocol; its service name takes the protocol as a suffix in a mixed layout
    duty: str | None = None


SERVICE_MAPPINGS: tuple[ServiceMappingInfo, ...] = (
    ServiceMappingInfo(
        name='node_services.get_node_info',
        service='uavcan_get_node_info',
        ros_module='sam_msgs.srv',
        ros_class='UavcanGetNodeInfo',
        ros_type='sam_msgs/srv/UavcanGetNodeInfo',
        data_type='uavcan.protocol.GetNodeInfo',
        data_type_id=1,
        signature=0xEE468A8121C46A9E,
        destination_node_id=0,
        device='',
        destination_field='node_id',
        timeout_s=1.0,
        request=(
        ),
        response=(
            ServiceLinkInfo('success', None, 'bool', True, None, None, -_INF, _INF),
            ServiceLinkInfo('name', 'name', 'text', None, None, None, -_INF, _INF),
            ServiceLinkInfo('uptime_sec', 'status.uptime_sec', 'int', None, None, None, 0.0, 4294967295.0),
            ServiceLinkInfo('health', 'status.health', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('mode', 'status.mode', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('vendor_specific_status_code', 'status.vendor_specific_status_code', 'int', None, None, None, 0.0, 65535.0),
            ServiceLinkInfo('software_version_major', 'software_version.major', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('software_version_minor', 'software_version.minor', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('hardware_version_major', 'hardware_version.major', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('hardware_version_minor', 'hardware_version.minor', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('software_vcs_revision_id', 'software_version.vcs_commit', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
            ServiceLinkInfo('unique_id', 'hardware_version.unique_id', 'bytes', None, None, None, -_INF, _INF),
        ),
        success_field='success',
        message_field='message',
        protocol='dronecan',
        duty='get_node_info',
    ),
    ServiceMappingInfo(
        name='node_services.get_node_info',
        service='uavcan_get_node_info',
        ros_module='sam_msgs.srv',
        ros_class='UavcanGetNodeInfo',
        ros_type='sam_msgs/srv/UavcanGetNodeInfo',
        data_type='uavcan.node.GetInfo.1.0',
        data_type_id=430,
        signature=0,
        destination_node_id=0,
        device='',
        destination_field='node_id',
        timeout_s=1.0,
        request=(
        ),
        response=(
            ServiceLinkInfo('success', None, 'bool', True, None, None, -_INF, _INF),
            ServiceLinkInfo('name', 'name', 'text', None, None, None, -_INF, _INF),
            ServiceLinkInfo('uptime_sec', 'heartbeat.uptime_s', 'int', None, None, None, 0.0, 4294967295.0),
            ServiceLinkInfo('health', 'heartbeat.health', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('mode', 'heartbeat.mode', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('vendor_specific_status_code', 'heartbeat.vssc', 'int', None, None, None, 0.0, 65535.0),
            ServiceLinkInfo('software_version_major', 'software_version.major', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('software_version_minor', 'software_version.minor', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('hardware_version_major', 'hardware_version.major', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('hardware_version_minor', 'hardware_version.minor', 'int', None, None, None, 0.0, 255.0),
            ServiceLinkInfo('software_vcs_revision_id', 'software_vcs_revision_id', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
            ServiceLinkInfo('unique_id', 'unique_id', 'bytes', None, None, None, -_INF, _INF),
        ),
        success_field='success',
        message_field='message',
        protocol='cyphal',
        duty='get_node_info',
    ),
    ServiceMappingInfo(
        name='node_services.restart_node',
        service='uavcan_restart_node',
        ros_module='sam_msgs.srv',
        ros_class='UavcanRestartNode',
        ros_type='sam_msgs/srv/UavcanRestartNode',
        data_type='uavcan.protocol.RestartNode',
        data_type_id=5,
        signature=0x569E05394A3017F0,
        destination_node_id=0,
        device='',
        destination_field='node_id',
        timeout_s=1.0,
        request=(
            ServiceLinkInfo('magic_number', None, 'int', 742196058910, None, None, 0.0, 1099511627775.0),
        ),
        response=(
            ServiceLinkInfo('success', 'ok', 'bool', None, None, None, -_INF, _INF),
        ),
        success_field='success',
        message_field='message',
        protocol='dronecan',
        duty='restart_node',
    ),
    ServiceMappingInfo(
        name='node_services.restart_node',
        service='uavcan_restart_node',
        ros_module='sam_msgs.srv',
        ros_class='UavcanRestartNode',
        ros_type='sam_msgs/srv/UavcanRestartNode',
        data_type='uavcan.node.ExecuteCommand.1.1',
        data_type_id=435,
        signature=0,
        destination_node_id=0,
        device='',
        destination_field='node_id',
        timeout_s=1.0,
        request=(
            ServiceLinkInfo('command', None, 'int', 65535, None, None, 0.0, 65535.0),
            ServiceLinkInfo('parameter', None, 'text', '', None, None, 0.0, 255.0),
        ),
        response=(
            ServiceLinkInfo('success', 'status', 'ok_if_zero', None, None, None, -_INF, _INF),
        ),
        success_field='success',
        message_field='message',
        protocol='cyphal',
        duty='restart_node',
    ),
    ServiceMappingInfo(
        name='node_services.get_transport_stats',
        service='uavcan_get_transport_stats',
        ros_module='sam_msgs.srv',
        ros_class='UavcanGetTransportStats',
        ros_type='sam_msgs/srv/UavcanGetTransportStats',
        data_type='uavcan.protocol.GetTransportStats',
        data_type_id=4,
        signature=0xBE6F76A7EC312B04,
        destination_node_id=0,
        device='',
        destination_field='node_id',
        timeout_s=1.0,
        request=(
        ),
        response=(
            ServiceLinkInfo('success', None, 'bool', True, None, None, -_INF, _INF),
            ServiceLinkInfo('transfers_tx', 'transfers_tx', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
            ServiceLinkInfo('transfers_rx', 'transfers_rx', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
            ServiceLinkInfo('transfer_errors', 'transfer_errors', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
        ),
        success_field='success',
        message_field='message',
        protocol='dronecan',
        duty='get_transport_stats',
    ),
    ServiceMappingInfo(
        name='node_services.get_transport_stats',
        service='uavcan_get_transport_stats',
        ros_module='sam_msgs.srv',
        ros_class='UavcanGetTransportStats',
        ros_type='sam_msgs/srv/UavcanGetTransportStats',
        data_type='uavcan.node.GetTransportStatistics.0.1',
        data_type_id=434,
        signature=0,
        destination_node_id=0,
        device='',
        destination_field='node_id',
        timeout_s=1.0,
        request=(
        ),
        response=(
            ServiceLinkInfo('success', None, 'bool', True, None, None, -_INF, _INF),
            ServiceLinkInfo('transfers_tx', 'transfer_statistics.num_emitted', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
            ServiceLinkInfo('transfers_rx', 'transfer_statistics.num_received', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
            ServiceLinkInfo('transfer_errors', 'transfer_statistics.num_errored', 'int', None, None, None, 0.0, 1.8446744073709552e+19),
        ),
        success_field='success',
        message_field='message',
        protocol='cyphal',
        duty='get_transport_stats',
    ),
)
