"""NaN and infinities on their way to an actuator (issue 29 items 5 and 6), through the generated wire codec
(codec.py: standard library only, so no ROS or pycyphal is needed; tests/codegen/test_codec.py checks that it agrees
with the object converters).

- A command whose value is NaN is rejected and counted (`rejected.<mapping>.<field>`, its drop `not_a_number` in the
  bridge), unless the mapping says `pass_nan: true`; a limited field rejects NaN either way.
- +-inf saturates to the field's `limits` where the spec gives them, else to the float16 range (+-65504).
- max/min follow IEEE 754-2019 maximum/minimum: a NaN argument gives NaN whichever its place, and that NaN result
  is rejected and counted as any NaN command.
"""

from __future__ import annotations

import importlib
import math
import struct
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets.python import convert as emit_python
from sam_codegen.targets.wire import codec as emit_codec
from sam_codegen.validate.resolve import validate

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "minimal.yaml").read_text(encoding="utf-8")

FIN = """
  buoy.Fin.0.1:
    sealed: true
    fields:
      - {name: angle, type: float16}
      - {name: trim, type: float16}
      - {name: gain, type: float16}
      - {name: bias, type: float16}
"""
MAPPINGS = """
    fin:
      direction: ros_to_uavcan
      subject_id: 102
      topic: /fin
      destination_node_id: 12
      fields:
        x: angle
        y: {from: trim, limits: [-0.5, 0.5]}
      uavcan_exprs:
        gain: "max(1.0, z)"
        bias: "min(z, 2.0)"
    fin_raw:
      direction: ros_to_uavcan
      subject_id: 103
      topic: /fin_raw
      destination_node_id: 12
      pass_nan: true
      fields:
        x: angle
        y: {from: trim, limits: [-0.5, 0.5]}
      uavcan_exprs:
        gain: "max(1.0, z)"
        bias: "min(z, 2.0)"
"""


def fin_spec(tmp_path: Path) -> Path:
    text = BASE.replace("dsdl_types:\n", "dsdl_types:" + FIN, 1)
    text = text.replace("  /valve: {type: std_msgs/UInt8}\n", "  /valve: {type: std_msgs/UInt8}\n"
                        "  /fin: {type: geometry_msgs/Vector3}\n  /fin_raw: {type: geometry_msgs/Vector3}\n", 1)
    text = text.replace("      - {subject_id: 101, type: buoy.Valve.0.1, rate_hz: 1}\n",
                        "      - {subject_id: 101, type: buoy.Valve.0.1, rate_hz: 1}\n"
                        "  fin:\n    node_id: 12\n    subscribes:\n"
                        "      - {subject_id: 102, type: buoy.Fin.0.1, rate_hz: 10}\n"
                        "      - {subject_id: 103, type: buoy.Fin.0.1, rate_hz: 10}\n", 1)
    text = text.replace("  mappings:\n", "  mappings:" + MAPPINGS, 1)
    text = text.replace("    publishes: [/valve]\n", "    publishes: [/valve, /fin, /fin_raw]\n", 1)
    path = tmp_path / "fin.yaml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def codec(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    """The spec's codec.py and conversion_support.py as a package, imported."""
    tmp = tmp_path_factory.mktemp("fin")
    resolved = validate(load_spec_file(fin_spec(tmp)))
    files = {**emit_python.emit(resolved), **emit_codec.emit(resolved)}
    package = tmp / "fin_pkg"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    for path, text in files.items():
        if path.endswith(("/codec.py", "/conversion_support.py")):
            (package / Path(path).name).write_text(text, encoding="utf-8")
    sys.path.insert(0, str(tmp))
    try:
        return importlib.import_module("fin_pkg.codec")
    finally:
        sys.path.remove(str(tmp))


class Stats:
    def __init__(self) -> None:
        self.saturated: dict[str, int] = {}
        self.rejected: dict[str, int] = {}
        self.nan: dict[str, int] = {}

    def saturate(self, key: str) -> None:
        self.saturated[key] = self.saturated.get(key, 0) + 1

    def reject(self, key: str) -> None:
        self.rejected[key] = self.rejected.get(key, 0) + 1

    def reject_nan(self, key: str) -> None:
        self.reject(key)
        self.nan[key] = self.nan.get(key, 0) + 1


