"""Names in the generated Python: pycyphal's attribute, module and class names, the fast constructors' names, locals
that never shadow a module name or builtin, the ROS classes and DSDL roots convert.py names, and dict literals that
fit the line.

Invariant: every name here is a pure function of the spec (no counters shared across modules), so the output does
not depend on the order the emitters run in.
"""

from __future__ import annotations

import builtins
import keyword
import re
from collections.abc import Callable
from typing import Any

from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.filters import natural_key
from sam_codegen.render.pysource import LINE_LIMIT
from sam_codegen.validate.mapping_rules import ResolvedMapping
from sam_codegen.validate.resolve import Resolved

# Names pycyphal (nunavut 2.3, Python target) appends "_" to: Python keywords and builtins
# (nunavut.lang.py.Language.PYTHON_RESERVED_IDENTIFIERS). Soft keywords (match, case, type) are not keywords there.
_NUNAVUT_RESERVED = frozenset([*keyword.kwlist, *dir(builtins)])
# Names no generated local may take: keywords, builtins (the converters call round, len, float ...), parameters.
_LOCAL_RESERVED = _NUNAVUT_RESERVED | frozenset(keyword.softkwlist) | {"src", "stats", "receive_ns", "msg"}


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


def ros_factory_name(alias: str) -> str:
    """The generated constructor of a ROS message class.

    >>> ros_factory_name("Imu")
    '_new_Imu'
    """
    return f"_new_{alias}"


def dsdl_factory_name(struct: DsdlStruct) -> str:
    """The generated constructor of a pycyphal class.

    >>> dsdl_factory_name(DsdlStruct("uavcan.time.SynchronizedTimestamp.1.0", []))
    '_new_uavcan_time_SynchronizedTimestamp_1_0'
    """
    return "_new_" + py_module(struct.namespace).replace(".", "_") + "_" + py_class_name(struct)


def dsdl_factory_supported(struct: DsdlStruct) -> bool:
    """Structures of primitives, primitive arrays and nested composites get a constructor; unions and arrays of
    composites (rare in bridged types) are built by their pycyphal class."""
    return not struct.union and not any(
        isinstance(f.type, DsdlType) and f.type.array and f.type.kind == "composite" for f in struct.fields)


def dict_literal(prefix: str, pairs: list[tuple[str, str]], width: int = LINE_LIMIT) -> str:
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


def identifier(text: str) -> str:
    """A lower-case identifier from a path: `rate_gyro_latest[0]` -> `rate_gyro_latest_0`."""
    ident = re.sub(r"[^0-9A-Za-z_]+", "_", text).strip("_").lower()
    return ident if ident and not ident[0].isdigit() else f"v_{ident}"


class LocalNames:
    """Local variable names of one function: readable, unique, never shadowing a module name or builtin."""

    def __init__(self, reserved: set[str]) -> None:
        self.reserved = reserved  # the module's names: shared, not copied (one LocalNames per function)
        self.taken = set(_LOCAL_RESERVED)

    def new(self, hint: str) -> str:
        base = identifier(hint)
        name, n = base, 2
        while name in self.taken or name in self.reserved:
            name, n = f"{base}_{n}", n + 1
        self.taken.add(name)
        return name


def access(base: str, path: tuple[tuple[str, Any], ...], attr: Callable[[str], str] = str) -> str:
    """The expression reading the field at `path` of `base`, attribute names through `attr`.

    >>> access("src", (("a", None), ("b", 2)))
    'src.a.b[2]'
    """
    text = base
    for name, index in path:
        text += f".{attr(name)}"
        if index is not None:
            text += f"[{index}]"
    return text


# ---- what convert.py imports -----------------------------------------------------------------------------


def ros_closure(resolved: Resolved, mappings: list[ResolvedMapping] | None = None) -> list[str]:
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


def ros_aliases(resolved: Resolved, mappings: list[ResolvedMapping] | None = None) -> dict[str, str]:
    """A local class name per ROS message type the converters use; package-qualified when names clash."""
    used = ros_closure(resolved, mappings)
    by_name: dict[str, list[str]] = {}
    for full in used:
        by_name.setdefault(full.split("/")[1], []).append(full)
    reserved = {"ConversionStats", "Callable", "Any"} | _NUNAVUT_RESERVED | set(keyword.softkwlist)
    aliases = {}
    for full in used:
        package, name = full.split("/")
        aliases[full] = name if len(by_name[name]) == 1 and name not in reserved else f"{package}_{name}"
    return aliases


def referenced_roots(resolved: Resolved) -> set[str]:
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


def isort_key(name: str) -> tuple[int, list[Any]]:
    """isort's (and ruff's) order of imported names: CONSTANTS, then Classes, then variables, case-insensitive."""
    kind = 0 if len(name) > 1 and name.isupper() else 1 if name[0].isupper() else 2
    return kind, natural_key(name)
