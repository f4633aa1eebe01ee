"""The generated DroneCAN wire codecs (codec_v0.py) against the object path they replace, with dronecan itself as
the oracle of the payload and rclpy of the CDR.

In this process (no ROS needed):

- the payload reader and writer (sam_codegen.targets.wire.v0_read / v0_write) against dronecan's own decoding and
  encoding for standard types, unions, void padding, tail arrays and nested arrays of composites included: random valid
  messages, and random, truncated and extended payloads (WireError exactly where dronecan raises);
- the float16 writer against dronecan's f16_from_f32 (it rounds differently from struct's ``e``);
- the generated module: lint-clean, deterministic, standard library only at import; SAM's byte for byte (golden).

In a child process with SAM's ROS package (as tests/test_v0_converters.py does it; the spec's own v0 types added by
sam_runtime.dronecan_io.types.ensure_types, never dronecan.load_dsdl), hypothesis property tests for every DroneCAN
mapping of SAM's spec and of the tests/specs of SPECS (ferry, minimal_v0, buoy_v0, trawler_v0, seiner, relay, power_v0,
power_prefix_v0, lolo_v0, hopper_v0: element records of bit fields):

(a) random dronecan messages -> dronecan's bytes (``Transfer(payload=obj).payload``) -> ``<m>_wire_to_ros`` gives
    the CDR of ``<m>_to_ros`` (NaN-aware), its stamp, the same counts, and ``WIRE_MATCHES`` agrees with ``MATCHES``;
(b) random ROS messages (any values: NaN, infinities, every integer) -> CDR -> ``<m>_ros_to_wire`` gives the bytes
    dronecan packs from ``<m>_to_uavcan``, or None when it gives None, with the same counts;
(c) malformed payloads (truncated, extended, bits flipped, random) raise WireError exactly where the object path
    refuses them (dronecan's decoding raises; or the decoded array does not fit the ROS field: rclpy refuses to
    serialize it), and truncated or random CDR raises WireError: never another exception.
"""

from __future__ import annotations

import json
import math
import os
import random
import shutil
import struct
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[2]
SPECS = {"sam": ROOT / "spec" / "interfaces.yaml", "ferry": ROOT / "tests" / "specs" / "ferry.yaml",
         "minimal_v0": ROOT / "tests" / "specs" / "minimal_v0.yaml", "buoy": ROOT / "tests" / "specs" / "buoy_v0.yaml",
         "trawler_v0": ROOT / "tests" / "specs" / "trawler_v0.yaml",
         "seiner": ROOT / "tests" / "specs" / "seiner.yaml", "relay": ROOT / "tests" / "specs" / "relay.yaml",
         "power_v0": ROOT / "tests" / "specs" / "power_v0.yaml",
         "power_prefix_v0": ROOT / "tests" / "specs" / "power_prefix_v0.yaml",
         "lolo_v0": ROOT / "tests" / "specs" / "lolo_v0.yaml",
         "hopper_v0": ROOT / "tests" / "specs" / "hopper_v0.yaml",
         "retrofit": ROOT / "tests" / "specs" / "retrofit.yaml"}
