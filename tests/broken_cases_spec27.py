# ruff: noqa: E501  (a table of exact diagnostics, one per line, as tests/broken_cases.py)
"""Broken specs of issue 27's constructs: each case breaks tests/specs/retrofit.yaml one way and names the exact
errors (as tests/broken_cases.py); a case with no errors is a spelling the spec accepts."""

from __future__ import annotations

from dataclasses import dataclass

from broken_cases import Case

RETROFIT_CASES: tuple[Case, ...] = (
    # ---- class 1: no frame, no header
    Case('frame_none_is_a_frame_name', "      frame_id: ''\n      fields:\n        temperature: {expr: \"float32(temperature_k",
         "      frame_id: none\n      fields:\n        temperature: {expr: \"float32(temperature_k",
        (
            "retrofit.yaml:58:5: error: frame_id 'none' of mapping 'thermo' is not a declared frame (expected one of base_link, or '' for an empty frame id)",
        ),
    ),
    Case('header_default_with_frame',
         '      ros_defaults: [header]',
         '      frame_id: base_link\n      ros_defaults: [header]',
        (
            "retrofit.yaml:68:5: error: mapping 'thermo_raw' leaves its header at its default (ros_defaults: [header]) but gives frame_id 'base_link' (expected either the frame_id or header in ros_defaults)",
        ),
    ),
    Case('header_without_frame',
         "      frame_id: ''\n      fields:\n        temperature: {expr: \"float32(temperature_k",
         "      fields:\n        temperature: {expr: \"float32(temperature_k",
        (
            "retrofit.yaml:58:5: error: mapping 'thermo' publishes sensor_msgs/Temperature, which has a header: it needs a frame_id (expected a declared frame, `frame_id: ''` for an empty one, or `ros_defaults: [header]` to leave the header at its default)",
        ),
    ),
    Case('header_default_and_stamp_written',
         '        temperature: temperature_k\n',
         '        temperature: temperature_k\n        header.stamp: raw\n',
        (
            "retrofit.yaml:75:9: error: mapping 'thermo_raw' leaves its header at its default (ros_defaults: [header]) but writes 'header.stamp' (expected either the line or header in ros_defaults)",
        ),
    ),
    # ---- class 2: float32() and wrap
    Case('float32_of_a_bool', '"trunc(float32(r * 80)) >> 3"', '"trunc(float32(r > 80)) >> 3"',
        (
            "retrofit.yaml:92:31: error: mapping 'light', UAVCAN field 'red': r > 80 is a bool, not a number (write int(r > 80) for 0 or 1)",
        ),
    ),
    Case('float32_two_arguments', '"trunc(float32(r * 80)) >> 3"', '"trunc(float32(r, 80)) >> 3"',
        (
            "retrofit.yaml:92:21: error: the expression of UAVCAN field 'red' in uavcan_exprs of mapping 'light': float32() takes 1 argument, not 2",
        ),
    ),
    Case('float32_into_an_integer', '"trunc(float32(r * 80)) >> 3"', '"float32(r * 80)"',
        (
            "retrofit.yaml:92:15: error: mapping 'light', UAVCAN field 'red': red is uint8, the expression gives a float (write trunc(...) or round(...))",
        ),
    ),
    Case('wrap_per_mapping', '      destination_node_id: 11\n', '      destination_node_id: 11\n      on_out_of_range: wrap\n',
        (
            "retrofit.yaml:90:7: error: on_out_of_range 'wrap' of mapping 'light' is per line, not per mapping (expected `{from: ..., on_out_of_range: wrap}` or `{expr: ..., on_out_of_range: wrap}` on the lines that must wrap; saturate or reject here)",
        ),
    ),
    Case('saturate_per_line', '{expr: "trunc(float32(g * 255 / a))", on_out_of_range: wrap}',
         '{expr: "trunc(float32(g * 255 / a))", on_out_of_range: saturate}',
        (
            "retrofit.yaml:93:54: error: on_out_of_range 'saturate' of UAVCAN field 'green' in uavcan_exprs of mapping 'light': a line takes only `wrap` (expected wrap (modulo 2**bits, as C stores), or saturate / reject for the whole mapping)",
        ),
    ),
    Case('wrap_of_a_float_expr', 'variance: {expr: "float32(raw * 0.1)"}',
         'variance: {expr: "float32(raw * 0.1)", on_out_of_range: wrap}',
        (
            "retrofit.yaml:75:9: error: mapping 'thermo_raw', field 'variance': on_out_of_range: wrap stores an integer modulo 2**bits; float64 is no integer scalar",
        ),
    ),
    Case('wrap_into_a_float_field', '        temperature: temperature_k\n',
         '        temperature: {from: temperature_k, on_out_of_range: wrap}\n',
        (
            "retrofit.yaml:74:9: error: mapping 'thermo_raw', field 'temperature': on_out_of_range: wrap stores an integer modulo 2**bits; float64 is no integer scalar",
        ),
    ),
    Case('wrap_nothing_to_wrap', 'data: {expr: "raw + 100", on_out_of_range: wrap}',
         'data: {expr: "raw >> 11", on_out_of_range: wrap}',
        (
            "retrofit.yaml:83:9: error: mapping 'thermo_count', field 'data': on_out_of_range: wrap has nothing to wrap: the value (-64..63) always fits int8",
        ),
    ),
    Case('wrap_of_a_rounded_float', 'data: {expr: "trunc(float32(static_temperature * 3.3))", on_out_of_range: wrap}',
         'data: {from: static_temperature, round: true, on_out_of_range: wrap}',
        (
            "retrofit.yaml:119:9: error: DroneCAN mapping 'air_level', field 'data': on_out_of_range: wrap takes an integer value; float16 is not an integer (a float needs an expr with trunc() or round())",
        ),
    ),
    Case('wrap_on_a_value', 'data: {expr: "raw + 100", on_out_of_range: wrap}',
         'data: {value: 3, on_out_of_range: wrap}',
        (
            "retrofit.yaml:83:26: error: on_out_of_range 'wrap' of field 'data' of mapping 'thermo_count': wrap applies to an integer field as it is or an `expr`, not to a line with 'value' (expected no wrap on a constant)",
        ),
    ),
    Case('wrap_typo', 'data: {expr: "raw + 100", on_out_of_range: wrap}',
         'data: {expr: "raw + 100", on_out_of_range: wrapped}',
        (
            "retrofit.yaml:83:35: error: on_out_of_range 'wrapped' of field 'data' of mapping 'thermo_count': a line takes only `wrap` (expected wrap (modulo 2**bits, as C stores), or saturate / reject for the whole mapping)",
        ),
    ),
    Case('uavcan_expr_without_expr', '{expr: "round(float32(b * 100 - 50))", on_out_of_range: wrap}',
         '{on_out_of_range: wrap}',
        (
            "retrofit.yaml:94:9: error: missing field 'expr' in UAVCAN field 'blue' in uavcan_exprs of mapping 'light'",
        ),
    ),
    # ---- class 3: service types of another package, srv constants
    Case('external_service_without_package', '  uavcan_ros_msgs/UavcanGetNodeInfo:\n', '  UavcanGetNodeInfo:\n',
        (
            "retrofit.yaml:136:3: error: external service 'UavcanGetNodeInfo' needs its package (expected pkg/Name)",
        ),
    ),
    Case('external_service_of_own_package', '  uavcan_ros_msgs/UavcanGetNodeInfo:\n',
         '  retrofit_msgs/UavcanGetNodeInfo:\n',
        (
            "retrofit.yaml:136:3: error: external service 'retrofit_msgs/UavcanGetNodeInfo' is of the spec's own package retrofit_msgs (expected a srv of `services` (bare name))",
        ),
    ),
    Case('srv_constant_bad_name', '{name: MODE_ZERO, type: uint8, value: 1}\n', '{name: mode_zero, type: uint8, value: 1}\n',
        (
            "retrofit.yaml:128:9: error: 'mode_zero' is not a valid ROS constant name in service type retrofit_msgs/Calibrate (expected UPPER_CASE)",
        ),
    ),
    Case('srv_constant_twice', '{name: MODE_SPAN, type: uint8, value: 2}', '{name: MODE_ZERO, type: uint8, value: 2}',
        (
            "retrofit.yaml:129:9: error: 'MODE_ZERO' is declared twice in service type retrofit_msgs/Calibrate (constants and request share one namespace) (expected a name of its own)",
        ),
    ),
    Case('srv_constant_not_primitive', '{name: MODE_SPAN, type: uint8, value: 2}',
         '{name: MODE_SPAN, type: std_msgs/Header, value: 2}',
        (
            'retrofit.yaml:129:9: error: constant MODE_SPAN of service type retrofit_msgs/Calibrate must have a primitive type, not std_msgs/Header',
        ),
    ),
    Case('srv_constant_out_of_range', '{name: MODE_SPAN, type: uint8, value: 2}', '{name: MODE_SPAN, type: uint8, value: 300}',
        (
            'retrofit.yaml:129:9: error: constant MODE_SPAN = 300 does not fit uint8 (expected an integer in [0, 255])',
        ),
    ),
    Case('duty_external_type_unknown', '{type: uavcan_ros_msgs/UavcanGetNodeInfo, response_defaults',
         '{type: uavcan_ros_msgs/GetNodeInfo, response_defaults',
        (
            "retrofit.yaml:124:21: error: unknown service type 'uavcan_ros_msgs/GetNodeInfo' of node service 'get_node_info' (expected a type of `services` or `external_services` (pkg/Name))",
        ),
    ),
    Case('duty_external_field_unwritten', 'response_defaults: [vendor_note]}', 'response_defaults: []}',
        (
            "retrofit.yaml:124:21: error: ROS response field 'vendor_note' (string) of uavcan_ros_msgs/UavcanGetNodeInfo is written by nothing in node service 'get_node_info' (expected a field the duty writes (success, name, uptime_sec, health, mode, vendor_specific_status_code, software_version_major, software_version_minor, hardware_version_major, hardware_version_minor, software_vcs_revision_id, unique_id), or `response_defaults: [vendor_note]` to keep its default)",
        ),
    ),

)



