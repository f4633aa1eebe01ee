"""Every spec in tests/specs/ (and SAM's own) names its own generated packages.

One pytest process imports the packages generated from several specs; two specs with the same vehicle name (or the
same ROS package or DSDL root namespace) give packages of the same name, and the later import is refused as shadowed
(GeneratedPackageError). This test names the clashing files, so a new spec picks a name of its own up front.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import pytest

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.spec import Spec

ROOT = Path(__file__).resolve().parents[2]
SPEC_FILES = [ROOT / "spec" / "interfaces.yaml", *sorted((ROOT / "tests" / "specs").glob("*.yaml"))]


def clashes(names: dict[str, str]) -> list[str]:
    """`names` (file -> name) as one line per name that more than one file uses.

    >>> clashes({"a.yaml": "buoy", "b.yaml": "buoy", "c.yaml": "ferry"})
    ["'buoy' in a.yaml, b.yaml"]
    """
    files: dict[str, list[str]] = defaultdict(list)
    for file, name in names.items():
        files[name].append(file)
    return [f"{name!r} in {', '.join(sorted(used))}" for name, used in sorted(files.items()) if len(used) > 1]


@pytest.fixture(scope="module")
def specs() -> dict[str, Spec]:
    return {path.name: load_spec_file(path) for path in SPEC_FILES}


def test_the_spec_files_are_found() -> None:
    assert len(SPEC_FILES) > 10 and SPEC_FILES[0].is_file()


@pytest.mark.parametrize("what", ["vehicle", "ros package", "DSDL root namespace"])
def test_specs_name_distinct_packages(specs: dict[str, Spec], what: str) -> None:
    name = {"vehicle": lambda s: s.vehicle, "ros package": lambda s: s.ros.name,
            "DSDL root namespace": lambda s: s.dsdl_root}[what]
    found = clashes({file: name(spec) for file, spec in specs.items()})
    assert not found, f"specs sharing a {what} name: {'; '.join(found)}"


def test_a_clash_names_both_files() -> None:
    assert clashes({"minimal.yaml": "buoy", "buoy_v0.yaml": "buoy", "ferry.yaml": "ferry"}) == [
        "'buoy' in buoy_v0.yaml, minimal.yaml"]
