"""Wire codec emitter: ``python/<vehicle>_bridge/codec.py``, the Cyphal mappings as bytes -> bytes functions.

Per mapping ``m`` of the spec's Cyphal mappings, both directions:

- ``m_wire_to_ros(payload, receive_ns, stats) -> (cdr, stamp_ns) | None``: a Cyphal transfer payload -> the ROS
  message's CDR bytes (encapsulation header included) and its header stamp in ns (-1 without a header);
- ``m_ros_to_wire(cdr, stats) -> payload | None``: CDR bytes (as a raw subscription gives them) -> the payload.

The value semantics are convert.py's, literally: the emitter is targets.python's ``MappingEmitter`` with the reads
and the result replaced. Reads come from the payload / CDR decoded by cyphal_read / cdr_read into locals (the
function's `decode` lines), and are handed to the emitter as values (``RosReads``, ``uav_access``); the result tree
(``CtorNode``) is written by the wire writers instead of calling constructors; the statements between them (checks,
saturation, stats keys, tables, stamps) are the same typed statements, rendered by the same
templates/python/statements.j2. Nothing is patched in generated text. codec.py imports the standard library only.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sam_codegen.model.spec import DsdlStruct, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.templating import render
from sam_codegen.targets.python.mapping import MappingEmitter, RosReads
from sam_codegen.targets.python.module import ArrayNode, ConvertModule, CtorNode, FunctionDraft
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.wire.cdr_write import LINE_LIMIT, MODULE_PRELUDE, Constants, cdr_reader, cdr_writer, wrap_line
from sam_codegen.targets.wire.cyphal_read import CYPHAL_PRELUDE, cyphal_reader, cyphal_writer
from sam_codegen.validate.mapping_rules import ResolvedMapping, Step
from sam_codegen.validate.resolve import Resolved

__all__ = ["HEADER", "WireCtorNode", "codec_context", "emit", "stamp_ns", "tree_values", "wrap_body"]

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


class _CodecModule(ConvertModule):
    """codec.py's view of types: nothing imported, nothing constructed; trees become bytes."""

    consts: Constants
    names: LocalNames  # the locals of the function being emitted (its writers take names from it too)

    def dsdl_ref(self, struct: DsdlStruct) -> str:
        return struct.name

    def dsdl_ctor(self, struct: DsdlStruct) -> CtorNode:
        return WireCtorNode(struct, [(f.name, f.type) for f in struct.fields])

    def ros_ctor(self, message: RosMessage) -> CtorNode:
        return WireCtorNode(message, [(f.name, f.type) for f in message.fields])

    def element_default(self, t: DsdlType | RosType) -> str:
        return "None"  # an element nobody sets: the writers give the type's default

    def format_return(self, root: CtorNode) -> list[str]:
        assert isinstance(root, WireCtorNode)
        values = tree_values(root)
        names = self.names
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


class _CodecEmitter(MappingEmitter):
    module: _CodecModule

    def __init__(self, module: _CodecModule, rm: ResolvedMapping) -> None:
        super().__init__(module, rm)
        self.reads: dict[tuple, str] = {}
        self.stamps: dict[str, tuple[str, str]] = {}  # token -> (sec local, nanosec local)

    # -- UAVCAN -> ROS: the reads come out of the payload
    def bind_uavcan_arrays(self, fn: FunctionDraft, names: LocalNames, steps: list[Step],
                           listed: dict[tuple, str] | None = None) -> dict[tuple, str]:
        wanted = {tuple(s.uavcan_path) for s in steps if s.kind != "value" and s.uavcan_path}
        self.module.names = names
        lines, self.reads = cyphal_reader(self.rm.dsdl_struct, wanted, self.module.resolved.dsdl.get, names,
                                          self.module.consts, PAYLOAD)
        fn.decode = wrap_body(lines)
        return {}

    def uav_access(self, base: str, path: tuple) -> str:
        return self.reads[tuple(path)]

    def uav_list(self, expr: str) -> str:
        return expr  # the reader's locals are lists already

    # -- ROS -> UAVCAN: the reads come out of the CDR
    def ros_reader(self, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> RosReads:
        wanted: set[tuple] = set()
        for s in steps:
            if s.kind == "time":
                wanted |= {(*s.ros_path, ("sec", None)), (*s.ros_path, ("nanosec", None))}
            else:
                wanted.add(tuple(s.ros_path))
        self.module.names = names
        lines, found = cdr_reader(self.rm.ros_message, wanted, self.module.resolved.ros.get, names,
                                  self.module.consts, CDR)
        fn.decode = wrap_body(lines)
        return RosReads(lambda path: found[tuple(path)],
                        lambda path: (found[(*path, ("sec", None))], found[(*path, ("nanosec", None))]))

    def ros_array_read(self, expr: str, ros_type: RosType) -> str:
        return expr  # the reader's locals are lists of plain values already (byte arrays as ints)

    # -- the functions, named and typed as codec.py's API says
    def wire_to_ros(self) -> FunctionDraft:
        fn = self.to_ros()
        rm = self.rm
        fn.name = f"{self.name}_wire_to_ros"
        fn.params = ["payload: bytes | bytearray | memoryview", "receive_ns: int", "stats: Any"]
        fn.returns = "tuple[bytes, int] | None"
        fn.doc = [f"Mapping {self.name!r}, UAVCAN -> ROS, payload bytes -> CDR bytes and stamp [ns].", "",
                  f"{rm.dsdl_struct.name} -> {rm.ros_message.full_name}"]
        return fn

    def ros_to_wire(self) -> FunctionDraft:
        fn = self.to_uavcan()
        rm = self.rm
        fn.name = f"{self.name}_ros_to_wire"
        fn.params = ["cdr: bytes | memoryview", "stats: Any"]
        fn.returns = "bytes | None"
        fn.doc = [f"Mapping {self.name!r}, ROS -> UAVCAN, CDR bytes -> payload bytes.", "",
                  f"{rm.ros_message.full_name} -> {rm.dsdl_struct.name}"]
        return fn


def codec_context(resolved: Resolved) -> dict[str, Any]:
    module = _CodecModule(resolved)
    module.consts = Constants("_W")
    module.ros_aliases = {}
    for rm in resolved.mappings:
        module.ros_aliases.setdefault(rm.ros_message.full_name, rm.ros_message.full_name)
    module.module_names = set(MODULE_NAMES) | {f"{rm.mapping.name}_wire_to_ros" for rm in resolved.mappings} \
        | {f"{rm.mapping.name}_ros_to_wire" for rm in resolved.mappings}
    functions = []
    for rm in resolved.mappings:
        emitter = _CodecEmitter(module, rm)
        functions.append((emitter.wire_to_ros(), emitter.ros_to_wire()))
    return {
        "uses_array": "array" in module.consts.imports,
        "prelude": [*MODULE_PRELUDE, *CYPHAL_PRELUDE],
        "constants": module.consts.lines(),
        "tables": module.tables,
        "functions": functions,
        "mappings": [rm.mapping.name for rm in resolved.mappings],
    }


def emit(resolved: Resolved) -> dict[str, str]:
    """codec.py, for a spec with Cyphal mappings."""
    if not resolved.mappings:
        return {}
    spec = resolved.spec
    package = f"{spec.vehicle}_bridge"
    common = {"spec_name": Path(spec.file).name, "package": package, "vehicle": spec.vehicle}
    return {f"python/{package}/codec.py": render("python/codec.py.j2", **common, **codec_context(resolved))}
