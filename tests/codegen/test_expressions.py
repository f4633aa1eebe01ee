"""Mapping expressions (issue 17 classes 1-3): the parser, the type and range checks, the lowering into the conversion
plan, the Python the converters and codecs run (against a reference evaluation of the typed tree), and
tests/specs/relay.yaml built and run: a ROS bool driving a float16 relay command, a leak predicate, LightsCommand
colours from a product of two ROS fields truncated and shifted, Cyphal predicates and arithmetic.

The broken-spec rows (exact messages) are in tests/broken_cases.py (`expr_*`, `ros_*`); the codec == object
converter property tests over relay.yaml are tests/codegen/test_codec.py and test_codec_v0.py.
"""

from __future__ import annotations

import functools
import importlib
import math
import struct
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sam_codegen.conversion_plan import Clamp, Evaluate, RejectNaN, lower_mapping
from sam_codegen.frontend.expr_parser import MAX_DEPTH, ExprSyntaxError, parse_expr
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.expr import INT64, EBinary, ECall, EConst, EField, ENode, EUnary, spell
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.render.templating import environment
from sam_codegen.targets.docs.wording import field_rows
from sam_codegen.targets.python.expressions import ExpressionWriter
from sam_codegen.targets.python.module import FunctionDraft
from sam_codegen.targets.python.names import LocalNames
from sam_codegen.validate.expressions import ExprError, check_expr, check_target
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).resolve().parents[2]
RELAY = ROOT / "tests" / "specs" / "relay.yaml"

FIELDS: dict[str, DsdlType | RosType] = {
    "a": DsdlType("int", 8), "b": DsdlType("uint", 5), "x": DsdlType("float", 32), "y": DsdlType("float", 16),
    "f": DsdlType("bool", 1), "r": RosType("uint8"), "s": RosType("float32"),
}


def _resolve(path: str) -> DsdlType | RosType:
    if path not in FIELDS:
        raise ValueError(f"no field {path!r}")
    return FIELDS[path]


def typed(text: str) -> ENode:
    return check_expr(parse_expr(text), _resolve)


# ---- parser ------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "spelled"), [
    ("a + b * 2", "a + b * 2"),
    ("(a + b) * 2", "(a + b) * 2"),
    ("a * r >> 3", "a * r >> 3"),
    ("a - (b - 1)", "a - (b - 1)"),
    ("not f and a == 3 or x < 0.5", "not f and a == 3 or x < 0.5"),
    ("not (f and f)", "not (f and f)"),
    ("-a * 2", "-a * 2"),
    ("-(a * 2)", "-(a * 2)"),
    ("min(trunc(x / 2.5), 7) << 1", "min(trunc(x / 2.5), 7) << 1"),
    ("(f == true) == false", "(f == true) == false"),
])
def test_precedence_and_spelling(text: str, spelled: str) -> None:
    """The parser binds as the grammar says; spell() writes the tree back with only the parentheses it needs, and
    reading that text again gives the same tree."""
    tree = typed(text)
    assert spell(tree) == spelled
    assert typed(spell(tree)) == tree


@pytest.mark.parametrize(("text", "message", "col"), [
    ("a &&& b", "unexpected '&' (write `and`)", 2),
    ("a = 3", "unexpected '=' (write `==`)", 2),
    ("a < b < 3", "comparisons do not chain (write `a < b and b < c`)", 6),
    ("(a + b", "expected ')', found the end", 6),
    ("a b", "unexpected 'b' after a complete expression", 2),
    ("", "the expression is empty", 0),
    ("sqrt(a)", "unknown function 'sqrt' (expected one of abs, float32, int, max, min, round, trunc)", 0),
    ("min(a)", "min() takes 2 arguments, not 1", 0),
    ("a + ", "expected a field, a number or '(', found the end", 3),
    ("x % 2", "unexpected '%' (write trunc() or a shift)", 2),
    ("x * 1e999", "the number 1e999 is beyond a float64", 4),
])
def test_syntax_errors_say_where(text: str, message: str, col: int) -> None:
    with pytest.raises(ExprSyntaxError) as exc:
        parse_expr(text)
    assert (exc.value.message, exc.value.col) == (message, col)


