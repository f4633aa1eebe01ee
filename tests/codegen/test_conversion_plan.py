"""The conversion plan is the one place a link's conversion is decided: the converters' statements and the
interface reference's wording both follow from its operations (codegen/conversion_plan/)."""

from __future__ import annotations

from pathlib import Path

import pytest

from sam_codegen.conversion_plan import (
    TO_ROS,
    TO_UAVCAN,
    Clamp,
    Convert,
    FixedLength,
    Limits,
    LinkPlan,
    MaxLength,
    Pad,
    RejectNaN,
    Round,
    lower_link,
    lower_mapping,
)
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.targets.docs.wording import describe_link
from sam_codegen.targets.python.convert import convert_module, object_emitter
from sam_codegen.targets.python.mapping import RosReads
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.targets.python.statements import Assign, Statement
from sam_codegen.validate.mapping_rules import Step
from sam_codegen.validate.resolve import Resolved, validate

ROOT = Path(__file__).parents[2]
SPECS = [ROOT / "spec" / "interfaces.yaml", *sorted((ROOT / "tests" / "specs").glob("*.yaml"))]
X = (("x", None),)


def _resolved(path: Path) -> Resolved:
    try:
        return validate(load_spec_file(path))
    except Exception as exc:  # a spec another test keeps broken on purpose, or one being written
        pytest.skip(f"{path.name} does not validate: {exc}")


def _own_links(resolved: Resolved) -> list[LinkPlan]:
    links: list[LinkPlan] = []
    for rm in [*resolved.mappings, *resolved.dronecan_mappings]:
        plan = lower_mapping(rm)
        links.extend(plan.to_ros if rm.mapping.direction == "uavcan_to_ros" else plan.to_uavcan)
    return links


@pytest.mark.parametrize("path", SPECS, ids=lambda p: p.name)
def test_docs_word_the_planned_operations(path: Path) -> None:
    """Every out-of-range note of the reference stands for a planned check, and every planned check has one."""
    for link in _own_links(_resolved(path)):
        text = describe_link(link)
        policy = "out of range rejected" if link.reject else "saturating"
        assert (policy in text) == link.has(Limits, Clamp), (link.key, text, link.ops)
        assert ("padded to" in text) == link.has(Pad), (link.key, text)
        assert ("other lengths" in text) == link.has(FixedLength), (link.key, text)
        assert (" elements " in text) == link.has(MaxLength), (link.key, text)


@pytest.mark.parametrize("path", SPECS[:1] + [p for p in SPECS if p.name in ("barge.yaml", "rover.yaml")],
                         ids=lambda p: p.name)
def test_converters_render_the_planned_operations(path: Path) -> None:
    """A ROS -> UAVCAN number link gets a check statement exactly when its plan has a check operation."""
    resolved = _resolved(path)
    module = convert_module(resolved)
    for rm in resolved.mappings:
        emitter = object_emitter(module, rm)
        for link in emitter.plan.to_uavcan:
            if link.step.kind != "number":
                continue
            statements: list[Statement] = []
            reads = RosReads(lambda p: "v", lambda p: ("v.sec", "v.nanosec"))
            emitter.step_to_uavcan(link.step, LocalNames(set()), reads, statements)
            checks = [s for s in statements if not isinstance(s, Assign) or "round(" in s.expr]
            assert len(checks) == sum(isinstance(op, (RejectNaN, Limits, Clamp, Round)) for op in link.ops), link


def test_lowering_is_deterministic() -> None:
    resolved = _resolved(SPECS[0])
    assert [lower_mapping(rm) for rm in resolved.mappings] == [lower_mapping(rm) for rm in resolved.mappings]


def test_same_signedness_narrowing_and_sign_change() -> None:
    """uint8 -> int8 saturates above 127 (and the reference says so); int16 -> uint8 checks both sides."""
    link = lower_link(Step("number", X, RosType("uint8"), X, DsdlType("int", 8)), TO_UAVCAN, "m", False)
    assert link.ops == (Convert("uint8", "int8"), Clamp("integer", None, 127, False))
    assert describe_link(link) == "uint8 → int8 (saturating)"
    link = lower_link(Step("number", X, RosType("int16"), X, DsdlType("uint", 8)), TO_UAVCAN, "m", True)
    assert link.ops == (Convert("int16", "uint8"), Clamp("integer", 0, 255, True))
    assert describe_link(link) == "int16 → uint8 (narrowed, out of range rejected)"


def test_equal_bounds_need_no_cut() -> None:
    """A ROS int8[<=3] cannot hold more than a DSDL int3[<=3]: no length check, and the reference claims none."""
    step = Step("array", X, RosType("int8", "bounded", 3), X, DsdlType("int", 3, array="bounded", capacity=3))
    link = lower_link(step, TO_UAVCAN, "m", False)
    assert not link.has(MaxLength)
    assert describe_link(link) == "int8[<=3] → int3[<=3] (narrowed, saturating)"
    longer = Step("array", X, RosType("int8", "dynamic"), X, DsdlType("int", 3, array="bounded", capacity=3))
    assert MaxLength(3, False, False) in lower_link(longer, TO_UAVCAN, "m", False).ops


def test_round_into_an_integer() -> None:
    """A float into a ROS integer (`round: true`): NaN rejects, what rounds beyond the integer saturates."""
    step = Step("number", X, RosType("int8"), X, DsdlType("float", 32), offset=-273.15, exact=False)
    link = lower_link(step, TO_ROS, "m", False)
    assert link.ops[-2:] == (RejectNaN(), Clamp("round", -128, 127, False))
    assert link.key == "m.x"