@dataclass(frozen=True)
class Edits:
    """A case of several edits of the base spec (each `old` replaced once), with its exact errors."""

    name: str
    edits: tuple[tuple[str, str], ...]
    errors: tuple[str, ...]


# ---- class 4: nested service response fields, none left unwritten (tests/specs/auv_services.yaml)
_STATUS_MSG = ("messages:\n  NodeStatus:\n    fields:\n      - {name: uptime_sec, type: uint32}\n"
               "      - {name: health, type: uint8}\n      - {name: mode, type: uint8}\n"
               "      - {name: vendor_specific_status_code, type: uint16}\nservices:\n")
# the duty's default srv name, declared by the spec: its own is used (README "Device duties")
_NODE_INFO_SRV = ("  UavcanGetNodeInfo:\n    request:\n      - {name: node_id, type: uint16}\n    response:\n"
                  "      - {name: success, type: bool}\n      - {name: message, type: string}\n"
                  "      - {name: name, type: string}\n      - {name: status, type: NodeStatus}\n")
_BRIDGE = "bridge:\n  name: bridge\n  node_id: 100\n"
_FLAT_STATUS = ("      - {name: uptime_sec, type: uint32}\n      - {name: health, type: uint8}\n"
                "      - {name: mode, type: uint8}\n")
