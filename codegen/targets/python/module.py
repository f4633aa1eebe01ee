"""The converter module being built: its functions (FunctionDraft), the constructor trees they return (CtorNode,
ArrayNode), and what the mappings add to it (ConvertModule: tables, imports, constructors used).

Invariant: the trees hold code (expressions) at their leaves and types at their nodes; how a tree becomes code (a
nested constructor call here, bytes in the wire codecs) is the module's `format_return`, nothing else.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import LINE_LIMIT, typed_literal
from sam_codegen.targets.python.names import (
    dsdl_factory_name,
    dsdl_factory_supported,
    py_attr,
    py_class_ref,
    py_module,
    ros_factory_name,
)
from sam_codegen.targets.python.statements import Statement
from sam_codegen.validate.resolve import Resolved


@dataclass
class FunctionDraft:
    """One generated function: signature, then `decode` lines (the wire codecs' reads), `binds`, `statements` and
    the `result` lines (its return), as the templates' `function` macro lays them out."""

    name: str
    params: list[str]
    returns: str
    doc: list[str]  # docstring lines
    binds: list[Statement] = field(default_factory=list)
    statements: list[Statement] = field(default_factory=list)
    result: list[str] = field(default_factory=list)
    decode: list[str] = field(default_factory=list)


class CtorNode:
    """A message under construction, a DSDL object or a ROS message: field name -> expression or nested node."""

    def __init__(self, ref: str, fields: list[tuple[str, Any]], keyword=lambda name: name) -> None:
        self.ref = ref  # what is called: the pycyphal class or the ROS message's constructor
        self.types = dict(fields)  # field name -> DsdlType | RosType, in declaration order
        self.keyword = keyword
        self.kwargs: dict[str, Any] = {}

    def arguments(self) -> list[tuple[str, Any]]:
        return [(self.keyword(name), self.kwargs[name]) for name in self.types if name in self.kwargs]


class ArrayNode:
    """A fixed-size array written element by element; the other elements get `default`."""

    def __init__(self, capacity: int, default: str) -> None:
        self.capacity, self.default = capacity, default
        self.items: dict[int, Any] = {}


@dataclass
class ConvertModule:
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

    def dsdl_ctor(self, struct: DsdlStruct) -> CtorNode:
        return CtorNode(self.dsdl_new(struct), [(f.name, f.type) for f in struct.fields], py_attr)

    def ros_ctor(self, message: RosMessage) -> CtorNode:
        fields = [(f.name, f.type) for f in message.fields]
        return CtorNode(ros_factory_name(self.ros_aliases[message.full_name]), fields)

    def child(self, t: DsdlType | RosType) -> CtorNode:
        """A node for a composite field (or element) of type t."""
        if isinstance(t, DsdlType):
            return self.dsdl_ctor(self.struct(t.composite))  # type: ignore[arg-type]
        return self.ros_ctor(self.ros_message(t.base))

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType):
            if t.kind == "composite":
                return f"{self.dsdl_new(self.struct(t.composite))}()"  # type: ignore[arg-type]
            return typed_literal(0, "float" if t.kind == "float" else t.kind)
        if not t.is_primitive:
            return f"{ros_factory_name(self.ros_aliases[t.base])}()"
        return typed_literal(0, t.base)

    def insert(self, root: CtorNode, path: tuple, value: str) -> None:
        """Set the field at `path` (segments (name, index or None)) of the tree under root to `value`."""
        node: Any = root
        prefix: tuple = ()
        for i, (name, index) in enumerate(path):
            node = self.insert_step(node, name, index, value if i == len(path) - 1 else None, prefix)
            prefix = (*prefix, (name, index))

    def insert_step(self, node: Any, name: str, index: Any, value: str | None, prefix: tuple) -> Any:
        """One segment of `insert`: set `value` there (the last segment), else the child to go on from."""
        t = node.types.get(name)
        assert t is not None, (prefix, name)
        if index is None:
            if value is not None:
                node.kwargs[name] = value
                return None
            if name not in node.kwargs:
                node.kwargs[name] = self.child(t)
            return node.kwargs[name]
        if name not in node.kwargs:
            node.kwargs[name] = ArrayNode(self.array_size(t, (*prefix, (name, None))), self.element_default(t.element))
        arr = node.kwargs[name]
        if value is not None:
            arr.items[index] = value
            return None
        if index not in arr.items:
            arr.items[index] = self.child(t.element)
        return arr.items[index]

    def array_size(self, t: Any, array_path: tuple) -> int:
        """How many elements the array at `array_path` is built with."""
        return t.capacity or 0

    def format_node(self, node: Any, indent: int) -> list[str]:
        """Lines of an expression; the first line is not indented, the rest are (absolute indent)."""
        if isinstance(node, str):
            return [node]
        if isinstance(node, ArrayNode):
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

    def format_return(self, root: CtorNode) -> list[str]:
        lines = self.format_node(root, 4)
        lines[0] = "return " + lines[0]
        return [line[4:] if i else line for i, line in enumerate(lines)]
