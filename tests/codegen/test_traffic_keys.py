"""A mapping's traffic keys (issue 19: max_rate_hz, deadline, enabled, enable_service) reach the generated tables the
bridge reads and the words of interfaces.md, for a spec other than SAM's (tests/specs/weir.yaml); SAM's mappings
get the defaults. The errors are rows of tests/broken_cases.py."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from helpers.spec_build import generated_spec


def _tables(generated: Path, package: str) -> Any:
    from sam_runtime.genpkg import GeneratedPackage

    return GeneratedPackage(generated, package).tables()


def test_traffic_keys_in_tables_and_docs() -> None:
    # the shared build of weir.yaml: a process imports one copy of weir_bridge (GeneratedPackage refuses a second)
    out = generated_spec("weir")
    tables = _tables(out, "weir_bridge")
    for mappings in (tables.MAPPINGS, tables.DRONECAN_MAPPINGS):
        got = {m.name: (m.max_rate_hz, m.deadline_s, m.enabled, m.enable_service) for m in mappings}
        assert got == {"level": (4.0, None, True, "~/enable_level"),
                       "level_raw": (None, None, False, "~/enable_level_raw"),
                       "gate": (2.0, 1.5, True, "start_stop_gate")}
    docs = (out / "docs" / "interfaces.md").read_text()
    assert "- Rate: at most 4 Hz, the latest message published to ROS" in docs
    assert ("- Switch: `std_srvs/SetBool` service `~/enable_level_raw` (under the bridge node's name), initially "
            "disabled") in docs
    assert ("- Deadline: a command older than 1.5 s since the bridge received it when it would be sent is not sent "
            "(counted as expired)") in docs
    assert "- Switch: `std_srvs/SetBool` service `start_stop_gate` (in the bridge's namespace)" in docs


def test_sam_mappings_get_the_defaults() -> None:
    generated = Path(__file__).parents[2] / "generated"
    tables = _tables(generated, "sam_bridge")
    for m in (*tables.MAPPINGS, *tables.DRONECAN_MAPPINGS):
        assert (m.max_rate_hz, m.deadline_s, m.enabled, m.enable_service) == (None, None, True,
                                                                              f"~/enable_{m.name}")
