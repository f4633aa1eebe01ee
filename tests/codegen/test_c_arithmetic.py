"""C arithmetic in a spec (issue 27): float32(...) and a line's `on_out_of_range: wrap`, value for value against
the C a legacy bridge runs, compiled here with `cc` (no fast-math, no FMA contraction: IEEE binary32 as C's float).

The generated wire codecs of tests/specs/retrofit.yaml (codec.py, codec_v0.py: the same ExpressionWriter writes the
object converters, and tests/codegen/test_codec*.py prove those equal to the codecs on this spec) are run on random
float32 inputs and on the edges (x.5 boundaries of round(), products that round up to an integer in binary32 but not
in binary64, NaN, +-inf, +-0, subnormals, beyond int64 and beyond every target), and every output field must be the
C's. Where C itself is undefined (a float beyond int64 into an integer, a NaN into an integer) the C below does what
the spec documents (saturate beyond int64, drop on NaN), so the comparison covers those inputs too.

It starts `cc` and the compiled program: a system test.
"""

from __future__ import annotations

import importlib
import math
import random
import shutil
import struct
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

pytestmark = pytest.mark.system

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "tests" / "specs" / "retrofit.yaml"

# The legacy bridge's conversions in C, one line of output per input line. Inputs: the four ColorRGBA floats as
# their binary32 bits, then one int32 (the thruster's rpm). Outputs: light's red green blue level or DROP, then the
# thruster's rpm[0] (int18, wrapped).
C_SOURCE = r"""
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static float f_of(uint32_t bits) { float f; memcpy(&f, &bits, 4); return f; }

/* trunc() / round() of a spec: NaN drops the message; beyond int64 saturates (C leaves both undefined). */
static int to_int64(float x, int rounding, int64_t *out) {
    if (isnan(x)) return 0;
    if (x >= 9223372036854775808.0f) { *out = INT64_MAX; return 1; }
    if (x < -9223372036854775808.0f) { *out = INT64_MIN; return 1; }
    *out = (int64_t)(rounding ? nearbyintf(x) : truncf(x));  /* nearbyint: to nearest, ties to even */
    return 1;
}

static int64_t saturate(int64_t v, int64_t lo, int64_t hi) { return v < lo ? lo : v > hi ? hi : v; }
static int64_t wrap_signed(int64_t v, int bits) {
    uint64_t m = (1ULL << bits) - 1, h = 1ULL << (bits - 1);
    return (int64_t)(((uint64_t)v + h) & m) - (int64_t)h;
}

int main(void) {
    unsigned r_bits, g_bits, b_bits, a_bits;
    long long n;
    while (scanf("%x %x %x %x %lld", &r_bits, &g_bits, &b_bits, &a_bits, &n) == 5) {
        float r = f_of(r_bits), g = f_of(g_bits), b = f_of(b_bits), a = f_of(a_bits);
        int64_t t_red, t_green, t_blue, t_level;
        /* red = (uint8_t)((int)(r * 80) >> 3), saturated; green = (uint8_t)(int)(g * 255 / a), wrapped;
           blue = (int6)round(b * 100 - 50), wrapped; level = (int)(a * 0.7f * 40), saturated into uint5 */
        if (to_int64(r * 80.0f, 0, &t_red) && to_int64(g * 255.0f / a, 0, &t_green)
                && to_int64(b * 100.0f - 50.0f, 1, &t_blue) && to_int64(a * 0.7f * 40.0f, 0, &t_level)) {
            printf("%lld %llu %lld %lld", (long long)saturate(t_red >> 3, 0, 255),
                   (unsigned long long)((uint64_t)t_green & 255), (long long)wrap_signed(t_blue, 6),
                   (long long)saturate(t_level, 0, 31));
        } else {
            printf("DROP");
        }
        printf(" %lld\n", (long long)wrap_signed(n, 18));
    }
    return 0;
}
"""


def _bits(x: float) -> int:
    return int(struct.unpack("<I", struct.pack("<f", x))[0])


def _f32(x: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


EDGE_FLOATS = [0.7, 0.0, -0.0, 0.5, -0.5, 1.5, 2.5, 0.125, 0.375, 0.505, 0.515, 0.625, 1.0, -1.0, 0.1, 0.35,
               1.4e-45, -1.4e-45, 1.1754942e-38, 3.4028235e38, -3.4028235e38, 1e20, -1e20, 1.2e17, 9.3e18, -9.3e18,
               math.inf, -math.inf, math.nan, 100.0, 0.0125, 3.2, 6.4, 1 / 3, 0.3, 0.9, 12.8]
EDGE_INTS = [0, 1, -1, 131071, 131072, -131072, -131073, 200000, -200000, 27, 28, 155, 156, -228, -229,
             2**31 - 1, -(2**31)]


def _inputs(count: int) -> list[tuple[int, int, int, int, int]]:
    rng = random.Random(27)
    floats = [_bits(_f32(x)) if not math.isnan(x) else 0x7FC00000 for x in EDGE_FLOATS]
    # x.5 boundaries and products that are integers only in binary32: k / 80, (k + 0.5) / 100, (k + 50.5) / 100
    floats += [_bits(_f32(k / 80)) for k in range(0, 400, 7)]
    floats += [_bits(_f32((k + 50.5) / 100)) for k in range(-60, 60, 3)]
    out = []
    for i in range(count):
        def one() -> int:
            pick = rng.random()
            if pick < 0.4:
                return rng.choice(floats)
            if pick < 0.7:
                return _bits(_f32(rng.uniform(-2.0, 2.0)))
            return rng.getrandbits(32)  # any bit pattern: NaNs, infinities, subnormals, huge values
        n = EDGE_INTS[i % len(EDGE_INTS)] if i < 4 * len(EDGE_INTS) else rng.randint(-(2**31), 2**31 - 1)
        out.append((one(), one(), one(), one(), n))
    return out


@pytest.fixture(scope="module")
def c_program(tmp_path_factory: pytest.TempPathFactory) -> Path:
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc)")
    folder = tmp_path_factory.mktemp("c_arith")
    (folder / "legacy.c").write_text(C_SOURCE, encoding="utf-8")
    exe = folder / "legacy"
    subprocess.run([cc, "-std=c11", "-O2", "-ffp-contract=off", "-fno-fast-math", str(folder / "legacy.c"), "-lm",
                    "-o", str(exe)], check=True, capture_output=True, timeout=120)
    return exe


