"""One mapping's conversion plan said in Python: its to_ros and to_uavcan functions.

MappingEmitter holds the value semantics (every check, saturation, stats key, table and stamp) and is the same for
every variant; what differs between convert.py, convert_v0.py, codec.py and codec_v0.py is composed in, as
strategies per variant (object or wire x Cyphal or DroneCAN), the way pycyphal combines transport and media:

- a UavcanReader: how the to_ros function reads the UAVCAN side (object attributes, or locals decoded from bytes);
- a RosReader: how the to_uavcan function reads the ROS side (message fields, or locals decoded from CDR);
- Signatures: the functions' names, parameters and docstrings;
- the ConvertModule's Construction: how the result tree becomes the return (module.py).

Object converters: CyphalObjectReader and RosObjectReader here, V0ObjectReader in mapping_v0; the wire codecs'
readers are in targets/wire.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from sam_codegen.conversion_plan import (
    CHECK_OPS,
    TO_ROS,
    TO_UAVCAN,
    Clamp,
    DecodeUtf8,
    ElementMapping,
    EncodeUtf8,
    Evaluate,
    FixedLength,
    LinkPlan,
    MaxLength,
    Offset,
    Pad,
    PlanDirection,
    ReceiveTime,
    Scale,
    SetConstant,
    StaticFrameId,
    Table,
    TimestampFromRos,
    TimestampToRos,
    Utf8Length,
    lower_link,
    lower_mapping,
    passes_nan,
)
from sam_codegen.model.expr import fields_of
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.pysource import py_literal, typed_literal
from sam_codegen.targets.python import statements as pys
from sam_codegen.targets.python.elements import element_to_ros, element_to_uavcan
from sam_codegen.targets.python.expressions import ExpressionWriter
from sam_codegen.targets.python.module import ConvertModule, FunctionDraft, TableConstant
from sam_codegen.targets.python.names import LocalNames, access, identifier, py_attr
from sam_codegen.targets.python.statements import (
    Assign,
    CutToMaxLength,
    CutUtf8,
    FixLength,
    PadArray,
    Policy,
    Statement,
    TableLookup,
    dsdl_literal,
)
from sam_codegen.validate.mapping_rules import ResolvedMapping, Step, format_path


@dataclass(frozen=True)
class RosReads:
    """How a to_uavcan function reads its ROS side: `value(path)` is the expression of a field, `time(path)` the
    (sec, nanosec) expressions of a builtin_interfaces/Time field. Values, not text to patch: the object and the
    wire converters differ here and nowhere in the statements built from these expressions."""

    value: Callable[[tuple], str]
    time: Callable[[tuple], tuple[str, str]]


class UavcanReader(Protocol):
    """How a to_ros function reads the received UAVCAN message."""

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        """Bind what the steps read (fn.decode, fn.binds); return the locals of arrays read by index."""
        ...

    def access(self, path: tuple) -> str:
        """The expression of the field at `path`."""
        ...

    def as_list(self, expr: str) -> str:
        """An array field's expression as a list of plain Python values."""
        ...


class RosReader(Protocol):
    """How a to_uavcan function reads the ROS message."""

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> RosReads: ...

    def array_read(self, expr: str, ros_type: RosType) -> str:
        """A ROS array field read as `expr`, as a list of plain Python values."""
        ...


class Signatures(Protocol):
    """The name, parameters, return type and docstring of a mapping's two functions (bodies empty)."""

    def to_ros(self, em: MappingEmitter) -> FunctionDraft: ...

    def to_uavcan(self, em: MappingEmitter) -> FunctionDraft: ...


