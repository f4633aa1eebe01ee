"""Broken specs: each case breaks tests/specs/minimal.yaml one way and names the error it must give.

`old` is replaced by `new` once (the case fails loudly if `old` is not in the base spec); `errors` are the
exact diagnostics, with the file shown as its base name.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Case:
    name: str
    old: str
    new: str
    errors: tuple[str, ...]


CASES: tuple[Case, ...] = (
    Case(
        'message_without_fields_or_constants',
        'messages:\n',
        'messages:\n  Empty:\n    description: Nothing.\n',
        (
            "minimal.yaml:7:3: error: message 'Empty' has neither fields nor constants (expected a `fields` list, `constants` or `derive_from`)",
        ),
    ),
    Case(
        'yaml_syntax',
        '  /level: {type: buoy_msgs/Level}',
        '  /level: {type: buoy_msgs/Level',
        (
            "minimal.yaml:26:9: error: YAML syntax error: expected ',' or '}', but got ':' while parsing a flow mapping",
        ),
    ),
    Case(
        'yaml_tab_indent',
        'vehicle: {name: buoy',
        'vehicle:\n\t{name: buoy',
        (
            "minimal.yaml:4:1: error: YAML syntax error: found character '\\t' that cannot start any token while scanning for the next token",
        ),
    ),
    Case(
        'python_tag',
        '  base_link: {}',
        "  base_link: !!python/object/apply:os.system ['true']",
        (
            "minimal.yaml:23:14: error: YAML tag 'tag:yaml.org,2002:python/object/apply:os.system' is not allowed in a spec",
        ),
    ),
    Case(
        'unknown_ros_type',
        '/valve: {type: std_msgs/UInt8}',
        '/valve: {type: std_msgs/UInt7}',
        (
            "minimal.yaml:26:3: error: unknown ROS type 'std_msgs/UInt7' of topic /valve (expected a message of this spec, an external_messages entry or an installed ROS message)",
        ),
    ),
    Case(
        'unknown_dsdl_type',
        'type: uavcan.time.SynchronizedTimestamp.1.0}',
        'type: uavcan.time.Timestamp.1.0}',
        (
            "minimal.yaml:16:9: error: unknown DSDL type 'uavcan.time.Timestamp.1.0' in DSDL type buoy.Level.0.1 (expected a type of this spec or of CYPHAL_PATH (uavcan.*, reg.*))",
        ),
    ),
    Case(
        'bad_dsdl_primitive',
        'type: int18}',
        'type: int65}',
        (
            'minimal.yaml:17:26: error: int65: integer bit length must be 1..64 (unsigned) or 2..64 (signed)',
        ),
    ),
    Case(
        'dsdl_array_capacity_beyond_transfer',
        '      - {name: open_pct, type: uint8}',
        '      - {name: open_pct, type: uint8}\n      - {name: blob, type: "uint8[<=1000000000]"}',
        (
            "minimal.yaml:22:22: error: array capacity 1,000,000,000 of 'uint8[<=1000000000]' is more than a transfer can carry (at most 65,535 elements)",
        ),
    ),
    Case(
        'parameter_default_nan',
        '  /warn_level: {type: double, unit: m, default: 1.0, min: 0.0, max: 10.0}',
        '  /warn_level: {type: double, unit: m, default: .nan, min: 0.0, max: 10.0}',
        (
            "minimal.yaml:28:40: error: default NaN of parameter '/warn_level' is not a valid value (expected a number; or `allow_nan: true` when NaN is a meaningful value of this parameter)",
        ),
    ),
    Case(
        'parameter_bound_nan',
        '  /warn_level: {type: double, unit: m, default: 1.0, min: 0.0, max: 10.0}',
        '  /warn_level: {type: double, unit: m, default: 1.0, min: .nan, max: 10.0}',
        (
            "minimal.yaml:28:59: error: min of parameter '/warn_level' must be finite",
        ),
    ),
    Case(
        'parameter_allow_nan_not_double',
        '  /warn_level: {type: double, unit: m, default: 1.0, min: 0.0, max: 10.0}',
        '  /warn_level: {type: integer, unit: m, default: 1, min: 0, max: 10, allow_nan: true}',
        (
            "minimal.yaml:28:70: error: parameter '/warn_level': allow_nan applies only to a double parameter, not integer",
        ),
    ),
    Case(
        'pass_nan_on_a_uavcan_to_ros_mapping',
        '      source_node_ids: [10]\n',
        '      source_node_ids: [10]\n      pass_nan: true\n',
        (
            "minimal.yaml:50:7: error: mapping 'level' goes UAVCAN->ROS: pass_nan is for commands (ros_to_uavcan); a UAVCAN->ROS mapping passes a float NaN on as it is (expected no pass_nan here)",
        ),
    ),
    Case(
        'pass_nan_not_a_bool',
        '      destination_node_id: 11\n',
        '      destination_node_id: 11\n      pass_nan: sometimes\n',
        (
            "minimal.yaml:59:17: error: 'pass_nan' of mapping 'valve' must be bool, found str 'sometimes' (expected bool)",
        ),
    ),
    Case(  # issue 29: an option that would act on nothing is an error, never a silent no-op
        'pass_nan_without_a_float_field',
        '      destination_node_id: 11\n',
        '      destination_node_id: 11\n      pass_nan: true\n',
        (
            "minimal.yaml:59:7: error: mapping 'valve': pass_nan: true acts on nothing: none of its values can carry a NaN into a UAVCAN float without limits (an integer or bool holds no NaN; a limited field rejects NaN either way) (expected no pass_nan here, or a float field without limits)",
        ),
    ),
    Case(  # uint8 into uint8: nothing is ever out of range, so the policy decides nothing
        'reject_policy_with_nothing_out_of_range',
        '      destination_node_id: 11\n',
        '      destination_node_id: 11\n      on_out_of_range: reject\n',
        (
            "minimal.yaml:54:5: error: mapping 'valve': on_out_of_range: reject acts on nothing: none of its values can be out of its target's range (each fits the field it goes into) (expected no on_out_of_range here)",
        ),
    ),
    Case(
        'table_default_on_a_ros_to_uavcan_mapping',
        '        data: open_pct\n',
        '        data: {from: open_pct, table: {0: 0, 1: 100, default: 0}}\n',
        (
            "minimal.yaml:60:9: error: mapping 'valve', field 'data': a table's default names the ROS value of the UAVCAN values it does not list, which only a UAVCAN -> ROS mapping receives; a ROS -> UAVCAN mapping rejects a ROS value no key gives (expected no default in this table)",
        ),
    ),
    Case(
        'limits_that_bound_nothing',
        '        data: open_pct\n',
        '        data: {from: open_pct, limits: [-5, 1000]}\n',
        (
            "minimal.yaml:60:9: error: mapping 'valve', field 'data': limits [-5, 1000] bound nothing: every uint8 value (0..255) lies within them (expected limits narrower than 0..255, or none)",
        ),
    ),
    Case(
        'unknown_top_field',
        'spec_version: 1',
        'spec_version: 1\ntopic: {}',
        (
            "minimal.yaml:3:1: error: unknown field 'topic' in the spec (expected one of spec_version, vehicle, ros, cyphal, external_messages, messages, dsdl_types, dronecan_types, frames, transforms, topics, parameters, parameter_rules, devices, layouts, bridge, nodes, bus, dronecan_namespaces, services, external_services)",
        ),
    ),
    Case(
        'unknown_mapping_field',
        '      subject_id: 100\n',
        '      subject_id: 100\n      subjectid: 100\n',
        (
            "minimal.yaml:48:7: error: unknown field 'subjectid' in mapping 'level' (expected one of direction, topic, subject_id, source_node_ids, destination_node_id, frame_id, fields, ignore, uavcan_values, on_out_of_range, uavcan_exprs, ros_defaults, max_rate_hz, deadline, enabled, enable_service, pass_nan)",
        ),
    ),
    Case(
        'missing_field_type',
        '      - {name: level, type: int32, comment: "Level [mm]."}',
        '      - {name: level, comment: "Level [mm]."}',
        (
            "minimal.yaml:11:9: error: missing field 'type' in a field of message 'Level'",
        ),
    ),
    Case(
        'two_types_one_topic',
        '  /valve: {type: std_msgs/UInt8}',
        '  /valve: {type: std_msgs/UInt8}\n  /level: {type: std_msgs/UInt8}',
        (
            "minimal.yaml:27:3: error: topic '/level' is declared twice (first at line 25, types buoy_msgs/Level and std_msgs/UInt8): two types on one topic (expected one type per topic; give the second its own topic)",
        ),
    ),
    Case(
        'ros_field_narrower',
        '      - {name: level, type: int32, comment: "Level [mm]."}',
        '      - {name: level, type: int16, comment: "Level [mm]."}',
        (
            "minimal.yaml:53:9: error: mapping 'level', field 'level': ROS int16 is narrower than the UAVCAN int18 it receives (range [-131072, 131071]); expected int32 or wider",
        ),
    ),
    Case(
        'unsigned_into_signed',
        '/valve: {type: std_msgs/UInt8}',
        '/valve: {type: std_msgs/Int8}',
        (
            "minimal.yaml:60:9: error: mapping 'valve', field 'data': ROS int8 is narrower than the UAVCAN uint8 it receives (range [0, 255]); expected uint8 or wider",
        ),
    ),
    Case(
        'node_id_out_of_range',
        '    node_id: 10',
        '    node_id: 128',
        (
            'minimal.yaml:33:3: error: node id 128 of device gauge is out of range for Cyphal/CAN (expected 0..127)',
            "minimal.yaml:45:5: error: source node id 10 of mapping 'level' does not publish subject 100 (expected the node id of a device that publishes it: 128)",
        ),
    ),
    Case(
        'bridge_node_id_out_of_range',
        '  node_id: 100\n  mappings',
        '  node_id: 200\n  mappings',
        (
            'minimal.yaml:42:3: error: bridge node id 200 is out of range for Cyphal/CAN (expected 0..127)',
        ),
    ),
    Case(
        'subject_id_out_of_range',
        '- {subject_id: 101, type: buoy.Valve.0.1',
        '- {subject_id: 8192, type: buoy.Valve.0.1',
        (
            'minimal.yaml:40:9: error: subject id 8192 of device valve is out of range (expected 0..8191)',
            "minimal.yaml:54:5: error: subject id 101 of mapping 'valve' is used by no device (expected a subject a device publishes or subscribes)",
        ),
    ),
    Case(
        'duplicate_subject_id',
        '    subscribes:\n      - {subject_id: 101',
        '    publishes:\n      - {subject_id: 100, type: buoy.Level.0.1, rate_hz: 1}\n    subscribes:\n      - {subject_id: 101',
        (
            'minimal.yaml:40:9: error: duplicate subject id 100: already published by device gauge (expected one publisher per subject)',
        ),
    ),
    Case(
        'duplicate_node_id',
        '    node_id: 11',
        '    node_id: 10',
        (
            'minimal.yaml:37:3: error: node id 10 of device valve is already used by device gauge (expected a unique node id)',
            "minimal.yaml:54:5: error: destination node id 11 of mapping 'valve' does not subscribe to subject 101 (expected the node id of a device that subscribes to it)",
        ),
    ),
    Case(
        'bad_ros_field_name',
        '{name: level, type: int32',
        '{name: Level, type: int32',
        (
            "minimal.yaml:11:9: error: 'Level' is not a valid ROS field name in message buoy_msgs/Level (expected lower_case with single underscores, not a Python keyword)",
            "minimal.yaml:53:9: error: mapping 'level', field 'level': buoy_msgs/Level has no field 'level'",
        ),
    ),
    Case(
        'bad_ros_field_double_underscore',
        '{name: level, type: int32',
        '{name: le__vel, type: int32',
        (
            "minimal.yaml:11:9: error: 'le__vel' is not a valid ROS field name in message buoy_msgs/Level (expected lower_case with single underscores, not a Python keyword)",
            "minimal.yaml:53:9: error: mapping 'level', field 'level': buoy_msgs/Level has no field 'level'",
        ),
    ),
    Case(
        'bad_dsdl_identifier',
        '{name: level_mm, type: int18}',
        '{name: uint8, type: int18}',
        (
            "minimal.yaml:17:9: error: 'uint8' is not a valid DSDL identifier in DSDL type buoy.Level.0.1 (expected letters, digits and underscores, not reserved (e.g. uint8, bool, saturated) nor a Python keyword)",
            "minimal.yaml:53:9: error: mapping 'level', field 'level': buoy.Level.0.1 has no field 'level_mm'",
        ),
    ),
    Case(
        'bad_topic_name',
        '  /valve: {type: std_msgs/UInt8}',
        '  /valve/: {type: std_msgs/UInt8}',
        (
            "minimal.yaml:26:3: error: topic name '/valve/' is not a valid ROS name: it ends with '/' (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
            "minimal.yaml:54:5: error: mapping 'valve' uses undeclared topic '/valve' (expected a topic of `topics`)",
            "minimal.yaml:67:17: error: node valve_control publishes undeclared topic '/valve' (expected a topic of `topics`)",
        ),
    ),
    Case(
        'bad_message_name',
        '  Level:\n    description',
        '  level_msg:\n    description',
        (
            "minimal.yaml:7:3: error: 'level_msg' is not a valid ROS message name (expected CamelCase, e.g. ThrusterRPMs)",
            "minimal.yaml:25:3: error: unknown ROS type 'buoy_msgs/Level' of topic /level (expected a message of this spec, an external_messages entry or an installed ROS message)",
        ),
    ),
    Case(
        'required_field_unmapped_to_ros',
        '        level: level_mm\n',
        '        level: {value: 3}\n',
        (
            "minimal.yaml:45:5: error: required field left unmapped: UAVCAN field 'level_mm' (int18) of buoy.Level.0.1 is neither mapped nor ignored in mapping 'level' (expected a `ros_field: level_mm` line or `level_mm` in ignore)",
        ),
    ),
    Case(
        'required_field_unmapped_to_uavcan',
        '        data: open_pct\n',
        '        {}\n',
        (
            "minimal.yaml:54:5: error: required field left unmapped: UAVCAN field 'open_pct' (uint8) of buoy.Valve.0.1 gets no value in mapping 'valve' (expected a `ros_field: open_pct` line or an entry in uavcan_values)",
        ),
    ),
    Case(
        'inconsistent_parameter_limits',
        'default: 2.0, min: 0.0',
        'default: 0.5, min: 0.0',
        (
            'minimal.yaml:31:5: error: inconsistent parameter limits: /alarm_level = 0.5 must be > /warn_level = 1.0',
        ),
    ),
    Case(
        'parameter_default_outside_range',
        'default: 1.0, min: 0.0, max: 10.0',
        'default: 11.0, min: 0.0, max: 10.0',
        (
            "minimal.yaml:28:40: error: default 11.0 of parameter '/warn_level' is outside its range (expected a value in [0.0, 10.0])",
        ),
    ),
    Case(
        'source_node_not_publisher',
        'source_node_ids: [10]',
        'source_node_ids: [11]',
        (
            "minimal.yaml:45:5: error: source node id 11 of mapping 'level' does not publish subject 100 (it is device valve) (expected the node id of a device that publishes it: 10)",
        ),
    ),
    Case(
        'destination_not_subscriber',
        'destination_node_id: 11',
        'destination_node_id: 10',
        (
            "minimal.yaml:54:5: error: destination node id 10 of mapping 'valve' does not subscribe to subject 101 (expected the node id of a device that subscribes to it)",
        ),
    ),
    Case(
        'unknown_topic_in_mapping',
        '      topic: /level\n',
        '      topic: /levels\n',
        (
            "minimal.yaml:45:5: error: mapping 'level' uses undeclared topic '/levels' (expected a topic of `topics`)",
            "minimal.yaml:63:18: error: node logger subscribes to /level, which nobody publishes (expected a topic some node publishes, or one the bridge publishes from UAVCAN, or `published_by: external` on the topic)",
            "minimal.yaml:66:18: error: node valve_control subscribes to /level, which nobody publishes (expected a topic some node publishes, or one the bridge publishes from UAVCAN, or `published_by: external` on the topic)",
        ),
    ),
    Case(
        'unknown_frame',
        'frame_id: base_link',
        'frame_id: odom',
        (
            "minimal.yaml:45:5: error: frame_id 'odom' of mapping 'level' is not a declared frame (expected one of base_link, or '' for an empty frame id)",
        ),
    ),
    Case(
        'wrong_value_type',
        '    node_id: 10',
        '    node_id: ten',
        (
            "minimal.yaml:34:14: error: 'node_id' of device 'gauge' must be int, found str 'ten' (expected int)",
        ),
    ),
    Case(
        'duplicate_key',
        '  /warn_level:',
        '  /alarm_level: {type: double, default: 3.0}\n  /warn_level:',
        (
            "minimal.yaml:30:3: error: duplicate key '/alarm_level' in parameters (first at line 28) (expected unique keys)",
        ),
    ),
    Case(
        'neither_sealed_nor_extent',
        '  buoy.Valve.0.1:\n    sealed: true',
        '  buoy.Valve.0.1:\n    description: valve',
        (
            "minimal.yaml:18:3: error: DSDL type 'buoy.Valve.0.1' needs `sealed: true` or `extent: <bytes>` (expected sealed or extent (DSDL requires one))",
        ),
    ),
    Case(
        'wrong_root_namespace',
        '  buoy.Valve.0.1:',
        '  other.Valve.0.1:',
        (
            "minimal.yaml:18:3: error: DSDL type other.Valve.0.1 is outside the spec's root namespace 'buoy' (expected buoy.<namespace>.Name.MAJOR.MINOR)",
            "minimal.yaml:40:9: error: unknown DSDL type 'buoy.Valve.0.1' of device valve (expected a type of this spec or of CYPHAL_PATH)",
        ),
    ),
    Case(
        'truncated_signed',
        '{name: level_mm, type: int18}',
        '{name: level_mm, type: truncated int18}',
        (
            "minimal.yaml:17:26: error: cast mode 'truncated' applies only to unsigned integers, floats and bool, not int18",
        ),
    ),
    Case(
        'index_into_scalar',
        '        level: level_mm',
        '        level: level_mm[0]',
        (
            "minimal.yaml:53:9: error: mapping 'level', field 'level': level_mm[0]: only fixed-size arrays take an index, level_mm is int18",
        ),
    ),
    Case(
        'scale_into_int',
        '        level: level_mm',
        '        level: {from: level_mm, scale: 0.5}',
        (
            "minimal.yaml:53:9: error: mapping 'level', field 'level': scale/offset give fractions: int18 with a scale needs a float ROS field, not int32",
        ),
    ),
    Case(
        'table_value_out_of_range',
        '        level: level_mm',
        '        level: {from: level_mm, table: {0: 3000000000}}',
        (
            "minimal.yaml:53:9: error: mapping 'level', field 'level': table value 3000000000 is outside the range of int32",
        ),
    ),
    Case(
        'node_unknown_topic',
        '    subscribes: [/level]',
        '    subscribes: [/levle]',
        (
            "minimal.yaml:63:18: error: node logger subscribes to undeclared topic '/levle' (expected a topic of `topics`)",
        ),
    ),
    Case(
        'python_keyword_field',
        '{name: level, type: int32',
        '{name: class, type: int32',
        (
            "minimal.yaml:11:9: error: 'class' is not a valid ROS field name in message buoy_msgs/Level (expected lower_case with single underscores, not a Python keyword)",
            "minimal.yaml:53:9: error: mapping 'level', field 'level': buoy_msgs/Level has no field 'level'",
        ),
    ),
    Case(
        'table_misses_values',
        '        level: level_mm',
        '        level: {from: level_mm, table: {0: 0, -1: 1}}',
        (
            "minimal.yaml:53:9: error: mapping 'level', field 'level': the table has no entry for 262142 of the 262144 values of int18 (-131072, -131071, -131070, -131069, -131068, ...); a message carrying one would be dropped (expected an entry for each value, or `default: <ROS value>` for the values it does not list)",
        ),
    ),
    Case(
        'table_default_out_of_range',
        '        level: level_mm',
        '        level: {from: level_mm, table: {0: 0, default: 3000000000}}',
        (
            "minimal.yaml:53:9: error: mapping 'level', field 'level': table default 3000000000 is outside the range of int32",
        ),
    ),
    Case(
        'table_default_not_an_integer',
        '        level: level_mm',
        '        level: {from: level_mm, table: {0: 0, default: none}}',
        (
            "minimal.yaml:53:56: error: table default of field 'level' of mapping 'level' must be int, found str 'none' (expected int)",
        ),
    ),
    Case(
        'table_key_not_an_integer',
        '        level: level_mm',
        '        level: {from: level_mm, table: {zero: 0, default: 1}}',
        (
            "minimal.yaml:53:41: error: table key 'zero' of field 'level' of mapping 'level' is not an integer (expected an integer or `default`)",
        ),
    ),
    Case(
        'derive_from_unknown_type',
        '  Level:\n    description: Water level.\n    fields:\n      - {name: header, type: std_msgs/Header}\n      - {name: level, type: int32, comment: "Level [mm]."}\n',
        '  Level:\n    derive_from: buoy.Level.0.2\n',
        (
            "minimal.yaml:7:3: error: message buoy_msgs/Level derives from unknown DSDL type 'buoy.Level.0.2'",
        ),
    ),
    Case(
        'void_padding_with_a_name',
        '      - {name: level_mm, type: int18}\n',
        '      - {name: level_mm, type: int18}\n      - {name: reserved, type: void6}\n',
        (
            "minimal.yaml:18:10: error: void padding in DSDL type 'buoy.Level.0.1' has no name in DSDL (expected {type: void6} without a name)",
        ),
    ),
    Case(
        'void_padding_array',
        '      - {name: level_mm, type: int18}\n',
        '      - {name: level_mm, type: int18}\n      - {type: "void6[2]"}\n',
        (
            "minimal.yaml:18:10: error: void cannot be an array element",
        ),
    ),
    Case(
        'fixed_array_element_left_unmapped',
        '      - {name: open_pct, type: uint8}',
        '      - {name: open_pct, type: uint8}\n      - {name: limits, type: "uint8[3]"}',
        (
            "minimal.yaml:55:5: error: required field left unmapped: UAVCAN field 'limits' (uint8[3]) of buoy.Valve.0.1 gets no value in mapping 'valve' (expected a `ros_field: limits` line or an entry in uavcan_values)",
        ),
    ),
    Case(
        'unknown_ros_field_type',
        '      - {name: header, type: std_msgs/Header}',
        '      - {name: header, type: std_msgs/Headr}',
        (
            "minimal.yaml:10:9: error: unknown ROS type 'std_msgs/Headr' in message buoy_msgs/Level (expected a primitive, a message of this spec or an installed ROS message)",
        ),
    ),
    Case(
        'limits_on_uavcan_to_ros',  # the converters apply limits only towards the device: never silently ignored
        '        level: level_mm',
        '        level: {from: level_mm, limits: [0, 10]}',
        (
            "minimal.yaml:53:9: error: mapping 'level', field 'level': limits bound the values a ROS -> UAVCAN mapping commands; a UAVCAN -> ROS mapping passes on what the device measured",
        ),
    ),
    # The YAML reader refuses what would make it hang or overflow the stack (issue 20), at the place in the text.
    Case(
        'yaml_alias_expansion',  # "billion laughs": 9 levels of 10 aliases each would be 10^9 nodes
        '  base_link: {}\n',
        '  base_link: {}\n' + ''.join(f'  l{i}: &l{i} [' + ', '.join([f'*l{i - 1}'] * 10 if i else ['lol'] * 10) + ']\n'
                                      for i in range(9)),
        (
            "minimal.yaml:27:47: error: alias *l2 would copy 1111 more nodes, past the 10000 that aliases may add to this spec (8997 so far) (expected aliases that copy at most 10000 nodes in all, or 10 per node written in a larger spec)",
        ),
    ),
    Case(
        'yaml_nesting_lists',
        '  base_link: {}',
        '  base_link: ' + '[' * 5000 + ']' * 5000,
        (
            "minimal.yaml:23:112: error: the YAML nests deeper than 100 levels (expected at most 100 lists and mappings inside each other)",
        ),
    ),
    Case(
        'yaml_nesting_mappings',
        '  base_link: {}',
        '  base_link: ' + '{a: ' * 5000 + '{}' + '}' * 5000,
        (
            "minimal.yaml:23:406: error: the YAML nests deeper than 100 levels (expected at most 100 lists and mappings inside each other)",
        ),
    ),
    Case(
        'yaml_nesting_unclosed',  # libyaml gives up at 1000 levels; the limit speaks first
        '  base_link: {}',
        '  base_link: ' + '[' * 5000,
        (
            "minimal.yaml:23:112: error: the YAML nests deeper than 100 levels (expected at most 100 lists and mappings inside each other)",
        ),
    ),
    Case(
        'yaml_alias_nesting',  # each alias one level deeper than its anchor: deep without deep text
        '  base_link: {}\n',
        '  base_link: {}\n  d0: &d0 [[]]\n' + ''.join(f'  d{i}: &d{i} [*d{i - 1}]\n' for i in range(1, 120)),
        (
            "minimal.yaml:121:14: error: alias *d96 nests the YAML deeper than 100 levels (expected at most 100 lists and mappings inside each other)",
        ),
    ),
    Case(
        'yaml_alias_loop',
        '  base_link: {}',
        '  base_link: &b {parent: *b}',
        (
            "minimal.yaml:23:26: error: alias *b is inside the node it names: a spec is a tree, not a loop (expected an alias after the end of its anchor's node)",
        ),
    ),
    Case(
        'yaml_alias_undefined',
        '  base_link: {}',
        '  base_link: *b',
        (
            'minimal.yaml:23:14: error: alias *b names no anchor (expected &b on a node before it)',
        ),
    ),
    Case(
        'yaml_anchor_twice',
        '  base_link: {}',
        '  base_link: &b {}\n  odom: &b {}',
        (
            'minimal.yaml:24:9: error: anchor &b is defined twice (first at line 23) (expected a new name for each anchor)',
        ),
    ),
    Case(
        'yaml_merge_scalar',
        '  base_link: {}',
        '  base_link: {<<: 3}',
        (
            "minimal.yaml:23:19: error: a merge key '<<' takes a mapping or a list of mappings (expected an alias of a mapping, or a list of such aliases)",
        ),
    ),
    Case(
        'yaml_merge_list_of_scalars',
        '  base_link: {}',
        '  base_link: &b {}\n  odom: {<<: [*b, 3]}',
        (
            "minimal.yaml:24:19: error: a merge key '<<' takes a mapping or a list of mappings (expected an alias of a mapping, or a list of such aliases)",
        ),
    ),
    Case(
        'yaml_merge_applies',  # the merged default is overridden, and the rule sees the result
        '  /warn_level: {type: double, unit: m, default: 1.0, min: 0.0, max: 10.0}\n  /alarm_level: {type: double, unit: m, default: 2.0, min: 0.0, max: 10.0}',
        '  /warn_level: &warn {type: double, unit: m, default: 1.0, min: 0.0, max: 10.0}\n  /alarm_level: {<<: *warn, default: 0.5}',
        (
            'minimal.yaml:31:5: error: inconsistent parameter limits: /alarm_level = 0.5 must be > /warn_level = 1.0',
        ),
    ),
    Case(
        'yaml_two_documents',
        'spec_version: 1\n',
        'spec_version: 1\n---\nspec_version: 1\n',
        (
            'minimal.yaml:3:1: error: a second YAML document in the spec file (expected a single document)',
        ),
    ),
    Case(
        'yaml_complex_key',
        '  base_link: {}',
        '  ? [base_link]\n  : {}',
        (
            'minimal.yaml:23:5: error: a mapping key must be a plain scalar',
        ),
    ),
    Case(
        'mapping_rate_zero',
        '      topic: /level\n',
        '      topic: /level\n      max_rate_hz: 0\n',
        (
            "minimal.yaml:49:7: error: max_rate_hz of mapping 'level' must be positive, found 0 (expected a rate in Hz above 0)",
        ),
    ),
    Case(
        'mapping_rate_negative',
        '      topic: /valve\n',
        '      topic: /valve\n      max_rate_hz: -5\n',
        (
            "minimal.yaml:58:7: error: max_rate_hz of mapping 'valve' must be positive, found -5 (expected a rate in Hz above 0)",
        ),
    ),
    Case(
        'mapping_rate_not_a_number',
        '      topic: /level\n',
        '      topic: /level\n      max_rate_hz: fast\n',
        (
            "minimal.yaml:49:20: error: 'max_rate_hz' of mapping 'level' must be int or number, found str 'fast' (expected int or number)",
        ),
    ),
    Case(
        'mapping_rate_infinite',
        '      topic: /level\n',
        '      topic: /level\n      max_rate_hz: .inf\n',
        (
            "minimal.yaml:49:20: error: 'max_rate_hz' of mapping 'level' must be finite",
        ),
    ),
    Case(
        'mapping_deadline_on_uavcan_to_ros',
        '      topic: /level\n',
        '      topic: /level\n      deadline: 0.5\n',
        (
            "minimal.yaml:49:7: error: mapping 'level' goes UAVCAN->ROS: a deadline applies to commands (ros_to_uavcan) only (expected max_rate_hz to thin a stream, or no deadline)",
        ),
    ),
    Case(
        'mapping_deadline_zero',
        '      topic: /valve\n',
        '      topic: /valve\n      deadline: 0\n',
        (
            "minimal.yaml:58:7: error: deadline of mapping 'valve' must be positive, found 0 (expected seconds above 0)",
        ),
    ),
    Case(
        'mapping_deadline_not_a_number',
        '      topic: /valve\n',
        '      topic: /valve\n      deadline: [1]\n',
        (
            "minimal.yaml:58:17: error: 'deadline' of mapping 'valve' must be int or number, found a list (expected int or number)",
        ),
    ),
    Case(
        'mapping_deadline_within_the_rate_interval',
        '      topic: /valve\n',
        '      topic: /valve\n      max_rate_hz: 2\n      deadline: 0.5\n',
        (
            "minimal.yaml:59:7: error: deadline of mapping 'valve' (0.5 s) is not longer than the interval of its max_rate_hz (0.5 s): a command held for its slot could expire every time (expected a deadline above 0.5 s)",
        ),
    ),
    Case(
        'mapping_enabled_not_bool',
        '      topic: /level\n',
        '      topic: /level\n      enabled: 1\n',
        (
            "minimal.yaml:49:16: error: 'enabled' of mapping 'level' must be bool, found int 1 (expected bool)",
        ),
    ),
    Case(
        'mapping_enable_service_invalid',
        '      topic: /valve\n',
        '      topic: /valve\n      enable_service: start stop//valve\n',
        (
            "minimal.yaml:58:23: error: enable_service 'start stop//valve' of mapping 'valve' is not a valid ROS service name (expected /name, name or ~/name, each segment a letter or underscore then letters, digits, underscores)",
        ),
    ),
    Case(
        'mapping_enable_service_empty',
        '      topic: /valve\n',
        '      topic: /valve\n      enable_service: \'\'\n',
        (
            "minimal.yaml:58:7: error: enable_service of mapping 'valve' is empty (expected a ROS service name)",
        ),
    ),
    Case(
        'mapping_enable_service_of_another_mapping',
        '      topic: /level\n',
        '      topic: /level\n      enable_service: ~/enable_valve\n',
        (
            "minimal.yaml:55:5: error: enable_service '~/enable_valve' of mapping 'valve' is also that of 'level' (line 45) (expected one service per mapping)",
        ),
    ),
    Case(
        'relative_topic_empty_segment',
        '  /valve: {type: std_msgs/UInt8}',
        '  core//valve: {type: std_msgs/UInt8}',
        (
            "minimal.yaml:26:3: error: topic name 'core//valve' is not a valid ROS name: it has an empty segment ('//') (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
            "minimal.yaml:54:5: error: mapping 'valve' uses undeclared topic '/valve' (expected a topic of `topics`)",
            "minimal.yaml:67:17: error: node valve_control publishes undeclared topic '/valve' (expected a topic of `topics`)",
        ),
    ),
    Case(
        'relative_topic_leading_digit',
        '  /valve: {type: std_msgs/UInt8}',
        '  2core/valve: {type: std_msgs/UInt8}',
        (
            "minimal.yaml:26:3: error: topic name '2core/valve' is not a valid ROS name: segment '2core' starts with a digit (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
            "minimal.yaml:54:5: error: mapping 'valve' uses undeclared topic '/valve' (expected a topic of `topics`)",
            "minimal.yaml:67:17: error: node valve_control publishes undeclared topic '/valve' (expected a topic of `topics`)",
        ),
    ),
    Case(
        'relative_topic_private',
        '  /valve: {type: std_msgs/UInt8}',
        '  ~/valve: {type: std_msgs/UInt8}',
        (
            "minimal.yaml:26:3: error: topic name '~/valve' is not a valid ROS name: private names ('~') are not supported (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
            "minimal.yaml:54:5: error: mapping 'valve' uses undeclared topic '/valve' (expected a topic of `topics`)",
            "minimal.yaml:67:17: error: node valve_control publishes undeclared topic '/valve' (expected a topic of `topics`)",
        ),
    ),
    Case(
        'relative_topic_substitution',
        '  /valve: {type: std_msgs/UInt8}',
        '  "{node}/valve": {type: std_msgs/UInt8}',
        (
            "minimal.yaml:26:3: error: topic name '{node}/valve' is not a valid ROS name: substitutions ('{...}') are not supported (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
            "minimal.yaml:54:5: error: mapping 'valve' uses undeclared topic '/valve' (expected a topic of `topics`)",
            "minimal.yaml:67:17: error: node valve_control publishes undeclared topic '/valve' (expected a topic of `topics`)",
        ),
    ),
    Case(
        'relative_parameter_leading_digit',
        '  /warn_level: {type',
        '  warn/2level: {type',
        (
            "minimal.yaml:28:3: error: parameter name 'warn/2level' is not a valid ROS name: segment '2level' starts with a digit (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
            "minimal.yaml:31:5: error: parameter rule names unknown parameter '/warn_level'",
            "minimal.yaml:64:18: error: node logger reads undeclared parameter '/warn_level' (expected a parameter of `parameters`)",
        ),
    ),
    Case(
        'expr_cyphal_float_into_uint8',
        '      fields:\n        data: open_pct\n',
        '      fields: {}\n      uavcan_exprs: {open_pct: "data * 2.5"}\n',
        (
            "minimal.yaml:60:33: error: mapping 'valve', UAVCAN field 'open_pct': open_pct is uint8, the expression gives a float (write trunc(...) or round(...))",
        ),
    ),
    Case(
        'expr_cyphal_unknown_ros_field',
        '      fields:\n        data: open_pct\n',
        '      fields: {}\n      uavcan_exprs: {open_pct: "round(level * 2.5)"}\n',
        (
            "minimal.yaml:60:39: error: mapping 'valve', UAVCAN field 'open_pct': unknown field: std_msgs/UInt8 has no field 'level'",
        ),
    ),
    Case(
        'expr_cyphal_syntax_in_uavcan_exprs',
        '      fields:\n        data: open_pct\n',
        '      fields: {}\n      uavcan_exprs:\n        open_pct: "min(data, 100"\n',
        (
            "minimal.yaml:61:33: error: the expression of UAVCAN field 'open_pct' in uavcan_exprs of mapping 'valve': expected ')' or ',', found the end",
        ),
    ),
    Case(
        'expr_cyphal_into_time',
        '        header.stamp: timestamp.microsecond\n',
        '        header.stamp: {expr: "timestamp.microsecond + 1"}\n',
        (
            "minimal.yaml:52:31: error: mapping 'level', field 'header.stamp': an expression sets a bool or numeric scalar, header.stamp is builtin_interfaces/Time",
        ),
    ),
    Case(
        'time_sync_period_out_of_range',
        '  node_id: 100\n  mappings:',
        '  node_id: 100\n  time_sync: {period_s: 2}\n  mappings:',
        (
            'minimal.yaml:44:15: error: period_s 2 of bridge time_sync is out of range (expected 0.04..1.0 s: DroneCAN GlobalTimeSync 40..1100 ms, Cyphal uavcan.time.Synchronization at most 1 s)',
        ),
    ),
    Case(
        'time_sync_not_a_mapping',
        '  node_id: 100\n  mappings:',
        '  node_id: 100\n  time_sync: sometimes\n  mappings:',
        (
            "minimal.yaml:44:14: error: bridge time_sync must be a mapping, true or false, found str 'sometimes' (expected {enabled: true, period_s: 0.5}, true or false)",
        ),
    ),
    Case(
        'time_sync_unknown_key_and_wrong_kinds',
        '  node_id: 100\n  mappings:',
        '  node_id: 100\n  time_sync: {enabled: 1, period_s: fast, rate_hz: 2}\n  mappings:',
        (
            "minimal.yaml:44:24: error: 'enabled' of bridge time_sync must be bool, found int 1 (expected bool)",
            "minimal.yaml:44:37: error: 'period_s' of bridge time_sync must be int or number, found str 'fast' (expected int or number)",
            "minimal.yaml:44:43: error: unknown field 'rate_hz' in bridge time_sync (expected one of enabled, period_s)",
        ),
    ),
)


# DroneCAN cases: each breaks tests/specs/minimal_v0.yaml one way (tests/test_v0_bad_specs.py runs them).
V0_CASES: tuple[Case, ...] = (
    Case(  # issue 29: float64 commands into integer rpm: NaN is rejected there whatever the mapping says
        'v0_pass_nan_into_integers',
        '      destination_node_ids: [20]\n',
        '      destination_node_ids: [20]\n      pass_nan: true\n',
        (
            "minimal_v0.yaml:71:7: error: mapping 'motors': pass_nan: true acts on nothing: none of its values can carry a NaN into a UAVCAN float without limits (an integer or bool holds no NaN; a limited field rejects NaN either way) (expected no pass_nan here, or a float field without limits)",
        ),
    ),
    Case(  # its only float field has limits, which reject NaN either way
        'v0_pass_nan_into_a_limited_float',
        '        data: "commands[actuator_id=2].command_value"\n      uavcan',
        '        data: {from: "commands[actuator_id=2].command_value", limits: [-1, 1]}\n      pass_nan: true\n      uavcan',
        (
            "minimal_v0.yaml:81:7: error: mapping 'rudder': pass_nan: true acts on nothing: none of its values can carry a NaN into a UAVCAN float without limits (an integer or bool holds no NaN; a limited field rejects NaN either way) (expected no pass_nan here, or a float field without limits)",
        ),
    ),
    Case(
        'v0_array_capacity_beyond_transfer',
        '      - {name: pump_id, type: uint4}',
        '      - {name: pump_id, type: uint4}\n      - {name: blob, type: "uint8[<100000]"}',
        (
            "minimal_v0.yaml:17:22: error: array capacity 99,999 of 'uint8[<100000]' is more than a transfer can carry (at most 65,535 elements)",
        ),
    ),
    Case(
        'v0_bool_constant_not_a_bit',
        '  skiff.Bilge:\n    id: 20120\n',
        '  skiff.Bilge:\n    id: 20120\n    constants:\n      - {name: OPEN, type: bool, value: 0}\n'
        '      - {name: TWO, type: bool, value: 2}\n      - {name: NEG, type: bool, value: -1}\n'
        '      - {name: HALF, type: bool, value: 0.5}\n',
        (
            'minimal_v0.yaml:16:9: error: constant TWO of DroneCAN type skiff.Bilge = 2 is not a bool (expected true, false, 0 or 1)',
            'minimal_v0.yaml:17:9: error: constant NEG of DroneCAN type skiff.Bilge = -1 is not a bool (expected true, false, 0 or 1)',
            'minimal_v0.yaml:18:9: error: constant HALF of DroneCAN type skiff.Bilge = 0.5 is not a bool (expected true, false, 0 or 1)',
        ),
    ),
    Case(
        'v0_unknown_standard_type',
        '{type: uavcan.equipment.esc.RPMCommand, rate_hz: 10}',
        '{type: uavcan.equipment.esc.RPMCmd, rate_hz: 10}',
        (
            "minimal_v0.yaml:37:9: error: unknown DroneCAN type 'uavcan.equipment.esc.RPMCmd' of device esc (expected a type of dronecan_types or a standard one, e.g. uavcan.equipment.ahrs.RawIMU)",
            "minimal_v0.yaml:66:5: error: destination node id 20 of DroneCAN mapping 'motors' does not subscribe to uavcan.equipment.esc.RPMCommand on DroneCAN (it is device esc) (expected a device with `uavcan.equipment.esc.RPMCommand` in its DroneCAN subscribes)",
        ),
    ),
    Case(
        'v0_service_type_port',
        '{type: uavcan.equipment.esc.RPMCommand, rate_hz: 10}',
        '{type: uavcan.protocol.GetNodeInfo, rate_hz: 10}',
        (
            "minimal_v0.yaml:37:9: error: DroneCAN type 'uavcan.protocol.GetNodeInfo' of device esc is a service type (expected a message type)",
            "minimal_v0.yaml:66:5: error: destination node id 20 of DroneCAN mapping 'motors' does not subscribe to uavcan.equipment.esc.RPMCommand on DroneCAN (it is device esc) (expected a device with `uavcan.equipment.esc.RPMCommand` in its DroneCAN subscribes)",
        ),
    ),
    Case(
        'v0_nested_type_port',
        '{type: skiff.Bilge, rate_hz: 2}',
        '{type: uavcan.Timestamp, rate_hz: 2}',
        (
            "minimal_v0.yaml:32:11: error: DroneCAN type 'uavcan.Timestamp' of device gauge has no data type id: it can only be nested in other types (expected a message type with a data type id)",
            "minimal_v0.yaml:57:5: error: source node id 10 of DroneCAN mapping 'bilge' does not publish skiff.Bilge on DroneCAN (it is device gauge) (expected a device with `skiff.Bilge` in its DroneCAN publishes)",
        ),
    ),
    Case(
        'v0_node_id_out_of_range',
        '    node_id: 20\n',
        '    node_id: 126\n',
        (
            'minimal_v0.yaml:33:3: error: node id 126 of device esc is out of range for DroneCAN (expected 1..125)',
            "minimal_v0.yaml:66:5: error: destination node id 20 of DroneCAN mapping 'motors' does not subscribe to uavcan.equipment.esc.RPMCommand on DroneCAN (expected the node id of a device that does: 126)",
        ),
    ),
    Case(
        'v0_bridge_node_id',
        '  node_id: 100\n',
        '  node_id: 127\n',
        (
            'minimal_v0.yaml:46:3: error: bridge node id 127 is out of range for DroneCAN (expected 1..125)',
        ),
    ),
    Case(
        'v0_type_id_taken',
        'id: 20120',
        'id: 20100',
        (
            'minimal_v0.yaml:12:3: error: data type id 20100 of DroneCAN type skiff.Bilge is taken by the standard type com.hobbywing.esc.RawCommand of namespace com, loaded by default (no dronecan_namespaces: every namespace) (expected a free vendor-specific id, e.g. in 20101..20199, or dronecan_namespaces without com if the vehicle never uses it)',
        ),
    ),
    Case(
        'v0_type_id_not_vendor',
        'id: 20120',
        'id: 1003',
        (
            'minimal_v0.yaml:12:3: error: data type id 1003 of DroneCAN type skiff.Bilge is outside the vendor-specific range (expected 20000..20999)',
        ),
    ),
    Case(
        'v0_type_in_standard_root',
        '  skiff.Bilge:\n    id:',
        '  uavcan.Bilge:\n    id:',
        (
            "minimal_v0.yaml:12:3: error: DroneCAN type uavcan.Bilge is in the root namespace 'uavcan' of the standard definitions (expected a root namespace of your own, e.g. the vehicle's)",
            "minimal_v0.yaml:32:11: error: unknown DroneCAN type 'skiff.Bilge' of device gauge (expected a type of dronecan_types or a standard one, e.g. uavcan.equipment.ahrs.RawIMU)",
            "minimal_v0.yaml:57:5: error: unknown DroneCAN type 'skiff.Bilge' of DroneCAN mapping 'bilge' (expected a type of dronecan_types or a standard one, e.g. uavcan.equipment.ahrs.RawIMU)",
        ),
    ),
    Case(
        'v0_type_uint1',
        '{name: pump_id, type: uint4}',
        '{name: pump_id, type: uint1}',
        (
            'minimal_v0.yaml:16:25: error: uint1: a v0 integer has 2..64 bits (a single bit is a bool)',
        ),
    ),
    Case(
        'v0_type_unknown_nested',
        '{name: timestamp, type: uavcan.Timestamp}',
        '{name: timestamp, type: uavcan.Time}',
        (
            "minimal_v0.yaml:15:9: error: unknown DroneCAN type 'uavcan.Time' in DroneCAN type skiff.Bilge (expected a type of dronecan_types or a standard one, by its full name (e.g. uavcan.Timestamp))",
        ),
    ),
    Case(
        'v0_type_keyword_field',
        '      - {name: level_mm, type: int13}\n',
        '      - {name: level_mm, type: int13}\n      - {name: class, type: bool}\n',
        (
            "minimal_v0.yaml:18:9: error: 'class' is not a valid DroneCAN field name in DroneCAN type skiff.Bilge (expected a letter, then letters, digits and underscores; not a Python keyword)",
        ),
    ),
    Case(
        'v0_type_self',
        '      - {name: level_mm, type: int13}\n',
        '      - {name: level_mm, type: int13}\n      - {name: next, type: "skiff.Bilge[<=2]"}\n',
        (
            'minimal_v0.yaml:12:3: error: DroneCAN type skiff.Bilge contains itself: skiff.Bilge -> skiff.Bilge',
        ),
    ),
    Case(
        'v0_mapping_subject_id',
        '      data_type: skiff.Bilge\n',
        '      data_type: skiff.Bilge\n      subject_id: 7\n',
        (
            "minimal_v0.yaml:60:7: error: unknown field 'subject_id' in DroneCAN mapping 'bilge' (expected one of direction, topic, data_type, select, source_node_ids, destination_node_ids, frame_id, fields, ignore, uavcan_values, on_out_of_range, uavcan_exprs, ros_defaults, shares_data_type, max_rate_hz, deadline, enabled, enable_service, pass_nan)",
        ),
    ),
    Case(
        'v0_mapping_unknown_data_type',
        '      data_type: skiff.Bilge\n',
        '      data_type: skiff.Bilges\n',
        (
            "minimal_v0.yaml:57:5: error: unknown DroneCAN type 'skiff.Bilges' of DroneCAN mapping 'bilge' (expected a type of dronecan_types or a standard one, e.g. uavcan.equipment.ahrs.RawIMU)",
        ),
    ),
    Case(
        'v0_source_not_publisher',
        '      source_node_ids: [10]\n      fields:\n        data: level_mm\n      ignore',
        '      source_node_ids: [20]\n      fields:\n        data: level_mm\n      ignore',
        (
            "minimal_v0.yaml:57:5: error: source node id 20 of DroneCAN mapping 'bilge' does not publish skiff.Bilge on DroneCAN (it is device esc) (expected the node id of a device that does: 10)",
        ),
    ),
    Case(
        'v0_destination_not_subscriber',
        '      destination_node_ids: [20]',
        '      destination_node_ids: [21]',
        (
            "minimal_v0.yaml:66:5: error: destination node id 21 of DroneCAN mapping 'motors' does not subscribe to uavcan.equipment.esc.RPMCommand on DroneCAN (it is device servo) (expected the node id of a device that does: 20)",
        ),
    ),
    Case(
        'v0_destination_missing',
        '      destination_node_ids: [20]\n',
        '',
        (
            "minimal_v0.yaml:66:5: error: DroneCAN mapping 'motors' needs destination_node_ids: the nodes its broadcast commands are meant for",
        ),
    ),
    Case(
        'v0_select_unknown_field',
        'select: {pump_id: 1}',
        'select: {pump: 1}',
        (
            "minimal_v0.yaml:57:5: error: required field left unmapped: UAVCAN field 'pump_id' (uint4) of skiff.Bilge is neither mapped nor ignored in DroneCAN mapping 'bilge' (expected a `ros_field: pump_id` line or `pump_id` in ignore)",
            "minimal_v0.yaml:60:7: error: select of DroneCAN mapping 'bilge': skiff.Bilge has no field 'pump'",
        ),
    ),
    Case(
        'v0_select_out_of_range',
        'select: {pump_id: 1}',
        'select: {pump_id: 16}',
        (
            "minimal_v0.yaml:60:7: error: select value 'pump_id' of DroneCAN mapping 'bilge' = 16 does not fit uint4 (expected an integer in [0, 15])",
        ),
    ),
    Case(
        'v0_select_composite',
        'select: {pump_id: 1}',
        'select: {timestamp: 1}',
        (
            "minimal_v0.yaml:57:5: error: required field left unmapped: UAVCAN field 'pump_id' (uint4) of skiff.Bilge is neither mapped nor ignored in DroneCAN mapping 'bilge' (expected a `ros_field: pump_id` line or `pump_id` in ignore)",
            "minimal_v0.yaml:60:7: error: select of DroneCAN mapping 'bilge': timestamp is uavcan.Timestamp; a selection compares an integer or bool field",
        ),
    ),
    Case(
        'v0_select_in_cyphal',
        '      source_node_ids: [10]\n      fields:\n        data: level_mm\n  dronecan',
        '      source_node_ids: [10]\n      select: {level_mm: 1}\n      fields:\n        data: level_mm\n  dronecan',
        (
            "minimal_v0.yaml:54:7: error: unknown field 'select' in mapping 'level' (expected one of direction, topic, subject_id, source_node_ids, destination_node_id, frame_id, fields, ignore, uavcan_values, on_out_of_range, uavcan_exprs, ros_defaults, max_rate_hz, deadline, enabled, enable_service, pass_nan)",
        ),
    ),
    Case(
        'v0_index_beyond_capacity',
        '        y: rpm[1]',
        '        y: rpm[20]',
        (
            "minimal_v0.yaml:73:9: error: DroneCAN mapping 'motors', field 'y': rpm[20]: index out of range, rpm holds at most 20 elements",
        ),
    ),
    Case(
        'v0_missing_element',
        '        x: rpm[0]\n        y: rpm[1]',
        '        y: rpm[1]',
        (
            "minimal_v0.yaml:66:5: error: required field left unmapped: UAVCAN field 'rpm[0]' (int18) of uavcan.equipment.esc.RPMCommand gets no value in DroneCAN mapping 'motors' (expected a `ros_field: rpm[0]` line or an entry in uavcan_values)",
        ),
    ),
    Case(
        'v0_key_unknown_field',
        'commands[actuator_id=2].command_value"',
        'commands[actuator=2].command_value"',
        (
            "minimal_v0.yaml:80:9: error: DroneCAN mapping 'rudder', field 'data': commands[actuator=2]: the key must be an integer field of uavcan.equipment.actuator.Command, which has no field 'actuator'",
        ),
    ),
    Case(
        'v0_key_out_of_range',
        'commands[actuator_id=2].command_value"',
        'commands[actuator_id=256].command_value"',
        (
            "minimal_v0.yaml:80:9: error: DroneCAN mapping 'rudder', field 'data': commands[actuator_id=256]: 256 is outside the range of actuator_id (uint8) [0, 255]",
        ),
    ),
    Case(
        'v0_key_on_scalar_array',
        '        y: rpm[1]',
        '        y: rpm[esc=1]',
        (
            "minimal_v0.yaml:73:9: error: DroneCAN mapping 'motors', field 'y': rpm[esc=1]: an item is chosen by key in an array of composites, rpm is int18[<=20]",
        ),
    ),
    Case(
        'v0_key_in_cyphal',
        '      fields:\n        data: level_mm\n  dronecan',
        '      fields:\n        data: "level_mm[id=1]"\n  dronecan',
        (
            "minimal_v0.yaml:55:9: error: mapping 'level', field 'data': level_mm[id=1]: an item is chosen by key only in the arrays of a DroneCAN message",
        ),
    ),
    Case(
        'v0_position_and_key',
        '{"commands[actuator_id=2].command_type": 1}',
        '{"commands[actuator_id=2].command_type": 1, "commands[0].command_type": 1}',
        (
            "minimal_v0.yaml:74:5: error: DroneCAN mapping 'rudder' names elements of commands both by position and by key (expected one way for one array)",
        ),
    ),
    Case(
        'v0_two_key_fields',
        '{"commands[actuator_id=2].command_type": 1}',
        '{"commands[command_type=1].actuator_id": 2}',
        (
            "minimal_v0.yaml:74:5: error: DroneCAN mapping 'rudder' chooses items of commands by more than one key field (actuator_id, command_type) (expected one key field per array)",
        ),
    ),
    Case(
        'v0_broadcast_conflict',
        'nodes:\n',
        '    rudder_2:\n      direction: ros_to_uavcan\n      data_type: uavcan.equipment.actuator.ArrayCommand\n      topic: /rudder\n      destination_node_ids: [21]\n      fields:\n        data: "commands[actuator_id=2].command_value"\n      uavcan_values: {"commands[actuator_id=2].command_type": 0}\nnodes:\n',
        (
            "minimal_v0.yaml:82:5: error: DroneCAN mappings 'rudder' and 'rudder_2' both command uavcan.equipment.actuator.ArrayCommand (commands[actuator_id=2]) (expected distinct `select` values or distinct items chosen by key, or one mapping that writes every element, or `shares_data_type: true` in 'rudder' and 'rudder_2': each then sends its own messages)",
        ),
    ),
    Case(
        'v0_round_on_integer',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {from: level_mm, round: true}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:64:9: error: DroneCAN mapping 'bilge', field 'data': `round` takes a UAVCAN float into a ROS integer, not int13 into int16",
        ),
    ),
    Case(
        'v0_float_into_integer',
        '{name: level_mm, type: int13}',
        '{name: level_mm, type: float16}',
        (
            "minimal_v0.yaml:64:9: error: DroneCAN mapping 'bilge', field 'data': a UAVCAN float16 maps to a ROS float, not int16 (or to an integer with `round: true`)",
        ),
    ),
    Case(
        'v0_layout_unknown_device',
        'protocol: dronecan}\n',
        'protocol: dronecan, devices: {boat: cyphal}}\n',
        (
            "minimal_v0.yaml:44:86: error: layout 'all_dronecan' names unknown device 'boat' (expected a device of `devices`)",
        ),
    ),
    Case(
        'v0_layout_without_ports',
        'protocol: dronecan}\n',
        'protocol: dronecan, devices: {esc: cyphal}}\n',
        (
            "minimal_v0.yaml:44:86: error: device esc has no cyphal ports for layout 'all_dronecan' (expected a `cyphal:` section in device esc)",
        ),
    ),
    Case(
        'v0_layout_named_default',
        '  all_dronecan: {',
        '  default: {',
        (
            "minimal_v0.yaml:44:3: error: layout name 'default' is reserved: it is every device on its own `protocol` (expected another name)",
        ),
    ),
    Case(
        'v0_protocol_unknown',
        '    protocol: dronecan\n    subscribes:\n      - {type: uavcan.equipment.esc.RPMCommand',
        '    protocol: can\n    subscribes:\n      - {type: uavcan.equipment.esc.RPMCommand',
        (
            "minimal_v0.yaml:35:5: error: protocol 'can' of device 'esc' is unknown (expected cyphal or dronecan)",
        ),
    ),
    Case(
        'v0_section_of_own_protocol',
        '    dronecan:\n      publishes:\n        - {type: skiff.Bilge',
        '    cyphal:\n      publishes:\n        - {type: skiff.Bilge',
        (
            "minimal_v0.yaml:30:5: error: device 'gauge' speaks cyphal: its cyphal ports are its `publishes` and `subscribes` (expected a section for the other protocol (dronecan))",
        ),
    ),
    Case(
        'v0_type_without_id',
        '    id: 20120\n',
        '',
        (
            "minimal_v0.yaml:31:11: error: DroneCAN type 'skiff.Bilge' of device gauge has no data type id: it can only be nested in other types (expected a message type with a data type id)",
            "minimal_v0.yaml:56:5: error: DroneCAN type 'skiff.Bilge' of DroneCAN mapping 'bilge' has no data type id: it can only be nested in other types (expected a message type with a data type id)",
        ),
    ),
    Case(
        'v0_namespaces_clash_inside',
        'dronecan_types:\n  skiff.Bilge:\n    id: 20120',
        'dronecan_namespaces: [com.hobbywing]\ndronecan_types:\n  skiff.Bilge:\n    id: 20100',
        (
            'minimal_v0.yaml:13:3: error: data type id 20100 of DroneCAN type skiff.Bilge is taken by the standard type com.hobbywing.esc.RawCommand of namespace com.hobbywing, which dronecan_namespaces loads (expected a free vendor-specific id, e.g. in 20101..20199, or dronecan_namespaces without com.hobbywing if the vehicle never uses it)',
        ),
    ),
    Case(
        'v0_namespaces_unknown',
        'dronecan_types:\n  skiff.Bilge:\n    id: 20120',
        'dronecan_namespaces: [uavcan, hobbywing, com.nobody]\ndronecan_types:\n  skiff.Bilge:\n    id: 20120',
        (
            "minimal_v0.yaml:11:31: error: unknown DroneCAN namespace 'hobbywing' in dronecan_namespaces (expected a namespace of the standard definitions: ardupilot, com, cuav, dronecan, uavcan, or one inside them, e.g. com.hobbywing)",
            "minimal_v0.yaml:11:42: error: unknown DroneCAN namespace 'com.nobody' in dronecan_namespaces (expected a namespace of the standard definitions: ardupilot, com, cuav, dronecan, uavcan, or one inside them, e.g. com.hobbywing; inside com: com.hex, com.himark, com.hobbywing, com.tmotor, com.volz, com.xacti)",
        ),
    ),
    Case(
        'v0_namespaces_twice',
        'dronecan_types:\n  skiff.Bilge:\n    id: 20120',
        'dronecan_namespaces: [ardupilot, ardupilot]\ndronecan_types:\n  skiff.Bilge:\n    id: 20120',
        (
            "minimal_v0.yaml:11:34: error: DroneCAN namespace 'ardupilot' appears twice in dronecan_namespaces (first at line 11) (expected each namespace once)",
        ),
    ),
    Case(
        'v0_namespaces_not_a_list',
        'dronecan_types:\n  skiff.Bilge:\n    id: 20120',
        'dronecan_namespaces: ardupilot\ndronecan_types:\n  skiff.Bilge:\n    id: 20120',
        (
            "minimal_v0.yaml:11:22: error: dronecan_namespaces must be a list, found str 'ardupilot' (expected a list)",
        ),
    ),
    Case(
        'v0_type_outside_namespaces',
        'dronecan_types:\n  skiff.Bilge:\n    id: 20120\n    fields:\n      - {name: timestamp, type: uavcan.Timestamp}',
        'dronecan_namespaces: [dronecan]\ndronecan_types:\n  skiff.Bilge:\n    id: 20120\n    fields:\n      - {name: timestamp, type: ardupilot.gnss.Heading}',
        (
            'minimal_v0.yaml:16:9: error: DroneCAN type ardupilot.gnss.Heading of DroneCAN type skiff.Bilge is in namespace ardupilot, which dronecan_namespaces does not load (expected ardupilot or ardupilot.gnss in dronecan_namespaces)',
        ),
    ),
    Case(
        'v0_deadline_on_uavcan_to_ros',
        '      select: {pump_id: 1}\n',
        '      select: {pump_id: 1}\n      deadline: 1\n',
        (
            "minimal_v0.yaml:61:7: error: DroneCAN mapping 'bilge' goes UAVCAN->ROS: a deadline applies to commands (ros_to_uavcan) only (expected max_rate_hz to thin a stream, or no deadline)",
        ),
    ),
    Case(
        'v0_rate_negative',
        '      destination_node_ids: [20]\n',
        '      destination_node_ids: [20]\n      max_rate_hz: -1\n',
        (
            "minimal_v0.yaml:71:7: error: max_rate_hz of DroneCAN mapping 'motors' must be positive, found -1 (expected a rate in Hz above 0)",
        ),
    ),
    Case(
        'expr_unknown_field',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "level_cm * 2"}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:57:5: error: required field left unmapped: UAVCAN field 'level_mm' (int13) of skiff.Bilge is neither mapped nor ignored in DroneCAN mapping 'bilge' (expected a `ros_field: level_mm` line or `level_mm` in ignore)",
            "minimal_v0.yaml:64:23: error: DroneCAN mapping 'bilge', field 'data': unknown field: skiff.Bilge has no field 'level_cm'",
        ),
    ),
    Case(
        'expr_bool_into_number',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "level_mm > 3"}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:64:23: error: DroneCAN mapping 'bilge', field 'data': data is int16, the expression gives a bool (write int(...) for 0 or 1)",
        ),
    ),
    Case(
        'expr_float_into_integer',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "level_mm * 0.5"}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:64:23: error: DroneCAN mapping 'bilge', field 'data': data is int16, the expression gives a float (write trunc(...) or round(...))",
        ),
    ),
    Case(
        'expr_bool_as_number',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "(level_mm > 3) + 1"}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:64:33: error: DroneCAN mapping 'bilge', field 'data': level_mm > 3 is a bool, not a number (write int(level_mm > 3) for 0 or 1)",
        ),
    ),
    Case(
        'expr_division_by_zero',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "trunc(level_mm / 0)"}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:64:38: error: DroneCAN mapping 'bilge', field 'data': division by zero (level_mm / 0)",
        ),
    ),
    Case(
        'expr_syntax',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "level_mm && 1"}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:64:32: error: the expression of field 'data' of mapping 'bilge': unexpected '&' (write `and`)",
        ),
    ),
    Case(
        'expr_with_scale',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "level_mm", scale: 2}\n      ignore: [timestamp]',
        (
            "minimal_v0.yaml:64:9: error: field 'data' of mapping 'bilge' has 'expr' and 'scale' (expected 'expr' alone (it says the whole conversion))",
        ),
    ),
    Case(
        'expr_shift_of_float',
        '        data: "commands[actuator_id=2].command_value"\n',
        '        {}\n      uavcan_exprs: {"commands[actuator_id=2].command_value": "data >> 2"}\n',
        (
            "minimal_v0.yaml:81:69: error: DroneCAN mapping 'rudder', UAVCAN field 'commands[actuator_id=2].command_value': `>>` shifts integers, data is a float (write trunc() or round() first)",
        ),
    ),
    Case(
        'expr_shift_by_field',
        '        data: "commands[actuator_id=2].command_value"\n',
        '        {}\n      uavcan_exprs: {"commands[actuator_id=2].command_value": "int(data > 0) << trunc(data)"}\n',
        (
            "minimal_v0.yaml:81:81: error: DroneCAN mapping 'rudder', UAVCAN field 'commands[actuator_id=2].command_value': the shift amount must be a constant 0..63, not trunc(data)",
        ),
    ),
    Case(
        'expr_in_ros_to_uavcan_fields',
        '        data: "commands[actuator_id=2].command_value"\n',
        '        data: {expr: "x"}\n',
        (
            "minimal_v0.yaml:74:5: error: required field left unmapped: UAVCAN field 'commands[actuator_id=2].command_value' (float16) of uavcan.equipment.actuator.ArrayCommand gets no value in DroneCAN mapping 'rudder' (expected a `ros_field: commands[actuator_id=2].command_value` line or an entry in uavcan_values)",
            "minimal_v0.yaml:80:9: error: DroneCAN mapping 'rudder', field 'data': an `expr` line computes a ROS field from UAVCAN fields; a ROS->UAVCAN mapping computes UAVCAN fields from ROS fields in uavcan_exprs",
        ),
    ),
    Case(
        'uavcan_exprs_in_uavcan_to_ros',
        '      ignore: [timestamp]\n',
        '      ignore: [timestamp]\n      uavcan_exprs: {level_mm: "data"}\n',
        (
            "minimal_v0.yaml:66:22: error: DroneCAN mapping 'bilge' goes UAVCAN->ROS: uavcan_exprs compute UAVCAN fields of a ROS->UAVCAN mapping (expected `ros_field: {expr: ...}` lines in fields)",
        ),
    ),
    Case(
        'ros_field_unwritten',
        '        data: level_mm\n      ignore: [timestamp]',
        '        {}\n      ignore: [timestamp, level_mm]',
        (
            "minimal_v0.yaml:57:5: error: ROS field 'data' (int16) of std_msgs/Int16 is written by nothing in DroneCAN mapping 'bilge': it would always keep its default (expected a `data: <uavcan field>` line, `data: {value: ...}`, `data: {expr: ...}` or `data` in ros_defaults)",
        ),
    ),
    Case(
        'ros_defaults_written',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: level_mm\n      ignore: [timestamp]\n      ros_defaults: [data]',
        (
            "minimal_v0.yaml:57:5: error: ROS field 'data' is in ros_defaults of DroneCAN mapping 'bilge' but the mapping writes it (expected ros_defaults lists only fields nothing writes)",
        ),
    ),
    Case(
        'ros_defaults_in_ros_to_uavcan',
        '        y: rpm[1]\n',
        '        y: rpm[1]\n      ros_defaults: [z]\n',
        (
            "minimal_v0.yaml:66:5: error: DroneCAN mapping 'motors' goes ROS->UAVCAN: ros_defaults name ROS fields a UAVCAN->ROS mapping leaves unwritten",
        ),
    ),
    Case(
        'expr_reads_no_field',
        '        data: level_mm\n      ignore: [timestamp]',
        '        data: {expr: "1 + 2"}\n      ignore: [timestamp, level_mm]',
        (
            "minimal_v0.yaml:64:23: error: DroneCAN mapping 'bilge', field 'data': the expression reads no field (a constant is a `value`, or an entry of uavcan_values)",
        ),
    ),
)

# Broken variants of tests/specs/trawler_v0.yaml (vendor data type ids, Panic mapped onto the spec's topics):
# tests/codegen/test_vendor_panic.py runs them.
TRAWLER_CASES: tuple[Case, ...] = (
    Case(
        'panic_duty_unset',
        '  panic_duty: mappings\n',
        '',
        (
            "trawler_v0.yaml:57:5: error: DroneCAN mapping 'panic_in' maps uavcan.protocol.Panic, which the bridge's built-in Panic duty (/trawler_bridge/panic, /trawler_bridge/panic_received) handles too: the spec must say which handles it (expected `panic_duty: mappings` in bridge (the mappings instead of the built-in duty) or `panic_duty: both`)",
        ),
    ),
    Case(
        'panic_duty_builtin_with_mapping',
        '  panic_duty: mappings\n',
        '  panic_duty: builtin\n',
        (
            "trawler_v0.yaml:39:3: error: panic_duty builtin leaves uavcan.protocol.Panic to the bridge's built-in duty, but DroneCAN mapping 'panic_in' maps it (expected `panic_duty: mappings` or `panic_duty: both`)",
        ),
    ),
    Case(
        'panic_duty_unknown',
        '  panic_duty: mappings\n',
        '  panic_duty: none\n',
        (
            "trawler_v0.yaml:39:3: error: panic_duty 'none' of the bridge is unknown (expected builtin (the bridge's built-in Panic duty), mappings (the spec's mappings of uavcan.protocol.Panic instead) or both)",
        ),
    ),
    Case(
        'panic_duty_yaml_off',
        '  panic_duty: mappings\n',
        '  panic_duty: off\n',
        (
            "trawler_v0.yaml:39:15: error: 'panic_duty' of bridge must be str, found bool False (expected str)",
        ),
    ),
    Case(
        'panic_duty_mappings_without_mapping',
        '    panic_in:\n      direction: uavcan_to_ros\n      data_type: uavcan.protocol.Panic\n      topic: /panic_in\n      source_node_ids: [30]\n      fields:\n        data: reason_text\n    panic_out:\n      direction: ros_to_uavcan\n      data_type: uavcan.protocol.Panic\n      topic: /panic_out\n      destination_node_ids: [31]\n      fields:\n        data: reason_text\n',
        '',
        (
            "trawler_v0.yaml:39:3: error: panic_duty mappings turns the bridge's built-in Panic duty off, but no DroneCAN mapping maps uavcan.protocol.Panic: nothing would send or receive Panic (expected a dronecan_mappings entry with `data_type: uavcan.protocol.Panic`, or `panic_duty: builtin`)",
            'trawler_v0.yaml:61:32: error: node deck subscribes to /panic_in, which nobody publishes (expected a topic some node publishes, or one the bridge publishes from UAVCAN, or `published_by: external` on the topic)',
        ),
    ),
    Case(
        'v0_text_into_number',
        '  /relay_level: {type: std_msgs/UInt16}',
        '  /relay_level: {type: std_msgs/String}',
        (
            "trawler_v0.yaml:56:9: error: DroneCAN mapping 'relay_level', field 'data': a DroneCAN uint8[<=N] maps to a ROS string, not uint16 to string",
        ),
    ),
    Case(
        'v0_text_namespace_outside',
        'dronecan_namespaces: [uavcan, ardupilot]',
        'dronecan_namespaces: [uavcan, com]',
        (
            'trawler_v0.yaml:12:3: error: data type id 20100 of DroneCAN type trawler.io.Switch is taken by the standard type com.hobbywing.esc.RawCommand of namespace com, which dronecan_namespaces loads (expected a free vendor-specific id, e.g. in 20101..20199, or dronecan_namespaces without com if the vehicle never uses it)',
        ),
    ),
)




# Service cases: each breaks tests/specs/auv_services.yaml one way (tests/codegen/test_bad_specs_services.py runs them).
SERVICE_CASES: tuple[Case, ...] = (
    Case(
        'service_id_out_of_range',
        '    id: 201\n',
        '    id: 20201\n',
        (
            'auv_services.yaml:21:3: error: data type id 20201 of DroneCAN service type lolo.power.UpdateBattery is outside the vendor-specific service range (expected 200..255)',
        ),
    ),
    Case(
        'service_id_standard_range',
        '    id: 201\n',
        '    id: 1\n',
        (
            'auv_services.yaml:21:3: error: data type id 1 of DroneCAN service type lolo.power.UpdateBattery is outside the vendor-specific service range (expected 200..255)',
        ),
    ),
    Case(
        'service_without_id',
        '    id: 201\n',
        '',
        (
            'auv_services.yaml:21:3: error: DroneCAN service type lolo.power.UpdateBattery needs its data type id (`id`) (expected a vendor-specific service id, 200..255)',
        ),
    ),
    Case(
        'service_without_response',
        '    response:\n      - {name: success, type: uint8, comment: 1 when done}\n',
        '',
        (
            "auv_services.yaml:21:3: error: service type 'lolo.power.UpdateBattery' needs `response` (expected both `request` and `response` (an empty list for an empty half))",
        ),
    ),
    Case(
        'service_with_fields',
        '    request:\n      - {name: command, type: uint8, comment: what to do}\n',
        '    fields:\n      - {name: x, type: uint8}\n    request:\n      - {name: command, type: uint8, comment: what to do}\n',
        (
            "auv_services.yaml:26:5: error: DroneCAN type 'lolo.power.UpdateBattery' has `request`/`response` (a service type): it cannot also list fields (expected `fields` for a message type, or `request` and `response` for a service type)",
        ),
    ),
    Case(
        'service_response_bad_field',
        '      - {name: success, type: uint8, comment: 1 when done}',
        '      - {name: 2success, type: uint8}',
        (
            "auv_services.yaml:30:9: error: '2success' is not a valid DroneCAN field name in the response of DroneCAN service type lolo.power.UpdateBattery (expected a letter, then letters, digits and underscores; not a Python keyword)",
        ),
    ),
    Case(
        'srv_bad_name',
        '  UpdateBattery:\n    description: Update',
        '  update_battery:\n    description: Update',
        (
            "auv_services.yaml:32:3: error: 'update_battery' is not a valid ROS service name (expected CamelCase, e.g. UpdateBattery)",
            "auv_services.yaml:93:5: error: unknown service type 'lolo_msgs/UpdateBattery' of service mapping 'update_battery' (expected a type of `services` or `external_services` (pkg/Name))",
        ),
    ),
    Case(
        'srv_bad_field_type',
        '      - {name: charge_percent, type: float32}',
        '      - {name: charge_percent, type: std_msgs/Floaty}',
        (
            "auv_services.yaml:36:9: error: unknown ROS type 'std_msgs/Floaty' in the request of service type lolo_msgs/UpdateBattery (expected a primitive, a message of this spec or an installed ROS message)",
        ),
    ),
    Case(
        'srv_missing_response',
        "    response:\n      - {name: success, type: bool, comment: true when the device did it}\n      - {name: status, type: uint8, comment: the device's answer}\n",
        '',
        (
            "auv_services.yaml:32:3: error: missing field 'response' in service type 'UpdateBattery' (expected a list of fields (an empty list for none))",
        ),
    ),
    Case(
        'srv_duplicate_field',
        "      - {name: status, type: uint8, comment: the device's answer}",
        '      - {name: success, type: uint8}',
        (
            "auv_services.yaml:39:9: error: field 'success' appears twice in the response of service type lolo_msgs/UpdateBattery",
        ),
    ),
    Case(
        'srv_with_package',
        'services:\n  UpdateBattery:',
        'services:\n  lolo_msgs/UpdateBattery:',
        (
            "auv_services.yaml:32:3: error: service type 'lolo_msgs/UpdateBattery' is declared in package lolo_msgs: give its bare name (expected Name)",
        ),
    ),
    Case(
        'svc_map_unknown_srv',
        '      type: lolo_msgs/UpdateBattery',
        '      type: lolo_msgs/UpdateBatt',
        (
            "auv_services.yaml:93:5: error: unknown service type 'lolo_msgs/UpdateBatt' of service mapping 'update_battery' (expected a type of `services` or `external_services` (pkg/Name))",
        ),
    ),
    Case(
        'svc_map_message_type',
        '      data_type: lolo.power.UpdateBattery',
        '      data_type: uavcan.equipment.power.BatteryInfo',
        (
            "auv_services.yaml:93:5: error: DroneCAN type 'uavcan.equipment.power.BatteryInfo' of service mapping 'update_battery' is a message type (expected a service type)",
        ),
    ),
    Case(
        'svc_map_unknown_type',
        '      data_type: lolo.power.UpdateBattery',
        '      data_type: lolo.power.Update',
        (
            "auv_services.yaml:93:5: error: unknown DroneCAN type 'lolo.power.Update' of service mapping 'update_battery' (expected a service type of dronecan_types or a standard one, e.g. uavcan.protocol.GetNodeInfo)",
        ),
    ),
    Case(
        'svc_map_not_a_device',
        '      destination_node_id: 30',
        '      destination_node_id: 31',
        (
            "auv_services.yaml:93:5: error: destination node id 31 of service mapping 'update_battery' is not a DroneCAN device (expected the node id of a device with DroneCAN ports)",
        ),
    ),
    Case(
        'svc_map_request_field_missing',
        '        charge_percent: charge\n',
        '',
        (
            "auv_services.yaml:93:5: error: service mapping 'update_battery' leaves request fields of lolo.power.UpdateBattery without a value: charge (expected a `request` line or a `uavcan_values` entry for each)",
        ),
    ),
    Case(
        'svc_map_unknown_ros_field',
        '        charge_percent: charge\n',
        '        charge_pct: charge\n',
        (
            "auv_services.yaml:101:9: error: 'charge_pct' of service mapping 'update_battery' is not a field of the srv request (expected command, charge_percent)",
        ),
    ),
    Case(
        'svc_map_unknown_uavcan_field',
        '        charge_percent: charge\n',
        '        charge_percent: charge_pct\n',
        (
            "auv_services.yaml:101:9: error: 'charge_pct' of service mapping 'update_battery' is not a field of the UAVCAN request (expected command, charge)",
        ),
    ),
    Case(
        'svc_map_request_twice',
        '        charge_percent: charge\n',
        '        charge_percent: command\n',
        (
            "auv_services.yaml:101:9: error: service mapping 'update_battery' writes UAVCAN request field 'command' twice",
        ),
    ),
    Case(
        'svc_map_request_value',
        '        charge_percent: charge\n',
        '        charge_percent: charge\n      uavcan_values: {charge: 50}\n',
        (
            "auv_services.yaml:93:5: error: service mapping 'update_battery' writes UAVCAN request field 'charge' twice",
        ),
    ),
    Case(
        'svc_map_uavcan_value_unknown',
        '        charge_percent: charge\n',
        '        charge_percent: charge\n      uavcan_values: {mode: 1}\n',
        (
            "auv_services.yaml:93:5: error: uavcan_values of service mapping 'update_battery' name 'mode', not a field of the request of lolo.power.UpdateBattery (expected command, charge)",
        ),
    ),
    Case(
        'svc_map_uavcan_value_range',
        '      request:\n        command: command\n',
        '      uavcan_values: {command: 300}\n      request:\n',
        (
            "auv_services.yaml:93:5: error: uavcan value 'command' of service mapping 'update_battery' = 300 does not fit uint8 (expected an integer in [0, 255])",
        ),
    ),
    Case(
        'svc_map_timeout',
        '      timeout: 0.5',
        '      timeout: 0',
        (
            "auv_services.yaml:98:7: error: 'timeout' of service mapping 'update_battery' is 0 s (expected 0 < timeout <= 60 (seconds))",
        ),
    ),
    Case(
        'svc_map_bad_service_name',
        '      service: /bms/update_battery',
        '      service: bms update',
        (
            "auv_services.yaml:93:5: error: service name 'bms update' of service mapping 'update_battery' is not a valid ROS name: segment 'bms update' has a character other than letters, digits and '_' (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
        ),
    ),
    Case(
        # Issue 27: one name rule for topics, duties and service mappings; a relative name is valid (no error).
        'svc_map_relative_service_name',
        '      service: /bms/update_battery',
        '      service: core/update_battery',
        (),
    ),
    Case(
        'svc_map_private_service_name',
        '      service: /bms/update_battery',
        '      service: ~/update_battery',
        (
            "auv_services.yaml:93:5: error: service name '~/update_battery' of service mapping 'update_battery' is not a valid ROS name: private names ('~') are not supported (expected an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each segment a letter or underscore then letters, digits, underscores)",
        ),
    ),
    Case(
        'svc_map_table',
        '        status: success\n',
        '        status: {from: success, table: {0: 1}}\n',
        (
            "auv_services.yaml:104:9: error: response field 'status' of service mapping 'update_battery': a service line takes `from`, `scale`, `offset` or `value` (expected no table, limits or round in a service mapping)",
        ),
    ),
    Case(
        'svc_map_protocol',
        '      timeout: 0.5',
        '      timeout: 0.5\n      protocol: cyphal',
        (
            "auv_services.yaml:93:5: error: Cyphal type 'lolo.power.UpdateBattery' of service mapping 'update_battery' is not a Cyphal service type of dsdl_types or CYPHAL_PATH (expected a service type by its versioned name, e.g. uavcan.node.GetInfo.1.0)",
            "auv_services.yaml:93:5: error: destination node id 30 of service mapping 'update_battery' is not a Cyphal device (expected the node id of a device with Cyphal ports)",
        ),
    ),
    Case(
        'svc_map_bool_scaled',
        '        success: success\n',
        '        success: {from: success, scale: 2}\n',
        (
            "auv_services.yaml:103:9: error: response field 'success' (bool) of service mapping 'update_battery' cannot take success (uint8) (expected numbers or bools (scale/offset on numbers), or a string with a uint8 array)",
        ),
    ),
    Case(
        'svc_map_unknown_key',
        '      timeout: 0.5',
        '      timeout: 0.5\n      retries: 3',
        (
            "auv_services.yaml:99:7: error: unknown field 'retries' in service mapping 'update_battery' (expected one of service, type, data_type, protocol, destination_node_id, timeout, request, response, uavcan_values, service_id, response_defaults)",
        ),
    ),
    Case(
        'svc_map_missing_service',
        '      service: /bms/update_battery\n',
        '',
        (
            "auv_services.yaml:94:7: error: missing field 'service' in service mapping 'update_battery'",
        ),
    ),
    Case(
        'svc_map_destination_field_unknown',
        '      data_type: uavcan.protocol.RestartNode\n      destination_node_id: node_id',
        '      data_type: uavcan.protocol.RestartNode\n      destination_node_id: node',
        (
            "auv_services.yaml:118:5: error: destination_node_id 'node' of service mapping 'restart_node' is not an integer field of the srv request (expected a node id, or the name of an integer field of the request)",
        ),
    ),
    Case(
        'svc_map_nested_unknown',
        '        uptime_sec: status.uptime_sec',
        '        uptime_sec: status.uptime',
        (
            "auv_services.yaml:113:9: error: 'status.uptime' of service mapping 'get_node_info' is not a field of the UAVCAN response (expected status, software_version, hardware_version, name (a field of a nested type as a.b))",
        ),
    ),
    Case(
        'svc_map_nested_request',
        '      uavcan_values: {magic_number: 742196058910}\n',
        '      uavcan_values: {magic_number: 742196058910}\n      request:\n        node_id: magic_number.x\n',
        (
            "auv_services.yaml:125:9: error: 'magic_number.x' of service mapping 'restart_node' is not a field of the UAVCAN request (expected magic_number)",
        ),
    ),
    Case(
        'svc_map_magic_missing',
        '      uavcan_values: {magic_number: 742196058910}\n',
        '',
        (
            "auv_services.yaml:118:5: error: service mapping 'restart_node' leaves request fields of uavcan.protocol.RestartNode without a value: magic_number (expected a `request` line or a `uavcan_values` entry for each)",
        ),
    ),
    Case(
        'dsdl_service_without_response',
        '      - {name: accepted, type: bool}\n      - {type: void7}\n      - {name: reason, type: "uint8[<=32]"}\n',
        '',
        (
            "auv_services.yaml:16:14: error: the fields of the response of DSDL service type 'lolo.power.SetChargeLimits.1.0' must be a list, found null (expected a list)",
        ),
    ),
    Case(
        'dsdl_service_without_extent',
        '    extent: 64\n    constants:',
        '    constants:',
        (
            "auv_services.yaml:8:3: error: DSDL service type 'lolo.power.SetChargeLimits.1.0' needs `sealed: true` or `extent: <bytes>` (expected sealed or extent (DSDL requires one))",
        ),
    ),
    Case(
        'dsdl_service_bad_field',
        '      - {name: high_percent, type: uint8}',
        '      - {name: uint8, type: uint8}',
        (
            "auv_services.yaml:15:9: error: 'uint8' is not a valid DSDL identifier in DSDL type lolo.power.SetChargeLimits.1.0 (expected letters, digits and underscores, not reserved (e.g. uint8, bool, saturated) nor a Python keyword)",
        ),
    ),
    Case(
        'dsdl_service_unknown_type',
        '      - {name: accepted, type: bool}',
        '      - {name: accepted, type: lolo.Missing.1.0}',
        (
            "auv_services.yaml:17:9: error: unknown DSDL type 'lolo.Missing.1.0' in DSDL type lolo.power.SetChargeLimits.1.0 (expected a type of this spec or of CYPHAL_PATH (uavcan.*, reg.*))",
        ),
    ),
    Case(
        'dsdl_service_outside_root',
        '  lolo.power.SetChargeLimits.1.0:',
        '  other.power.SetChargeLimits.1.0:',
        (
            "auv_services.yaml:8:3: error: DSDL type other.power.SetChargeLimits.1.0 is outside the spec's root namespace 'lolo' (expected lolo.<namespace>.Name.MAJOR.MINOR)",
        ),
    ),
    Case(
        'svc_map_duplicate_service',
        '      service: /bridge/restart_node',
        '      service: /bridge/get_node_info',
        (
            "auv_services.yaml:118:5: error: service /bridge/get_node_info of service mapping 'restart_node' is already served by service mapping 'get_node_info' (expected one mapping per ROS service)",
        ),
    ),
    Case(
        'svc_cyphal_no_service_id',
        '      data_type: lolo.power.UpdateBattery\n',
        '      protocol: cyphal\n      data_type: lolo.power.SetChargeLimits.1.0\n',
        (
            "auv_services.yaml:93:5: error: destination node id 30 of service mapping 'update_battery' is not a Cyphal device (expected the node id of a device with Cyphal ports)",
            "auv_services.yaml:93:5: error: service mapping 'update_battery' needs a `service_id`: lolo.power.SetChargeLimits.1.0 has no fixed port id (expected a service id, 0..511)",
        ),
    ),
    Case(
        'svc_cyphal_service_id_range',
        '      data_type: lolo.power.UpdateBattery\n',
        '      protocol: cyphal\n      service_id: 600\n      data_type: lolo.power.SetChargeLimits.1.0\n',
        (
            "auv_services.yaml:93:5: error: destination node id 30 of service mapping 'update_battery' is not a Cyphal device (expected the node id of a device with Cyphal ports)",
            "auv_services.yaml:93:5: error: service id 600 of service mapping 'update_battery' is not a Cyphal service id (expected 0..511)",
        ),
    ),
    Case(
        'svc_cyphal_message_type',
        '      data_type: lolo.power.UpdateBattery\n',
        '      protocol: cyphal\n      data_type: uavcan.node.Heartbeat.1.0\n',
        (
            "auv_services.yaml:93:5: error: Cyphal type 'uavcan.node.Heartbeat.1.0' of service mapping 'update_battery' is a message type (expected a service type by its versioned name, e.g. uavcan.node.GetInfo.1.0)",
            "auv_services.yaml:93:5: error: destination node id 30 of service mapping 'update_battery' is not a Cyphal device (expected the node id of a device with Cyphal ports)",
        ),
    ),
    Case(
        'svc_service_id_on_dronecan',
        '      timeout: 0.5',
        '      timeout: 0.5\n      service_id: 200',
        (
            "auv_services.yaml:93:5: error: service mapping 'update_battery' has a `service_id`, which only Cyphal service mappings take (expected the DroneCAN type's data type id (no service_id), or protocol: cyphal)",
        ),
    ),
)


# Routing (issue 17 classes 5-7): each breaks tests/specs/seiner.yaml one way (tests/codegen/test_routing.py).
ROUTING_CASES: tuple[Case, ...] = (
    Case(
        'routing_select_also_commanded',
        '        data: command\n',
        '        data: hardpoint_id\n      uavcan_values: {command: 0}\n',
        (
            "seiner.yaml:159:5: error: UAVCAN field 'hardpoint_id' is set by `select` in DroneCAN mapping 'hook'; it cannot also be mapped (expected the field in select only)",
        ),
    ),
    Case(
        'routing_share_not_opted_in',
        '      destination_node_ids: [30]\n      shares_data_type: true\n',
        '      destination_node_ids: [30]\n',
        (
            "seiner.yaml:124:5: error: DroneCAN mappings 'thrusters' and 'legacy_rpm' both command uavcan.equipment.esc.RPMCommand (expected distinct `select` values or distinct items chosen by key, or one mapping that writes every element, or `shares_data_type: true` in 'legacy_rpm': each then sends its own messages)",
            "seiner.yaml:131:5: error: DroneCAN mappings 'legacy_rpm' and 'legacy_stbd_rpm' both command uavcan.equipment.esc.RPMCommand (expected distinct `select` values or distinct items chosen by key, or one mapping that writes every element, or `shares_data_type: true` in 'legacy_rpm': each then sends its own messages)",
        ),
    ),
    Case(
        'routing_share_stale',
        '      destination_node_ids: [33]\n',
        '      destination_node_ids: [33]\n      shares_data_type: true\n',
        (
            "seiner.yaml:159:5: error: DroneCAN mapping 'hook' says `shares_data_type: true`, but no other mapping commands what it commands of uavcan.equipment.hardpoint.Command (expected no `shares_data_type`: it shares nothing)",
        ),
    ),
    Case(
        'routing_share_on_uavcan_to_ros',
        '      select: {actuator_id: 3}\n',
        '      select: {actuator_id: 3}\n      shares_data_type: true\n',
        (
            "seiner.yaml:106:5: error: DroneCAN mapping 'rudder_position' goes UAVCAN->ROS: `shares_data_type` is for ROS->UAVCAN mappings (UAVCAN->ROS mappings of one data type are told apart by source node and select) (expected no `shares_data_type`)",
        ),
    ),
    Case(
        'routing_share_in_cyphal',
        '      subject_id: 700\n',
        '      subject_id: 700\n      shares_data_type: true\n',
        (
            "seiner.yaml:78:7: error: unknown field 'shares_data_type' in mapping 'winch' (expected one of direction, topic, subject_id, source_node_ids, destination_node_id, frame_id, fields, ignore, uavcan_values, on_out_of_range, uavcan_exprs, ros_defaults, max_rate_hz, deadline, enabled, enable_service, pass_nan)",
        ),
    ),
    Case(
        'routing_share_not_bool',
        '      destination_node_ids: [30]\n      shares_data_type: true\n',
        '      destination_node_ids: [30]\n      shares_data_type: yes please\n',
        (
            "seiner.yaml:129:25: error: 'shares_data_type' of DroneCAN mapping 'legacy_rpm' must be bool, found str 'yes please' (expected bool)",
        ),
    ),
    Case(
        'routing_any_misspelt',
        '      select: {actuator_id: 3}\n      topic: /rudder/position\n      source_node_ids: any\n',
        '      select: {actuator_id: 3}\n      topic: /rudder/position\n      source_node_ids: all\n',
        (
            "seiner.yaml:111:24: error: source_node_ids of DroneCAN mapping 'rudder_position' must be a list of node ids or `any`, found 'all' (expected a list of node ids, or `any` for every node)",
        ),
    ),
    Case(
        'routing_any_no_publisher',
        '      - {type: uavcan.equipment.actuator.Status, rate_hz: 10}\n',
        '      - {type: uavcan.equipment.esc.Status, rate_hz: 10}\n',
        (
            "seiner.yaml:111:7: error: DroneCAN mapping 'rudder_position' says `source_node_ids: any`, but no device publishes uavcan.equipment.actuator.Status on DroneCAN (expected a device with `uavcan.equipment.actuator.Status` in its DroneCAN publishes)",
        ),
    ),
    Case(
        'routing_any_no_subscriber',
        'data_type: uavcan.equipment.esc.RPMCommand\n      topic: /legacy/stbd_rpm\n      destination_node_ids: any\n      shares_data_type: true\n      fields:\n        data: rpm[1]\n      uavcan_values: {"rpm[0]": 0}',
        'data_type: uavcan.equipment.esc.RawCommand\n      topic: /legacy/stbd_rpm\n      destination_node_ids: any\n      shares_data_type: true\n      fields:\n        data: cmd[1]\n      uavcan_values: {"cmd[0]": 0}',
        (
            "seiner.yaml:132:5: error: DroneCAN mapping 'legacy_stbd_rpm' says `shares_data_type: true`, but no other mapping commands what it commands of uavcan.equipment.esc.RawCommand (expected no `shares_data_type`: it shares nothing)",
            "seiner.yaml:136:7: error: DroneCAN mapping 'legacy_stbd_rpm' says `destination_node_ids: any`, but no device subscribes to uavcan.equipment.esc.RawCommand on DroneCAN (expected a device with `uavcan.equipment.esc.RawCommand` in its DroneCAN subscribes)",
        ),
    ),
    Case(
        'routing_any_source_on_command',
        '      topic: /legacy/rudder\n      destination_node_ids: any\n',
        '      topic: /legacy/rudder\n      source_node_ids: any\n',
        (
            "seiner.yaml:154:7: error: DroneCAN mapping 'legacy_rudder' goes ROS->UAVCAN: it has a destination, not sources (expected destination_node_ids)",
        ),
    ),
    Case(
        'routing_any_cyphal_destination',
        '      source_node_ids: any\n      fields:\n        data: tension\n      ignore: [winch_id]\n',
        '      source_node_ids: any\n      fields:\n        data: tension\n      ignore: [winch_id]\n    winch_cmd:\n      direction: ros_to_uavcan\n      subject_id: 701\n      topic: /hook\n      destination_node_id: any\n      fields:\n        data: winch_id\n',
        (
            "seiner.yaml:83:5: error: mapping 'winch_cmd' needs destination_node_id: the node its commands are meant for",
            "seiner.yaml:87:28: error: 'destination_node_id' of mapping 'winch_cmd' must be int, found str 'any' (expected int)",
        ),
    ),
    Case(
        'routing_any_cyphal_no_publisher',
        '    publishes:\n      - {subject_id: 700, type: seiner.Winch.0.1, rate_hz: 5}\n',
        '    subscribes:\n      - {subject_id: 700, type: seiner.Winch.0.1, rate_hz: 5}\n',
        (
            "seiner.yaml:79:7: error: mapping 'winch' says `source_node_ids: any`, but no device publishes subject 700 (expected a device with subject 700 in its publishes)",
        ),
    ),
)


POWER_CASES: tuple[Case, ...] = (
    Case(
        'element_unknown_uavcan_field',
        '            charge: charge\n',
        '            charge: charge_ah\n',
        (
            "power_v0.yaml:70:9: error: required field left unmapped: UAVCAN field 'charge' (float32) of power.ConsumedCharge is neither mapped nor ignored in DroneCAN mapping 'charges', elements of 'charges' (expected a `ros_field: charge` line or `charge` in ignore)",
            "power_v0.yaml:74:13: error: DroneCAN mapping 'charges', elements of 'charges', field 'charge': power.ConsumedCharge has no field 'charge_ah'",
        ),
    ),
    Case(
        'element_unknown_ros_field',
        '            circuit_id: circuit_id\n',
        '            circuit: circuit_id\n',
        (
            "power_v0.yaml:70:9: error: ROS element field 'circuit_id' (uint16) of power_msgs/ConsumedCharge is set by nothing in DroneCAN mapping 'charges', elements of 'charges' (expected a `circuit_id: <UAVCAN element field>` line in its fields)",
            "power_v0.yaml:73:13: error: DroneCAN mapping 'charges', elements of 'charges', field 'circuit': power_msgs/ConsumedCharge has no field 'circuit'",
        ),
    ),
    Case(
        'element_type_mismatch',
        '            circuit_id: circuit_id\n',
        '            circuit_id: charge\n            foo: circuit_id\n',
        (
            "power_v0.yaml:73:13: error: DroneCAN mapping 'charges', elements of 'charges', field 'circuit_id': a UAVCAN float32 maps to a ROS float, not uint16 (or to an integer with `round: true`)",
            "power_v0.yaml:74:13: error: DroneCAN mapping 'charges', elements of 'charges', field 'foo': power_msgs/ConsumedCharge has no field 'foo'",
        ),
    ),
    Case(
        'element_uavcan_field_unmapped',
        '            charge: charge\n',
        '',
        (
            "power_v0.yaml:70:9: error: ROS element field 'charge' (float64) of power_msgs/ConsumedCharge is set by nothing in DroneCAN mapping 'charges', elements of 'charges' (expected a `charge: <UAVCAN element field>` line in its fields)",
            "power_v0.yaml:70:9: error: required field left unmapped: UAVCAN field 'charge' (float32) of power.ConsumedCharge is neither mapped nor ignored in DroneCAN mapping 'charges', elements of 'charges' (expected a `ros_field: charge` line or `charge` in ignore)",
        ),
    ),
    Case(
        'element_uavcan_field_no_value',
        '            command_type: command_type\n',
        '',
        (
            "power_v0.yaml:81:9: error: required field left unmapped: UAVCAN field 'command_type' (uint8) of uavcan.equipment.actuator.Command gets no value in DroneCAN mapping 'actuators', elements of 'commands' (expected a `ros_field: command_type` line or an entry in uavcan_values)",
        ),
    ),
    Case(
        'element_nested',
        '            charge: charge\n',
        '            charge: {each: charges, fields: {a: b}}\n',
        (
            "power_v0.yaml:74:13: error: DroneCAN mapping 'charges', elements of 'charges', field 'charge': element mappings do not nest (an element field with `each`) (expected a mapping of its own for the inner array)",
        ),
    ),
    Case(
        'element_each_not_composite_array',
        '          each: charges\n',
        '          each: timestamp\n',
        (
            "power_v0.yaml:62:5: error: required field left unmapped: UAVCAN field 'charges' (power.ConsumedCharge[<=15]) of power.ConsumedChargeArray is neither mapped nor ignored in DroneCAN mapping 'charges' (expected a `ros_field: charges` line or `charges` in ignore)",
            "power_v0.yaml:70:9: error: DroneCAN mapping 'charges', field 'charges': `each` takes an array of composites, timestamp is uavcan.Timestamp",
        ),
    ),
    Case(
        'element_ros_not_array',
        '        charges:\n          each: charges\n',
        '        header:\n          each: charges\n',
        (
            "power_v0.yaml:62:5: error: ROS field 'charges' (power_msgs/ConsumedCharge[]) of power_msgs/ConsumedCharges is written by nothing in DroneCAN mapping 'charges': it would always keep its default (expected a `charges: <uavcan field>` line, `charges: {value: ...}`, `charges: {expr: ...}` or `charges` in ros_defaults)",
            "power_v0.yaml:70:9: error: DroneCAN mapping 'charges', field 'header': `each` maps an array of messages element by element, header is std_msgs/Header",
        ),
    ),
    Case(
        'element_link_key_outside',
        '          each: commands\n',
        '          each: commands\n          scale: 2\n',
        (
            "power_v0.yaml:83:11: error: field 'commands' of mapping 'actuators' maps elements (`each`): 'scale' belongs to its element fields (expected `scale` inside `fields`)",
        ),
    ),
    Case(
        'element_fields_missing',
        '          each: commands\n          fields:\n            actuator_id: actuator_id\n            command_type: command_type\n            value: command_value\n',
        '          each: commands\n',
        (
            "power_v0.yaml:81:9: error: field 'commands' of mapping 'actuators' maps elements of 'commands' but has no `fields` (expected fields: {<ROS element field>: <UAVCAN element field>})",
        ),
    ),
    Case(
        'element_each_missing',
        '          each: commands\n',
        '',
        (
            "power_v0.yaml:81:9: error: field 'commands' of mapping 'actuators' has `fields` but no `each` (the UAVCAN array whose elements it maps) (expected each: <UAVCAN array of composites>)",
        ),
    ),
    Case(
        'composite_array_without_each',
        '        charges:\n          each: charges\n          fields:\n            circuit_id: circuit_id\n            charge: charge\n',
        '        charges: charges\n',
        (
            "power_v0.yaml:70:9: error: DroneCAN mapping 'charges', field 'charges': charges is power_msgs/ConsumedCharge[]: map it element by element with `{each: <UAVCAN array>, fields: {...}}`",
        ),
    ),
    Case(
        'element_each_indexed',
        '          each: charges\n',
        '          each: charges[0]\n',
        (
            "power_v0.yaml:70:9: error: DroneCAN mapping 'charges', field 'charges': charges[0] names an array element; `each` maps a whole array",
        ),
    ),
    Case(
        'element_value_unknown',
        '          each: commands\n',
        '          each: commands\n          uavcan_values: {command_kind: 1}\n',
        (
            "power_v0.yaml:81:9: error: uavcan_values of DroneCAN mapping 'actuators', elements of 'commands': uavcan.equipment.actuator.Command has no field 'command_kind'",
        ),
    ),
    Case(
        'element_value_and_link',
        '          each: commands\n',
        '          each: commands\n          uavcan_values: {command_type: 1}\n',
        (
            "power_v0.yaml:81:9: error: UAVCAN field 'command_type' is both mapped and in uavcan_values in DroneCAN mapping 'actuators', elements of 'commands'",
        ),
    ),
    Case(
        'element_array_also_by_key',
        '            value: command_value\n',
        '            value: command_value\n        foo: commands[actuator_id=3].command_value\n',
        (
            "power_v0.yaml:81:9: error: DroneCAN mapping 'actuators', field 'commands': commands is mapped element by element here and also named by field 'foo'; one way for one array",
            "power_v0.yaml:87:9: error: DroneCAN mapping 'actuators', field 'foo': power_msgs/Commands has no field 'foo'",
        ),
    ),
    Case(
        'element_array_also_valued',
        '      destination_node_ids: [31]\n',
        '      destination_node_ids: [31]\n      uavcan_values: {"commands[actuator_id=1].command_type": 1}\n',
        (
            "power_v0.yaml:82:9: error: DroneCAN mapping 'actuators', field 'commands': commands is mapped element by element here and also named by uavcan_values 'commands[actuator_id=1].command_type'; one way for one array",
        ),
    ),
    Case(
        'element_ros_fixed_array',
        '      - {name: commands, type: "power_msgs/Command[]"}\n',
        '      - {name: commands, type: "power_msgs/Command[3]"}\n',
        (
            "power_v0.yaml:81:9: error: DroneCAN mapping 'actuators', field 'commands': `each` maps into a ROS sequence (T[] or T[<=N]), commands is a fixed-size array (power_msgs/Command[3])",
        ),
    ),
    Case(
        'element_ros_bounded_too_small',
        '      - {name: charges, type: "power_msgs/ConsumedCharge[]"}\n',
        '      - {name: charges, type: "power_msgs/ConsumedCharge[<=4]"}\n',
        (
            "power_v0.yaml:70:9: error: DroneCAN mapping 'charges', field 'charges': charges (power_msgs/ConsumedCharge[<=4]) holds fewer elements than charges (power.ConsumedCharge[<=15])",
        ),
    ),
    Case(
        'element_ros_field_ignored_only',
        '            charge: charge\n',
        '          ignore: [charge]\n',
        (
            "power_v0.yaml:70:9: error: ROS element field 'charge' (float64) of power_msgs/ConsumedCharge is set by nothing in DroneCAN mapping 'charges', elements of 'charges' (expected a `charge: <UAVCAN element field>` line in its fields)",
        ),
    ),
)
