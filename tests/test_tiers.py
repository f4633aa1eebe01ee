"""The suite's tiers and distribution (tests/helpers/tiers.py): what holds them together."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers import tiers

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("module", sorted(tiers.SPREAD_MODULES))
def test_every_spread_module_exists(module: str) -> None:
    # a renamed module would silently go back to one worker (the scheduler matches the test ids' file part)
    assert (ROOT / module).is_file(), module


def test_only_the_listed_modules_are_spread() -> None:
    spread = sorted(tiers.SPREAD_MODULES)[0]
    assert tiers.scope_of(f"{spread}::test_a[x]") == f"{spread}::test_a[x]"
    assert tiers.scope_of("tests/codegen/test_yaml_limits.py::test_b[y]") == "tests/codegen/test_yaml_limits.py"
    assert tiers.scope_of("codegen/model/expr.py::sam_codegen.model.expr.f") == "codegen/model/expr.py"  # doctests


def test_no_two_test_modules_share_a_name() -> None:
    # the test folders are no packages (rootdir-relative imports, pythonpath = tests): two test modules of one
    # basename collide at collection ("import file mismatch"), and only when both are collected in one process
    # (a whole run, not a single folder), so a folder-by-folder check never shows it
    seen: dict[str, Path] = {}
    clashes = []
    for path in sorted((ROOT / "tests").rglob("test_*.py")):
        if path.name in seen:
            clashes.append(f"{seen[path.name].relative_to(ROOT)} and {path.relative_to(ROOT)}")
        seen.setdefault(path.name, path)
    assert not clashes, clashes
