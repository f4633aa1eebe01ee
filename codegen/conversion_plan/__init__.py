"""The conversion plan: every mapping lowered once into typed operations, per link and direction.

`lower_mapping(rm)` decides, for both converters of a mapping (UAVCAN -> ROS and ROS -> UAVCAN), what each link
does to its value, in order: scale and offset, representation changes, NaN rejection, rounding, clamping with its
policy (saturate or reject; finite-only for float32, infinities too for float16, round-into-range for float ->
integer), padding, cutting, tables, timestamps and constants, and mapping expressions (Evaluate: a typed tree of
model.expr, followed by the same checks into the target field). The renderers only word it: targets.python (through
its statements) turns the operations into statements, the wire codecs do the same with their own reads and
writes, and targets.docs words the same operations in the interface reference. Nothing here knows Python syntax.

For an array link the value operations apply to every element; Pad, FixedLength and MaxLength to the array.

The parts, by job: conversion_plan.value_ranges (the ranges of the types), conversion_plan.operations (the
operations and the plans made of them) and conversion_plan.lowering (mappings into plans). Import from here.
"""

from __future__ import annotations

from sam_codegen.conversion_plan.lowering import (
    expr_target,
    float32_overflow,
    lower_elements,
    lower_expr,
    lower_link,
    lower_mapping,
    passes_nan,
    range_ops,
    ros_value,
)
from sam_codegen.conversion_plan.operations import (
    CHECK_OPS,
    EXPRESSION_OPS,
    TO_ROS,
    TO_UAVCAN,
    Clamp,
    ClampMode,
    Convert,
    DecodeUtf8,
    ElementMapping,
    EncodeUtf8,
    Evaluate,
    FieldSet,
    FixedLength,
    Limits,
    LinkPlan,
    MappingPlan,
    MaxLength,
    Offset,
    Op,
    Pad,
    PlanDirection,
    ReceiveTime,
    RejectNaN,
    RequireItem,
    RequireLength,
    Round,
    Scale,
    SetConstant,
    StaticFrameId,
    Table,
    TimestampFromRos,
    TimestampToRos,
    Utf8Length,
    Wrap,
)
from sam_codegen.conversion_plan.value_ranges import (
    FLOAT16_MAX,
    FLOAT32_MAX,
    INT32_MAX,
    TIME_US_MAX_FROM_ROS,
    TIME_US_MAX_TO_ROS,
    TIME_US_MIN,
    ValueRange,
    dsdl_range,
    is_int_dsdl,
    ros_range,
    width_change,
)

__all__ = [
    "CHECK_OPS",
    "EXPRESSION_OPS",
    "FLOAT16_MAX",
    "FLOAT32_MAX",
    "INT32_MAX",
    "TIME_US_MAX_FROM_ROS",
    "TIME_US_MAX_TO_ROS",
    "TIME_US_MIN",
    "TO_ROS",
    "TO_UAVCAN",
    "Clamp",
    "ClampMode",
    "Convert",
    "DecodeUtf8",
    "ElementMapping",
    "EncodeUtf8",
    "Evaluate",
    "FieldSet",
    "FixedLength",
    "Limits",
    "LinkPlan",
    "MappingPlan",
    "MaxLength",
    "Offset",
    "Op",
    "Pad",
    "PlanDirection",
    "ReceiveTime",
    "RejectNaN",
    "RequireItem",
    "RequireLength",
    "Round",
    "Scale",
    "SetConstant",
    "StaticFrameId",
    "Table",
    "TimestampFromRos",
    "TimestampToRos",
    "Utf8Length",
    "ValueRange",
    "Wrap",
    "dsdl_range",
    "expr_target",
    "float32_overflow",
    "is_int_dsdl",
    "lower_elements",
    "lower_expr",
    "lower_link",
    "lower_mapping",
    "passes_nan",
    "range_ops",
    "ros_range",
    "ros_value",
    "width_change",
]
