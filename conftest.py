"""pytest collects the doctests of codegen/ and runtime/ as well as tests/ (pyproject's testpaths).

pytest names a module it collects by its folder (``runtime.nav.mission``); the installed package is
``sam_runtime`` (``sam_codegen`` for codegen/). :class:`_SourceFolderAlias` makes the folder names aliases of the
packages, so a doctest runs in the one module the code imports (exceptions print as ``sam_runtime....Error``, module
state is not duplicated).

The ROS node implementations import the generated node bases (``sam_nodes``), which only a run or a test that
built them puts on the path; they hold no doctests (their logic, with its doctests, is in sam_runtime.nav).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
from types import ModuleType
from typing import ClassVar

collect_ignore = [f"runtime/nodes/{name}.py" for name in
                  ("controller", "dead_reckoning", "mission", "motion_planner", "performance_monitor", "slam")]


class _SourceFolderAlias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    PACKAGES: ClassVar[dict[str, str]] = {"codegen": "sam_codegen", "runtime": "sam_runtime"}

    def find_spec(self, name: str, path: object = None, target: object = None) -> importlib.machinery.ModuleSpec | None:
        return importlib.util.spec_from_loader(name, self) if name.partition(".")[0] in self.PACKAGES else None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        top, dot, rest = spec.name.partition(".")
        return importlib.import_module(self.PACKAGES[top] + dot + rest)

    def exec_module(self, module: ModuleType) -> None:
        """The real module is executed by its own import."""


sys.meta_path.insert(0, _SourceFolderAlias())
