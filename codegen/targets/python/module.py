"""The converter module being built: its functions (FunctionDraft), the result trees they return (CtorNode,
ArrayNode, KeyedItems), and what the mappings add to it (ConvertModule: tables, local names, array lengths).

One ConvertModule serves every variant (object or wire, Cyphal or DroneCAN): what differs is its Construction, the
strategy that names the UAVCAN types, makes the tree's nodes and turns a finished tree into the function's return
(a nested constructor call here, bytes in the wire codecs). PycyphalObjects is convert.py's.

Invariant: the trees hold code (expressions) at their leaves and types at their nodes; nothing but the
Construction's `format_return` decides how a tree becomes code.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import LINE_LIMIT, py_literal, typed_literal
from sam_codegen.targets.python.names import (
    LocalNames,
    dict_literal,
    dsdl_factory_name,
    dsdl_factory_supported,
    py_attr,
    py_class_ref,
    py_module,
    ros_factory_name,
)
from sam_codegen.targets.python.statements import Statement
from sam_codegen.validate.mapping_rules import Key, ResolvedMapping
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

    def __init__(self, ref: str, fields: list[tuple[str, Any]], keyword: Callable[[str], str] = str) -> None:
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


@dataclass(frozen=True)
class TableConstant:
    """A module-level dict of a table link (int -> int), one per link and direction; `what` is its comment."""

    name: str
    items: tuple[tuple[str, str], ...]  # (key literal, value literal)
    what: str

    @property
    def literal(self) -> str:
        return dict_literal(f"{self.name}: dict[int, int] = ", list(self.items))


class KeyedItems:
    """An array of composites built item by item, each chosen by a key (ArrayCommand.commands[actuator_id=3]):
    DroneCAN's broadcast arrays."""

    def __init__(self) -> None:
        self.items: dict[Key, CtorNode] = {}


class Construction(Protocol):
    """How one variant names UAVCAN types, makes the nodes of a result tree, and writes a finished tree as the
    function's return (the "result" strategy of a ConvertModule)."""

    # DSDL arrays that are not fixed are built with the elements the mapping names (DroneCAN's broadcast arrays),
    # not with their capacity
    sized_by_use: ClassVar[bool]

    def dsdl_ref(self, struct: DsdlStruct) -> str:
        """The UAVCAN type as the function's signature names it."""
        ...

    def struct(self, name: str) -> DsdlStruct: ...

    def dsdl_ctor(self, struct: DsdlStruct) -> CtorNode: ...

    def ros_ctor(self, message: RosMessage) -> CtorNode: ...

    def element_default(self, t: DsdlType | RosType) -> str:
        """The expression of an array element nobody sets."""
        ...

    def format_return(self, module: ConvertModule, root: CtorNode, names: LocalNames) -> list[str]:
        """The lines that return the finished tree (body indentation removed: the template indents them)."""
        ...