def test_nesting_and_length_are_bounded() -> None:
    """No input exhausts the stack: too deep or too long is an error, not a RecursionError."""
    with pytest.raises(ExprSyntaxError, match=f"deeper than {MAX_DEPTH}"):
        parse_expr("(" * 200 + "a" + ")" * 200)
    with pytest.raises(ExprSyntaxError, match=f"deeper than {MAX_DEPTH}"):
        parse_expr("-" * 100 + "a")
    with pytest.raises(ExprSyntaxError, match="longer than"):
        parse_expr("a + " * 200 + "a")
    parse_expr("(" * MAX_DEPTH + "a" + ")" * MAX_DEPTH)


# ---- types and ranges -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "kind", "rng"), [
    ("a * b", "int", (-128 * 31, 127 * 31)),
    ("a * r >> 3", "int", ((-128 * 255) >> 3, (127 * 255) >> 3)),
    ("b << 2", "int", (0, 124)),
    ("a - b", "int", (-128 - 31, 127)),
    ("int(f)", "int", (0, 1)),
    ("trunc(x)", "int", INT64),
    ("min(a, b)", "int", (-128, 31)),
    ("abs(a)", "int", (0, 128)),
    ("a / 2", "float", None),
    ("a + x", "float", None),
    ("y == 100", "bool", None),
    ("f or x > 0.5 and not f", "bool", None),
])
def test_kinds_and_ranges(text: str, kind: str, rng: tuple[int, int] | None) -> None:
    tree = typed(text)
    assert (tree.kind, tree.range) == (kind, rng)


@pytest.mark.parametrize(("text", "message", "col"), [
    ("q + 1", "no field 'q'", 0),
    ("f + 1", "f is a bool, not a number (write int(f) for 0 or 1)", 0),
    ("a and f", "`and` takes a bool, a is an int (compare it: x != 0)", 0),
    ("not x", "not takes a bool, x is a float (compare it: x != 0)", 0),
    ("f == 1", "`==` compares a bool with a number (f == 1)", 2),
    ("f < f", "`<` orders numbers; bools compare with == and !=", 2),
    ("x >> 2", "`>>` shifts integers, x is a float (write trunc() or round() first)", 2),
    ("a << b", "the shift amount must be a constant 0..63, not b", 5),
    ("a << 64", "the shift amount must be a constant 0..63, not 64", 5),
    ("a / 0", "division by zero (a / 0)", 2),
    ("trunc(a)", "trunc() takes a float, a is an int already", 0),
    ("int(x)", "int() takes a bool (0 or 1); for a float write trunc() or round(), x is float", 0),
    ("1 + 2", "the expression reads no field (a constant is a `value`, or an entry of uavcan_values)", 0),
    ("trunc(x) << 63 << 63", "the integers of this expression reach beyond 128 bits", 15),
])
def test_type_errors_say_where(text: str, message: str, col: int) -> None:
    with pytest.raises(ExprError) as exc:
        typed(text)
    assert (exc.value.message, exc.value.col) == (message, col)


@pytest.mark.parametrize(("text", "target", "message"), [
    ("a > 3", DsdlType("float", 16), "v is float16, the expression gives a bool (write int(...) for 0 or 1)"),
    ("a * 0.5", DsdlType("int", 18), "v is int18, the expression gives a float (write trunc(...) or round(...))"),
    ("a", RosType("bool"), "v is a bool: the expression must give a bool (a comparison), it gives an int"),
    ("a", RosType("string"), "an expression sets a bool or numeric scalar, v is string"),
])
def test_target_mismatch(text: str, target: DsdlType | RosType, message: str) -> None:
    with pytest.raises(ExprError) as exc:
        check_target(typed(text), target, "v")
    assert exc.value.message == message


# ---- the Python the converters run, against a reference evaluation ----------------------------------------------


class _Rejected(Exception):
    pass


def _ieee_min_max(func: str, p: Any, q: Any) -> Any:
    """IEEE 754-2019 minimum / maximum: NaN if either is NaN; -0 below +0."""
    if math.isnan(p) or math.isnan(q):
        return math.nan
    if p == q == 0:
        negative = [v for v in (p, q) if math.copysign(1.0, v) < 0]
        positive = [v for v in (p, q) if math.copysign(1.0, v) > 0]
        return (negative or positive)[0] if func == "min" else (positive or negative)[0]
    return min(p, q) if func == "min" else max(p, q)


