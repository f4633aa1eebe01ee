"""Options of a mapping or line that would change nothing where they are written (issue 29): an exact error each,
never a silent no-op, since whoever wrote one believes it guards something.

- `pass_nan: true` on a command mapping none of whose values can carry a NaN into a UAVCAN float without `limits`
  (an integer or bool field cannot hold NaN; a limited field rejects NaN either way);
- a table's `default` in a ROS -> UAVCAN mapping (the reverse lookup rejects a ROS value no key gives; the default
  names the ROS value of unlisted UAVCAN values, which only a UAVCAN -> ROS mapping receives);
- `limits` on an integer field whose whole range lies within them (they bound nothing);
- `on_out_of_range: reject` on a mapping none of whose values, in its direction, can be out of its target's range
  (uint8 into uint8, float32 into float32...): the policy decides nothing there. Judged conservatively (a line whose
  range is not known here, a timestamp, an expression, elements, a string, counts as one that may decide).

Checked on the resolved mappings (both protocols), and only on a mapping whose lines all resolved: a line that
failed is reported already, and without it whether an option acts is unknown."""

from __future__ import annotations

from collections.abc import Iterable, Iterator

from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import ROS_TO_UAVCAN, FieldLink, Mapping
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES
from sam_codegen.validate.mapping_rules import ResolvedMapping, Step


def _nan_reaches_float(step: Step) -> bool:
    """Whether a ROS -> UAVCAN step can carry a float NaN into a UAVCAN float without limits (what `pass_nan`
    lets through; conversion_plan.lowering decides it the same way)."""
    uav = step.uavcan_type
    if uav is None or not step.uavcan_path:
        return False
    if step.kind == "elements":
        return step.elements is not None and any(_nan_reaches_float(s) for s in step.elements.steps)
    if step.kind == "expr":
        return step.expr is not None and step.expr.kind == "float" and uav.kind == "float"
    if step.kind in ("number", "array"):
        target = uav.element if step.kind == "array" else uav
        return step.ros_type.base in ROS_FLOAT_BITS and target.kind == "float" and step.limits is None
    return False  # time, table, string, value: no float NaN on the way


def _may_decide(step: Step, to_uavcan: bool) -> bool:
    """Whether `on_out_of_range` can decide anything for this step in this direction: a value that may lie beyond
    its target's range (conversion_plan.lowering plans a clamp there). True whenever unsure."""
    uav = step.uavcan_type
    if step.kind in ("value", "table"):  # a table's miss is rejected whatever the policy
        return False
    if step.kind not in ("number", "array") or uav is None or step.wrap:
        return True
    elem = uav.element if step.kind == "array" else uav
    ros = step.ros_type.base
    if to_uavcan and step.kind == "array":  # a length the UAVCAN array may not take
        cap = uav.capacity or 0
        if step.ros_type.array != "fixed" or (step.ros_type.capacity or 0) > cap or (
                uav.array == "fixed" and step.ros_type.capacity != cap):
            return True
    if ros == "bool" or elem.kind == "bool":
        return not (ros == "bool" and elem.kind == "bool")
    if step.scale is not None or step.offset is not None or step.limits is not None:
        return True
    ros_int = ros in ROS_INT_RANGES
    if not ros_int and ros not in ROS_FLOAT_BITS:
        return True
    if not to_uavcan:  # into ROS only a UAVCAN float into a ROS integer (`round`) has a range to meet
        return elem.kind == "float" and ros_int
    if ros_int and elem.kind in ("int", "uint", "byte"):
        lo, hi = ROS_INT_RANGES[ros]
        return not (elem.range[0] <= lo and hi <= elem.range[1])
    if elem.kind == "float":  # a ROS integer into float16 may pass 65504; a float into a narrower float
        if ros_int:
            return elem.bits == 16 and max(abs(v) for v in ROS_INT_RANGES[ros]) > 65504
        return elem.bits < ROS_FLOAT_BITS[ros]
    return True


def _links(mapping: Mapping) -> Iterator[tuple[FieldLink, str]]:
    """Every line of the mapping with the name errors give it, element lines included."""
    for link in mapping.links:
        yield link, repr(link.ros_path)
        for inner in link.element_links or ():
            yield inner, f"{inner.ros_path!r} of the elements of {link.ros_path!r}"


def _limits_bind_nothing(steps: Iterable[Step]) -> Iterator[Step]:
    for step in steps:
        if step.kind == "elements" and step.elements is not None:
            yield from _limits_bind_nothing(step.elements.steps)
        elif step.limits is not None and not step.ros_type.array and step.ros_type.base in ROS_INT_RANGES:
            lo, hi = ROS_INT_RANGES[step.ros_type.base]
            if step.limits[0] <= lo and hi <= step.limits[1]:
                yield step


def check_mapping_options(resolved: Iterable[ResolvedMapping], diag: Diagnostics, reported: set[Pos]) -> None:
    """Report every option of the `resolved` mappings that would act on nothing. `reported`: the positions that
    have an error already (a mapping with one of its lines among them is skipped)."""
    for rm in resolved:
        m = rm.mapping
        lines = list(_links(m))
        if any(link.pos in reported for link, _ in lines):
            continue
        what = f"mapping {m.name!r}"
        if m.direction == ROS_TO_UAVCAN and m.pass_nan and not any(_nan_reaches_float(s) for s in rm.steps):
            diag.error(m.pass_nan_pos or m.pos, f"{what}: pass_nan: true acts on nothing: none of its values can "
                       "carry a NaN into a UAVCAN float without limits (an integer or bool holds no NaN; a limited "
                       "field rejects NaN either way)", "no pass_nan here, or a float field without limits")
        for link, name in lines:
            if m.direction == ROS_TO_UAVCAN and link.table_default is not None:
                diag.error(link.pos, f"{what}, field {name}: a table's default names the ROS value of the UAVCAN "
                           "values it does not list, which only a UAVCAN -> ROS mapping receives; a ROS -> UAVCAN "
                           "mapping rejects a ROS value no key gives", "no default in this table")
        to_uavcan = m.direction == ROS_TO_UAVCAN
        own = [s for s in rm.steps if (s.uavcan_path if to_uavcan else s.ros_path)]  # what its direction converts
        if m.on_out_of_range == "reject" and own and not any(_may_decide(s, to_uavcan) for s in own):
            diag.error(m.pos, f"{what}: on_out_of_range: reject acts on nothing: none of its values can be out of "
                       "its target's range (each fits the field it goes into)", "no on_out_of_range here")
        for step in _limits_bind_nothing(rm.steps):
            lo, hi = ROS_INT_RANGES[step.ros_type.base]
            assert step.limits is not None
            diag.error(step.pos, f"{what}, field {step.ros!r}: limits [{step.limits[0]:g}, {step.limits[1]:g}] bound "
                       f"nothing: every {step.ros_type.base} value ({lo}..{hi}) lies within them",
                       f"limits narrower than {lo}..{hi}, or none")