@dataclass
class ConvertModule:
    """What a generated converter module needs beyond its functions, and the result trees they build."""

    resolved: Resolved
    build: Construction
    ros_aliases: dict[str, str] = field(default_factory=dict)  # pkg/Name -> local class name
    tables: list[TableConstant] = field(default_factory=list)
    module_names: set[str] = field(default_factory=set)
    lengths: dict[tuple, int] = field(default_factory=dict)  # the current mapping's arrays sized by use
    # Functions beside the mappings' own (targets.python.elements: one pair per element mapping), emitted after them
    extra_functions: list[tuple[FunctionDraft, FunctionDraft]] = field(default_factory=list)

    def start(self, rm: ResolvedMapping) -> None:
        """Begin the functions of mapping `rm`: the arrays it builds element by element get their lengths."""
        self.lengths = {path: max(uses) + 1 for path, uses in rm.elements.items()
                        if uses and not isinstance(uses[0], Key)}

    def dsdl_ref(self, struct: DsdlStruct) -> str:
        return self.build.dsdl_ref(struct)

    def struct(self, name: str) -> DsdlStruct:
        return self.build.struct(name)

    def ros_message(self, full_name: str) -> RosMessage:
        message = self.resolved.ros.get(full_name)
        assert message is not None, full_name
        return message

    def dsdl_ctor(self, struct: DsdlStruct) -> CtorNode:
        return self.build.dsdl_ctor(struct)

    def ros_ctor(self, message: RosMessage) -> CtorNode:
        return self.build.ros_ctor(message)

    def child(self, t: DsdlType | RosType) -> CtorNode:
        """A node for a composite field (or element) of type t."""
        if isinstance(t, DsdlType):
            return self.dsdl_ctor(self.struct(t.composite))  # type: ignore[arg-type]
        return self.ros_ctor(self.ros_message(t.base))

    def insert(self, root: CtorNode, path: tuple, value: str) -> None:
        """Set the field at `path` (segments (name, index, Key or None)) of the tree under root to `value`."""
        node: Any = root
        prefix: tuple = ()
        for i, (name, index) in enumerate(path):
            node = self.insert_step(node, name, index, value if i == len(path) - 1 else None, prefix)
            prefix = (*prefix, (name, index))

    def insert_step(self, node: Any, name: str, index: Any, value: str | None, prefix: tuple) -> Any:
        """One segment of `insert`: set `value` there (the last segment), else the child to go on from."""
        t = node.types.get(name)
        assert t is not None, (prefix, name)
        if isinstance(index, Key):  # an item chosen by key: the key field set to its value
            assert value is None, (prefix, name)
            items = node.kwargs.setdefault(name, KeyedItems())
            if index not in items.items:
                item = self.child(t.element)
                item.kwargs[index.field] = py_literal(index.value)
                items.items[index] = item
            return items.items[index]
        if index is None:
            if value is not None:
                node.kwargs[name] = value
                return None
            if name not in node.kwargs:
                node.kwargs[name] = self.child(t)
            return node.kwargs[name]
        if name not in node.kwargs:
            size = self.array_size(t, (*prefix, (name, None)))
            node.kwargs[name] = ArrayNode(size, self.build.element_default(t.element))
        arr = node.kwargs[name]
        if value is not None:
            arr.items[index] = value
            return None
        if index not in arr.items:
            arr.items[index] = self.child(t.element)
        return arr.items[index]

    def array_size(self, t: Any, array_path: tuple) -> int:
        """How many elements the array at `array_path` is built with."""
        if self.build.sized_by_use and isinstance(t, DsdlType) and t.array != "fixed":
            return self.lengths[array_path] or 0
        return t.capacity or 0

    def format_node(self, node: Any, indent: int) -> list[str]:
        """Lines of an expression; the first line is not indented, the rest are (absolute indent)."""
        if isinstance(node, str):
            return [node]
        if isinstance(node, KeyedItems):
            lines = ["["]
            for item in node.items.values():
                part = self.format_node(item, indent + 4)
                lines.append(" " * (indent + 4) + part[0])
                lines.extend(part[1:])
                lines[-1] += ","
            lines.append(" " * indent + "]")
            return lines
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
        keyed = [(k, self.format_node(v, indent + 4)) for k, v in node.arguments()]
        one = f"{node.ref}(" + ", ".join(f"{k}={p[0]}" for k, p in keyed) + ")"
        if all(len(p) == 1 for _, p in keyed) and indent + len(one) <= LINE_LIMIT - 20:
            return [one]
        lines = [f"{node.ref}("]
        for k, p in keyed:
            lines.append(" " * (indent + 4) + f"{k}={p[0]}")
            lines.extend(p[1:])
            lines[-1] += ","
        lines.append(" " * indent + ")")
        return lines

    def format_call(self, root: CtorNode) -> list[str]:
        """`return <nested constructor call>` (the object converters' return)."""
        lines = self.format_node(root, 4)
        lines[0] = "return " + lines[0]
        return [line[4:] if i else line for i, line in enumerate(lines)]

    def format_return(self, root: CtorNode, names: LocalNames) -> list[str]:
        return self.build.format_return(self, root, names)


class PycyphalObjects:
    """convert.py's Construction: pycyphal objects and ROS messages, built by the generated fast constructors
    (factories.py) where a type has one; records the DSDL modules and constructors it uses."""

    sized_by_use: ClassVar[bool] = False

    def __init__(self, resolved: Resolved, ros_aliases: dict[str, str]) -> None:
        self.resolved, self.ros_aliases = resolved, ros_aliases
        self.dsdl_modules: set[str] = set()
        self.dsdl_factories: dict[str, DsdlStruct] = {}  # full name -> struct, as used

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

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType):
            if t.kind == "composite":
                return f"{self.dsdl_new(self.struct(t.composite))}()"  # type: ignore[arg-type]
            return typed_literal(0, "float" if t.kind == "float" else t.kind)
        if not t.is_primitive:
            return f"{ros_factory_name(self.ros_aliases[t.base])}()"
        return typed_literal(0, t.base)

    def format_return(self, module: ConvertModule, root: CtorNode, names: LocalNames) -> list[str]:
        return module.format_call(root)
