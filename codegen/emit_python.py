"""Python emitter: the bridge's tables (pure data) and its converters (ROS messages <-> pycyphal objects).

Output, under generated/:
- ``python/<vehicle>_bridge/__init__.py``
- ``python/<vehicle>_bridge/tables.py``: devices, topics, mappings, parameters and frames as frozen dataclasses;
  standard library only, so the runtime can read it without ROS or DSDL.
- ``python/<vehicle>_bridge/convert.py``: per mapping ``<name>_to_ros(src, receive_ns, stats)`` and
  ``<name>_to_uavcan(src, stats)``, straight-line code with every range decided here, at generation time.

This module decides *what* each converter does (names, literals, which checks a value needs); the templates in
templates/python/ decide how the files look. Everything is deterministic: no timestamps, no absolute paths,
and every text from the spec reaches the output as a Python literal (repr).
"""

from __future__ import annotations

import builtins
import keyword
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import emit_nodes  # the tables' QoS, transforms and nodes
from .filters import natural_key, py_str
from .mapping_rules import ResolvedMapping, Step, format_path
from .model import DsdlStruct, Port, RosMessage, Scalar
from .templating import render
from .typesys import ROS_FLOAT_BITS, ROS_INT_RANGES, DsdlType, RosType
from .validate import Resolved

__all__ = ["emit", "py_attr", "py_class_ref", "py_literal"]

# Names pycyphal (nunavut 2.3, Python target) appends "_" to: Python keywords and builtins
# (nunavut.lang.py.Language.PYTHON_RESERVED_IDENTIFIERS). Soft keywords (match, case, type) are not keywords there.
_NUNAVUT_RESERVED = frozenset([*keyword.kwlist, *dir(builtins)])
# Names no generated local may take: keywords, builtins (the converters call round, len, float ...), parameters.
_LOCAL_RESERVED = _NUNAVUT_RESERVED | frozenset(keyword.softkwlist) | {"src", "stats", "receive_ns", "msg"}

FLOAT16_MAX = 65504.0
FLOAT32_MAX = 3.4028234663852886e38
INT32_MAX = 2**31 - 1
# builtin_interfaces/Time holds sec as int32 and nanosec as uint32.
TIME_US_MIN = -(2**31) * 1_000_000
TIME_US_MAX_TO_ROS = INT32_MAX * 1_000_000 + 999_999  # the last microsecond a Time can hold
TIME_US_MAX_FROM_ROS = INT32_MAX * 1_000_000 + (2**32 - 1) // 1000  # nanosec may exceed 1e9 in a bad message
LINE_LIMIT = 110


# ---- names -------------------------------------------------------------------------------------------------


def py_attr(name: str) -> str:
    """The attribute (and keyword argument) name pycyphal gives a DSDL field or namespace component.

    >>> py_attr("rpm"), py_attr("id"), py_attr("type"), py_attr("match")
    ('rpm', 'id_', 'type_', 'match')
    """
    return name + "_" if name in _NUNAVUT_RESERVED else name


def py_module(namespace: str) -> str:
    """The Python module of a DSDL namespace.

    >>> py_module("sam.sensor")
    'sam.sensor'
    """
    return ".".join(py_attr(part) for part in namespace.split("."))


def py_class_name(struct: DsdlStruct) -> str:
    """The pycyphal class of a DSDL type: `<ShortName>_<major>_<minor>`."""
    major, minor = struct.version
    return f"{struct.short_name}_{major}_{minor}"


def py_class_ref(struct: DsdlStruct) -> str:
    """The qualified reference used in generated code, e.g. `sam.sensor.RawIMU_0_1`."""
    return f"{py_module(struct.namespace)}.{py_class_name(struct)}"


def dict_literal(prefix: str, pairs: list[tuple[str, str]], width: int = 110) -> str:
    """``prefix{k: v, ...}`` on one line when it fits in `width`, else wrapped with four spaces of indent.

    >>> dict_literal("T = ", [("0", "1"), ("2", "3")])
    'T = {0: 1, 2: 3}'
    >>> print(dict_literal("T = ", [(str(k), "3") for k in range(8)], width=30))
    T = {
        0: 3, 1: 3, 2: 3, 3: 3,
        4: 3, 5: 3, 6: 3, 7: 3,
    }
    """
    one = prefix + "{" + ", ".join(f"{k}: {v}" for k, v in pairs) + "}"
    if len(one) <= width:
        return one
    lines, line = [prefix + "{"], ""
    for k, v in pairs:
        item = f"{k}: {v},"
        if line and 4 + len(line) + 1 + len(item) > width:
            lines.append("    " + line)
            line = ""
        line = f"{line} {item}" if line else item
    if line:
        lines.append("    " + line)
    return "\n".join([*lines, "}"])