def reference(node: ENode, env: dict[str, Any], reject: bool, saturated: list[str]) -> Any:
    """The typed tree's semantics (model.expr's docstring), evaluated directly."""
    if isinstance(node, EConst):
        return node.value
    if isinstance(node, EField):
        return {"int": int, "float": float, "bool": bool}[node.kind](env[node.text])
    if isinstance(node, EUnary):
        v = reference(node.arg, env, reject, saturated)
        return (not v) if node.op == "not" else -v
    if isinstance(node, ECall):
        args = [reference(a, env, reject, saturated) for a in node.args]
        if node.func in ("trunc", "round"):
            v = args[0]
            if math.isnan(v):
                raise _Rejected
            if v >= 2.0**63 or v < -(2.0**63):
                if reject:
                    raise _Rejected
                saturated.append("k")
                return INT64[1] if v > 0 else INT64[0]
            return math.trunc(v) if node.func == "trunc" else round(v)
        if node.func in ("min", "max") and any(a.kind == "float" for a in node.args):
            return _ieee_min_max(node.func, *args)
        return {"min": min, "max": max, "abs": abs, "int": int}[node.func](*args)
    assert isinstance(node, EBinary)
    left = reference(node.left, env, reject, saturated)
    right = reference(node.right, env, reject, saturated)
    if node.op == "div":
        if right == 0:
            return math.nan if left == 0 or math.isnan(left) else math.copysign(math.inf, left)
        return left / right
    ops = {"add": lambda p, q: p + q, "sub": lambda p, q: p - q, "mul": lambda p, q: p * q,
           "shl": lambda p, q: p << q, "shr": lambda p, q: p >> q, "eq": lambda p, q: p == q,
           "ne": lambda p, q: p != q, "lt": lambda p, q: p < q, "le": lambda p, q: p <= q,
           "gt": lambda p, q: p > q, "ge": lambda p, q: p >= q, "and": lambda p, q: p and q,
           "or": lambda p, q: p or q}
    return ops[node.op](left, right)


class _Stats:
    def __init__(self) -> None:
        self.saturated: list[str] = []
        self.rejected: list[str] = []

    def saturate(self, key: str) -> None:
        self.saturated.append(key)

    def reject(self, key: str) -> None:
        self.rejected.append(key)

    def reject_nan(self, key: str) -> None:
        self.rejected.append(key)


def run_generated(node: ENode, env: dict[str, Any], reject: bool) -> tuple[Any, _Stats]:
    """The statements ExpressionWriter emits, rendered by statements.j2 into a function and run."""
    writer = ExpressionWriter(lambda path: f"env[{path[0][0]!r}]", LocalNames(set()), "'k'", reject)
    text = writer.write(node)
    draft = FunctionDraft("f", ["env", "stats"], "Any", ["The expression."], statements=writer.statements,
                          result=[f"return {text}"])
    body = environment().from_string('{% import "python/statements.j2" as s %}{{ s.function(f) }}').render(f=draft)
    assert max(len(line) for line in body.splitlines()) <= 110, body  # long expressions are split into locals
    namespace: dict[str, Any] = {}
    support = _support_helpers()
    exec(body, {"_support": type("S", (), {name: staticmethod(f) for name, f in support.items()})}, namespace)
    stats = _Stats()
    return namespace["f"](env, stats), stats


@functools.cache
def _support_helpers() -> dict[str, Any]:
    source = environment().get_template("python/conversion_support.py.j2").render(spec_name="t", vehicle="t")
    namespace: dict[str, Any] = {}
    exec(compile(source, "conversion_support.py", "exec"), namespace)
    return {name: namespace[name] for name in ("divide", "maximum", "minimum")}


EXPRESSIONS = ["a * r >> 3", "trunc(x * s) >> 2", "round(x / y) - a", "min(trunc(x), a) + max(b, 3)",
               "f or x > 0.5 and not f", "y == 100", "int(f) * 2 - b", "x / (a - 3)", "trunc(s / x)",
               "abs(a) << 4", "-x * 2.5 + s",
               "max(trunc(x * s / (y + 1.5)) >> 3, min(a * r * b, abs(a - b) << 2)) - round(s / 2) * int(f or "
               "y >= 0.25 and x != s)"]
