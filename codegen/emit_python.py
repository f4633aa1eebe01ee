"""Python emitter: the bridge's tables (pure data) and its converters (ROS messages <-> pycyphal objects).

Output, under generated/:
- ``python/<vehicle>_bridge/__init__.py``
- ``python/<vehicle>_bridge/tables.py``: devices, topics, mappings, parameters and frames as frozen dataclasses;
  standard library only, so the runtime can read it without ROS or DSDL.
- ``python/<vehicle>_bridge/convert.py``: per mapping ``<name>_to_ros(src, receive_ns, stats)`` and
  ``<name>_to_uavcan(src, stats)``, straight-line code with every range decided here, at generation time.

What each converter does to each value is decided once, in the conversion plan (conversion_plan.lower_mapping);
this module renders the plan's operations as Python (through python_statements: names, literals, statements) and
the templates in templates/python/ decide how the files look. Everything is deterministic: no timestamps, no
absolute paths, and every text from the spec reaches the output as a Python literal (repr).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import emit_nodes  # the tables' QoS, transforms and nodes
from . import python_statements as pys
from .conversion_plan import (  # the constants stay importable from here (tests use them)
    CHECK_OPS,
    FLOAT16_MAX,
    FLOAT32_MAX,
    INT32_MAX,
    TIME_US_MAX_FROM_ROS,
    TIME_US_MAX_TO_ROS,
    TIME_US_MIN,
    TO_ROS,
    TO_UAVCAN,
    Clamp,
    Constant,
    DecodeUtf8,
    EncodeUtf8,
    FixedLength,
    LinkPlan,
    MaxLength,
    Offset,
    Pad,
    ReceiveTime,
    Scale,
    StaticFrameId,
    Table,
    TimestampFromRos,
    TimestampToRos,
    Utf8Length,
    dsdl_range,
    is_int_dsdl,
    lower_link,
    lower_mapping,
    range_ops,
    ros_range,
    ros_value,
)
from .mapping_rules import ResolvedMapping, Step, format_path
from .model import DsdlStruct, RosMessage
from .python_factories import (
    _dsdl_factory,
    _ros_factory,
    dsdl_factory_name,
    dsdl_factory_supported,
    ros_factory_name,
)
from .python_names import (
    LINE_LIMIT,
    _access,
    _identifier,
    _isort_key,
    _Names,
    _referenced_roots,
    _ros_aliases,
    dict_literal,
    py_attr,
    py_class_ref,
    py_module,
)
from .python_names import _ros_closure as _ros_closure
from .python_names import py_class_name as py_class_name  # re-exported (tests)
from .python_statements import dsdl_literal, py_literal
from .python_statements import typed_literal as _typed_literal
from .python_tables import _tables_context
from .python_tables import _text as _text  # re-exported: emit_nodes, emit_python_v0
from .python_tables import _tuple as _tuple
from .templating import render
from .typesys import DsdlType, RosType
from .validate import Resolved

__all__ = ["FLOAT16_MAX", "FLOAT32_MAX", "INT32_MAX", "TIME_US_MAX_FROM_ROS", "TIME_US_MAX_TO_ROS", "TIME_US_MIN",
           "emit", "py_attr", "py_class_ref", "py_literal"]

# ---- the plan's value ranges and statements, under the names the codec emitters know ------------------------

_dsdl_range = dsdl_range
_ros_range = ros_range
_is_int_dsdl = is_int_dsdl
_num = py_literal  # a numeric literal in generated code (ints stay ints)
_st = pys.st  # one statement for templates/python/statements.j2
_Policy = pys.Policy
_bound_statement = pys.bound_statement


def _number_checks(var: str, value_is_float: bool, value_range: tuple[float, float] | None, target: DsdlType,
                   limits: tuple[float, float] | None, policy: _Policy) -> list[dict[str, Any]]:
    """The statements that make `var` (a ROS-side value) acceptable to a DSDL scalar of type `target`: the plan's
    range operations (conversion_plan.range_ops), rendered."""
    return pys.check_statements(var, range_ops(value_is_float, value_range, target, limits, policy.reject),
                                policy.key)


# ---- one mapping ---------------------------------------------------------------------------------------------


@dataclass
class _Function:
    name: str
    params: list[str]
    returns: str
    doc: list[str]  # docstring lines
    binds: list[dict[str, Any]] = field(default_factory=list)
    statements: list[dict[str, Any]] = field(default_factory=list)
    result: list[str] = field(default_factory=list)  # lines of the final return (to_uavcan) or empty


class _Ctor:
    """A message under construction, a DSDL object or a ROS message: field name -> expression or nested node."""

    def __init__(self, ref: str, fields: list[tuple[str, Any]], keyword=lambda name: name) -> None:
        self.ref = ref  # what is called: the pycyphal class or the ROS message's constructor
        self.types = dict(fields)  # field name -> DsdlType | RosType, in declaration order
        self.keyword = keyword
        self.kwargs: dict[str, Any] = {}

    def arguments(self) -> list[tuple[str, Any]]:
        return [(self.keyword(name), self.kwargs[name]) for name in self.types if name in self.kwargs]


class _Arr:
    """A fixed-size array written element by element; the other elements get `default`."""

    def __init__(self, capacity: int, default: str) -> None:
        self.capacity, self.default = capacity, default
        self.items: dict[int, Any] = {}


@dataclass
class _Module:
    """What convert.py needs beyond the functions."""

    resolved: Resolved
    ros_aliases: dict[str, str] = field(default_factory=dict)  # pkg/Name -> local class name
    dsdl_modules: set[str] = field(default_factory=set)
    tables: list[dict[str, Any]] = field(default_factory=list)
    module_names: set[str] = field(default_factory=set)
    dsdl_factories: dict[str, DsdlStruct] = field(default_factory=dict)  # full name -> struct, as used

    def dsdl_ref(self, struct: DsdlStruct) -> str:
        self.dsdl_modules.add(py_module(struct.namespace))
        return py_class_ref(struct)

    def struct(self, name: str) -> DsdlStruct:
        struct = self.resolved.dsdl.get(name)
        assert struct is not None, name
        return struct

    def ros_message(self, full_name: str) -> RosMessage:
        message = self.resolved.ros.get(full_name)
        assert message is not None, full_name
        return message

    def dsdl_new(self, struct: DsdlStruct) -> str:
        """What builds an object of `struct`: its generated constructor, or the class where there is none."""
        ref = self.dsdl_ref(struct)
        if not dsdl_factory_supported(struct):
            return ref
        self.dsdl_factories.setdefault(struct.name, struct)
        return dsdl_factory_name(struct)

    def dsdl_ctor(self, struct: DsdlStruct) -> _Ctor:
        return _Ctor(self.dsdl_new(struct), [(f.name, f.type) for f in struct.fields], py_attr)

    def ros_ctor(self, message: RosMessage) -> _Ctor:
        return _Ctor(ros_factory_name(self.ros_aliases[message.full_name]), [(f.name, f.type) for f in message.fields])

    def child(self, t: DsdlType | RosType) -> _Ctor:
        """A node for a composite field (or element) of type t."""
        if isinstance(t, DsdlType):
            return self.dsdl_ctor(self.struct(t.composite))  # type: ignore[arg-type]
        return self.ros_ctor(self.ros_message(t.base))

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType):
            if t.kind == "composite":
                return f"{self.dsdl_new(self.struct(t.composite))}()"  # type: ignore[arg-type]
            return _typed_literal(0, "float" if t.kind == "float" else t.kind)
        if not t.is_primitive:
            return f"{ros_factory_name(self.ros_aliases[t.base])}()"
        return _typed_literal(0, t.base)

    def insert(self, root: _Ctor, path: tuple, value: str) -> None:
        """Set the field at `path` (segments (name, index or None)) of the tree under root to `value`."""
        node: Any = root
        for i, (name, index) in enumerate(path):
            last = i == len(path) - 1
            t = node.types.get(name)
            assert t is not None, (path, name)
            if index is None:
                if last:
                    node.kwargs[name] = value
                else:
                    if name not in node.kwargs:
                        node.kwargs[name] = self.child(t)
                    node = node.kwargs[name]
            else:
                if name not in node.kwargs:
                    node.kwargs[name] = _Arr(t.capacity or 0, self.element_default(t.element))
                arr = node.kwargs[name]
                if last:
                    arr.items[index] = value
                else:
                    if index not in arr.items:
                        arr.items[index] = self.child(t.element)
                    node = arr.items[index]

    def format_node(self, node: Any, indent: int) -> list[str]:
        """Lines of an expression; the first line is not indented, the rest are (absolute indent)."""
        if isinstance(node, str):
            return [node]
        if isinstance(node, _Arr):
            items = [node.items.get(i, node.default) for i in range(node.capacity)]
            parts = [self.format_node(item, indent + 4) for item in items]
            one = "[" + ", ".join(p[0] for p in parts) + "]"
            if all(len(p) == 1 for p in parts) and indent + len(one) <= LINE_LIMIT - 20:
                return [one]
            lines = ["["]
            for p in parts:
                lines.append(" " * (indent + 4) + p[0])
                lines.extend(p[1:])
                lines[-1] += ","
            lines.append(" " * indent + "]")
            return lines
        parts = [(k, self.format_node(v, indent + 4)) for k, v in node.arguments()]
        one = f"{node.ref}(" + ", ".join(f"{k}={p[0]}" for k, p in parts) + ")"
        if all(len(p) == 1 for _, p in parts) and indent + len(one) <= LINE_LIMIT - 20:
            return [one]
        lines = [f"{node.ref}("]
        for k, p in parts:
            lines.append(" " * (indent + 4) + f"{k}={p[0]}")
            lines.extend(p[1:])
            lines[-1] += ","
        lines.append(" " * indent + ")")
        return lines

    def format_return(self, root: _Ctor) -> list[str]:
        lines = self.format_node(root, 4)
        lines[0] = "return " + lines[0]
        return [line[4:] if i else line for i, line in enumerate(lines)]


class _MappingEmitter:
    def __init__(self, module: _Module, rm: ResolvedMapping) -> None:
        self.module, self.rm = module, rm
        self.mapping = rm.mapping
        self.name = rm.mapping.name
        self.reject = rm.mapping.on_out_of_range == "reject"
        self.ros_class = module.ros_aliases[rm.ros_message.full_name]
        self.dsdl_ref = module.dsdl_ref(rm.dsdl_struct)
        self.plan = lower_mapping(rm)  # what both converters do; the methods below only say it in Python
        self._links = {(id(link.step), link.direction): link for link in (*self.plan.to_ros, *self.plan.to_uavcan)}

    def policy(self, path: str) -> _Policy:
        return _Policy(repr(f"{self.name}.{path}"), self.reject)

    def link(self, s: Step, direction: str) -> LinkPlan:
        """The plan of one link (lowered here for a step that is not the mapping's own)."""
        found = self._links.get((id(s), direction))
        if found is not None and found.step == s:
            return found
        return lower_link(s, direction, self.name, self.reject)  # type: ignore[arg-type]

    # -- UAVCAN -> ROS ---------------------------------------------------------------------------------------
    def to_ros(self) -> _Function:
        """Values first (every check and drop before anything is built), then one nested constructor call."""
        rm = self.rm
        names = _Names(self.module.module_names)
        fn = _Function(
            f"{self.name}_to_ros",
            [f"src: {self.dsdl_ref}", "receive_ns: int", "stats: ConversionStats"],
            f"{self.ros_class} | None",
            [f"Mapping {self.name!r}, UAVCAN -> ROS.", "", f"{rm.dsdl_struct.name} -> {rm.ros_message.full_name}"],
        )
        steps = list(rm.steps)
        listed = self.bind_uavcan_arrays(fn, names, steps)

        def uav_read(path: tuple) -> str:
            if path[-1][1] is not None:
                array_path = (*path[:-1], (path[-1][0], None))
                if array_path in listed:
                    return f"{listed[array_path]}[{path[-1][1]}]"
            return self.uav_access("src", path)

        root = self.module.ros_ctor(rm.ros_message)
        for fs in self.plan.ros_fields:
            if isinstance(fs.op, StaticFrameId):
                self.module.insert(root, fs.path, py_literal(fs.op.value))
            elif isinstance(fs.op, ReceiveTime):
                self.module.insert(root, (*fs.path, ("sec", None)), "receive_ns // 1_000_000_000")
                self.module.insert(root, (*fs.path, ("nanosec", None)), "receive_ns % 1_000_000_000")
        for s in steps:
            for path, value in self.step_to_ros(s, names, uav_read, fn.statements):
                self.module.insert(root, path, value)
        fn.result = self.module.format_return(root)
        return fn

    def bind_uavcan_arrays(self, fn: _Function, names: _Names, steps: list[Step],
                           listed: dict[tuple, str] | None = None) -> dict[tuple, str]:
        """Locals for UAVCAN primitive arrays read by index (rate_gyro_latest[0..2]): one list each (beside those
        in `listed` already)."""
        listed = {} if listed is None else listed
        for s in steps:
            if s.kind in ("number", "table") and s.uavcan_path and s.uavcan_path[-1][1] is not None:
                array_path = (*s.uavcan_path[:-1], (s.uavcan_path[-1][0], None))
                if array_path not in listed:
                    listed[array_path] = names.new(format_path(list(array_path)))
                    fn.binds.append(_st("assign", target=listed[array_path],
                                        expr=self.uav_list(self.uav_access("src", array_path))))
        return listed

    def uav_access(self, base: str, path: tuple) -> str:
        """The expression reading a field of a received UAVCAN object."""
        return _access(base, path, py_attr)

    def uav_list(self, expr: str) -> str:
        """A UAVCAN array as a list of plain Python values (pycyphal keeps them in numpy arrays)."""
        return f"{expr}.tolist()"

    def step_to_ros(self, s: Step, names: _Names, uav_read, statements: list[dict[str, Any]]
                    ) -> list[tuple[tuple, str]]:
        """Append the statements of one link (its planned operations); return the (ROS path, expression) pairs
        it sets."""
        link = self.link(s, TO_ROS)
        ops = link.ops
        key = repr(link.key)
        first = ops[0] if ops else None
        if isinstance(first, Constant):
            return [(s.ros_path, _typed_literal(first.value, s.ros_type.base))]
        assert s.uavcan_type is not None
        read = uav_read(s.uavcan_path)
        if isinstance(first, TimestampToRos):
            us, sec, nanosec = names.new("us"), names.new("sec"), names.new("nanosec")
            statements.append(pys.timestamp_to_ros(first, us, read, sec, nanosec, key))
            return [((*s.ros_path, ("sec", None)), sec), ((*s.ros_path, ("nanosec", None)), nanosec)]
        if isinstance(first, Table):
            var = names.new(s.ros)
            table = self.module_table(s, TO_ROS)
            default = None if first.default is None else py_literal(first.default)
            statements.append(_st("table", var=var, table=table, read=read, key=key, default=default))
            return [(s.ros_path, var)]
        if isinstance(first, DecodeUtf8):
            return [(s.ros_path, f"{read}.tobytes().decode(errors='replace')")]
        ros_base = s.ros_type.base
        if s.kind == "number":
            expr = pys.to_ros_expr(read, ops, ros_base)
            if not link.has(*CHECK_OPS):
                return [(s.ros_path, expr)]
            var = names.new(s.ros)
            statements.append(_st("assign", target=var, expr=expr))
            statements.extend(pys.check_statements(var, ops, key))
            return [(s.ros_path, var)]
        # array: the elements, their float32 range, then the padding
        elem = pys.to_ros_expr("x", ops, ros_base)
        base_list = self.uav_list(read)
        expr = base_list if elem == "x" else f"[{elem} for x in {base_list}]"
        pad = link.first(Pad)
        overflow = link.has(Clamp)
        if pad is None and not overflow:
            return [(s.ros_path, expr)]
        var = names.new(s.ros)
        statements.append(_st("assign", target=var, expr=expr))
        if overflow:
            statements.append(pys.float32_helper(var, link))
        if isinstance(pad, Pad):
            statements.append(_st("pad", var=var, size=pad.size, zero=_typed_literal(0, ros_base)))
        return [(s.ros_path, var)]

    def module_table(self, s: Step, direction: str) -> str:
        """The module constant holding a link's table in `direction` (one per link and direction)."""
        const = f"_{self.name}_{_identifier(s.ros)}".upper() + ("_TO_ROS" if direction == TO_ROS else "_TO_UAVCAN")
        if not any(t["name"] == const for t in self.module.tables):
            pairs = [(py_literal(k), py_literal(v))
                     for k, v in Table(s.table, s.table_default, direction != TO_ROS).lookup()]
            self.module.tables.append({
                "name": const,
                "items": pairs,
                "literal": dict_literal(f"{const}: dict[int, int] = ", pairs),
                "what": f"{self.name}: {s.uavcan} -> {s.ros}" if direction == TO_ROS
                else f"{self.name}: {s.ros} -> {s.uavcan} (first key per value)",
            })
        return const

    # -- ROS -> UAVCAN ---------------------------------------------------------------------------------------
    def to_uavcan(self) -> _Function:
        rm = self.rm
        names = _Names(self.module.module_names)
        fn = _Function(
            f"{self.name}_to_uavcan",
            [f"src: {self.ros_class}", "stats: ConversionStats"],
            f"{self.dsdl_ref} | None",
            [f"Mapping {self.name!r}, ROS -> UAVCAN.", "", f"{rm.ros_message.full_name} -> {rm.dsdl_struct.name}"],
        )
        steps = [s for s in rm.steps if s.uavcan_path]
        ros_read = self.ros_reader(fn, names, steps)
        root = self.module.dsdl_ctor(rm.dsdl_struct)
        for s in steps:
            value = self.step_to_uavcan(s, names, ros_read, fn.statements)
            self.module.insert(root, s.uavcan_path, value)
        for fs in self.plan.uavcan_fields:  # uavcan_values, then DroneCAN's select
            assert isinstance(fs.op, Constant) and isinstance(fs.type, DsdlType)
            self.module.insert(root, fs.path, dsdl_literal(fs.op.value, fs.type))
        fn.result = self.module.format_return(root)
        return fn

    def ros_reader(self, fn: _Function, names: _Names, steps: list[Step]) -> Callable[[tuple], str]:
        """The to_uavcan read helper: binds what the steps read (appended to fn.binds) and returns the function
        from a ROS path to the expression reading it (a Time path: an expression with .sec and .nanosec).
        Overridden by the wire codecs (emit_codec), which read from CDR bytes."""
        # Locals for ROS parents read more than once, and one .tolist() per ROS array read by index.
        reads: dict[tuple, int] = {}
        for s in steps:
            if s.kind == "time":
                reads[s.ros_path] = reads.get(s.ros_path, 0) + 2
            elif len(s.ros_path) > 1:
                reads[s.ros_path[:-1]] = reads.get(s.ros_path[:-1], 0) + 1
        parent_local: dict[tuple, str] = {}
        for parent, count in reads.items():
            if count >= 2 and all(index is None for _, index in parent):
                parent_local[parent] = names.new(parent[-1][0])
                fn.binds.append(_st("assign", target=parent_local[parent], expr=_access("src", parent)))
        listed: dict[tuple, str] = {}
        for s in steps:
            if s.kind in ("number", "table") and s.ros_path[-1][1] is not None:
                array_path = (*s.ros_path[:-1], (s.ros_path[-1][0], None))
                if array_path not in listed:
                    listed[array_path] = names.new(format_path(list(array_path)))
                    fn.binds.append(_st("assign", target=listed[array_path],
                                        expr=self.ros_array_read(_access("src", array_path), s.ros_type)))

        def ros_read(path: tuple) -> str:
            if path in parent_local:
                return parent_local[path]
            if path[-1][1] is not None:
                array_path = (*path[:-1], (path[-1][0], None))
                if array_path in listed:
                    return f"{listed[array_path]}[{path[-1][1]}]"
            parent = path[:-1]
            if parent in parent_local:
                return _access(parent_local[parent], path[-1:])
            return _access("src", path)

        return ros_read

    def ros_array_read(self, expr: str, ros_type: RosType) -> str:
        """A ROS array field as a list of plain Python values."""
        base = ros_type.base
        if base == "byte":
            return f"[b[0] for b in {expr}]"
        if base == "bool":
            return f"list({expr})"
        return f"{expr}.tolist()"

    def step_to_uavcan(self, s: Step, names: _Names, ros_read, statements: list[dict[str, Any]]) -> str:
        """Append the statements of one link (its planned operations); return the expression of the UAVCAN
        value."""
        assert s.uavcan_type is not None
        link = self.link(s, TO_UAVCAN)
        ops = link.ops
        key = repr(link.key)
        uav = s.uavcan_type
        first = ops[0] if ops else None
        if isinstance(first, TimestampFromRos):
            stamp = ros_read(s.ros_path)
            var = names.new("us")
            statements.extend(pys.timestamp_from_ros(first, var, self.ros_time_us(stamp), key))
            return var
        read = ros_read(s.ros_path)
        if isinstance(first, Table):
            var = names.new(s.uavcan)
            table = self.module_table(s, TO_UAVCAN)
            statements.append(_st("table", var=var, table=table, read=read, key=key, default=None))
            return var
        if isinstance(first, EncodeUtf8):
            var = names.new(s.uavcan)
            cut = ops[1]
            assert isinstance(cut, Utf8Length)
            statements.append(_st("assign", target=var, expr=f"{read}.encode(errors='replace')"))
            statements.append(_st("utf8_length", var=var, cap=cut.capacity, key=key, reject=cut.reject))
            return var
        if s.kind == "number":
            return self.scalar_to_uavcan(link, names, read, statements)
        # array: the elements' arithmetic, the length, then the elements' range
        elem_uav = uav.element
        var = names.new(s.uavcan)
        elem = pys.to_uavcan_expr("x", ops)
        base_list = self.ros_array_read(read, s.ros_type)
        expr = base_list if elem == "x" else f"[{elem} for x in {base_list}]"
        statements.append(_st("assign", target=var, expr=expr))
        for op in ops:
            if isinstance(op, FixedLength):
                statements.append(_st("fixed_length", var=var, cap=op.size, zero=dsdl_literal(0, elem_uav), key=key,
                                      reject=op.reject))
            elif isinstance(op, MaxLength):  # a longer fixed ROS array: only non-zero elements count
                statements.append(_st("max_length", var=var, cap=op.capacity, key=key, reject=op.reject,
                                      padded=op.padded))
        helper = pys.array_check_helper(var, link, elem_uav)
        if helper is not None:
            statements.append(helper)
        return var

    def ros_time_us(self, stamp: str) -> str:
        """Microseconds of a builtin_interfaces/Time read as `stamp` (the expression ros_read gave)."""
        return f"{stamp}.sec * 1_000_000 + {stamp}.nanosec // 1000"

    def scalar_to_uavcan(self, link: LinkPlan, names: _Names, read: str, statements: list[dict[str, Any]]) -> str:
        """A number link's operations in order: its arithmetic builds an expression, the first check binds it to a
        local (limits come before the inverse scale/offset: they are in ROS units)."""
        s = link.step
        expr = f"{read}[0]" if s.ros_type.base == "byte" else read
        var: str | None = None
        pending: list = []  # arithmetic not yet applied to var
        for op in link.ops:
            if isinstance(op, (Offset, Scale)):
                pending.append(op)
            elif isinstance(op, CHECK_OPS):
                if var is None or pending:
                    target = var if var is not None else names.new(s.uavcan)
                    statements.append(_st("assign", target=target, expr=pys.to_uavcan_expr(var or expr, pending)))
                    var, pending = target, []
                statements.extend(pys.check_statements(var, [op], repr(link.key)))
        if var is None:
            return pys.to_uavcan_expr(expr, pending)
        if pending:
            statements.append(_st("assign", target=var, expr=pys.to_uavcan_expr(var, pending)))
        return var

    def to_uavcan_scalar(self, s: Step, ros_base: str, read: str, transform: bool = True
                         ) -> tuple[bool, tuple[float, float] | None, str]:
        """(float-valued, range of the value if known, expression) of a ROS-side element after the inverse
        scale/offset (without them unless `transform`)."""
        transformed = transform and (s.scale is not None or s.offset is not None)
        value_is_float, value_range = ros_value(ros_base, transformed)
        expr = f"{read}[0]" if ros_base == "byte" and s.kind == "number" else read
        if transform:
            arithmetic = [op for op in self.link(s, TO_UAVCAN).ops if isinstance(op, (Offset, Scale))]
            expr = pys.to_uavcan_expr(expr, arithmetic)
        return value_is_float, value_range, expr


# ---- convert.py ----------------------------------------------------------------------------------------------


def _convert_context(resolved: Resolved) -> dict[str, Any]:
    module = _Module(resolved)
    module.ros_aliases = _ros_aliases(resolved)
    roots = {resolved.spec.dsdl_root, "uavcan", "reg"} | _referenced_roots(resolved)
    for rm in resolved.mappings:
        module.dsdl_ref(rm.dsdl_struct)
    module.module_names = (
        set(module.ros_aliases.values())
        | {py_attr(r) for r in roots}
        | {f"{rm.mapping.name}_to_ros" for rm in resolved.mappings}
        | {f"{rm.mapping.name}_to_uavcan" for rm in resolved.mappings}
        | {"CONVERTERS", "ConversionStats", "Callable", "Any", "_NAN", "_INF", "FAST_CONSTRUCTORS", "_np", "_support"}
    )
    functions = []
    for rm in resolved.mappings:
        emitter = _MappingEmitter(module, rm)
        functions.append((emitter.to_ros(), emitter.to_uavcan()))
    ros_imports: dict[str, list[str]] = {}
    for full, alias in sorted(module.ros_aliases.items()):
        package, name = full.split("/")
        ros_imports.setdefault(package, []).append(name if alias == name else f"{name} as {alias}")
    for names in ros_imports.values():
        names.sort(key=_isort_key)
    factories = [_ros_factory(module, full) for full in sorted(module.ros_aliases)]
    done: set[str] = set()
    while len(done) < len(module.dsdl_factories):  # a constructor's defaults may bring in nested ones
        for name in sorted(set(module.dsdl_factories) - done):
            factories.append(_dsdl_factory(module, module.dsdl_factories[name]))
            done.add(name)
    if any("_np." in str(f["fields"]) for f in factories):
        module.dsdl_modules.add("numpy as _np")
    return {
        "factories": factories,
        "uses_copy": any("_copy(" in str(x) for f in factories for x in f["fields"]),
        "dsdl_imports": sorted(module.dsdl_modules),
        "ros_imports": sorted(ros_imports.items()),
        "tables": module.tables,
        "functions": functions,
        "mappings": [rm.mapping.name for rm in resolved.mappings],
    }


def emit(resolved: Resolved) -> dict[str, str]:
    """Render the bridge package: {path under generated/: text}."""
    from . import emit_python_v0  # (it builds on this module)

    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    root = f"python/{package}"
    return {
        f"{root}/__init__.py": render("python/__init__.py.j2", **common),
        f"{root}/tables.py": render("python/tables.py.j2", **common, **_tables_context(resolved),
                                    **emit_nodes.tables_context(resolved), **emit_python_v0.tables_context(resolved)),
        f"{root}/conversion_support.py": render("python/conversion_support.py.j2", **common),
        f"{root}/convert.py": render("python/convert.py.j2", **common, **_convert_context(resolved)),
    }