_STATUS_LINES = "        uptime_sec: status.uptime_sec\n        health: status.health\n        mode: status.mode\n"

SERVICE27_CASES: tuple[Edits, ...] = (
    # the failing example: a duty given the spec's own srv with a nested `status` writes it (no error)
    Edits('duty_nested_status', (('services:\n', _STATUS_MSG + _NODE_INFO_SRV),), ()),
    Edits('duty_field_nothing_writes',
          (('services:\n', _STATUS_MSG + _NODE_INFO_SRV + "      - {name: battery, type: float32}\n"),),
        (
            "auv_services.yaml:47:9: error: ROS response field 'battery' (float32) of lolo_msgs/UavcanGetNodeInfo is written by nothing in node service 'get_node_info' (expected a field the duty writes (success, name, uptime_sec, health, mode, vendor_specific_status_code, software_version_major, software_version_minor, hardware_version_major, hardware_version_minor, software_vcs_revision_id, unique_id), or `response_defaults: [battery]` to keep its default)",
        ),
    ),
    Edits('duty_response_defaults', ((_BRIDGE, _BRIDGE + "  node_services:\n    get_node_info: {type: GetNodeInfo, "
                                                         "response_defaults: [software_major, software_minor]}\n"),),
          ()),
    Edits('duty_response_defaults_missing', ((_BRIDGE, _BRIDGE + "  node_services:\n    get_node_info: "
                                                                 "{type: GetNodeInfo}\n"),),
        (
            "auv_services.yaml:82:21: error: ROS response field 'software_major' (uint8) of lolo_msgs/GetNodeInfo is written by nothing in node service 'get_node_info' (expected a field the duty writes (success, name, uptime_sec, health, mode, vendor_specific_status_code, software_version_major, software_version_minor, hardware_version_major, hardware_version_minor, software_vcs_revision_id, unique_id), or `response_defaults: [software_major]` to keep its default)",
            "auv_services.yaml:82:21: error: ROS response field 'software_minor' (uint8) of lolo_msgs/GetNodeInfo is written by nothing in node service 'get_node_info' (expected a field the duty writes (success, name, uptime_sec, health, mode, vendor_specific_status_code, software_version_major, software_version_minor, hardware_version_major, hardware_version_minor, software_vcs_revision_id, unique_id), or `response_defaults: [software_minor]` to keep its default)",
        ),
    ),
    Edits('mapping_nested_ros_response',
          ((_FLAT_STATUS, "      - {name: status, type: NodeStatus}\n"), ('services:\n', _STATUS_MSG),
           (_STATUS_LINES, "        status.uptime_sec: status.uptime_sec\n        status.health: status.health\n"
                           "        status.mode: status.mode\n        status.vendor_specific_status_code: "
                           "status.vendor_specific_status_code\n")), ()),
    Edits('mapping_nested_left_unwritten',
          ((_FLAT_STATUS, "      - {name: status, type: NodeStatus}\n"), ('services:\n', _STATUS_MSG),
           (_STATUS_LINES, "        status.uptime_sec: status.uptime_sec\n")),
        (
            "auv_services.yaml:110:5: error: ROS response field 'status.health' (uint8) of lolo_msgs/GetNodeInfo is written by nothing in service mapping 'get_node_info' (expected a `response` line, or `response_defaults: [status.health]` to keep its default)",
            "auv_services.yaml:110:5: error: ROS response field 'status.mode' (uint8) of lolo_msgs/GetNodeInfo is written by nothing in service mapping 'get_node_info' (expected a `response` line, or `response_defaults: [status.mode]` to keep its default)",
            "auv_services.yaml:110:5: error: ROS response field 'status.vendor_specific_status_code' (uint16) of lolo_msgs/GetNodeInfo is written by nothing in service mapping 'get_node_info' (expected a `response` line, or `response_defaults: [status.vendor_specific_status_code]` to keep its default)",
        ),
    ),
    Edits('mapping_field_nothing_writes', (('        status: success\n', ''),),
        (
            "auv_services.yaml:93:5: error: ROS response field 'status' (uint8) of lolo_msgs/UpdateBattery is written by nothing in service mapping 'update_battery' (expected a `response` line, or `response_defaults: [status]` to keep its default)",
        ),
    ),
    Edits('mapping_response_defaults', (('        status: success\n', '      response_defaults: [status]\n'),), ()),
    Edits('mapping_response_defaults_unknown',
          (('        status: success\n', '        status: success\n      response_defaults: [state]\n'),),
        (
            "auv_services.yaml:93:5: error: response_defaults of service mapping 'update_battery': 'state' is not a field of the response of lolo_msgs/UpdateBattery (expected success, status)",
        ),
    ),
    Edits('mapping_response_defaults_written',
          (('        status: success\n', '        status: success\n      response_defaults: [status]\n'),),
        (
            "auv_services.yaml:93:5: error: ROS response field 'status' is in response_defaults of service mapping 'update_battery' but it is written (expected response_defaults lists only fields nothing writes)",
        ),
    ),
    Edits('mapping_nested_unknown', (('        status: success\n', '        status.code: success\n'),),
        (
            "auv_services.yaml:104:9: error: 'status.code' of service mapping 'update_battery' is not a field of the srv response (expected success, status)",
        ),
    ),
)