FLOATS = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=32), st.sampled_from([0.0, -0.0, 100.0]))


@pytest.mark.parametrize("text", EXPRESSIONS)
@pytest.mark.parametrize("reject", [False, True])
@settings(max_examples=60, deadline=None, database=None)
@given(a=st.integers(-128, 127), b=st.integers(0, 31), r=st.integers(0, 255), x=FLOATS, y=FLOATS, s=FLOATS,
       f=st.booleans())
def test_generated_python_matches_the_reference(text: str, reject: bool, a: int, b: int, r: int, x: float, y: float,
                                                 s: float, f: bool) -> None:
    """Whatever the values (NaN, infinities, zero divisors), the generated statements give the reference's value,
    reject where it rejects and count a saturation where it saturates."""
    node = typed(text)
    env = {"a": a, "b": b, "r": r, "x": x, "y": y, "s": s, "f": f}
    saturated: list[str] = []
    try:
        expected: Any = reference(node, env, reject, saturated)
    except _Rejected:
        expected = None
    got, stats = run_generated(node, env, reject)
    if expected is None:
        assert got is None and stats.rejected == ["k"]
    else:
        assert stats.rejected == []
        assert got == expected or (isinstance(got, float) and math.isnan(got) and math.isnan(expected))
        assert type(got) is type(expected)
        assert len(stats.saturated) == len(saturated)


# ---- tests/specs/relay.yaml ----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def relay() -> Any:
    return validate(load_spec_file(RELAY))


def _plan(resolved: Any, name: str) -> Any:
    return lower_mapping(next(rm for rm in [*resolved.mappings, *resolved.dronecan_mappings]
                              if rm.mapping.name == name))


def test_relay_plan(relay: Any) -> None:
    """Class 1: int(data) of a bool, into a float16: evaluated as a float, nothing to check (0 and 1 fit).
    Class 3: the lights mapping rejects what does not fit, each colour a Clamp into uint5 / uint6 after the
    trunc() (min(..., 31) bounds blue above: only its low bound is checked). Class 2: the leak predicate is a bool,
    nothing after it."""
    (relay_link,) = _plan(relay, "relay_dvl").to_uavcan
    assert [type(op) for op in relay_link.ops] == [Evaluate] and relay_link.ops[0].as_float
    lights = {link.step.uavcan: link for link in _plan(relay, "lights").to_uavcan}
    red = lights["commands[light_id=1].color.red"]
    assert red.ops[1:] == (Clamp("integer", 0, 31, True),)
    blue = lights["commands[light_id=1].color.blue"]
    assert blue.ops[1:] == (Clamp("integer", 0, None, True),)  # min(..., 31) bounds it above
    (leak,) = _plan(relay, "leak").to_ros
    assert [type(op) for op in leak.ops] == [Evaluate]
    depth = _plan(relay, "hull_depth").to_ros[0]
    assert depth.ops[1:] == (Clamp("integer", -32768, 32767, False),)
    rail = {link.step.uavcan: link for link in _plan(relay, "rail").to_uavcan}
    assert not any(isinstance(op, RejectNaN) for op in rail["enabled"].ops)


def test_relay_docs_rows(relay: Any) -> None:
    """The interface reference words an expression in the spec's syntax, beside the fields it reads."""
    rows = {(row["ros"], row["uavcan"]): row["conversion"]
            for name in ("relay_dvl", "lights", "leak")
            for row in field_rows(next(rm for rm in relay.dronecan_mappings if rm.mapping.name == name))}
    assert rows[("data", "commands[actuator_id=7].command_value")] == "= int(data) → float16"
    assert rows[("a, r", "commands[light_id=1].color.red")] == \
        "= trunc(a * r * 255) >> 3 → uint5 (NaN rejected, trunc beyond int64 rejected, out of range rejected)"
    assert rows[("data", "position")] == "= position == 100 → bool"


