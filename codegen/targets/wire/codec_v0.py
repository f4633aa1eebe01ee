"""Wire codec emitter for the DroneCAN (UAVCAN v0) mappings: ``python/<vehicle>_bridge/codec_v0.py``.

Per mapping, ``<mapping>_wire_to_ros(payload, receive_ns, stats)`` (v0 payload bytes -> ROS CDR bytes and the header
stamp) and ``<mapping>_ros_to_wire(cdr, stats)`` (CDR -> payload bytes), and ``WIRE_MATCHES``: convert_v0.py's
converters and MATCHES on bytes instead of objects.

The value semantics are convert_v0's, not re-implemented: the mapping emitters here are emit_python_v0's, with only
what they read and what they build replaced. Reads come from locals that wire_v0's reader decodes from the payload
(wire_cdr's from the CDR); the tree of values the converter would pass to the constructors goes to wire_cdr's
writer (ROS) or wire_v0_writer (DroneCAN) instead. The checks, saturation, stats keys, tables and stamps are the
same statements, rendered by the same templates/python/statements.j2.

Where the object path refuses a payload, the codec raises WireError: where dronecan's decoding raises (see
wire_v0), and where a decoded array reaches a ROS sequence beyond its bound (rclpy refuses to serialize it). A ROS
fixed array gets the first elements of a longer one, as rclpy serializes it.
"""

from __future__ import annotations

import ast
from dataclasses import replace
from pathlib import Path
from typing import Any

from sam_codegen.model.spec import RosMessage, V0Struct
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import py_literal, typed_literal
from sam_codegen.render.templating import render
from sam_codegen.targets.python.mapping import RosReads
from sam_codegen.targets.python.mapping_v0 import KeyedItems, V0ConvertModule, V0MappingEmitter
from sam_codegen.targets.python.module import ArrayNode, CtorNode, FunctionDraft
from sam_codegen.targets.python.names import LocalNames, ros_aliases
from sam_codegen.targets.python.statements import FindItem
from sam_codegen.targets.wire.cdr_write import MODULE_PRELUDE, cdr_reader, cdr_writer
from sam_codegen.targets.wire.code import Constants
from sam_codegen.targets.wire.codec import WireCtorNode, stamp_ns, wrap_body
from sam_codegen.targets.wire.v0_layout import V0Layout, record_index
from sam_codegen.targets.wire.v0_read import WirePath, v0_reader
from sam_codegen.targets.wire.v0_write import HELPERS, V0Items, V0Node, v0_writer
from sam_codegen.validate.mapping_rules import Key, ResolvedMapping, Step
from sam_codegen.validate.resolve import Resolved

__all__ = ["emit"]

_DEFAULT = "<default>"  # an element left at its default (never rendered: the writers know the defaults)


class _CodecV0Module(V0ConvertModule):
    """codec_v0.py's view: the same tree of values as convert_v0, written as bytes."""

    consts: Constants
    layout: V0Layout
    names: LocalNames  # the locals of the function being emitted

    def dsdl_ctor(self, struct: Any) -> CtorNode:
        return WireCtorNode(struct, [(f.name, f.type) for f in struct.fields])

    def ros_ctor(self, message: RosMessage) -> CtorNode:
        return WireCtorNode(message, [(f.name, f.type) for f in message.fields])

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType):
            return _DEFAULT if t.kind == "composite" else typed_literal(0, "float" if t.kind == "float" else t.kind)
        return _DEFAULT if not t.is_primitive else typed_literal(0, t.base)

    def format_return(self, root: CtorNode) -> list[str]:
        assert isinstance(root, WireCtorNode)
        if isinstance(root.of, V0Struct):
            lines, expr = v0_writer(root.of, _v0_node(root), self.layout, self.consts)
            return _lines([*lines, f"return {expr}"])
        assert isinstance(root.of, RosMessage)
        values: dict[tuple, str] = {}
        checks: list[str] = []
        _ros_values(root, (), values, checks)
        lines, expr = cdr_writer(root.of, values, self.resolved.ros.get, self.names, self.consts)
        return _lines([*checks, *lines, f"return {expr}, {stamp_ns(root.of, values)}"])