def send(codec: ModuleType, mapping: str, x: float, y: float, z: float) -> tuple[Any, Stats]:
    stats = Stats()
    out = getattr(codec, f"{mapping}_ros_to_wire")(b"\x00\x01\x00\x00" + struct.pack("<3d", x, y, z), stats)
    return (None if out is None else struct.unpack("<4e", out)), stats


NAN, INF = math.nan, math.inf


def test_a_nan_command_is_rejected_and_counted(codec: ModuleType) -> None:
    """Item 5: NaN reached two actuators (thrust vector, ballast). Now: no payload, counted as NaN."""
    assert send(codec, "fin", 0.5, 0.0, 1.5)[0] == (0.5, 0.0, 1.5, 1.5)
    out, stats = send(codec, "fin", NAN, 0.0, 1.5)
    assert out is None and stats.nan == {"fin.angle": 1} and stats.rejected == {"fin.angle": 1}
    out, stats = send(codec, "fin", 0.0, NAN, 1.5)  # a limited field: rejected, as before
    assert out is None and stats.nan == {"fin.trim": 1}


def test_a_mapping_may_pass_nan_on(codec: ModuleType) -> None:
    """`pass_nan: true`: a float field without limits takes NaN; a limited one still rejects it."""
    out, stats = send(codec, "fin_raw", NAN, 0.0, NAN)
    assert out is not None and math.isnan(out[0]) and math.isnan(out[2]) and math.isnan(out[3])
    assert not stats.rejected
    out, stats = send(codec, "fin_raw", 0.0, NAN, 1.0)
    assert out is None and stats.nan == {"fin_raw.trim": 1}


def test_infinity_saturates_to_the_limits(codec: ModuleType) -> None:
    """+-inf into a limited field: its limits; into one without: the float16 range (the documented rule)."""
    out, stats = send(codec, "fin", INF, -INF, 1.0)
    assert out == (65504.0, -0.5, 1.0, 1.0)
    assert stats.saturated == {"fin.angle": 1, "fin.trim": 1}
    out, _ = send(codec, "fin", -INF, INF, 1.0)
    assert out == (-65504.0, 0.5, 1.0, 1.0)


@pytest.mark.parametrize("mapping", ["fin", "fin_raw"])
def test_max_and_min_propagate_nan_whichever_the_place(codec: ModuleType, mapping: str) -> None:
    """Item 6: max(1, NaN) published 1.0 uncounted while max(NaN, 1) dropped. IEEE 754-2019 maximum/minimum: NaN
    from either place; then rule 5 (rejected and counted, or passed on with pass_nan)."""
    out, stats = send(codec, mapping, 0.0, 0.0, NAN)  # gain = max(1.0, NaN), bias = min(NaN, 2.0)
    if mapping == "fin":
        assert out is None and stats.nan == {"fin.gain": 1}
    else:
        assert out is not None and math.isnan(out[2]) and math.isnan(out[3])
    assert send(codec, mapping, 0.0, 0.0, 3.0)[0] == (0.0, 0.0, 3.0, 2.0)
    assert send(codec, mapping, 0.0, 0.0, -3.0)[0] == (0.0, 0.0, 1.0, -3.0)


def test_ieee_maximum_and_minimum() -> None:
    """The helpers themselves: NaN in either place, and -0 below +0."""
    namespace: dict[str, Any] = {}
    from sam_codegen.render.templating import environment

    source = environment().get_template("python/conversion_support.py.j2").render(spec_name="t", vehicle="t")
    exec(compile(source, "conversion_support.py", "exec"), namespace)
    maximum, minimum = namespace["maximum"], namespace["minimum"]
    for a, b in ((1.0, NAN), (NAN, 1.0), (NAN, NAN), (INF, NAN), (NAN, -INF)):
        assert math.isnan(maximum(a, b)) and math.isnan(minimum(a, b))
    assert math.copysign(1.0, maximum(-0.0, 0.0)) == 1.0 and math.copysign(1.0, maximum(0.0, -0.0)) == 1.0
    assert math.copysign(1.0, minimum(-0.0, 0.0)) == -1.0 and math.copysign(1.0, minimum(0.0, -0.0)) == -1.0
    assert (maximum(2, 3.5), minimum(2, 3.5), maximum(-INF, 1), minimum(INF, 1)) == (3.5, 2, 1, 1)
