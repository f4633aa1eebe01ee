"""Wire codec emitter for the DroneCAN (UAVCAN v0) mappings: ``python/<vehicle>_bridge/codec_v0.py``.

Per mapping, ``<mapping>_wire_to_ros(payload, receive_ns, stats)`` (v0 payload bytes -> ROS CDR bytes and the header
stamp) and ``<mapping>_ros_to_wire(cdr, stats)`` (CDR -> payload bytes), and ``WIRE_MATCHES``: convert_v0.py's
converters and MATCHES on bytes instead of objects.

The value semantics are convert_v0's, not re-implemented: the emitter is targets.python's MappingEmitter composed with
this module's reads and result instead of the object ones. Reads come from locals that v0_read decodes from the
payload (V0WireReader; the DroneCAN elements a mapping needs are bound by mapping_v0.bind_required_elements, as for
objects) and cdr_read from the CDR (V0CdrReader); the tree of values the converter would pass to the constructors goes
to cdr_write (ROS) or v0_write (DroneCAN) instead (DroneCanWire). The checks, saturation, stats keys, tables and
stamps are the same typed statements, rendered by the same templates/python/statements.j2.

Element mappings (arrays of composites, targets.python.elements) get element functions on records (element_records):
a v0 array of composites as v0_read's records, a ROS sequence of messages as cdr_read's / cdr_write's tuples of
leaves; element types a record cannot hold stay in OBJECT_ONLY with the reason.

Where the object path refuses a payload, the codec raises WireError: where dronecan's decoding raises (see
v0_read), and where a decoded array reaches a ROS sequence beyond its bound (rclpy refuses to serialize it). A ROS
fixed array gets the first elements of a longer one, as rclpy serializes it.
"""

from __future__ import annotations

import ast
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any, ClassVar

from sam_codegen.model.expr import fields_of
from sam_codegen.model.spec import DsdlStruct, RosMessage, V0Struct
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import py_literal, typed_literal
from sam_codegen.render.templating import render
from sam_codegen.targets.python.elements import has_elements
from sam_codegen.targets.python.mapping import MappingEmitter, RosReads
from sam_codegen.targets.python.mapping_v0 import Predicate, bind_required_elements, matches
from sam_codegen.targets.python.module import ArrayNode, ConvertModule, CtorNode, FunctionDraft, KeyedItems
from sam_codegen.targets.python.names import LocalNames, ros_aliases
from sam_codegen.targets.wire.cdr_write import MODULE_PRELUDE, cdr_reader, cdr_writer
from sam_codegen.targets.wire.code import Constants
from sam_codegen.targets.wire.codec import WireCtorNode, WireSignatures, stamp_ns, wrap_body
from sam_codegen.targets.wire.element_records import (
    RecordUavcanReader,
    default_literal,
    element_record,
    record_scope,
    unsupported,
)
from sam_codegen.targets.wire.v0_layout import V0Layout, record_index
from sam_codegen.targets.wire.v0_read import WirePath, v0_reader
from sam_codegen.targets.wire.v0_write import HELPERS, V0Items, V0Node, v0_writer
from sam_codegen.validate.mapping_rules import Key, ResolvedMapping, Step
from sam_codegen.validate.resolve import Resolved

__all__ = ["DroneCanWire", "V0CdrReader", "V0WireReader", "emit", "wire_matches"]

_DEFAULT = "<default>"  # an element left at its default (never rendered: the writers know the defaults)


class DroneCanWire:
    """codec_v0.py's Construction: the same tree of values as convert_v0's, written as CDR (to_ros) or as a v0
    payload (to_uavcan) by the wire writers, with module constants from `consts`."""

    sized_by_use: ClassVar[bool] = True

    def __init__(self, resolved: Resolved, consts: Constants, layout: V0Layout) -> None:
        self.resolved, self.consts, self.layout = resolved, consts, layout
        self.records = False  # in an element function: records in and out (element_records)

    def element_scope(self, em: MappingEmitter, s: Step, base: str) -> AbstractContextManager[tuple[Any, Any, Any]]:
        """The readers and signatures of an element mapping's functions (targets.python.elements), which take
        and return records."""
        assert s.elements is not None
        return record_scope(self, RecordUavcanReader(s.elements, self.layout.struct), self.resolved.ros.get, base)

    def dsdl_ref(self, struct: DsdlStruct) -> str:
        return "Any"

    def struct(self, name: str) -> DsdlStruct:
        assert self.resolved.dronecan is not None
        struct = self.resolved.dronecan.get(name)
        assert struct is not None, name
        return struct

    def dsdl_ctor(self, struct: DsdlStruct) -> CtorNode:
        return WireCtorNode(struct, [(f.name, f.type) for f in struct.fields])

    def ros_ctor(self, message: RosMessage) -> CtorNode:
        return WireCtorNode(message, [(f.name, f.type) for f in message.fields])

    def frame_id(self, frame: str) -> str:
        return self.consts.frame_id(frame)  # the frame prefix before it: bound at start (code.Constants)

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType):
            return _DEFAULT if t.kind == "composite" else typed_literal(0, "float" if t.kind == "float" else t.kind)
        return _DEFAULT if not t.is_primitive else typed_literal(0, t.base)

    def format_return(self, module: ConvertModule, root: CtorNode, names: LocalNames) -> list[str]:
        assert isinstance(root, WireCtorNode)
        if self.records:
            leaves: dict[tuple, str] = {}
            if isinstance(root.of, V0Struct):
                _v0_leaves(_v0_node(root), (), leaves)
                record = element_record(root.of, leaves, self.layout.struct)
            else:
                _ros_values(root, (), leaves, [])
                self.consts.use_frames(leaves.values())  # a record holds its frame id as a string
                record = element_record(root.of, leaves, self.resolved.ros.get, default_literal)
            return _lines([f"return {record}"])
        if isinstance(root.of, V0Struct):
            lines, expr = v0_writer(root.of, _v0_node(root), self.layout, self.consts)
            return _lines([*lines, f"return {expr}"])
        assert isinstance(root.of, RosMessage)
        values: dict[tuple, str] = {}
        checks: list[str] = []
        _ros_values(root, (), values, checks)
        lines, expr = cdr_writer(root.of, values, self.resolved.ros.get, names, self.consts)
        return _lines([*checks, *lines, f"return {expr}, {stamp_ns(root.of, values)}"])