def _package(tmp_path: Path, resolved: Any) -> Any:
    from sam_codegen.targets.python import convert as emit_python
    from sam_codegen.targets.wire import codec as emit_codec
    from sam_codegen.targets.wire import codec_v0 as emit_codec_v0

    files = {**emit_python.emit(resolved), **emit_codec.emit(resolved), **emit_codec_v0.emit(resolved)}
    for path, text in files.items():
        if path.endswith(("conversion_support.py", "codec.py", "codec_v0.py")):
            target = tmp_path / path
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text, encoding="utf-8")
    (tmp_path / "python" / "relay_bridge" / "__init__.py").write_text("", encoding="utf-8")
    sys.path.insert(0, str(tmp_path / "python"))
    try:
        return (importlib.import_module("relay_bridge.codec"), importlib.import_module("relay_bridge.codec_v0"),
                importlib.import_module("relay_bridge.conversion_support"))
    finally:
        sys.path.remove(str(tmp_path / "python"))
        for name in [n for n in sys.modules if n.startswith("relay_bridge")]:
            del sys.modules[name]


CDR = b"\x00\x01\x00\x00"  # little-endian plain CDR


def _dronecan(type_name: str, payload: bytes) -> Any:
    import dronecan

    t = dronecan.TYPENAMES[type_name]
    obj = t()
    obj._unpack(dronecan.transport.bits_from_bytes(payload), True)
    return obj


def _payload(obj: Any) -> bytes:
    import dronecan

    return dronecan.transport.Transfer(payload=obj).payload  # type: ignore[no-any-return]


def test_relay_codecs_run(relay: Any, tmp_path: Path) -> None:
    """The generated wire codecs of relay.yaml on real values, dronecan as the oracle of the payloads."""
    pytest.importorskip("dronecan")
    import dronecan

    codec, codec_v0, support = _package(tmp_path, relay)
    stats = support.ConversionStats()
    # class 1: a ROS bool -> the float16 relay command, 0 or 1, in the item with actuator_id 7
    for value in (True, False):
        payload = codec_v0.relay_dvl_ros_to_wire(CDR + bytes([value]), stats)
        msg = _dronecan("uavcan.equipment.actuator.ArrayCommand", payload)
        (item,) = msg.commands
        assert (item.actuator_id, item.command_type, item.command_value) == (7, 0, float(value))
    # class 2: the leak flag is `position == 100`
    for position, leak in ((100.0, True), (99.9, False), (float("nan"), False)):
        status = dronecan.uavcan.equipment.actuator.Status(actuator_id=9, position=position)
        cdr, _stamp = codec_v0.leak_wire_to_ros(_payload(status), 0, stats)
        assert cdr[:5] == CDR + bytes([leak])
    # class 3: red = trunc(a * r * 255) >> 3 (truncated, not rounded); the mapping rejects what does not fit
    rgba = struct.pack("<4f", 0.5, 0.25, 1.0, 0.9)  # r, g, b, a
    msg = _dronecan("uavcan.equipment.indication.LightsCommand", codec_v0.lights_ros_to_wire(CDR + rgba, stats))
    (light,) = msg.commands
    r, g, b, a = struct.unpack("<4f", rgba)
    assert light.light_id == 1
    assert (light.color.red, light.color.green, light.color.blue) == (
        math.trunc(a * r * 255) >> 3, math.trunc(a * g * 255) >> 2, min(math.trunc(a * b * 31), 31))
    assert codec_v0.lights_ros_to_wire(CDR + struct.pack("<4f", 2.0, 0, 0, 1.0), stats) is None
    # (alpha * r) >> 3 in integers as the firmware's bridge writes it; what passes uint5 saturates, never wraps
    msg = _dronecan("uavcan.equipment.indication.LightsCommand",
                    codec_v0.led_ros_to_wire(CDR + bytes([30, 200, 255, 8]), stats))  # r, g, b, alpha
    (light,) = msg.commands
    assert (light.light_id, light.color.red, light.color.green, light.color.blue) == (0, 30, 1, 0)
    msg = _dronecan("uavcan.equipment.indication.LightsCommand",
                    codec_v0.led_ros_to_wire(CDR + bytes([200, 255, 255, 255]), stats))
    assert (msg.commands[0].color.red, msg.commands[0].color.green, msg.commands[0].color.blue) == (31, 63, 31)
    assert stats.saturated["led.commands[light_id=0].color.red"] == 1
    assert stats.rejected == {"lights.commands[light_id=1].color.red": 1}
    # Cyphal: hull_leak = flooded or probes[1] or water_mm > 40 and pressure_pa >= 1.5e5;
    # hull_depth saturates into int16
    def hull(water: int, pressure: float, flooded: bool, probe: bool = False) -> bytes:
        bits = (water & 0xFFF) | struct.unpack("<I", struct.pack("<f", pressure))[0] << 12 | int(flooded) << 44
        return (bits | int(probe) << 46).to_bytes(6, "little")  # probes[0..2] at bits 45..47

    assert codec.hull_leak_wire_to_ros(hull(41, 2e5, False), 0, stats)[0][:5] == CDR + b"\x01"
    assert codec.hull_leak_wire_to_ros(hull(41, 1e5, False), 0, stats)[0][:5] == CDR + b"\x00"
    assert codec.hull_leak_wire_to_ros(hull(-5, 0.0, True), 0, stats)[0][:5] == CDR + b"\x01"
    assert codec.hull_leak_wire_to_ros(hull(0, 0.0, False, probe=True), 0, stats)[0][:5] == CDR + b"\x01"
    assert codec.hull_leak_wire_to_ros(hull(0, 0.0, False), 0, stats)[0][:5] == CDR + b"\x00"
    assert codec.hull_depth_wire_to_ros(hull(10, 981.0, False), 0, stats)[0][:6] == CDR + struct.pack("<h", 100 - 20)
    assert codec.hull_depth_wire_to_ros(hull(0, 1e9, False), 0, stats)[0][:6] == CDR + struct.pack("<h", 32767)
    assert stats.saturated["hull_depth.data"] == 1
    # rail: one ROS float32 into three fields; 300 V * 1000 >> 1 saturates into int18, never wraps
    bits = int.from_bytes(codec.rail_ros_to_wire(CDR + struct.pack("<f", 300.0), stats), "little")
    assert (bits & 1, bits >> 1 & 0x7F, bits >> 8 & 0x3FFFF) == (1, 127, 2**17 - 1)
    assert codec.rail_ros_to_wire(CDR + struct.pack("<f", float("nan")), stats) is None