class MappingEmitter:
    """One mapping's two functions, in the variant its module's Construction and the given strategies make."""

    def __init__(self, module: ConvertModule, rm: ResolvedMapping, uavcan: UavcanReader, ros: RosReader,
                 signatures: Signatures) -> None:
        self.module, self.rm = module, rm
        self.uavcan, self.ros, self.signatures = uavcan, ros, signatures
        module.start(rm)
        self.mapping = rm.mapping
        self.name = rm.mapping.name
        self.reject = rm.mapping.on_out_of_range == "reject"
        self.ros_class = module.ros_aliases[rm.ros_message.full_name]
        self.dsdl_ref = module.dsdl_ref(rm.dsdl_struct)
        self.plan = lower_mapping(rm)  # what both converters do; the methods below only say it in Python
        self._links = {(id(link.step), link.direction): link for link in (*self.plan.to_ros, *self.plan.to_uavcan)}

    def policy(self, path: str) -> Policy:
        return Policy(repr(f"{self.name}.{path}"), self.reject)

    def link(self, s: Step, direction: PlanDirection) -> LinkPlan:
        """The plan of one link (lowered here for a step that is not the mapping's own)."""
        found = self._links.get((id(s), direction))
        if found is not None and found.step == s:
            return found
        return lower_link(s, direction, self.name, self.reject, passes_nan(self.mapping))

    # -- UAVCAN -> ROS ---------------------------------------------------------------------------------------
    def to_ros(self) -> FunctionDraft:
        """Values first (every check and drop before anything is built), then the result tree, returned as the
        module's Construction says (a nested constructor call, or CDR bytes)."""
        rm = self.rm
        names = LocalNames(self.module.module_names)
        fn = self.signatures.to_ros(self)
        steps = [s for s in rm.steps if s.ros_path]  # (a ROS -> UAVCAN expression sets nothing in ROS)
        listed = self.uavcan.bind(self, fn, names, read_steps(steps, TO_ROS))

        def uav_read(path: tuple) -> str:
            if path[-1][1] is not None:
                array_path = (*path[:-1], (path[-1][0], None))
                if array_path in listed:
                    return f"{listed[array_path]}[{path[-1][1]}]"
            return self.uavcan.access(path)

        root = self.module.ros_ctor(rm.ros_message)
        for fs in self.plan.ros_fields:
            if isinstance(fs.op, StaticFrameId):
                # the wire codecs write the run's frame prefix before it (a name bound at start), the object
                # converters the spec's frame id (the bridge adds the prefix)
                frame_id = getattr(self.module.build, "frame_id", py_literal)
                self.module.insert(root, fs.path, frame_id(fs.op.value))
            elif isinstance(fs.op, ReceiveTime):
                self.module.insert(root, (*fs.path, ("sec", None)), "receive_ns // 1_000_000_000")
                self.module.insert(root, (*fs.path, ("nanosec", None)), "receive_ns % 1_000_000_000")
        # element mappings last: their elements take the message's stamp, which a time link computes
        for s in [*(s for s in steps if s.kind != "elements"), *(s for s in steps if s.kind == "elements")]:
            for path, value in self.step_to_ros(s, names, uav_read, fn.statements):
                self.module.insert(root, path, value)
        fn.result = self.module.format_return(root, names)
        return fn

    def step_to_ros(self, s: Step, names: LocalNames, uav_read, statements: list[Statement]
                    ) -> list[tuple[tuple, str]]:
        """Append the statements of one link (its planned operations); return the (ROS path, expression) pairs
        it sets."""
        link = self.link(s, TO_ROS)
        ops = link.ops
        key = repr(link.key)
        first = ops[0] if ops else None
        if isinstance(first, ElementMapping):
            return element_to_ros(self, s, names, uav_read, statements)
        if isinstance(first, SetConstant):
            return [(s.ros_path, typed_literal(first.value, s.ros_type.base))]
        if isinstance(first, Evaluate):
            return [(s.ros_path, self.evaluate(link, first, s.ros, uav_read, names, statements))]
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
            statements.append(TableLookup(var, table, read, key, default))
            return [(s.ros_path, var)]
        if isinstance(first, DecodeUtf8):  # utf8[<=N]; a DroneCAN uint8[<=N] (v0 has no utf8) as a list of bytes
            raw = f"{read}.tobytes()" if s.uavcan_type.kind == "utf8" else f"bytes({self.uavcan.as_list(read)})"
            return [(s.ros_path, f"{raw}.decode(errors='replace')")]
        ros_base = s.ros_type.base
        if s.kind == "number":
            expr = pys.to_ros_expr(read, ops, ros_base)
            if not link.has(*CHECK_OPS):
                return [(s.ros_path, expr)]
            var = names.new(s.ros)
            statements.append(Assign(var, expr))
            statements.extend(pys.check_statements(var, ops, key))
            return [(s.ros_path, var)]
        # array: the elements, their float32 range, then the padding
        elem = pys.to_ros_expr("x", ops, ros_base)
        base_list = self.uavcan.as_list(read)
        expr = base_list if elem == "x" else f"[{elem} for x in {base_list}]"
        pad = link.first(Pad)
        overflow = link.has(Clamp)
        if pad is None and not overflow:
            return [(s.ros_path, expr)]
        var = names.new(s.ros)
        statements.append(Assign(var, expr))
        if overflow:
            statements.append(pys.float32_helper(var, link))
        if isinstance(pad, Pad):
            statements.append(PadArray(var, pad.size, typed_literal(0, ros_base)))
        return [(s.ros_path, var)]

    def module_table(self, s: Step, direction: PlanDirection) -> str:
        """The module constant holding a link's table in `direction` (one per link and direction)."""
        const = f"_{self.name}_{identifier(s.ros)}".upper() + ("_TO_ROS" if direction == TO_ROS else "_TO_UAVCAN")
        if not any(t.name == const for t in self.module.tables):
            pairs = tuple((py_literal(k), py_literal(v))
                          for k, v in Table(s.table, s.table_default, direction != TO_ROS).lookup())
            what = (f"{self.name}: {s.uavcan} -> {s.ros}" if direction == TO_ROS
                    else f"{self.name}: {s.ros} -> {s.uavcan} (first key per value)")
            self.module.tables.append(TableConstant(const, pairs, what))
        return const

    # -- ROS -> UAVCAN ---------------------------------------------------------------------------------------
    def to_uavcan(self) -> FunctionDraft:
        rm = self.rm
        names = LocalNames(self.module.module_names)
        fn = self.signatures.to_uavcan(self)
        steps = [s for s in rm.steps if s.uavcan_path]
        reads = self.ros.bind(self, fn, names, read_steps(steps, TO_UAVCAN))
        root = self.module.dsdl_ctor(rm.dsdl_struct)
        for s in steps:
            value = self.step_to_uavcan(s, names, reads, fn.statements)
            self.module.insert(root, s.uavcan_path, value)
        for fs in self.plan.uavcan_fields:  # uavcan_values, then DroneCAN's select
            assert isinstance(fs.op, SetConstant) and isinstance(fs.type, DsdlType)
            self.module.insert(root, fs.path, dsdl_literal(fs.op.value, fs.type))
        fn.result = self.module.format_return(root, names)
        return fn

    def step_to_uavcan(self, s: Step, names: LocalNames, reads: RosReads, statements: list[Statement]) -> str:
        """Append the statements of one link (its planned operations); return the expression of the UAVCAN
        value."""
        assert s.uavcan_type is not None
        link = self.link(s, TO_UAVCAN)
        ops = link.ops
        key = repr(link.key)
        uav = s.uavcan_type
        first = ops[0] if ops else None
        if isinstance(first, Evaluate):
            return self.evaluate(link, first, s.uavcan, reads.value, names, statements)
        if isinstance(first, ElementMapping):
            return element_to_uavcan(self, s, names, reads, statements)
        if isinstance(first, TimestampFromRos):
            sec, nanosec = reads.time(s.ros_path)
            var = names.new("us")
            statements.extend(pys.timestamp_from_ros(first, var, f"{sec} * 1_000_000 + {nanosec} // 1000", key))
            return var
        read = reads.value(s.ros_path)
        if isinstance(first, Table):
            var = names.new(s.uavcan)
            table = self.module_table(s, TO_UAVCAN)
            statements.append(TableLookup(var, table, read, key, None))
            return var
        if isinstance(first, EncodeUtf8):
            var = names.new(s.uavcan)
            cut = ops[1]
            assert isinstance(cut, Utf8Length)
            statements.append(Assign(var, f"{read}.encode(errors='replace')"))
            statements.append(CutUtf8(var, cut.capacity, key, cut.reject))
            return var
        if s.kind == "number":
            return self.scalar_to_uavcan(link, names, read, statements)
        # array: the elements' arithmetic, the length, then the elements' range
        elem_uav = uav.element
        var = names.new(s.uavcan)
        elem = pys.to_uavcan_expr("x", ops)
        base_list = self.ros.array_read(read, s.ros_type)
        expr = base_list if elem == "x" else f"[{elem} for x in {base_list}]"
        statements.append(Assign(var, expr))
        for op in ops:
            if isinstance(op, FixedLength):
                statements.append(FixLength(var, op.size, dsdl_literal(0, elem_uav), key, op.reject))
            elif isinstance(op, MaxLength):  # a longer fixed ROS array: only non-zero elements count
                statements.append(CutToMaxLength(var, op.capacity, key, op.reject, op.padded))
        for helper in (pys.array_nan_helper(var, link, elem_uav), pys.array_check_helper(var, link, elem_uav)):
            if helper is not None:
                statements.append(helper)
        return var

    def evaluate(self, link: LinkPlan, op: Evaluate, target: str, read: Callable[[tuple], str], names: LocalNames,
                 statements: list[Statement]) -> str:
        """An expression link: its trunc()/round() statements, the value bound to a local, then its checks."""
        writer = ExpressionWriter(read, names, repr(link.key), link.reject)
        text = writer.write(op.tree)
        statements.extend(writer.statements)
        var = names.new(target)
        statements.append(Assign(var, f"float({text})" if op.as_float else text))
        statements.extend(pys.check_statements(var, link.ops[1:], repr(link.key)))
        return var

    def scalar_to_uavcan(self, link: LinkPlan, names: LocalNames, read: str, statements: list[Statement]) -> str:
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
                    statements.append(Assign(target, pys.to_uavcan_expr(var or expr, pending)))
                    var, pending = target, []
                statements.extend(pys.check_statements(var, [op], repr(link.key)))
        if var is None:
            return pys.to_uavcan_expr(expr, pending)
        if pending:
            statements.append(Assign(var, pys.to_uavcan_expr(var, pending)))
        return var


