"""Wire codec emitter: ``python/<vehicle>_bridge/codec.py``, the Cyphal mappings as bytes -> bytes functions.

Per mapping ``m`` of the spec's Cyphal mappings, both directions:

- ``m_wire_to_ros(payload, receive_ns, stats) -> (cdr, stamp_ns) | None``: a Cyphal transfer payload -> the ROS
  message's CDR bytes (encapsulation header included) and its header stamp in ns (-1 without a header);
- ``m_ros_to_wire(cdr, stats) -> payload | None``: CDR bytes (as a raw subscription gives them) -> the payload.

The value semantics are convert.py's, literally: the emitter is targets.python's ``MappingEmitter`` composed with
this module's reads (CyphalWireReader, CdrReader) and result (CyphalWire) instead of the object ones. Reads come
from the payload / CDR decoded by cyphal_read / cdr_read into locals (the function's `decode` lines) and reach the
emitter as values (expressions per path, RosReads); the result tree (``CtorNode``) is written by the wire writers
instead of calling constructors; the statements between them (checks, saturation, stats keys, tables, stamps) are
the same typed statements, rendered by the same templates/python/statements.j2. Nothing is patched in generated
text. codec.py imports the standard library only.
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.templating import render
from sam_codegen.targets.python.elements import element_function_names, has_elements
from sam_codegen.targets.python.mapping import MappingEmitter, RosReads
from sam_codegen.targets.python.module import ArrayNode, ConvertModule, CtorNode, FunctionDraft
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.wire.cdr_write import LINE_LIMIT, MODULE_PRELUDE, Constants, cdr_reader, cdr_writer, wrap_line
from sam_codegen.targets.wire.cyphal_elements import unsupported, zero_record
from sam_codegen.targets.wire.cyphal_read import CYPHAL_PRELUDE, cyphal_reader, cyphal_writer
from sam_codegen.targets.wire.element_records import RecordUavcanReader, default_literal, element_record, record_scope
from sam_codegen.validate.mapping_rules import Step
from sam_codegen.validate.resolve import Resolved

__all__ = ["HEADER", "CdrReader", "CyphalWire", "CyphalWireReader", "WireCtorNode", "WireSignatures", "codec_context",
           "emit", "stamp_ns", "tree_values", "wrap_body"]

HEADER = "std_msgs/Header"
PAYLOAD, CDR = "payload", "cdr"
# Module-level names of codec.py that no local may take.
MODULE_NAMES = frozenset({"WireError", "CODECS", "Any", "Callable", "ConversionStats", "_NAN", "_INF", "_ZEROS",
                          "_struct", "_array", "_extend", "_support", PAYLOAD, CDR})


class WireCtorNode(CtorNode):
    """A message under construction whose fields are written as wire bytes: knows its type."""

    def __init__(self, of: DsdlStruct | RosMessage, fields: list[tuple[str, Any]]) -> None:
        super().__init__(of.name if isinstance(of, DsdlStruct) else of.full_name, fields)
        self.of = of


class CyphalWire:
    """codec.py's Construction: nothing imported, nothing constructed; the result tree is written as CDR (to_ros)
    or as a Cyphal payload (to_uavcan) by the wire writers, with module constants from `consts`."""

    sized_by_use: ClassVar[bool] = False

    def __init__(self, resolved: Resolved, consts: Constants) -> None:
        self.resolved, self.consts = resolved, consts
        self.records = False  # in an element function: records in and out (cyphal_elements)

    def element_scope(self, em: MappingEmitter, s: Step, base: str) -> AbstractContextManager[tuple[Any, Any, Any]]:
        """The readers and signatures of an element mapping's functions (targets.python.elements), which take
        and return records."""
        assert s.elements is not None
        return record_scope(self, RecordUavcanReader(s.elements, lambda t: self.struct(t.composite or "")),
                            self.resolved.ros.get, base)

    def dsdl_ref(self, struct: DsdlStruct) -> str:
        return struct.name

    def struct(self, name: str) -> DsdlStruct:
        struct = self.resolved.dsdl.get(name)
        assert struct is not None, name
        return struct

    def dsdl_ctor(self, struct: DsdlStruct) -> CtorNode:
        return WireCtorNode(struct, [(f.name, f.type) for f in struct.fields])

    def ros_ctor(self, message: RosMessage) -> CtorNode:
        return WireCtorNode(message, [(f.name, f.type) for f in message.fields])

    def frame_id(self, frame: str) -> str:
        return self.consts.frame_id(frame)  # the frame prefix before it: bound at start (code.Constants)

    def element_default(self, t: DsdlType | RosType) -> str:
        if isinstance(t, DsdlType) and t.kind == "composite":
            return zero_record(self.struct(t.composite or ""), self.struct)  # a fixed array of records padded
        return "None"  # an element nobody sets: the writers give the type's default

    def format_return(self, module: ConvertModule, root: CtorNode, names: LocalNames) -> list[str]:
        assert isinstance(root, WireCtorNode)
        values = tree_values(root)
        if self.records:
            if isinstance(root.of, RosMessage):
                self.consts.use_frames(values.values())  # a record holds its frame id as a string
                record = element_record(root.of, values, self.resolved.ros.get, default_literal)
            else:
                record = element_record(root.of, values, lambda t: self.struct(t.composite or ""))
            return wrap_body([f"return {record}"])
        if isinstance(root.of, RosMessage):
            lines, expr = cdr_writer(root.of, values, self.resolved.ros.get, names, self.consts)
            return wrap_body([*lines, f"return {expr}, {stamp_ns(root.of, values)}"])
        lines, expr = cyphal_writer(root.of, values, self.resolved.dsdl.get, names, self.consts)
        return wrap_body([*lines, f"return {expr}"])


def wrap_body(lines: list[str]) -> list[str]:
    """Statements of a function body (indented by 4 in the module) within the line limit."""
    return [part for line in lines for part in wrap_line(line, LINE_LIMIT - 4)]


def tree_values(root: CtorNode, prefix: tuple = ()) -> dict[tuple, str]:
    """The leaf expressions of a result tree by path; an element of a bounded array makes it a whole list."""
    out: dict[tuple, str] = {}
    for name, node in root.kwargs.items():
        path = (*prefix, (name, None))
        if isinstance(node, str):
            out[path] = node
        elif isinstance(node, ArrayNode):
            t = root.types[name]
            if t.array == "bounded":  # built with `capacity` elements, as the object converter does
                if not all(isinstance(v, str) for v in node.items.values()):
                    raise NotImplementedError(f"{path}: composites by index in a bounded array")
                zero = _zero(t)
                out[path] = "[" + ", ".join(node.items.get(i, zero) for i in range(node.capacity)) + "]"
                continue
            for i, item in sorted(node.items.items()):
                element = (*prefix, (name, i))
                if isinstance(item, str):
                    out[element] = item
                else:
                    out.update(tree_values(item, element))
        else:
            out.update(tree_values(node, path))
    return out


def _zero(t: DsdlType | RosType) -> str:
    """The literal zero of an array element.

    >>> _zero(DsdlType("float", 16)), _zero(RosType("bool")), _zero(RosType("int8"))
    ('0.0', 'False', '0')
    """
    kind = t.kind if isinstance(t, DsdlType) else t.base
    return "0.0" if kind.startswith("float") else "False" if kind == "bool" else "0"


def stamp_ns(message: RosMessage, values: dict[tuple, str]) -> str:
    """The expression of the header stamp in ns (-1 for a message without a std_msgs/Header `header`)."""
    header = message.field("header")
    if header is None or not isinstance(header.type, RosType) or header.type.base != HEADER or header.type.array:
        return "-1"
    stamp = (("header", None), ("stamp", None))
    sec, nanosec = values.get((*stamp, ("sec", None)), "0"), values.get((*stamp, ("nanosec", None)), "0")
    if sec == "receive_ns // 1_000_000_000" and nanosec == "receive_ns % 1_000_000_000":
        return "receive_ns"
    return f"{sec} * 1_000_000_000 + {nanosec}"


class CyphalWireReader:
    """A Cyphal payload: the fields the mapping reads, decoded into locals (lists for arrays). One per mapping."""

    def __init__(self, build: CyphalWire) -> None:
        self.build = build
        self.reads: dict[tuple, str] = {}

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        wanted = {tuple(s.uavcan_path) for s in steps if s.kind != "value" and s.uavcan_path}
        lines, self.reads = cyphal_reader(em.rm.dsdl_struct, wanted, self.build.resolved.dsdl.get, names,
                                          self.build.consts, PAYLOAD)
        fn.decode = wrap_body(lines)
        return {}

    def access(self, path: tuple) -> str:
        return self.reads[tuple(path)]

    def as_list(self, expr: str) -> str:
        return expr  # the reader's locals are lists already


class CdrReader:
    """ROS CDR bytes: the fields the mapping reads, decoded into locals (a Time as its sec and nanosec)."""

    def __init__(self, resolved: Resolved, consts: Constants) -> None:
        self.resolved, self.consts = resolved, consts

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> RosReads:
        wanted: set[tuple] = set()
        for s in steps:
            if s.kind == "time":
                wanted |= {(*s.ros_path, ("sec", None)), (*s.ros_path, ("nanosec", None))}
            else:
                wanted.add(tuple(s.ros_path))
        lines, found = cdr_reader(em.rm.ros_message, wanted, self.resolved.ros.get, names, self.consts, CDR)
        fn.decode = wrap_body(lines)
        return RosReads(lambda path: found[tuple(path)],
                        lambda path: (found[(*path, ("sec", None))], found[(*path, ("nanosec", None))]))

    def array_read(self, expr: str, ros_type: RosType) -> str:
        return expr  # the reader's locals are lists of plain values already (byte arrays as ints)


@dataclass(frozen=True)
class WireSignatures:
    """The codecs' functions: `<mapping>_wire_to_ros(payload, receive_ns, stats)` and
    `<mapping>_ros_to_wire(cdr, stats)`; `to_ros_doc` / `to_uavcan_doc` end their docstrings' first lines."""

    to_ros_doc: str = ", payload bytes -> CDR bytes and stamp [ns]."
    to_uavcan_doc: str = ", CDR bytes -> payload bytes."

    def to_ros(self, em: MappingEmitter) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(
            f"{em.name}_wire_to_ros",
            ["payload: bytes | bytearray | memoryview", "receive_ns: int", "stats: Any"],
            "tuple[bytes, int] | None",
            [f"Mapping {em.name!r}, UAVCAN -> ROS{self.to_ros_doc}", "",
             f"{rm.dsdl_struct.name} -> {rm.ros_message.full_name}"],
        )

    def to_uavcan(self, em: MappingEmitter) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(
            f"{em.name}_ros_to_wire",
            ["cdr: bytes | memoryview", "stats: Any"],
            "bytes | None",
            [f"Mapping {em.name!r}, ROS -> UAVCAN{self.to_uavcan_doc}", "",
             f"{rm.ros_message.full_name} -> {rm.dsdl_struct.name}"],
        )