def py_literal(value: Scalar) -> str:
    """A Python literal; non-finite floats refer to the module constants _NAN and _INF of convert.py.

    >>> py_literal(1.0), py_literal(float("nan")), py_literal(-float("inf")), py_literal("a'b"), py_literal(2)
    ('1.0', '_NAN', '-_INF', '"a\\'b"', '2')
    """
    if isinstance(value, float):
        if math.isnan(value):
            return "_NAN"
        if math.isinf(value):
            return "_INF" if value > 0 else "-_INF"
    return repr(value)


def _typed_literal(value: Scalar, base: str) -> str:
    """A literal of the Python type rclpy / pycyphal keep for a field of primitive type `base`."""
    if base in ROS_FLOAT_BITS or base.startswith("float"):
        return py_literal(float(value))
    if base == "bool":
        return py_literal(bool(value))
    if base == "byte":
        return repr(bytes((int(value),)))
    if base in ("string", "wstring"):
        return py_literal(str(value))
    return py_literal(int(value))


def _identifier(text: str) -> str:
    """A lower-case identifier from a path: `rate_gyro_latest[0]` -> `rate_gyro_latest_0`."""
    ident = re.sub(r"[^0-9A-Za-z_]+", "_", text).strip("_").lower()
    return ident if ident and not ident[0].isdigit() else f"v_{ident}"


class _Names:
    """Local variable names of one function: readable, unique, never shadowing a module name or builtin."""

    def __init__(self, reserved: set[str]) -> None:
        self.reserved = reserved  # the module's names: shared, not copied (one _Names per function)
        self.taken = set(_LOCAL_RESERVED)

    def new(self, hint: str) -> str:
        base = _identifier(hint)
        name, n = base, 2
        while name in self.taken or name in self.reserved:
            name, n = f"{base}_{n}", n + 1
        self.taken.add(name)
        return name


def _access(base: str, path: tuple[tuple[str, int | None], ...], attr=lambda n: n) -> str:
    text = base
    for name, index in path:
        text += f".{attr(name)}"
        if index is not None:
            text += f"[{index}]"
    return text


# ---- value ranges ------------------------------------------------------------------------------------------


def _dsdl_range(t: DsdlType) -> tuple[float, float] | None:
    """Finite value range of a primitive DSDL scalar (None for bool)."""
    if t.kind in ("int", "uint", "byte"):
        return t.range
    if t.kind == "float":
        return {16: (-FLOAT16_MAX, FLOAT16_MAX), 32: (-FLOAT32_MAX, FLOAT32_MAX)}.get(t.bits, (-math.inf, math.inf))
    return None


def _ros_range(base: str) -> tuple[float, float] | None:
    if base in ROS_INT_RANGES:
        return ROS_INT_RANGES[base]
    if base == "float32":
        return -FLOAT32_MAX, FLOAT32_MAX
    if base == "float64":
        return -math.inf, math.inf
    return None


def _is_int_dsdl(t: DsdlType) -> bool:
    return t.kind in ("int", "uint", "byte")


def _num(value: float) -> str:
    """A numeric literal in generated code (ints stay ints)."""
    return py_literal(value)


# ---- statements (rendered by templates/python/statements.j2) -----------------------------------------------


def _st(kind: str, **kw: Any) -> dict[str, Any]:
    return {"kind": kind, **kw}


@dataclass
class _Policy:
    key: str  # the stats key literal
    reject: bool  # on_out_of_range == "reject"


def _bound_statement(var: str, checks: list[tuple[str, str]], policy: _Policy, otherwise: str | None = None
                     ) -> dict[str, Any]:
    """if/elif chain: each (condition, saturated value) saturates or rejects; `otherwise` runs when none hit."""
    return _st("bound", var=var, checks=checks, key=policy.key, reject=policy.reject, otherwise=otherwise)