GOLDEN = ROOT / "tests" / "golden" / "python_v0"
WORKER_ENV = "SAM_CODEC_V0_WORKER"
WORKER = os.environ.get(WORKER_ENV)
EXAMPLES = int(os.environ.get("SAM_CODEC_EXAMPLES", "80"))
SETTINGS = settings(max_examples=EXAMPLES, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


class WireError(ValueError):
    pass


def _exec_module(constants: list[str], body: str) -> dict[str, Any]:
    """Run generated code with what codec_v0.py defines around it."""
    from sam_codegen.targets.wire.cdr_write import MODULE_PRELUDE
    from sam_codegen.targets.wire.v0_write import HELPERS

    namespace: dict[str, Any] = {"WireError": WireError, "_struct": struct, "_INF": math.inf, "_NAN": math.nan}
    exec("\n".join([*MODULE_PRELUDE, *constants, HELPERS, body]), namespace)
    return namespace


def _function(name: str, params: str, lines: list[str], result: str) -> str:
    return "\n".join([f"def {name}({params}):", *[f"    {line}" for line in lines], f"    return {result}", ""])


# ============================================================================================ parent

if not WORKER:
    dronecan = pytest.importorskip("dronecan")
    from dronecan import dsdl, transport

    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.targets.wire.cdr_write import Constants
    from sam_codegen.targets.wire.v0_read import V0Layout, v0_reader
    from sam_codegen.targets.wire.v0_write import V0Items, V0Node, f16_bits, v0_writer
    from sam_codegen.validate.resolve import validate

    # Standard types: SAM's and ferry's and more; Indication holds a union (NumericValue, with an empty member).
    STANDARD = (
        "uavcan.equipment.ahrs.RawIMU", "uavcan.equipment.gnss.Fix2", "uavcan.equipment.actuator.ArrayCommand",
        "uavcan.equipment.power.BatteryInfo", "uavcan.equipment.esc.RPMCommand", "uavcan.equipment.esc.Status",
        "uavcan.protocol.enumeration.Indication", "uavcan.equipment.ahrs.MagneticFieldStrength",
        "uavcan.protocol.debug.LogMessage", "uavcan.equipment.gnss.Auxiliary", "uavcan.equipment.esc.RawCommand",
        "uavcan.equipment.range_sensor.Measurement", "uavcan.equipment.air_data.StaticPressure",
        "uavcan.protocol.NodeStatus", "uavcan.equipment.hardpoint.Status", "uavcan.equipment.camera_gimbal.Status",
    )

    @pytest.fixture(scope="module")
    def layout() -> V0Layout:
        return V0Layout(validate(load_spec_file(SPECS["sam"])).dronecan.get)  # type: ignore[union-attr]

    def plain(v: Any) -> Any:
        """A dronecan value as the reader gives it: records as tuples, unions as (tag, value), arrays as lists."""
        if isinstance(v, transport.CompoundValue):
            keys = [k for k in v._fields if not k.startswith("_void")]
            if v._is_union:
                every = list(v._fields)
                name = v._union_field or every[0]
                inner = v._fields[name]
                return (every.index(name), inner.value if isinstance(inner, transport.PrimitiveValue) else plain(inner))
            return tuple(plain(getattr(v, k)) for k in keys)
        if isinstance(v, transport.ArrayValue):
            return [plain(x) for x in v]
        return v

    def same(a: Any, b: Any) -> bool:
        if isinstance(a, float) and isinstance(b, float):
            return a == b or (math.isnan(a) and math.isnan(b))
        if isinstance(a, (list, tuple)):
            return type(a) is type(b) and len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
        return type(a) is type(b) and a == b

    def reader_of(layout: V0Layout, name: str) -> tuple[Any, list[str]]:
        struct_ = layout.struct(name)
        fields = [f.name for f in struct_.fields]
        consts = Constants()
        taken: set[str] = set()

        def new(hint: str) -> str:
            taken.add(f"{hint}_{len(taken)}")
            return f"{hint}_{len(taken) - 1}"

        lines, found = v0_reader(struct_, [(f,) for f in fields], layout, consts, "payload", new)
        ns = _exec_module(consts.lines(), _function("decode", "payload", lines,
                                                    "(" + "".join(f"{found[(f,)]}, " for f in fields) + ")"))
        return ns["decode"], fields

    def dronecan_decode(name: str, payload: bytes) -> Any:
        obj = dronecan.TYPENAMES[name]()
        obj._unpack(transport.bits_from_bytes(bytearray(payload)), True)  # as Transfer.from_frames, classic CAN
        return obj

    def random_value(t: Any, rng: random.Random) -> tuple[Any, Any]:
        """(a value dronecan takes, the writer's view of it: expression into V / V0Node / V0Items)."""
        if isinstance(t, dsdl.PrimitiveType):
            if t.kind == t.KIND_BOOLEAN:
                value: Any = rng.random() < 0.5
            elif t.kind == t.KIND_FLOAT:
                m = t.value_range[1]
                value = rng.choice([0.0, -0.0, 1.5, math.nan, math.inf, -math.inf, 65519.9, 6e-8, 3e-5, 1e-40,
                                    rng.uniform(-m, m), rng.uniform(-70000, 70000), 1e39 if t.bitlen == 64 else 1e30])
            elif t.cast_mode == t.CAST_MODE_TRUNCATED:
                value = rng.randint(int(t.value_range[0]) - 99, int(t.value_range[1]) + 99)
            else:
                value = rng.randint(int(t.value_range[0]), int(t.value_range[1]))
            VALUES.append(value)
            return value, f"V[{len(VALUES) - 1}]"
        if isinstance(t, dsdl.ArrayType):
            n = t.max_size if t.mode == t.MODE_STATIC else rng.randint(0, t.max_size)
            if isinstance(t.value_type, dsdl.PrimitiveType) and rng.random() < 0.5:  # a list expression
                items = [random_value(t.value_type, rng)[0] for _ in range(n)]
                del VALUES[len(VALUES) - n:]
                VALUES.append(items)
                return items, f"V[{len(VALUES) - 1}]"
            pairs = [random_value(t.value_type, rng) for _ in range(n)]
            return [p[0] for p in pairs], V0Items([p[1] for p in pairs])
        obj = transport.CompoundValue(t)
        if t.union:  # (never given: unions cannot be mapped) the first field, at its default
            return obj, None
        node = V0Node()
        for f in t.fields:
            if isinstance(f.type, dsdl.VoidType) or rng.random() < 0.1:
                continue
            value, node.fields[f.name] = random_value(f.type, rng)
            setattr(obj, f.name, value)
        return obj, node

    VALUES: list[Any] = []

    @pytest.mark.parametrize("name", STANDARD)
    def test_writer_packs_as_dronecan(layout: V0Layout, name: str) -> None:
        """Random messages, values beyond every range included (dronecan's cast), give dronecan's bytes."""
        rng = random.Random(name)
        for _ in range(150):
            VALUES.clear()
            obj, node = random_value(dronecan.TYPENAMES[name], rng)
            consts = Constants()
            lines, expr = v0_writer(layout.struct(name), node, layout, consts)
            encode = _exec_module(consts.lines(), _function("encode", "V", lines, expr))["encode"]
            assert encode(list(VALUES)) == bytes(transport.Transfer(payload=obj).payload), VALUES

    @pytest.mark.parametrize("name", STANDARD)
    def test_reader_decodes_as_dronecan(layout: V0Layout, name: str) -> None:
        """dronecan's bytes of random messages, cut, extended, flipped and random: the same values, or WireError
        exactly where dronecan raises."""
        decode, fields = reader_of(layout, name)
        rng = random.Random(name)
        refused = 0
        for i in range(600):
            VALUES.clear()
            payload = bytes(transport.Transfer(payload=random_value(dronecan.TYPENAMES[name], rng)[0]).payload)
            payload = _mutated(payload, rng, i % 6)
            try:
                obj = dronecan_decode(name, payload)
            except Exception:
                refused += 1
                with pytest.raises(WireError):
                    decode(payload)
                continue
            got = decode(payload)
            assert same(list(got), [plain(getattr(obj, f)) for f in fields]), payload.hex()
        assert 0 < refused < 600

    def _mutated(payload: bytes, rng: random.Random, how: int) -> bytes:
        if how == 1:
            return payload[:rng.randint(0, len(payload))]
        if how == 2:
            return payload + bytes(rng.getrandbits(8) for _ in range(rng.randint(1, 12)))
        if how == 3 and payload:
            data = bytearray(payload)
            for _ in range(rng.randint(1, 4)):
                data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
            return bytes(data)
        if how == 4:
            return bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 80)))
        return payload

    @SETTINGS
    @given(st.integers(0, 2**32 - 1))
    def test_float16_as_dronecan(bits: int) -> None:
        """dronecan's f16_from_f32 (ties away, the low bits of the float32 dropped, its own subnormals)."""
        x = struct.unpack("<f", struct.pack("<I", bits))[0]
        expected = transport.f16_from_f32(min(max(x, -65504.0), 65504.0))
        assert f16_bits(x) == expected
        truncated = math.inf if x > 65504.0 else -math.inf if x < -65504.0 else x
        assert f16_bits(x, truncated=True) == transport.f16_from_f32(truncated)

    def test_float16_ties_differ_from_struct() -> None:
        """Why the writer does not use struct's `e`: dronecan rounds a tie away from zero."""
        tie = 1.0 + 2**-11  # halfway between two float16 values
        assert struct.unpack("<H", struct.pack("<e", tie))[0] == 0x3C00
        assert f16_bits(tie) == transport.f16_from_f32(tie) == 0x3C01

    # ---------------------------------------------------------------------------------------- the module

    @pytest.fixture(scope="module")
    def modules() -> dict[str, dict[str, str]]:
        from sam_codegen.targets.wire import codec_v0 as emit_codec_v0

        return {spec: emit_codec_v0.emit(validate(load_spec_file(path))) for spec, path in SPECS.items()}

    def test_golden_codec(modules: dict[str, dict[str, str]]) -> None:
        """SAM's codec_v0.py, byte for byte (tests/test_v0_dsdl.py compares it with the converters' golden;
        SAM_UPDATE_GOLDEN=1 there rewrites both)."""
        text = modules["sam"]["python/sam_bridge/codec_v0.py"]
        assert text == (GOLDEN / "python" / "sam_bridge" / "codec_v0.py.golden").read_text(encoding="utf-8"), \
            "run tests/test_v0_dsdl.py with SAM_UPDATE_GOLDEN=1 after an intended change"

    @pytest.mark.system  # starts a process: not in the unit tier
    @pytest.mark.parametrize("spec", sorted(SPECS))
    def test_codec_is_lint_clean_deterministic_and_standard_library_only(
            spec: str, modules: dict[str, dict[str, str]], tmp_path: Path) -> None:
        from sam_codegen.targets.python import convert as emit_python
        from sam_codegen.targets.wire import codec_v0 as emit_codec_v0

        files = modules[spec]
        assert files == emit_codec_v0.emit(validate(load_spec_file(SPECS[spec])))
        (path, text), = files.items()
        compile(text, path, "exec")
        target = tmp_path / path
        target.parent.mkdir(parents=True)
        target.write_text(text, encoding="utf-8")
        (target.parent / "__init__.py").write_text("", encoding="utf-8")
        support = emit_python.emit(validate(load_spec_file(SPECS[spec])))  # codec_v0 imports conversion_support
        (target.parent / "conversion_support.py").write_text(
            support[path.replace("codec_v0.py", "conversion_support.py")], encoding="utf-8")
        ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
        if Path(ruff).exists():
            proc = subprocess.run(
                [ruff, "check", "--isolated", "--no-cache", "--line-length", "110", "--target-version", "py311",
                 "--select", "E,F,W,I,B,UP,RUF", "--ignore", "RUF001,RUF002,RUF003", str(target)],
                capture_output=True, text=True, check=False)
            assert proc.returncode == 0, proc.stdout + proc.stderr
        package = target.parent.name
        probe = (f"import sys; sys.path.insert(0, {str(tmp_path / 'python')!r}); import {package}.codec_v0 as c; "
                 "print(sorted({m.split('.')[0] for m in sys.modules} & {'dronecan', 'rclpy', 'numpy', 'pycyphal'}),"
                 " len(c.CODECS))")
        out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout.split()
        assert out[0] == "[]"

