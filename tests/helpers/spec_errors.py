"""The errors a spec file gives, as the broken-spec tables (tests/broken_cases*.py) write them."""

from __future__ import annotations

from pathlib import Path

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.validate.resolve import validate


def spec_errors(path: Path) -> list[str]:
    """Every diagnostic of loading and validating `path`, its directory left out (`minimal.yaml:3:1: error: ...`);
    [] for a valid spec."""
    try:
        validate(load_spec_file(path))
    except SpecError as exc:
        return [str(d).replace(str(path), path.name) for d in exc.diagnostics]
    return []