@pytest.mark.parametrize(("value", "expected", "saturations"), [
    (200000.0, 131071, 1), (-1e30, -131072, 2), (1500.7, 1500, 0), (float("inf"), 131071, 2)])
def test_out_of_range_commands_saturate_never_wrap(value: float, expected: int, saturations: int) -> None:
    """200000 rpm into an int18 is 131071 (a wrapping bridge sends -62144 and reverses the thruster); the trunc()
    of what int64 cannot hold (an infinity too) saturates into int64 first, then into int18. Each is counted."""
    from sam_codegen.conversion_plan import lower_expr
    from sam_codegen.targets.python.statements import Assign, check_statements

    node = typed("trunc(x * 2) >> 1")
    ops = lower_expr(node, DsdlType("int", 18), reject=False)
    assert ops[1:] == [Clamp("integer", -131072, 131071, False)]
    writer = ExpressionWriter(lambda path: f"env[{path[0][0]!r}]", LocalNames(set()), "'k'", False)
    text = writer.write(node)
    statements = [*writer.statements, Assign("v", text), *check_statements("v", ops, "'k'")]
    draft = FunctionDraft("f", ["env", "stats"], "Any", ["The command."], statements=statements,
                          result=["return v"])
    body = environment().from_string('{% import "python/statements.j2" as s %}{{ s.function(f) }}').render(f=draft)
    namespace: dict[str, Any] = {}
    exec(body, {}, namespace)
    stats = _Stats()
    assert namespace["f"]({"x": value}, stats) == expected
    assert len(stats.saturated) == saturations


ALPHABET = st.sampled_from([*"ab xyfrs()+-*/<>=!.,[]0123456789_e", "and", "or", "not", "trunc(", "min(", "int(",
                            "true", "<<", ">>", "=="])


@settings(max_examples=400, deadline=None, database=None)
@given(st.lists(ALPHABET, max_size=40).map("".join))
def test_any_text_parses_or_is_a_syntax_error(text: str) -> None:
    """No spec text makes the parser or the checker raise anything but their own errors (never a traceback)."""
    try:
        tree = parse_expr(text)
    except ExprSyntaxError as exc:
        assert 0 <= exc.col <= max(len(text), 0) and exc.message
        return
    try:
        node = check_expr(tree, _resolve)
    except ExprError as exc:
        assert 0 <= exc.col <= len(text) and exc.message
        return
    assert typed(spell(node)) == node  # what it says is what it reads