def _lines(lines: list[str]) -> list[str]:
    """Statements within the line limit where wire_cdr's wrapping keeps their meaning (the same syntax tree), else
    as they are, marked (a long bit expression or comprehension)."""
    out: list[str] = []
    for line in lines:
        wrapped = wrap_body([line])
        if len(wrapped) == 1 or line.rstrip().endswith(":") or _tree(wrapped) != _tree([line]):
            out.append(line if len(wrapped) == 1 else f"{line}  # noqa: E501")
        else:
            out.extend(wrapped)
    return out


def _tree(lines: list[str]) -> str:
    """The syntax tree of a statement ("" when it does not parse alone)."""
    pad = len(lines[0]) - len(lines[0].lstrip())
    try:
        return ast.dump(ast.parse("\n".join(line[pad:] for line in lines)))
    except SyntaxError:
        return ""


def _v0_node(node: Any) -> Any:
    """The writer's view of a DroneCAN value: V0Node / V0Items / expression / None (default)."""
    if isinstance(node, CtorNode):
        return V0Node({name: _v0_node(value) for name, value in node.kwargs.items()})
    if isinstance(node, KeyedItems):
        return V0Items([_v0_node(item) for item in node.items.values()])
    if isinstance(node, ArrayNode):
        return V0Items([_v0_node(node.items[i]) if i in node.items else None for i in range(node.capacity)])
    return None if node == _DEFAULT else node


def _ros_values(node: CtorNode, prefix: tuple, out: dict[tuple, str], checks: list[str]) -> None:
    """The CDR writer's values: leaf path -> expression. A whole array goes into a ROS sequence only within its
    bound (rclpy refuses to serialize more), into a fixed array as its first elements (rclpy keeps those)."""
    for name, value in node.kwargs.items():
        t = node.types[name]
        path = (*prefix, (name, None))
        if isinstance(value, CtorNode):
            _ros_values(value, path, out, checks)
        elif isinstance(value, ArrayNode):
            for i, item in sorted(value.items.items()):
                element = (*prefix, (name, i))
                if isinstance(item, CtorNode):
                    _ros_values(item, element, out, checks)
                elif item != _DEFAULT:
                    out[element] = item
        elif value != _DEFAULT:
            if isinstance(t, RosType) and t.array == "fixed":
                value = f"{value}[:{t.capacity}]"
            elif isinstance(t, RosType) and t.array == "bounded":
                checks += [f"if len({value}) > {t.capacity}:",
                           f"    raise WireError({f'{name}: more than {t.capacity} elements for the ROS field'!r})"]
            out[path] = value