def read_steps(steps: list[Step], direction: PlanDirection) -> list[Step]:
    """The steps as the readers see them: an expression step becomes one plain `number` step per source field it
    reads (a UAVCAN field to ROS, a ROS field to UAVCAN), so that every reader binds what expressions read."""
    out: list[Step] = []
    for s in steps:
        if s.kind != "expr" or s.expr is None:
            out.append(s)
            continue
        for f in fields_of(s.expr):
            if direction == TO_ROS:
                out.append(Step("number", (), RosType("float64"), f.path, f.source, pos=s.pos))
            else:
                out.append(Step("number", f.path, f.source, pos=s.pos))
    return out


# ---- convert.py's strategies -------------------------------------------------------------------------------------


def bind_indexed_arrays(reader: UavcanReader, fn: FunctionDraft, names: LocalNames, steps: list[Step],
                        listed: dict[tuple, str] | None = None) -> dict[tuple, str]:
    """Locals for UAVCAN primitive arrays read by index (rate_gyro_latest[0..2]): one list each (beside those in
    `listed` already)."""
    listed = {} if listed is None else listed
    for s in steps:
        if s.kind in ("number", "table") and s.uavcan_path and s.uavcan_path[-1][1] is not None:
            array_path = (*s.uavcan_path[:-1], (s.uavcan_path[-1][0], None))
            if array_path not in listed:
                listed[array_path] = names.new(format_path(list(array_path)))
                fn.binds.append(Assign(listed[array_path], reader.as_list(reader.access(array_path))))
    return listed


