"""Where the Cyphal DSDL root namespaces (``uavcan``, ``reg``, vendor namespaces) are looked up.

The Cyphal ecosystem convention (yakut, pycyphal's import hook) is the environment variable ``CYPHAL_PATH``:
a list of directories that *contain* DSDL root namespace directories, separated by ``os.pathsep``
(``;`` is accepted too, as pycyphal and yakut do). When it is unset or empty, the copy of the public
regulated data types shipped beside the repository (``<repo>/../shared/dsdl/public_regulated_data_types``)
is used.

This module deliberately imports nothing from pycyphal/pydsdl so that the code generator can use it
without the runtime extras installed.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

__all__ = [
    "ENV_VAR",
    "CyphalPathError",
    "default_search_dirs",
    "dsdl_lookup_roots",
    "repo_root",
    "search_dirs",
]

ENV_VAR = "CYPHAL_PATH"

# Same rule as pycyphal's DsdlMetaFinder, but anchored at both ends (".git", "docs-v2" are not namespaces).
_ROOT_NAMESPACE_NAME = re.compile(r"[a-zA-Z_][a-zA-Z0-9_]*")


class CyphalPathError(Exception):
    """No usable DSDL root namespace set (in particular no ``uavcan``) could be found."""


def repo_root() -> Path:
    """The repository root (the directory holding pyproject.toml, codegen/ and runtime/)."""
    return Path(__file__).resolve().parents[1]


def default_search_dirs() -> list[Path]:
    """The directories searched when CYPHAL_PATH is unset: the shared public regulated data types."""
    return [(repo_root().parent / "shared" / "dsdl" / "public_regulated_data_types").resolve()]


def search_dirs(environ: Mapping[str, str] | None = None) -> list[Path]:
    """The directories listed in CYPHAL_PATH (in order, duplicates removed), or the default ones."""
    env = os.environ if environ is None else environ
    raw = env.get(ENV_VAR, "")
    entries = [e.strip() for e in raw.replace(os.pathsep, ";").split(";")]
    out: list[Path] = []
    for e in entries:
        if not e:
            continue
        p = Path(os.path.expanduser(e)).resolve()
        if p not in out:
            out.append(p)
    return out or default_search_dirs()


def _is_root_namespace_dir(p: Path) -> bool:
    if not p.is_dir() or not _ROOT_NAMESPACE_NAME.fullmatch(p.name):
        return False
    # A directory without any definition (docs/, tools/, an empty checkout) is not a namespace.
    return next(p.rglob("*.dsdl"), None) is not None


def dsdl_lookup_roots(environ: Mapping[str, str] | None = None) -> list[Path]:
    """The DSDL root namespace directories found in the CYPHAL_PATH directories (or the default).

    Sorted by namespace name, one per name: when two CYPHAL_PATH directories hold a namespace of the
    same name, the one from the earlier directory wins. Raises :class:`CyphalPathError` when no
    ``uavcan`` namespace is found (pycyphal.application and every standard port need it).
    """
    env = os.environ if environ is None else environ
    dirs = search_dirs(env)
    found: dict[str, Path] = {}
    for d in dirs:
        if not d.is_dir():
            continue
        for child in sorted(d.iterdir()):
            if child.name not in found and _is_root_namespace_dir(child):
                found[child.name] = child.resolve()
    if "uavcan" not in found:
        raw = env.get(ENV_VAR)
        where = ", ".join(f"{d}{'' if d.is_dir() else ' (missing)'}" for d in dirs)
        setting = f"{ENV_VAR}={raw!r}" if raw else f"{ENV_VAR} is unset, so the default was used"
        raise CyphalPathError(
            f"no DSDL root namespace 'uavcan' found; searched: {where} ({setting}). "
            f"{ENV_VAR} must list directories that CONTAIN root namespace directories such as uavcan/ "
            f"(e.g. the public_regulated_data_types checkout), separated by {os.pathsep!r}."
        )
    return [found[name] for name in sorted(found)]
