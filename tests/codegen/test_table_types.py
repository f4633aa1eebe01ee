"""The types of the generated tables.py: table_types.py is copied verbatim into it, imports only the standard library,
and tables_api.TablesModule names exactly what a generated tables.py defines at module level."""

from __future__ import annotations

import ast
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from sam_codegen.contracts import table_types
from sam_codegen.contracts.tables_api import TablesModule
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.targets.python.convert import emit
from sam_codegen.targets.python.tables import table_types_source, tables_context
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).resolve().parents[2]


def _generated_tables(tmp_path: Path) -> tuple[str, ModuleType]:
    resolved = validate(load_spec_file(ROOT / "spec" / "interfaces.yaml"))
    text = emit(resolved)[f"python/{resolved.spec.vehicle}_bridge/tables.py"]
    path = tmp_path / "tables.py"
    path.write_text(text, encoding="utf-8")
    spec = importlib.util.spec_from_file_location("_generated_tables_under_test", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while building the classes
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[spec.name]
    return text, module


def test_the_classes_are_copied_verbatim(tmp_path: Path) -> None:
    text, module = _generated_tables(tmp_path)
    assert table_types_source() in text
    classes = {n.name for n in ast.parse(Path(table_types.__file__).read_text()).body if isinstance(n, ast.ClassDef)}
    assert len(classes) == 17
    assert all(isinstance(getattr(module, name), type) for name in classes)


def test_table_types_needs_only_the_standard_library() -> None:
    tree = ast.parse(Path(table_types.__file__).read_text())
    imported = {alias.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for alias in n.names}
    imported |= {(n.module or "").split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    assert imported <= set(sys.stdlib_module_names) | {"__future__"}


def test_the_protocol_names_the_module_level_tables(tmp_path: Path) -> None:
    _, module = _generated_tables(tmp_path)
    public = {name for name, value in vars(module).items()
              if name.isupper() and not name.startswith("_") and not isinstance(value, type)}
    assert public == set(TablesModule.__annotations__)


def test_the_context_carries_the_types() -> None:
    resolved = validate(load_spec_file(ROOT / "spec" / "interfaces.yaml"))
    assert tables_context(resolved)["table_types"] == table_types_source()