class _CodecV0MappingEmitter(V0MappingEmitter):
    module: _CodecV0Module

    def __init__(self, module: _CodecV0Module, rm: ResolvedMapping) -> None:
        super().__init__(module, rm)
        self.wire: dict[WirePath, str] = {}  # wire path -> the local the payload is decoded into
        self.found: dict[tuple, str] = {}  # ROS path -> the local the CDR is decoded into

    # -- reading the payload
    def wire_path(self, path: tuple) -> WirePath:
        """The top-level wire path holding a mapping path: names through composites, to an array or a leaf."""
        struct: V0Struct = self.rm.dsdl_struct  # type: ignore[assignment]
        names: WirePath = ()
        for name, _index in path:
            names = (*names, name)
            f = struct.field(name)
            assert f is not None, (struct.name, name)
            t: DsdlType = f.type  # type: ignore[assignment]
            if t.array or t.kind != "composite":
                return names
            struct = self.module.layout.struct(t)
        return names

    def wanted(self, matches: bool = False) -> set[WirePath]:
        """What the converter reads (or MATCHES: the selection and the elements read)."""
        paths = list(self.rm.elements)
        if matches:
            paths += [path for path, _, _ in self.rm.select]
        else:
            paths += [s.uavcan_path for s in self.rm.steps if s.uavcan_path]
        return {self.wire_path(p) for p in paths}

    def decode(self, names: LocalNames, wanted: set[WirePath]) -> list[str]:
        lines, self.wire = v0_reader(self.rm.dsdl_struct, wanted, self.module.layout,  # type: ignore[arg-type]
                                     self.module.consts, "payload", names.new)
        return _lines(lines)

    def bind_uavcan_arrays(self, fn: FunctionDraft, names: LocalNames, steps: list[Step],
                           listed: dict[tuple, str] | None = None) -> dict[tuple, str]:
        self.module.names = names
        fn.decode = self.decode(names, self.wanted())
        result = super().bind_uavcan_arrays(fn, names, steps)
        for i, st in enumerate(fn.binds):
            if isinstance(st, FindItem):  # records: the key field by position
                struct = self.item_struct(st.var)
                fn.binds[i] = replace(st, field=str(record_index(struct, ast.literal_eval(st.field))))
        return result

    def item_struct(self, local: str) -> V0Struct:
        path = next(p for p, v in self.items.items() if v == local)
        return self.element_struct(path)

    def element_struct(self, array_path: tuple) -> V0Struct:
        struct: V0Struct = self.rm.dsdl_struct  # type: ignore[assignment]
        for name, _index in array_path:
            f = struct.field(name)
            assert f is not None
            struct = self.module.layout.struct(f.type)  # type: ignore[arg-type]
        return struct

    def uav_list(self, expr: str) -> str:
        return f"list({expr})"

    def uav_access(self, base: str, path: tuple) -> str:
        for cut in range(len(path), 0, -1):
            local = self.items.get(tuple(path[:cut]))
            if local is not None:
                return local + self.record_access(self.element_struct(path[:cut]), path[cut:])
        struct: V0Struct = self.rm.dsdl_struct  # type: ignore[assignment]
        names: WirePath = ()
        for k, (name, index) in enumerate(path):
            names = (*names, name)
            f = struct.field(name)
            assert f is not None, (struct.name, name)
            t: DsdlType = f.type  # type: ignore[assignment]
            if t.array or t.kind != "composite":
                expr = self.wire[names]
                if index is None:
                    assert k == len(path) - 1, path
                    return expr
                expr += f"[{index}]"
                rest = path[k + 1:]
                return expr + (self.record_access(self.module.layout.struct(t), rest) if rest else "")
            struct = self.module.layout.struct(t)
        raise AssertionError(f"{path}: a composite read whole")

    def record_access(self, struct: V0Struct, rest: tuple) -> str:
        text = ""
        for name, index in rest:
            text += f"[{record_index(struct, name)}]"
            f = struct.field(name)
            assert f is not None
            if f.type.kind == "composite":  # type: ignore[union-attr]
                struct = self.module.layout.struct(f.type)  # type: ignore[arg-type]
            if index is not None:
                text += f"[{index}]"
        return text

    def to_ros(self) -> FunctionDraft:
        fn = super().to_ros()
        fn.name = f"{self.name}_wire_to_ros"
        fn.params = ["payload: bytes | bytearray | memoryview", "receive_ns: int", "stats: Any"]
        fn.returns = "tuple[bytes, int] | None"
        fn.doc = [f"Mapping {self.name!r}, UAVCAN -> ROS: payload -> (CDR, stamp in ns).", "",
                  f"{self.rm.dsdl_struct.name} -> {self.rm.ros_message.full_name}"]
        return fn

    # -- reading the CDR
    def ros_reader(self, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> RosReads:
        self.module.names = names
        wanted: set[tuple] = set()
        sequences: dict[tuple, int] = {}  # a sequence element read by index -> the index
        for s in steps:
            if s.kind == "time":
                wanted |= {(*s.ros_path, ("sec", None)), (*s.ros_path, ("nanosec", None))}
            elif s.ros_path[-1][1] is not None and self.ros_type(whole := (*s.ros_path[:-1], (
                    s.ros_path[-1][0], None))).array != "fixed":
                wanted.add(whole)
                sequences[s.ros_path] = s.ros_path[-1][1]
            else:
                wanted.add(s.ros_path)
        lines, self.found = cdr_reader(self.rm.ros_message, wanted, self.module.resolved.ros.get, names,
                                       self.module.consts, "cdr")
        for path, index in sequences.items():  # the object path fails (IndexError) on a shorter sequence
            whole = self.found[(*path[:-1], (path[-1][0], None))]
            lines += [f"if len({whole}) <= {index}:",
                      f"    raise WireError({f'{path[-1][0]}: no element {index}'!r})"]
            self.found[path] = f"{whole}[{index}]"
        fn.decode = _lines(lines)
        return RosReads(lambda path: self.found[tuple(path)],
                        lambda path: (self.found[(*path, ("sec", None))], self.found[(*path, ("nanosec", None))]))

    def ros_type(self, path: tuple) -> RosType:
        message = self.rm.ros_message
        t: Any = None
        for name, _ in path:
            f = message.field(name)
            assert f is not None
            t = f.type
            if not t.is_primitive:
                message = self.module.ros_message(t.base)
        return t

    def ros_array_read(self, expr: str, ros_type: RosType) -> str:
        return f"list({expr})"  # the CDR reader's list (byte arrays as ints), copied: converters may trim it

    def to_uavcan(self) -> FunctionDraft:
        fn = super().to_uavcan()
        fn.name = f"{self.name}_ros_to_wire"
        fn.params = ["cdr: bytes | memoryview", "stats: Any"]
        fn.returns = "bytes | None"
        fn.doc = [f"Mapping {self.name!r}, ROS -> UAVCAN: CDR -> payload.", "",
                  f"{self.rm.ros_message.full_name} -> {self.rm.dsdl_struct.name}"]
        return fn

    # -- WIRE_MATCHES
    def wire_matches(self) -> dict[str, Any] | None:
        """MATCHES' predicate on the payload: the same conditions (select values, the elements read are there);
        WireError where the payload does not decode."""
        if self.matches() is None:
            return None
        names = LocalNames(self.module.module_names)
        saved_wire, saved_items = self.wire, self.items
        self.items = {}
        decode = self.decode(names, self.wanted(matches=True))
        conditions = []
        for path, leaf, value in self.rm.select:
            conditions.append(f"{self.uav_access('payload', path)} == "
                              f"{typed_literal(value, 'float' if leaf.kind == 'float' else leaf.kind)}")
        for array_path, uses in self.rm.elements.items():
            if any(i is not None for _, i in array_path):
                continue  # inside an item: the converter checks it
            source = self.uav_access("payload", array_path)
            if uses and isinstance(uses[0], Key):
                struct = self.element_struct(array_path)
                conditions += [f"_item({source}, {record_index(struct, k.field)}, {py_literal(k.value)}) is not None"
                               for k in uses]
            else:
                conditions.append(f"len({source}) > {max(uses)}")
        self.wire, self.items = saved_wire, saved_items
        return {"name": f"_wire_matches_{self.name}", "decode": decode, "conditions": conditions}


def _context(resolved: Resolved) -> dict[str, Any]:
    module = _CodecV0Module(resolved)
    module.consts = Constants("_K")
    assert resolved.dronecan is not None
    module.layout = V0Layout(resolved.dronecan.get)
    module.used_ros = set()
    module.ros_aliases = ros_aliases(resolved, resolved.dronecan_mappings)
    mappings = resolved.dronecan_mappings
    module.module_names = (
        {f"{rm.mapping.name}_wire_to_ros" for rm in mappings} | {f"{rm.mapping.name}_ros_to_wire" for rm in mappings}
        | {f"_wire_matches_{rm.mapping.name}" for rm in mappings}
        | {"CODECS", "WIRE_MATCHES", "WireError", "ConversionStats", "Callable", "Any", "payload", "cdr",
           "_NAN", "_INF", "_item", "_struct", "_array", "_ZEROS", "_support"}
    )
    functions, matches = [], []
    for rm in mappings:
        emitter = _CodecV0MappingEmitter(module, rm)
        functions.append((emitter.to_ros(), emitter.to_uavcan()))
        matches.append((rm.mapping.name, emitter.wire_matches()))
    return {
        "uses_array": "array" in module.consts.imports,
        "tables": module.tables,
        "functions": functions,
        "matches": matches,
        "constants": module.consts.lines(),
        "prelude": MODULE_PRELUDE,
        "helpers": HELPERS.strip("\n").splitlines(),
    }


def emit(resolved: Resolved) -> dict[str, str]:
    """codec_v0.py, for a spec with DroneCAN mappings."""
    if not resolved.dronecan_mappings:
        return {}
    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    return {f"python/{package}/codec_v0.py": render("python/codec_v0.py.j2", **common, **_context(resolved))}

