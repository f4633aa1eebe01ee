"""Where the Cyphal DSDL root namespaces (``uavcan``, ``reg``, vendor namespaces) are looked up.

In this order (earlier wins for a namespace found twice):

1. ``CYPHAL_PATH``, the Cyphal ecosystem convention that yakut and pycyphal follow: a list of directories that
   *contain* DSDL root namespace directories, separated by ``os.pathsep`` (``;`` is accepted too, as pycyphal and
   yakut do). When it is set, it is the whole search path.
2. When it is unset or empty, the conventional places: every checkout under ``~/.cyphal/`` (yakut's documentation
   clones e.g. ``~/.cyphal/public_regulated_data_types`` there), then, only when running from this repository's
   source tree, its development default: the shared copy ``<repo>/../shared/dsdl/public_regulated_data_types``.

When no ``uavcan`` namespace is found, :class:`CyphalPathError` says how to set CYPHAL_PATH.

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
    "conventional_search_dirs",
    "default_search_dirs",
    "dsdl_lookup_roots",
    "repo_root",
    "search_dirs",
    "source_checkout",
]

ENV_VAR = "CYPHAL_PATH"

# Same rule as pycyphal's DsdlMetaFinder, but anchored at both ends (".git", "docs-v2" are not namespaces).
_ROOT_NAMESPACE_NAME = re.compile(r"[a-zA-Z_][a-zA-Z0-9_]*")


class CyphalPathError(Exception):
    """No usable DSDL root namespace set (in particular no ``uavcan``) could be found."""


def repo_root() -> Path:
    """The folder above the sam_codegen package: the repository root in a source checkout (see source_checkout)."""
    return Path(__file__).resolve().parents[2]


def source_checkout() -> Path | None:
    """The repository root when running from this project's source tree; None in an installed wheel, whose
    package folder sits in site-packages."""
    root = repo_root()
    return root if (root / "pyproject.toml").is_file() and (root / "codegen").is_dir() else None


def default_search_dirs() -> list[Path]:
    """This repository's development default: the shared public regulated data types beside the checkout (none in an
    installed wheel)."""
    checkout = source_checkout()
    if checkout is None:
        return []
    return [(checkout.parent / "shared" / "dsdl" / "public_regulated_data_types").resolve()]


def conventional_search_dirs(environ: Mapping[str, str] | None = None) -> list[Path]:
    """The checkouts under ``~/.cyphal`` (each may hold root namespaces), by name."""
    env = os.environ if environ is None else environ
    home = env.get("HOME", "").strip()
    base = Path(home) / ".cyphal" if home else None
    if base is None:
        try:
            base = Path.home() / ".cyphal"
        except RuntimeError:  # no home directory at all
            return []
    try:
        return sorted(p.resolve() for p in base.iterdir() if p.is_dir() and not p.name.startswith("."))
    except OSError:
        return []


def search_dirs(environ: Mapping[str, str] | None = None) -> list[Path]:
    """The directories listed in CYPHAL_PATH (in order, duplicates removed); when it is unset or empty, the
    conventional ones, then the development default."""
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
    if not out:
        for p in (*conventional_search_dirs(env), *default_search_dirs()):
            if p not in out:
                out.append(p)
    return out


def _is_root_namespace_dir(p: Path) -> bool:
    if not p.is_dir() or not _ROOT_NAMESPACE_NAME.fullmatch(p.name):
        return False
    # A directory without any definition (docs/, tools/, an empty checkout) is not a namespace.
    return next(p.rglob("*.dsdl"), None) is not None


def dsdl_lookup_roots(environ: Mapping[str, str] | None = None) -> list[Path]:
    """The DSDL root namespace directories found in the :func:`search_dirs`.

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
        raw = env.get(ENV_VAR, "").strip()
        where = ", ".join(f"{d}{'' if d.is_dir() else ' (missing)'}" for d in dirs) or "nothing"
        fallback = "the checkouts in ~/.cyphal/" + (" and this repository's development default"
                                                    if source_checkout() is not None else "")
        setting = f"{ENV_VAR}={env.get(ENV_VAR)!r}" if raw else f"{ENV_VAR} is unset, so {fallback} were searched"
        raise CyphalPathError(
            f"no DSDL root namespace 'uavcan' found; searched: {where} ({setting}). "
            f"Set {ENV_VAR} to the directories that CONTAIN root namespace directories such as uavcan/, separated "
            f"by {os.pathsep!r}: e.g. clone the public regulated data types "
            "(github.com/OpenCyphal/public_regulated_data_types) and "
            f"`export {ENV_VAR}=/path/to/public_regulated_data_types`."
        )
    return [found[name] for name in sorted(found)]
