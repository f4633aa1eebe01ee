"""Arrays of signed integers of at most 8 bits serialize (found with the glider spec, issue 11).

nunavut 2.3's serializer did `value & 0xFF` and `2**8 + value` on numpy.int8 elements; NumPy 2 raises
OverflowError there, so the bridge dropped every command with an int3[<=3] field as ``publish_error``.
sam_runtime.cyphal_io.dsdl_cache patches the compiled support module; this checks the round trip at the limits.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pycyphal")

DSDL = """\
bool flag
int3[<=3] trims
int5[2] pair
int8[<=4] bytes_unaligned
int2 scalar
uint3[<=2] unsigned
@sealed
"""


def test_signed_sub_byte_arrays_round_trip(tmp_path: Path) -> None:
    import importlib
    import sys

    from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled

    ns = tmp_path / "sbtest"
    ns.mkdir()
    (ns / "Arrays.1.0.dsdl").write_text(DSDL)
    saved = list(sys.path)
    try:
        ensure_compiled([ns], tmp_path / "cache")
        import pycyphal.dsdl

        arrays = importlib.import_module("sbtest").Arrays_1_0
        cases = [
            dict(flag=True, trims=[3, -4, -1], pair=[15, -16], bytes_unaligned=[127, -128, -1, 0], scalar=-2,
                 unsigned=[7, 0]),
            dict(flag=False, trims=[], pair=[0, -1], bytes_unaligned=[], scalar=1, unsigned=[]),
        ]
        for values in cases:
            wire = b"".join(bytes(x) for x in pycyphal.dsdl.serialize(arrays(**values)))
            back = pycyphal.dsdl.deserialize(arrays, [memoryview(wire)])
            assert back is not None
            for name, want in values.items():
                got = getattr(back, name)
                got = [int(x) for x in got] if isinstance(want, list) else got
                assert got == want, (name, got, want)
    finally:
        sys.path[:] = saved
        for mod in [m for m in sys.modules if m == "sbtest" or m.startswith("sbtest.")]:
            del sys.modules[mod]