class CyphalObjectReader:
    """A received pycyphal object: attributes (pycyphal's names), numpy arrays read with .tolist()."""

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> dict[tuple, str]:
        return bind_indexed_arrays(self, fn, names, steps)

    def access(self, path: tuple) -> str:
        return access("src", path, py_attr)

    def as_list(self, expr: str) -> str:
        return f"{expr}.tolist()"


class RosObjectReader:
    """A ROS message object: its fields, parents read more than once bound to a local."""

    def bind(self, em: MappingEmitter, fn: FunctionDraft, names: LocalNames, steps: list[Step]) -> RosReads:
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
                fn.binds.append(Assign(parent_local[parent], access("src", parent)))
        listed: dict[tuple, str] = {}
        for s in steps:
            if s.kind in ("number", "table") and s.ros_path[-1][1] is not None:
                array_path = (*s.ros_path[:-1], (s.ros_path[-1][0], None))
                if array_path not in listed:
                    listed[array_path] = names.new(format_path(list(array_path)))
                    fn.binds.append(Assign(listed[array_path],
                                        self.array_read(access("src", array_path), s.ros_type)))

        def ros_read(path: tuple) -> str:
            if path in parent_local:
                return parent_local[path]
            if path[-1][1] is not None:
                array_path = (*path[:-1], (path[-1][0], None))
                if array_path in listed:
                    return f"{listed[array_path]}[{path[-1][1]}]"
            parent = path[:-1]
            if parent in parent_local:
                return access(parent_local[parent], path[-1:])
            return access("src", path)

        def time_read(path: tuple) -> tuple[str, str]:
            stamp = ros_read(path)
            return f"{stamp}.sec", f"{stamp}.nanosec"

        return RosReads(ros_read, time_read)

    def array_read(self, expr: str, ros_type: RosType) -> str:
        """A ROS array field as a list of plain Python values."""
        base = ros_type.base
        if base == "byte":
            return f"[b[0] for b in {expr}]"
        if base == "bool":
            return f"list({expr})"
        return f"{expr}.tolist()"


class ObjectSignatures:
    """convert.py's and convert_v0.py's functions: `<mapping>_to_ros(src, receive_ns, stats)` and
    `<mapping>_to_uavcan(src, stats)`."""

    def to_ros(self, em: MappingEmitter) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(
            f"{em.name}_to_ros",
            [f"src: {em.dsdl_ref}", "receive_ns: int", "stats: ConversionStats"],
            f"{em.ros_class} | None",
            [f"Mapping {em.name!r}, UAVCAN -> ROS.", "", f"{rm.dsdl_struct.name} -> {rm.ros_message.full_name}"],
        )

    def to_uavcan(self, em: MappingEmitter) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(
            f"{em.name}_to_uavcan",
            [f"src: {em.ros_class}", "stats: ConversionStats"],
            f"{em.dsdl_ref} | None",
            [f"Mapping {em.name!r}, ROS -> UAVCAN.", "", f"{rm.ros_message.full_name} -> {rm.dsdl_struct.name}"],
        )