# ---- class 3: a DroneCAN service response's constants (tests/specs/retrofit.yaml)
V0_RESPONSE_CASES: tuple[Case, ...] = (
    Case('v0_response_constant_bad_name', '{name: RESULT_BUSY, type: uint8, value: 3}',
         '{name: 3BUSY, type: uint8, value: 3}',
        (
            "retrofit.yaml:161:9: error: '3BUSY' is not a valid DroneCAN constant name in the response of DroneCAN type retrofit.power.Calibrate (expected a letter, then letters, digits and underscores; not a Python keyword)",
        ),
    ),
    Case('v0_response_constant_twice', '{name: RESULT_BUSY, type: uint8, value: 3}',
         '{name: RESULT_OK, type: uint8, value: 3}',
        (
            "retrofit.yaml:161:9: error: 'RESULT_OK' appears twice in the response of DroneCAN type retrofit.power.Calibrate",
        ),
    ),
    Case('v0_response_constant_named_as_a_field', '{name: RESULT_BUSY, type: uint8, value: 3}',
         '{name: result, type: uint8, value: 3}',
        (
            "retrofit.yaml:161:9: error: 'result' appears twice in the response of DroneCAN type retrofit.power.Calibrate",
        ),
    ),
    Case('v0_response_constant_out_of_range', '{name: RESULT_BUSY, type: uint8, value: 3}',
         '{name: RESULT_BUSY, type: uint8, value: 256}',
        (
            'retrofit.yaml:161:9: error: constant RESULT_BUSY of DroneCAN type retrofit.power.Calibrate = 256 does not fit uint8 (expected an integer in [0, 255])',
        ),
    ),
)