def codec_context(resolved: Resolved) -> dict[str, Any]:
    consts = Constants("_W")
    build = CyphalWire(resolved, consts)
    module = ConvertModule(resolved, build)
    # Element mappings (arrays of composites, targets.python.elements) get element functions on records
    # (cyphal_elements); those whose elements a record cannot hold have no wire codec: a bridge that has one runs
    # on the object converters (the runtime falls back when CODECS lacks a mapping; OBJECT_ONLY says why).
    object_only = {rm.mapping.name: why for rm in resolved.mappings if has_elements(rm)
                   and (why := unsupported(rm, resolved.dsdl.get, resolved.ros.get)) is not None}
    mappings = [rm for rm in resolved.mappings if rm.mapping.name not in object_only]
    for rm in mappings:
        for message in (rm.ros_message, *(s.elements.ros_message for s in rm.steps if s.elements is not None)):
            module.ros_aliases.setdefault(message.full_name, message.full_name)
    module.module_names = set(MODULE_NAMES) | {f"{rm.mapping.name}_wire_to_ros" for rm in mappings} \
        | {f"{rm.mapping.name}_ros_to_wire" for rm in mappings} | element_function_names(mappings) | {"src"}
    functions = []
    for rm in mappings:
        emitter = MappingEmitter(module, rm, CyphalWireReader(build), CdrReader(resolved, consts), WireSignatures())
        functions.append((emitter.to_ros(), emitter.to_uavcan()))
    functions.extend(module.extra_functions)  # element mappings' functions, after the registry's
    return {
        "uses_array": "array" in consts.imports,
        "prelude": [*MODULE_PRELUDE, *CYPHAL_PRELUDE],
        "constants": consts.lines(),
        "bind": consts.bind_lines(),
        "tables": module.tables,
        "functions": functions,
        "mappings": [rm.mapping.name for rm in mappings],
        "object_only": list(object_only.items()),
    }


def emit(resolved: Resolved) -> dict[str, str]:
    """codec.py, for a spec with Cyphal mappings."""
    if not resolved.mappings:
        return {}
    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    return {f"python/{package}/codec.py": render("python/codec.py.j2", **common, **codec_context(resolved))}
