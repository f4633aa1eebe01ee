"""Element mappings said in Python: an array of composites converted element by element (conversion_plan's
ElementMapping), in the object converters.

Each element mapping becomes a pair of module functions of its own, made by a MappingEmitter on the element types
(`_<mapping>_<ros array>_item_to_ros(src, receive_ns, stats)` / `..._item_to_uavcan(src, stats)`), so an element's
fields get every check, saturation, table and stats key a mapping's fields get (keys `<mapping>.<ros array>[].<field>`).
The mapping's own function calls it once per element:

- to ROS: the elements in order; the first element that rejects drops the message (counted once, by it); an
  element's header gets the message's stamp (the source timestamp, or the receive time: `receive_ns` of the element
  function is the message's stamp) and the mapping's frame_id;
- to UAVCAN: a bounded array is cut to its capacity first (saturate: counted under `<mapping>.<uavcan array>`) or
  the message rejected, then the elements are converted; a fixed array is cut the same way, or padded with default
  elements after the conversion (counted once either way).

The DroneCAN wire codec emits the same functions on records instead of objects: its Construction's
`element_scope(em, step, base)` gives the element emitter its readers and signatures (targets.wire.element_records).

The functions are collected in ConvertModule.extra_functions, which the module emitters append after the mappings'
own functions (the registry indexes those by position).
"""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import dataclass
from typing import Any, ClassVar

from sam_codegen.conversion_plan import TO_ROS, TO_UAVCAN, ElementMapping, FixedLength, MaxLength, TimestampToRos
from sam_codegen.targets.python.module import ConvertModule, FunctionDraft
from sam_codegen.targets.python.names import LocalNames, identifier
from sam_codegen.targets.python.statements import Assign, CutToMaxLength, FixLength, Statement, TimeToRos
from sam_codegen.validate.mapping_rules import ResolvedMapping, Step

__all__ = ["element_function_names", "element_to_ros", "element_to_uavcan", "has_elements"]


def has_elements(rm: ResolvedMapping) -> bool:
    return any(s.kind == "elements" for s in rm.steps)


def _base(mapping: str, s: Step) -> str:
    return f"_{mapping}_{identifier(s.ros)}_item"


def element_function_names(mappings: list[ResolvedMapping]) -> set[str]:
    """The module names the element functions of `mappings` take (so no local shadows them)."""
    return {f"{_base(rm.mapping.name, s)}_{d}" for rm in mappings for s in rm.steps if s.kind == "elements"
            for d in ("to_ros", "to_uavcan")}


class _ElementSignatures:
    def __init__(self, base: str, ros_class: str) -> None:
        self.base, self.ros_class = base, ros_class

    def to_ros(self, em: Any) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(f"{self.base}_to_ros", ["src: Any", "receive_ns: int", "stats: ConversionStats"],
                             f"{self.ros_class} | None",
                             [f"One element of {rm.mapping.name}, UAVCAN -> ROS (receive_ns: the message's stamp).",
                              "", f"{rm.dsdl_struct.name} -> {rm.ros_message.full_name}"])

    def to_uavcan(self, em: Any) -> FunctionDraft:
        rm = em.rm
        return FunctionDraft(f"{self.base}_to_uavcan", [f"src: {self.ros_class}", "stats: ConversionStats"],
                             "Any | None",
                             [f"One element of {rm.mapping.name}, ROS -> UAVCAN.", "",
                              f"{rm.ros_message.full_name} -> {rm.dsdl_struct.name}"])


def _functions(em: Any, s: Step) -> str:
    """Emit the element functions of step `s` of the mapping `em` emits (once); return their base name."""
    module: ConvertModule = em.module
    base = _base(em.name, s)
    if any(to_ros.name == f"{base}_to_ros" for to_ros, _ in module.extra_functions):
        return base
    assert s.elements is not None
    saved = dict(module.lengths)
    # the wire codecs give their own readers and signatures (elements as records: targets.wire.element_records)
    hook = getattr(module.build, "element_scope", None)
    scope = hook(em, s, base) if hook is not None else nullcontext((
        type(em.uavcan)(), type(em.ros)(),
        _ElementSignatures(base, module.ros_aliases[s.elements.ros_message.full_name])))
    with scope as (uavcan, ros, signatures):
        sub = type(em)(module, s.elements, uavcan, ros, signatures)
        sub.name = identifier(f"{em.name}_{s.ros}")  # module table names; the stats keys are the plan's
        module.extra_functions.append((sub.to_ros(), sub.to_uavcan()))
    module.lengths = saved
    return base


def _stamp_ns(em: Any, statements: list[Statement]) -> str:
    """The message's stamp in nanoseconds: its source timestamp (rendered already: element links come last) or the
    receive time."""
    for link in em.plan.to_ros:
        if link.step.kind == "time" and link.step.ros == "header.stamp" and isinstance(link.ops[0], TimestampToRos):
            key = repr(link.key)
            for st in statements:
                if isinstance(st, TimeToRos) and st.key == key:
                    return f"{st.sec} * 1_000_000_000 + {st.nanosec}"
    return "receive_ns"


def element_to_ros(em: Any, s: Step, names: LocalNames, uav_read: Any, statements: list[Statement]
                   ) -> list[tuple[tuple, str]]:
    link = em.link(s, TO_ROS)
    assert isinstance(link.ops[0], ElementMapping)
    base = _functions(em, s)
    var = names.new(s.ros)
    stamp = _stamp_ns(em, statements)
    source = f"list({uav_read(s.uavcan_path)})"  # dronecan's ArrayValue, pycyphal's list of objects
    statements.append(_ElementLoop(var, names.new("element"), names.new("item"), source,
                                   f"{base}_to_ros({{}}, {stamp}, stats)"))
    return [(s.ros_path, var)]


def element_to_uavcan(em: Any, s: Step, names: LocalNames, reads: Any, statements: list[Statement]) -> str:
    link = em.link(s, TO_UAVCAN)
    key = repr(link.key)
    assert isinstance(link.ops[0], ElementMapping)
    base = _functions(em, s)
    items = names.new(f"{s.uavcan}_items")
    var = names.new(s.uavcan)
    statements.append(Assign(items, f"list({reads.value(s.ros_path)})"))
    for op in link.ops[1:]:
        # cut before converting: the elements cut are not converted (nor counted); a fixed array is padded after
        # (its default elements are UAVCAN ones), so either way the length is counted once
        if isinstance(op, (MaxLength, FixedLength)):
            statements.append(CutToMaxLength(items, op.capacity if isinstance(op, MaxLength) else op.size, key,
                                             op.reject, False))
    statements.append(_ElementLoop(var, names.new("element"), names.new("item"), items,
                                   f"{base}_to_uavcan({{}}, stats)"))
    for op in link.ops[1:]:
        if isinstance(op, FixedLength):
            assert s.uavcan_type is not None
            default = em.module.build.element_default(s.uavcan_type.element)
            statements.append(FixLength(var, op.size, default, key, op.reject))
    return var


@dataclass(frozen=True)
class _ElementLoop(Statement):
    """`var` = the elements of `source` converted one by one by `call` (its `{}` the element); the first element
    rejected (counted by the element function, once) drops the message, as a mapping's first rejected field does."""

    kind: ClassVar[str] = "element_loop"
    var: str
    element: str
    item: str
    source: str
    call: str

    @property
    def call_element(self) -> str:
        return self.call.format(self.element)