# ============================================================================================ the ROS child

if not WORKER:
    from helpers.ros_packages import built_prefix, missing_tools, run_child
    from helpers.runtime_support import domain_id

    @pytest.mark.ros
    @pytest.mark.slow
    @pytest.mark.skipif(missing_tools() is not None, reason=str(missing_tools()))
    @pytest.mark.parametrize("spec", sorted(SPECS))
    def test_codecs_equal_the_object_path(spec: str, tmp_path: Path) -> None:
        from sam_codegen.build import build
        from sam_codegen.project.ros_install import ros_packages_in_order

        generated = tmp_path / "generated"  # built afresh: the codecs of the generator as it is
        build(SPECS[spec], generated)
        packages = ros_packages_in_order(ROOT / "generated" / "ros")  # SAM's messages (others: installed)
        if spec in ("relay", "power_v0", "power_prefix_v0", "lolo_v0", "hopper_v0"):  # and the spec's own messages
            packages = [*packages, *ros_packages_in_order(generated / "ros")]
        prefix = built_prefix(packages)
        config = {"spec": str(SPECS[spec]), "generated": str(generated)}
        proc = run_child(["-m", "pytest", __file__, "-q", "-p", "no:cacheprovider", "--rootdir", str(ROOT),
                          "-W", "error::RuntimeWarning"], prefix, domain_id(70 + sorted(SPECS).index(spec)),
                         {WORKER_ENV: json.dumps(config)}, timeout=900)
        report = proc.stdout[-12000:] + proc.stderr[-4000:]
        assert proc.returncode == 0, f"worker tests for {spec} failed:\n{report}"
        assert " passed" in proc.stdout and " skipped" not in proc.stdout and " failed" not in proc.stdout, report


if WORKER:
    from helpers.codec_v0_worker import *  # noqa: F403  (the child's tests, collected here)
