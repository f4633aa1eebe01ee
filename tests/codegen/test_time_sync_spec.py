"""`bridge.time_sync` (sam_codegen.frontend.time_sync) reaches the generated tables: the master's period (None when
the spec turns it off, the default 0.5 s when the key is absent), and per protocol the UAVCAN->ROS mappings whose
header.stamp is the device's timestamp (the bridge counts their unknown stamps); the errors are in
tests/broken_cases.py."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Any

import pytest

from sam_codegen.build import generate
from sam_codegen.frontend.loader import load_spec_file

SPECS = Path(__file__).parents[1] / "specs"


def _tables(tmp_path: Path, name: str, old: str = "", new: str = "") -> dict[str, Any]:
    text = (SPECS / f"{name}.yaml").read_text(encoding="utf-8")
    if old:
        assert old in text
        text = text.replace(old, new, 1)
    spec = tmp_path / f"{name}.yaml"
    spec.write_text(text, encoding="utf-8")
    source = next(s for p, s in generate(spec).items() if p.endswith("tables.py"))
    path = tmp_path / "tables_under_test.py"
    path.write_text(source, encoding="utf-8")
    module_spec = importlib.util.spec_from_file_location("tables_under_test", path)
    assert module_spec is not None and module_spec.loader is not None
    module = importlib.util.module_from_spec(module_spec)
    sys.modules["tables_under_test"] = module  # (dataclasses look their module up)
    try:
        module_spec.loader.exec_module(module)
    finally:
        del sys.modules["tables_under_test"]
    return vars(module)


@pytest.mark.parametrize(("setting", "period"), [
    ("", 0.5),
    ("  time_sync: false\n", None),
    ("  time_sync: true\n", 0.5),
    ("  time_sync: {period_s: 0.2}\n", 0.2),
    ("  time_sync: {enabled: false, period_s: 0.2}\n", None),
    ("  time_sync: {period_s: 1}\n", 1.0),
])
def test_period_in_the_tables(tmp_path: Path, setting: str, period: float | None) -> None:
    t = _tables(tmp_path, "minimal", "  node_id: 100\n", "  node_id: 100\n" + setting)
    assert t["TIME_SYNC_PERIOD_S"] == period
    spec = load_spec_file(tmp_path / "minimal.yaml")
    assert spec.bridge is not None and spec.bridge.time_sync.enabled == (period is not None)


def test_device_stamped_mappings_per_protocol(tmp_path: Path) -> None:
    # minimal: /level's header.stamp is the device's timestamp; the command mapping has none
    t = _tables(tmp_path, "minimal")
    assert t["DEVICE_STAMPED_MAPPINGS"] == frozenset({"level"})
    assert t["DRONECAN_DEVICE_STAMPED_MAPPINGS"] == frozenset()
    # the same mapping with the receive time as its stamp (no stamp field mapped) is not stamped by the device
    t = _tables(tmp_path, "minimal", "        header.stamp: timestamp.microsecond\n        level: level_mm\n",
                "        level: level_mm\n      ignore: [timestamp]\n")
    assert t["DEVICE_STAMPED_MAPPINGS"] == frozenset()


def test_no_bridge_no_master(tmp_path: Path) -> None:
    text = (SPECS / "minimal.yaml").read_text(encoding="utf-8")
    t = _tables(tmp_path, "minimal", text[text.index("bridge:\n"):], "")
    assert t["TIME_SYNC_PERIOD_S"] is None and t["DEVICE_STAMPED_MAPPINGS"] == frozenset()
