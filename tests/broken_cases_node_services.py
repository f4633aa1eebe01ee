# ruff: noqa: E501  (exact messages, one a line, as in broken_cases.py)
"""Broken `bridge.node_services` (the device duties as typed services, issue 19): each case breaks
tests/specs/auv_services.yaml one way and gives exact errors (tests/codegen/test_bad_specs_node_services.py)."""

from __future__ import annotations

from broken_cases import Case

_BRIDGE = "bridge:\n  name: bridge\n  node_id: 100\n"

NODE_SERVICE_CASES: tuple[Case, ...] = (
    Case(
        'node_services_unknown_duty',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    get_info: false\n',
        (
            "auv_services.yaml:82:5: error: unknown field 'get_info' in bridge node_services (expected one of get_node_info, restart_node, get_transport_stats)",
        ),
    ),
    Case(
        'node_services_unknown_key',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    get_node_info: {name: info}\n',
        (
            "auv_services.yaml:82:21: error: unknown field 'name' in node service 'get_node_info' (expected one of service, type, timeout, response_defaults)",
        ),
    ),
    Case(
        'node_services_not_a_mapping',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    restart_node: 3\n',
        (
            "auv_services.yaml:82:19: error: node service 'restart_node' must be a mapping, found int 3 (expected a mapping)",
        ),
    ),
    Case(
        'node_services_bad_timeout',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    get_transport_stats: {timeout: 0}\n',
        (
            "auv_services.yaml:82:27: error: 'timeout' of node service 'get_transport_stats' is 0 s (expected 0 < timeout <= 60 (seconds))",
        ),
    ),
    Case(
        'node_services_bad_service_name',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    get_node_info: {service: core//info}\n',
        (
            "auv_services.yaml:82:20: error: service name 'core//info' of node service 'get_node_info' is not a valid ROS name: it has an empty segment ('//') (expected a ROS name, e.g. uavcan_get_node_info or core/uavcan_get_node_info)",
        ),
    ),
    Case(
        'node_services_service_taken_by_mapping',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    get_node_info: {service: /bms/update_battery}\n',
        (
            "auv_services.yaml:82:20: error: service /bms/update_battery of node service 'get_node_info' is already served by service mapping 'update_battery' (expected a name of its own)",
        ),
    ),
    Case(
        'node_services_service_taken_by_duty',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    restart_node: {service: uavcan_get_node_info}\n',
        (
            "auv_services.yaml:82:19: error: service uavcan_get_node_info of node service 'restart_node' is already served by node service 'get_node_info' (expected a name of its own)",
        ),
    ),
    Case(
        'node_services_unknown_type',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    get_node_info: {type: NodeInfo}\n',
        (
            "auv_services.yaml:82:21: error: unknown service type 'lolo_msgs/NodeInfo' of node service 'get_node_info' (expected a type of `services` or `external_services` (pkg/Name))",
        ),
    ),
    Case(
        'node_services_type_without_node_id',
        _BRIDGE,
        _BRIDGE + '  node_services:\n    restart_node: {type: UpdateBattery}\n',
        (
            "auv_services.yaml:82:20: error: the request of lolo_msgs/UpdateBattery (node service 'restart_node') has no integer field 'node_id' (expected a request field `node_id` of an integer type (uint16: Cyphal/UDP node ids exceed 255))",
        ),
    ),
    Case(
        'node_services_own_srv_incompatible',
        '  GetTransportStats:\n    request:\n      - {name: node_id, type: uint8}\n    response:\n      - {name: success, type: bool}\n      - {name: message, type: string}\n      - {name: transfers_tx, type: uint64}\n',
        '  UavcanGetTransportStats:\n    request:\n      - {name: node_id, type: uint8}\n    response:\n      - {name: success, type: bool}\n      - {name: message, type: string}\n      - {name: transfers_tx, type: float64}\n',
        (
            "auv_services.yaml:65:9: error: response field 'transfers_tx' (float64) of lolo_msgs/UavcanGetTransportStats cannot hold transfers_tx of node service 'get_transport_stats' (expected an integer)",
            "auv_services.yaml:126:5: error: unknown service type 'lolo_msgs/GetTransportStats' of service mapping 'get_transport_stats' (expected a type of `services` or `external_services` (pkg/Name))",
        ),
    ),
)