@pytest.fixture(scope="module")
def codecs(tmp_path_factory: pytest.TempPathFactory) -> tuple[ModuleType, ModuleType]:
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.targets.python import convert
    from sam_codegen.targets.wire import codec, codec_v0
    from sam_codegen.validate.resolve import validate

    resolved = validate(load_spec_file(SPEC))
    folder = tmp_path_factory.mktemp("c_arith_codecs")
    package = folder / "retrofit_c_arith"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    for files in (convert.emit(resolved), codec.emit(resolved), codec_v0.emit(resolved)):
        for path, text in files.items():
            name = Path(path).name
            if name in ("conversion_support.py", "codec.py", "codec_v0.py"):
                (package / name).write_text(text, encoding="utf-8")
    sys.path.insert(0, str(folder))
    try:
        return (importlib.import_module("retrofit_c_arith.codec"), importlib.import_module("retrofit_c_arith.codec_v0"))
    finally:
        sys.path.remove(str(folder))


class Stats:
    def __init__(self) -> None:
        self.saturated: list[str] = []
        self.rejected: list[str] = []

    def saturate(self, key: str) -> None:
        self.saturated.append(key)

    def reject(self, key: str) -> None:
        self.rejected.append(key)

    def reject_nan(self, key: str) -> None:  # a NaN is counted apart from an out-of-range reject
        self.rejected.append(key)


def _light(codec: ModuleType, bits: tuple[int, int, int, int]) -> str:
    cdr = b"\x00\x01\x00\x00" + struct.pack("<4I", *bits)
    payload = codec.light_ros_to_wire(cdr, Stats())
    if payload is None:
        return "DROP"
    red, green, packed = struct.unpack("<BBH", payload)  # blue: bits 0-5, level: bits 6-10
    blue = (packed & 63) - 64 if packed & 32 else packed & 63
    return f"{red} {green} {blue} {packed >> 6}"


def _thruster(codec_v0: Any, n: int) -> int:
    """rpm[0] of the RPMCommand payload the codec writes, decoded by dronecan (the v0 payload's oracle)."""
    import dronecan
    from dronecan import transport

    payload = codec_v0.thruster_ros_to_wire(b"\x00\x01\x00\x00" + struct.pack("<i", n), Stats())
    obj = dronecan.TYPENAMES["uavcan.equipment.esc.RPMCommand"]()
    obj._unpack(transport.bits_from_bytes(bytearray(payload)), True)  # as Transfer.from_frames, classic CAN
    return int(obj.rpm[0])


def test_float32_and_wrap_agree_with_c(c_program: Path, codecs: tuple[ModuleType, ModuleType]) -> None:
    codec, codec_v0 = codecs
    inputs = _inputs(6000)
    text = "\n".join(f"{r:x} {g:x} {b:x} {a:x} {n}" for r, g, b, a, n in inputs) + "\n"
    done = subprocess.run([str(c_program)], input=text, capture_output=True, text=True, check=True, timeout=120)
    lines = done.stdout.splitlines()
    assert len(lines) == len(inputs)
    drops = 0
    for (r, g, b, a, n), line in zip(inputs, lines, strict=True):
        *light, rpm = line.split()
        mine = _light(codec, (r, g, b, a))
        drops += mine == "DROP"
        assert mine == " ".join(light), f"light({r:#x}, {g:#x}, {b:#x}, {a:#x}): spec {mine}, C {' '.join(light)}"
        assert _thruster(codec_v0, n) == int(rpm), f"thruster({n})"
    assert 0 < drops < len(inputs) // 2  # NaN inputs drop, most do not: both branches compared


def test_the_issue_examples(codecs: tuple[ModuleType, ModuleType]) -> None:
    """0.7 * 80 is 55.99999952... in binary64 but 56.0f in C: float32() gives C's 7 after >> 3, not 6; 200000 rpm
    into an int18 wraps to -62144 (the reversal the README warns of) where saturation gives 131071."""
    codec, codec_v0 = codecs
    assert _light(codec, (_bits(0.7), 0, 0, _bits(1.0))).split()[0] == "7"
    assert math.trunc(_f32(0.7) * 80) >> 3 == 6  # what binary64 (the spec without float32) gives
    assert _thruster(codec_v0, 200000) == -62144