def _number_checks(var: str, value_is_float: bool, value_range: tuple[float, float] | None, target: DsdlType,
                   limits: tuple[float, float] | None, policy: _Policy) -> list[dict[str, Any]]:
    """The statements that make `var` (a ROS-side value) acceptable to a DSDL scalar of type `target`.

    `value_range` is the finite range the value is known to lie in (None: unknown); a float value may also be
    NaN or infinite. Nothing is emitted for what cannot happen (e.g. a ROS uint8 into a DSDL uint8).
    """
    out: list[dict[str, Any]] = []
    if target.kind == "bool":
        return out
    integer = _is_int_dsdl(target)
    nonfinite = value_is_float
    if value_is_float and (integer or limits is not None):
        out.append(_st("nan_reject", var=var, key=policy.key))
    if limits is not None:
        low, high = (float(v) if not integer or not float(v).is_integer() else int(v) for v in limits)
        out.append(_bound_statement(var, [(f"{var} < {_num(low)}", _num(low)), (f"{var} > {_num(high)}", _num(high))],
                                    policy))
        value_range = (low, high) if value_range is None else (max(low, value_range[0]), min(high, value_range[1]))
        nonfinite = False
        value_is_float = value_is_float or isinstance(low, float) or isinstance(high, float)
    rng = _dsdl_range(target)
    assert rng is not None
    lo, hi = rng
    beyond = value_range is None or value_range[0] < lo or value_range[1] > hi
    if integer:
        lo, hi = int(lo), int(hi)
        if value_is_float:
            if value_range is not None and not nonfinite and lo - 0.5 < value_range[0] and value_range[1] < hi + 0.5:
                out.append(_st("assign", target=var, expr=f"round({var})"))
            else:  # round half to even, but only what rounds into the range: round() would raise on inf
                out.append(_bound_statement(var, [(f"{var} >= {_num(hi + 0.5)}", _num(hi)),
                                                  (f"{var} <= {_num(lo - 0.5)}", _num(lo))],
                                            policy, otherwise=f"{var} = round({var})"))
        elif beyond:
            checks = []
            if value_range is None or value_range[1] > hi:
                checks.append((f"{var} > {_num(hi)}", _num(hi)))
            if value_range is None or value_range[0] < lo:
                checks.append((f"{var} < {_num(lo)}", _num(lo)))
            out.append(_bound_statement(var, checks, policy))
    elif target.bits == 16:
        # float16: beyond the largest finite value, infinities included, saturates to +-65504; NaN passes.
        if nonfinite or beyond:
            out.append(_bound_statement(var, [(f"{var} > {_num(hi)}", _num(hi)), (f"{var} < {_num(lo)}", _num(lo))],
                                        policy))
    elif target.bits == 32 and beyond:
        # float32: finite values beyond its range saturate; infinities and NaN are float32 values and pass.
        out.append(_bound_statement(var, [(f"{_num(hi)} < {var} < _INF", _num(hi)),
                                          (f"-_INF < {var} < {_num(lo)}", _num(lo))], policy))
    return out


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

    def policy(self, path: str) -> _Policy:
        return _Policy(repr(f"{self.name}.{path}"), self.reject)

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
        if rm.has_header and self.mapping.frame_id is not None:
            self.module.insert(root, (("header", None), ("frame_id", None)), py_literal(self.mapping.frame_id))
        if rm.has_header and not rm.stamp_from_source:
            stamp = (("header", None), ("stamp", None))
            self.module.insert(root, (*stamp, ("sec", None)), "receive_ns // 1_000_000_000")
            self.module.insert(root, (*stamp, ("nanosec", None)), "receive_ns % 1_000_000_000")
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
        """Append the statements of one link; return the (ROS path, expression) pairs it sets."""
        pol = self.policy(s.ros)
        if s.kind == "value":
            return [(s.ros_path, _typed_literal(s.value, s.ros_type.base))]  # type: ignore[arg-type]
        assert s.uavcan_type is not None
        read = uav_read(s.uavcan_path)
        if s.kind == "time":
            us, sec, nanosec = names.new("us"), names.new("sec"), names.new("nanosec")
            lo, hi = s.uavcan_type.range
            checks = []
            if hi > TIME_US_MAX_TO_ROS:
                checks.append((f"{us} > {TIME_US_MAX_TO_ROS}", str(INT32_MAX), "999_999_999"))
            if lo < TIME_US_MIN:
                checks.append((f"{us} < {TIME_US_MIN}", str(-(2**31)), "0"))
            statements.append(_st("time_to_ros", us=us, read=read, sec=sec, nanosec=nanosec, checks=checks,
                                  key=pol.key, reject=pol.reject))
            return [((*s.ros_path, ("sec", None)), sec), ((*s.ros_path, ("nanosec", None)), nanosec)]
        if s.kind == "table":
            var = names.new(s.ros)
            table = self.module_table(s, "to_ros")
            default = None if s.table_default is None else py_literal(s.table_default)
            statements.append(_st("table", var=var, table=table, read=read, key=pol.key, default=default))
            return [(s.ros_path, var)]
        if s.kind == "string":
            return [(s.ros_path, f"{read}.tobytes().decode(errors='replace')")]
        ros_base = s.ros_type.base
        uav = s.uavcan_type.element if s.kind == "array" else s.uavcan_type
        expr_of = self.to_ros_scalar_expr(s, uav, ros_base)
        overflow = self.to_ros_float32_overflow(s, uav, ros_base)
        if s.kind == "number":
            expr = expr_of(read)
            if uav.kind == "float" and ros_base in ROS_INT_RANGES:  # `round: true`
                var = names.new(s.ros)
                statements.append(_st("assign", target=var, expr=expr))
                lo, hi = ROS_INT_RANGES[ros_base]
                as_dsdl = DsdlType("int" if lo < 0 else "uint", (hi - lo).bit_length())
                statements.extend(_number_checks(var, True, None, as_dsdl, None, pol))
                return [(s.ros_path, var)]
            if overflow:
                var = names.new(s.ros)
                statements.append(_st("assign", target=var, expr=expr))
                statements.append(_bound_statement(var, [(f"{_num(FLOAT32_MAX)} < {var} < _INF", _num(FLOAT32_MAX)),
                                                         (f"-_INF < {var} < {_num(-FLOAT32_MAX)}",
                                                          _num(-FLOAT32_MAX))], pol))
                return [(s.ros_path, var)]
            return [(s.ros_path, expr)]
        # array
        elem = expr_of("x")
        base_list = self.uav_list(read)
        expr = base_list if elem == "x" else f"[{elem} for x in {base_list}]"
        pad = s.ros_type.array == "fixed" and s.uavcan_type.array == "bounded"
        if not pad and not overflow:
            return [(s.ros_path, expr)]
        var = names.new(s.ros)
        statements.append(_st("assign", target=var, expr=expr))
        if overflow:
            statements.append(_st("helper", var=var, helper="_clamp_finite_floats",
                                  args=[var, _num(FLOAT32_MAX), "stats", pol.key, str(pol.reject)]))
        if pad:
            zero = _typed_literal(0, ros_base)
            statements.append(_st("pad", var=var, size=s.ros_type.capacity, zero=zero))
        return [(s.ros_path, var)]

    def to_ros_scalar_expr(self, s: Step, uav: DsdlType, ros_base: str):
        """A function from a UAVCAN-side element expression to the ROS-side one."""
        scale = None if s.scale is None else _num(float(s.scale))
        offset = None if s.offset is None else float(s.offset)

        def expr(x: str) -> str:
            text = x
            if scale is not None:
                text = f"{text} * {scale}"
            if offset is not None:
                text = f"{text} + {_num(offset)}" if offset >= 0 else f"{text} - {_num(-offset)}"
            if scale is None and offset is None:
                if ros_base in ROS_FLOAT_BITS and uav.kind != "float":
                    text = f"float({x})"
                elif ros_base == "byte":
                    text = f"bytes(({x},))"
            return text

        return expr

    def to_ros_float32_overflow(self, s: Step, uav: DsdlType, ros_base: str) -> bool:
        if ros_base != "float32" or (s.scale is None and s.offset is None):
            return False
        rng = _dsdl_range(uav)
        if rng is None:
            return False
        bound = max(abs(rng[0]), abs(rng[1])) * abs(s.scale if s.scale is not None else 1.0) + abs(s.offset or 0.0)
        return bound > FLOAT32_MAX

    def module_table(self, s: Step, direction: str) -> str:
        const = f"_{self.name}_{_identifier(s.ros)}".upper()
        if direction == "to_ros":
            items = list(s.table)
            const += "_TO_ROS"
        else:
            inverse: dict[int, int] = {}
            for key, value in s.table:
                inverse.setdefault(value, key)  # first key per value
            items = sorted(inverse.items())
            const += "_TO_UAVCAN"
        if not any(t["name"] == const for t in self.module.tables):
            pairs = [(py_literal(k), py_literal(v)) for k, v in items]
            self.module.tables.append({
                "name": const,
                "items": pairs,
                "literal": dict_literal(f"{const}: dict[int, int] = ", pairs),
                "what": f"{self.name}: {s.uavcan} -> {s.ros}" if direction == "to_ros"
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

        root = self.module.dsdl_ctor(rm.dsdl_struct)
        for s in steps:
            value = self.step_to_uavcan(s, names, ros_read, fn.statements)
            self.module.insert(root, s.uavcan_path, value)
        for path, leaf_type, value in [*rm.uavcan_values, *rm.select]:  # (select: DroneCAN's)
            self.module.insert(root, path,
                               _typed_literal(value, "float" if leaf_type.kind == "float" else leaf_type.kind))
        fn.result = self.module.format_return(root)
        return fn

    def ros_array_read(self, expr: str, ros_type: RosType) -> str:
        """A ROS array field as a list of plain Python values."""
        base = ros_type.base
        if base == "byte":
            return f"[b[0] for b in {expr}]"
        if base == "bool":
            return f"list({expr})"
        return f"{expr}.tolist()"

    def step_to_uavcan(self, s: Step, names: _Names, ros_read, statements: list[dict[str, Any]]) -> str:
        assert s.uavcan_type is not None
        pol = self.policy(s.uavcan)
        uav = s.uavcan_type
        if s.kind == "time":
            stamp = ros_read(s.ros_path)
            var = names.new("us")
            statements.append(_st("assign", target=var, expr=f"{stamp}.sec * 1_000_000 + {stamp}.nanosec // 1000"))
            lo, hi = uav.range
            checks = []
            if TIME_US_MAX_FROM_ROS > hi:
                checks.append((f"{var} > {hi}", str(hi)))
            if TIME_US_MIN < lo:
                checks.append((f"{var} < {lo}", str(lo)))
            if checks:
                statements.append(_bound_statement(var, checks, pol))
            return var
        read = ros_read(s.ros_path)
        if s.kind == "table":
            var = names.new(s.uavcan)
            table = self.module_table(s, "to_uavcan")
            statements.append(_st("table", var=var, table=table, read=read, key=pol.key, default=None))
            return var
        if s.kind == "string":
            var = names.new(s.uavcan)
            statements.append(_st("assign", target=var, expr=f"{read}.encode(errors='replace')"))
            statements.append(_st("utf8_length", var=var, cap=uav.capacity, key=pol.key, reject=pol.reject))
            return var
        ros_base = s.ros_type.base
        if s.kind == "number":
            if s.limits is not None and (s.scale is not None or s.offset is not None):
                # limits are in ROS units: checked before the inverse scale/offset
                var = names.new(s.uavcan)
                statements.append(_st("assign", target=var, expr=read))
                ros_is_float, ros_range, _ = self.to_uavcan_scalar(s, ros_base, var, transform=False)
                limit_type = DsdlType("float", 64) if ros_is_float else DsdlType("int", 64)
                statements.extend(_number_checks(var, ros_is_float, ros_range, limit_type, s.limits, pol))
                value_is_float, value_range, expr = self.to_uavcan_scalar(s, ros_base, var)
                statements.append(_st("assign", target=var, expr=expr))
                statements.extend(_number_checks(var, value_is_float, value_range, uav, None, pol))
                return var
            value_is_float, value_range, expr = self.to_uavcan_scalar(s, ros_base, read)
            if not _number_checks("x", value_is_float, value_range, uav, s.limits, pol):
                return expr
            var = names.new(s.uavcan)
            statements.append(_st("assign", target=var, expr=expr))
            statements.extend(_number_checks(var, value_is_float, value_range, uav, s.limits, pol))
            return var
        # array
        elem_uav = uav.element
        value_is_float, value_range, elem = self.to_uavcan_scalar(s, ros_base, "x")
        var = names.new(s.uavcan)
        base_list = self.ros_array_read(read, s.ros_type)
        expr = base_list if elem == "x" else f"[{elem} for x in {base_list}]"
        statements.append(_st("assign", target=var, expr=expr))
        # Length: the ROS array may be longer (or, for a fixed DSDL array, shorter) than the DSDL one.
        cap = uav.capacity or 0
        ros_fixed = s.ros_type.array == "fixed"
        if uav.array == "fixed":
            if not ros_fixed:
                zero = _typed_literal(0, "float" if elem_uav.kind == "float" else elem_uav.kind)
                statements.append(_st("fixed_length", var=var, cap=cap, zero=zero, key=pol.key, reject=pol.reject))
        elif s.ros_type.array == "dynamic" or (s.ros_type.capacity or 0) > cap:
            # A fixed ROS array longer than the bound holds zero padding: only non-zero elements count.
            statements.append(_st("max_length", var=var, cap=cap, key=pol.key, reject=pol.reject, padded=ros_fixed))
        if _number_checks("x", value_is_float, value_range, elem_uav, None, pol):
            if _is_int_dsdl(elem_uav):
                lo, hi = elem_uav.range
                helper = "_round_ints" if value_is_float else "_clamp_ints"
                args = [var, str(lo), str(hi), "stats", pol.key, str(pol.reject)]
            else:  # float16 saturates infinities too, float32 keeps them (as for scalars)
                helper = "_clamp_floats" if elem_uav.bits == 16 else "_clamp_finite_floats"
                args = [var, _num(_dsdl_range(elem_uav)[1]), "stats", pol.key, str(pol.reject)]  # type: ignore[index]
            statements.append(_st("helper", var=var, helper=helper, args=args))
        return var

    def to_uavcan_scalar(self, s: Step, ros_base: str, read: str, transform: bool = True
                         ) -> tuple[bool, tuple[float, float] | None, str]:
        """(float-valued, range of the value if known, expression) of a ROS-side element after the inverse
        scale/offset (without them unless `transform`)."""
        value_range = _ros_range(ros_base)
        value_is_float = ros_base in ROS_FLOAT_BITS
        expr = read
        if ros_base == "byte" and s.kind == "number":
            expr = f"{read}[0]"
        if not transform:
            return value_is_float, value_range if value_range and math.isfinite(value_range[1]) else None, expr
        if s.offset is not None:
            off = float(s.offset)
            expr = f"{expr} - {_num(off)}" if off >= 0 else f"{expr} + {_num(-off)}"
        if s.scale is not None:
            expr = f"({expr}) / {_num(float(s.scale))}" if s.offset is not None else f"{expr} / {_num(float(s.scale))}"
        if s.scale is not None or s.offset is not None:
            value_is_float, value_range = True, None
        if value_range is not None and not math.isfinite(value_range[1]):
            value_range = None
        return value_is_float, value_range, expr


# ---- tables.py -----------------------------------------------------------------------------------------------


def _ros_type_parts(full: str) -> tuple[str, str, str]:
    """`sensor_msgs/Imu` -> ("sensor_msgs/msg/Imu", "sensor_msgs.msg", "Imu")."""
    package, name = full.split("/")
    return f"{package}/msg/{name}", f"{package}.msg", name


def _text(text: str, indent: int) -> str:
    """A string literal (py_str: repr, inert) at `indent`; long text becomes implicitly concatenated chunks."""
    literal = py_str(text)
    if indent + len(literal) <= LINE_LIMIT - 10:
        return literal
    chunks: list[str] = []
    for word in re.findall(r"\S*\s*", text):
        if chunks and len(py_str(chunks[-1] + word)) + indent + 4 <= LINE_LIMIT - 2:
            chunks[-1] += word
        elif word:
            chunks.append(word)
    pad = " " * (indent + 4)
    return "(\n" + "".join(f"{pad}{py_str(c)}\n" for c in chunks) + " " * indent + ")"


def _tuple(items: list[str], indent: int) -> str:
    """A tuple literal of rendered items, on one line if it fits."""
    if not items:
        return "()"
    one = "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"
    if indent + len(one) <= LINE_LIMIT - 30:
        return one
    pad = " " * (indent + 4)
    return "(\n" + "".join(f"{pad}{item},\n" for item in items) + " " * indent + ")"


def _port_info(resolved: Resolved, port: Port, indent: int, prefix: int = 0) -> str:
    """A PortInfo(...) at `indent`, after `prefix` characters on its line and before a comma."""
    struct = resolved.dsdl.get(port.type)
    assert struct is not None, port.type
    args = [str(port.subject_id), py_str(port.type), py_str(py_module(struct.namespace)),
            py_str(py_class_name(struct)), py_literal(float(port.rate_hz))]
    one = "PortInfo(" + ", ".join(args) + ")"
    if indent + prefix + len(one) + 1 <= LINE_LIMIT:
        return one
    names = ("subject_id", "dsdl_type", "dsdl_module", "dsdl_class", "rate_hz")
    pad = " " * (indent + 4)
    return "PortInfo(\n" + "".join(f"{pad}{k}={v},\n" for k, v in zip(names, args, strict=True)) + " " * indent + ")"


def _tables_context(resolved: Resolved) -> dict[str, Any]:
    spec = resolved.spec
    devices = [{
        "name": py_str(d.name), "node_id": str(d.node_id), "description": _text(d.description, 8),
        "publishes": [_port_info(resolved, p, 12) for p in d.publishes],
        "subscribes": [_port_info(resolved, p, 12) for p in d.subscribes],
    } for d in spec.devices.values() if "cyphal" in d.protocols]
    topics = []
    for topic in spec.topics.values():
        ros_type, module, cls = _ros_type_parts(topic.type)
        topics.append({"name": py_str(topic.name), "ros_type": py_str(ros_type), "ros_module": py_str(module),
                       "ros_class": py_str(cls), "description": _text(topic.description, 8)})
    ports = {}
    for d in spec.devices.values():
        for p in [*d.publishes, *d.subscribes]:
            ports.setdefault(p.subject_id, p)
    mappings = []
    for rm in resolved.mappings:
        m = rm.mapping
        linked = [py_str(s.uavcan) for s in rm.steps if s.uavcan_path]
        exact = [py_str(s.uavcan) for s in rm.steps if s.uavcan_path and s.exact]
        sources = sorted(set(m.source_node_ids))
        mappings.append({
            "name": py_str(m.name), "direction": py_str(m.direction), "topic": py_str(m.topic),
            "port": _port_info(resolved, ports[m.subject_id], 8, len("port=")),
            "source_node_ids": "frozenset({" + ", ".join(map(str, sources)) + "})" if sources else "frozenset()",
            "destination_node_id": py_literal(m.destination_node_id),
            "frame_id": py_str(m.frame_id) if m.frame_id is not None else "None",
            "rate_hz": py_literal(float(rm.rate_hz)), "on_out_of_range": py_str(m.on_out_of_range),
            "to_ros": py_str(f"{m.name}_to_ros"), "to_uavcan": py_str(f"{m.name}_to_uavcan"),
            "exact_uavcan_fields": _tuple(exact, 8), "linked_uavcan_fields": _tuple(linked, 8),
        })
    parameters = []
    for p in spec.parameters.values():
        default = p.default
        if p.type == "double":
            default = float(default)
        parameters.append({
            "name": py_str(p.name), "type": py_str(p.type),
            "default": _text(default, 8) if isinstance(default, str) else py_literal(default),
            "minimum": py_literal(None if p.minimum is None else float(p.minimum)),
            "maximum": py_literal(None if p.maximum is None else float(p.maximum)),
            "unit": py_str(p.unit), "description": _text(p.description, 8),
        })
    rules = [{"left": py_str(r.left), "op": py_str(r.op), "right": py_str(r.right),
              "description": _text(r.description, 8)} for r in spec.parameter_rules]
    frames = [(py_str(f.name), py_str(f.parent) if f.parent is not None else "None") for f in spec.frames.values()]
    bridge = spec.bridge
    return {
        "vehicle_literal": py_str(spec.vehicle), "ros_package": py_str(spec.ros.name),
        "dsdl_root": py_str(spec.dsdl_root),
        "bridge_name": py_str(bridge.name) if bridge else "None",
        "bridge_node_id": str(bridge.node_id) if bridge else "None",
        "devices": devices, "topics": topics,
        "mappings": mappings, "parameters": parameters, "rules": rules, "frames": frames,
    }


# ---- convert.py ----------------------------------------------------------------------------------------------


def _ros_closure(resolved: Resolved, mappings: list[ResolvedMapping] | None = None) -> list[str]:
    """Every ROS message type the converters build: the mapped ones and, transitively, their nested types."""
    seen: set[str] = set()
    todo = [rm.ros_message.full_name for rm in (resolved.mappings if mappings is None else mappings)]
    while todo:
        full = todo.pop()
        if full in seen:
            continue
        seen.add(full)
        message = resolved.ros.get(full)
        assert message is not None, full
        todo.extend(f.type.base for f in message.fields if isinstance(f.type, RosType) and not f.type.is_primitive)
    return sorted(seen)


def _ros_aliases(resolved: Resolved, mappings: list[ResolvedMapping] | None = None) -> dict[str, str]:
    """A local class name per ROS message type the converters use; package-qualified when names clash."""
    used = _ros_closure(resolved, mappings)
    by_name: dict[str, list[str]] = {}
    for full in used:
        by_name.setdefault(full.split("/")[1], []).append(full)
    reserved = {"ConversionStats", "Callable", "Any"} | _NUNAVUT_RESERVED | set(keyword.softkwlist)
    aliases = {}
    for full in used:
        package, name = full.split("/")
        aliases[full] = name if len(by_name[name]) == 1 and name not in reserved else f"{package}_{name}"
    return aliases


def ros_factory_name(alias: str) -> str:
    """The generated constructor of a ROS message class.

    >>> ros_factory_name("Imu")
    '_new_Imu'
    """
    return f"_new_{alias}"


# rosidl_generator_py keeps fixed-size arrays of these in numpy arrays (`char` is uint8 in ROS 2 IDL).
_NUMPY_BASES = frozenset(base for base in [*ROS_INT_RANGES, *ROS_FLOAT_BITS] if base != "byte")
_PY_TYPES = {"bool": "bool", "byte": "bytes", "string": "str", "wstring": "str"}


def _factory_field(slot: str, param: str, default: str, given: list[tuple[str | None, str]] | None = None
                   ) -> dict[str, Any]:
    """One field of a generated constructor: `default` when the argument is None, else `given` (if/elif/else
    branches: (condition or None, statement)); by default the argument goes into the slot as it is."""
    if given is None:
        line = f"_m.{slot} = {default} if {param} is None else {param}"
        if len(line) + 4 <= LINE_LIMIT - 30:
            return {"line": line}
        given = [(None, f"_m.{slot} = {param}")]
    return {"branches": [(f"{param} is None", f"_m.{slot} = {default}"), *given]}


def _ros_factory(module: _Module, full: str) -> dict[str, Any]:
    """What templates/python/convert.py.j2 needs to write the fast constructor of one ROS message class.

    Scalars, strings and nested messages go straight into their slots, as rosidl_generator_py's setters put them
    when field checks are off; arrays go through the setters (which convert to numpy / array.array), and their
    defaults are copies of a default instance's.
    """
    message = module.ros_message(full)
    alias = module.ros_aliases[full]
    prototype = f"_DEFAULT_{alias}"
    params: list[str] = []
    fields: list[dict[str, Any]] = []
    uses_prototype = False
    for f in message.fields:
        t = f.type
        assert isinstance(t, RosType)
        if t.array:
            params.append(f"{f.name}: Any = None")
            if not t.is_primitive:
                nested = ros_factory_name(module.ros_aliases[t.base])
                default = f"[{nested}() for _ in range({t.capacity})]" if t.array == "fixed" else "[]"
            elif t.array == "fixed" and t.base in _NUMPY_BASES:
                default, uses_prototype = f"{prototype}._{f.name}.copy()", True
            else:
                default, uses_prototype = f"_copy({prototype}._{f.name})", True
            # the setter converts a given sequence to the class's array type
            fields.append(_factory_field(f"_{f.name}", f.name, default, [(None, f"_m.{f.name} = {f.name}")]))
        elif not t.is_primitive:
            params.append(f"{f.name}: {module.ros_aliases[t.base]} | None = None")
            fields.append(_factory_field(f"_{f.name}", f.name, f"{ros_factory_name(module.ros_aliases[t.base])}()"))
        else:
            py_type = _PY_TYPES.get(t.base, "float" if t.base in ROS_FLOAT_BITS else "int")
            default = _typed_literal(f.default if f.default is not None else 0, t.base)
            if t.base in ("string", "wstring") and f.default is None:
                default = "''"
            params.append(f"{f.name}: {py_type} = {default}")
            fields.append({"line": f"_m._{f.name} = {f.name}"})
    return {"name": ros_factory_name(alias), "cls": alias, "ros": True, "params": params, "fields": fields,
            "prototype": prototype if uses_prototype else None}


def dsdl_factory_name(struct: DsdlStruct) -> str:
    """The generated constructor of a pycyphal class.

    >>> from sam_codegen.model import DsdlStruct
    >>> dsdl_factory_name(DsdlStruct("uavcan.time.SynchronizedTimestamp.1.0", []))
    '_new_uavcan_time_SynchronizedTimestamp_1_0'
    """
    return "_new_" + py_module(struct.namespace).replace(".", "_") + "_" + py_class_name(struct)


def dsdl_factory_supported(struct: DsdlStruct) -> bool:
    """Structures of primitives, primitive arrays and nested composites get a constructor; unions and arrays of
    composites (rare in bridged types) are built by their pycyphal class."""
    return not struct.union and not any(
        isinstance(f.type, DsdlType) and f.type.array and f.type.kind == "composite" for f in struct.fields)


def _numpy_dtype(t: DsdlType) -> str:
    """The numpy element type pycyphal (nunavut 2.3) keeps a primitive array in.

    >>> [_numpy_dtype(DsdlType(k, b)) for k, b in (("float", 16), ("int", 18), ("uint", 7), ("bool", 1), ("utf8", 8))]
    ['_np.float16', '_np.int32', '_np.uint8', '_np.bool_', '_np.uint8']
    """
    if t.kind == "float":
        return f"_np.float{t.bits}"
    if t.kind == "bool":
        return "_np.bool_"
    if t.kind in ("byte", "utf8"):
        return "_np.uint8"
    bits = next(b for b in (8, 16, 32, 64) if b >= t.bits)
    return f"_np.{t.kind}{bits}"


def _dsdl_factory(module: _Module, struct: DsdlStruct) -> dict[str, Any]:
    """What templates/python/convert.py.j2 needs to write the fast constructor of one pycyphal class.

    Values go straight into the attributes pycyphal's properties keep them in (`_<name>`), converted as its
    setters convert them; the converters have already checked ranges and lengths, which the setters check again.
    """
    params: list[str] = []
    fields: list[dict[str, Any]] = []
    for f in struct.fields:
        t = f.type
        assert isinstance(t, DsdlType)
        if t.kind == "void":
            continue
        name = py_attr(f.name)
        if t.kind == "composite":
            nested = module.struct(t.composite)  # type: ignore[arg-type]
            params.append(f"{name}: Any = None")
            fields.append(_factory_field(f"_{name}", name, f"{module.dsdl_new(nested)}()"))
        elif t.array or t.kind == "utf8":
            dtype = _numpy_dtype(t)
            default = f"_np.zeros({t.capacity}, {dtype})" if t.array == "fixed" else f"_np.array([], {dtype})"
            given: list[tuple[str | None, str]] = [(None, f"_m._{name} = _np.array({name}, {dtype})")]
            if dtype == "_np.uint8":  # pycyphal takes bytes for these too (utf8 text, byte strings)
                given.insert(0, (f"{name}.__class__ is bytes", f"_m._{name} = _np.frombuffer({name}, _np.uint8)"))
            params.append(f"{name}: Any = None")
            fields.append(_factory_field(f"_{name}", name, default, given))
        elif t.kind == "float":
            params.append(f"{name}: float = 0.0")
            fields.append({"line": f"_m._{name} = float({name})"})
        else:
            params.append(f"{name}: {'bool' if t.kind == 'bool' else 'int'} = {'False' if t.kind == 'bool' else '0'}")
            fields.append({"line": f"_m._{name} = {name}"})
    return {"name": dsdl_factory_name(struct), "cls": module.dsdl_ref(struct), "ros": False, "params": params,
            "fields": fields,
            "prototype": None}


def _referenced_roots(resolved: Resolved) -> set[str]:
    """Root namespaces of every composite the mapped DSDL types contain (module names locals must not shadow)."""
    roots: set[str] = set()
    seen: set[str] = set()
    todo = [rm.dsdl_struct for rm in resolved.mappings]
    while todo:
        struct = todo.pop()
        if struct.name in seen:
            continue
        seen.add(struct.name)
        roots.add(struct.name.split(".")[0])
        for f in struct.fields:
            if isinstance(f.type, DsdlType) and f.type.composite:
                nested = resolved.dsdl.get(f.type.composite)
                if nested is not None:
                    todo.append(nested)
    return roots


def _isort_key(name: str) -> tuple[int, list[Any]]:
    """isort's (and ruff's) order of imported names: CONSTANTS, then Classes, then variables, case-insensitive."""
    kind = 0 if len(name) > 1 and name.isupper() else 1 if name[0].isupper() else 2
    return kind, natural_key(name)


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
        | {"CONVERTERS", "ConversionStats", "Callable", "Any", "_NAN", "_INF", "FAST_CONSTRUCTORS", "_np"}
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
        f"{root}/convert.py": render("python/convert.py.j2", **common, **_convert_context(resolved)),
    }