def _v0_leaves(node: Any, prefix: tuple, out: dict[tuple, str]) -> None:
    """The expressions of a DroneCAN element's scalars by path (nested composites by their fields'), for its record."""
    for name, value in node.fields.items():
        if isinstance(value, V0Node):
            _v0_leaves(value, (*prefix, (name, None)), out)
        elif value is not None:
            out[(*prefix, (name, None))] = value


def _lines(lines: list[str]) -> list[str]:
    """Statements within the line limit where cdr_write's wrapping keeps their meaning (the same syntax tree), else
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


class V0WireReader:
    """A v0 payload: the fields the mapping reads (or MATCHES checks), decoded into locals; arrays of composites as
    lists of records (tuples), their fields by position. One per function."""

    def __init__(self, build: DroneCanWire, rm: ResolvedMapping) -> None:
        self.build, self.rm = build, rm
        self.wire: dict[WirePath, str] = {}  # wire path -> the local the payload is decoded into
        self.items: dict[tuple, str] = {}  # path ending in an item chosen by key -> its local

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
            struct = self.build.layout.struct(t)
        return names

    def wanted(self, matches: bool = False) -> set[WirePath]:
        """What the converter reads (or MATCHES: the selection and the elements read)."""
        paths = list(self.rm.elements)
        if matches:
            paths += [path for path, _, _ in self.rm.select]
        else:
            paths += [s.uavcan_path for s in self.rm.steps if s.uavcan_path]
            paths += [f.path for s in self.rm.steps if s.expr is not None and not s.uavcan_path
                      for f in fields_of(s.expr)]  # what UAVCAN -> ROS expressions read
        return {self.wire_path(p) for p in paths}

    def decode(self, names: LocalNames, wanted: set[WirePath]) -> list[str]:
        lines, self.wire = v0_reader(self.rm.dsdl_struct, wanted, self.build.layout,  # type: ignore[arg-type]
                                     self.build.consts, "payload", names.new)
        return _lines(lines)

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        fn.decode = self.decode(names, self.wanted())
        return bind_required_elements(self, em, fn, names, steps)

    def item_field(self, item_path: tuple, name: str) -> str:
        return str(record_index(self.element_struct(item_path), name))  # records: the key field by position

    def element_struct(self, array_path: tuple) -> V0Struct:
        struct: V0Struct = self.rm.dsdl_struct  # type: ignore[assignment]
        for name, _index in array_path:
            f = struct.field(name)
            assert f is not None
            struct = self.build.layout.struct(f.type)  # type: ignore[arg-type]
        return struct

    def as_list(self, expr: str) -> str:
        return f"list({expr})"

    def access(self, path: tuple) -> str:
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
                return expr + (self.record_access(self.build.layout.struct(t), rest) if rest else "")
            struct = self.build.layout.struct(t)
        raise AssertionError(f"{path}: a composite read whole")

    def record_access(self, struct: V0Struct, rest: tuple) -> str:
        text = ""
        for name, index in rest:
            text += f"[{record_index(struct, name)}]"
            f = struct.field(name)
            assert f is not None
            if f.type.kind == "composite":  # type: ignore[union-attr]
                struct = self.build.layout.struct(f.type)  # type: ignore[arg-type]
            if index is not None:
                text += f"[{index}]"
        return text


class V0CdrReader:
    """ROS CDR bytes for a DroneCAN mapping: as CdrReader, and a sequence element read by index is checked
    (the object converter fails on a shorter sequence); arrays are copied (converters may trim them)."""

    def __init__(self, build: DroneCanWire) -> None:
        self.build = build
        self.found: dict[tuple, str] = {}  # ROS path -> the local the CDR is decoded into

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> RosReads:
        wanted: set[tuple] = set()
        sequences: dict[tuple, Any] = {}  # a sequence element read by index -> the index
        for s in steps:
            if s.kind == "time":
                wanted |= {(*s.ros_path, ("sec", None)), (*s.ros_path, ("nanosec", None))}
            elif s.ros_path[-1][1] is not None and self.ros_type(em, whole := (*s.ros_path[:-1], (
                    s.ros_path[-1][0], None))).array != "fixed":
                wanted.add(whole)
                sequences[s.ros_path] = s.ros_path[-1][1]
            else:
                wanted.add(s.ros_path)
        lines, self.found = cdr_reader(em.rm.ros_message, wanted, self.build.resolved.ros.get, names,
                                       self.build.consts, "cdr")
        for path, index in sequences.items():  # the object path fails (IndexError) on a shorter sequence
            local = self.found[(*path[:-1], (path[-1][0], None))]
            lines += [f"if len({local}) <= {index}:",
                      f"    raise WireError({f'{path[-1][0]}: no element {index}'!r})"]
            self.found[path] = f"{local}[{index}]"
        fn.decode = _lines(lines)
        found = self.found
        return RosReads(lambda path: found[tuple(path)],
                        lambda path: (found[(*path, ("sec", None))], found[(*path, ("nanosec", None))]))

    def ros_type(self, em: MappingEmitter, path: tuple) -> RosType:
        message = em.rm.ros_message
        t: Any = None
        for name, _ in path:
            f = message.field(name)
            assert f is not None
            t = f.type
            if not t.is_primitive:
                message = em.module.ros_message(t.base)
        return t

    def array_read(self, expr: str, ros_type: RosType) -> str:
        return f"list({expr})"  # the CDR reader's list (byte arrays as ints), copied: converters may trim it


def wire_matches(em: MappingEmitter, build: DroneCanWire) -> Predicate | None:
    """MATCHES' predicate on the payload: the same conditions (select values, the elements read are there);
    WireError where the payload does not decode. Its own reader: it decodes what MATCHES needs, no more."""
    if matches(em) is None:
        return None
    rm = em.rm
    reader = V0WireReader(build, rm)
    decode = reader.decode(LocalNames(em.module.module_names), reader.wanted(matches=True))
    conditions: list[str] = []
    for path, leaf, value in rm.select:
        conditions.append(f"{reader.access(path)} == "
                          f"{typed_literal(value, 'float' if leaf.kind == 'float' else leaf.kind)}")
    for array_path, uses in rm.elements.items():
        if any(i is not None for _, i in array_path):
            continue  # inside an item: the converter checks it
        source = reader.access(array_path)
        if uses and isinstance(uses[0], Key):
            struct = reader.element_struct(array_path)
            conditions += [f"_item({source}, {record_index(struct, k.field)}, {py_literal(k.value)}) is not None"
                           for k in uses]
        else:
            conditions.append(f"len({source}) > {max(uses)}")
    return Predicate(f"_wire_matches_{em.name}", tuple(conditions), tuple(decode))


def _context(resolved: Resolved) -> dict[str, Any]:
    consts = Constants("_K")
    assert resolved.dronecan is not None
    build = DroneCanWire(resolved, consts, V0Layout(resolved.dronecan.get))
    module = ConvertModule(resolved, build, ros_aliases=ros_aliases(resolved, resolved.dronecan_mappings))
    # Element mappings (arrays of composites, targets.python.elements) whose elements a record cannot hold have no
    # wire codec (element_records.unsupported): a bridge that has one runs on the object converters (the runtime falls
    # back when CODECS lacks a mapping).
    object_only = {rm.mapping.name: why for rm in resolved.dronecan_mappings if has_elements(rm)
                   and (why := unsupported(rm, build.layout, resolved.ros.get)) is not None}
    mappings = [rm for rm in resolved.dronecan_mappings if rm.mapping.name not in object_only]
    module.module_names = (
        {f"{rm.mapping.name}_wire_to_ros" for rm in mappings} | {f"{rm.mapping.name}_ros_to_wire" for rm in mappings}
        | {f"_wire_matches_{rm.mapping.name}" for rm in mappings}
        | {"CODECS", "WIRE_MATCHES", "WireError", "ConversionStats", "Callable", "Any", "payload", "cdr",
           "_NAN", "_INF", "_item", "_struct", "_array", "_ZEROS", "_support", "src"}
    )
    signatures = WireSignatures(": payload -> (CDR, stamp in ns).", ": CDR -> payload.")
    functions, predicates = [], []
    for rm in mappings:
        emitter = MappingEmitter(module, rm, V0WireReader(build, rm), V0CdrReader(build), signatures)
        functions.append((emitter.to_ros(), emitter.to_uavcan()))
        predicates.append((rm.mapping.name, wire_matches(emitter, build)))
    functions.extend(module.extra_functions)  # element mappings' functions, after the registry's
    return {
        "uses_array": "array" in consts.imports,
        "tables": module.tables,
        "functions": functions,
        "matches": predicates,
        "mappings": [rm.mapping.name for rm in mappings],
        "object_only": list(object_only.items()),
        "constants": consts.lines(),
        "bind": consts.bind_lines(),
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

