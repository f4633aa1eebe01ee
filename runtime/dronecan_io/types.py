"""The spec's own UAVCAN v0 types made known to ``dronecan`` without reloading the others.

``dronecan.load_dsdl`` replaces every type object of the process, the standard ones too: a handler registered on an
old one never fires again, and a message built from an old one no longer matches (a bridge, a simulated device or a
test's node in the same process). :func:`ensure_types` parses only the spec's folders (their references resolved
against dronecan's bundled definitions) and registers the new types beside the loaded ones, as ``load_dsdl`` would.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sam_codegen.targets.python.tables_api import TablesModule


__all__ = ["add_types", "ensure_types", "type_problems"]


def type_problems(tables: TablesModule) -> list[str]:
    """How the types dronecan has loaded differ from the tables' DRONECAN_TYPES (data type id and signature)."""
    import dronecan

    problems = []
    for info in tables.DRONECAN_TYPES:
        t = dronecan.TYPENAMES.get(info.name)
        if t is None:
            problems.append(f"{info.name}: not loaded")
        elif t.default_dtid != info.data_type_id or t.get_data_type_signature() != info.signature:
            problems.append(f"{info.name}: data type id {t.default_dtid}, signature "
                            f"0x{t.get_data_type_signature():016X}; the spec's: {info.data_type_id}, "
                            f"0x{info.signature:016X}")
    return problems


def ensure_types(gen: Any) -> None:
    """The spec's own v0 types known to dronecan, then every type of the tables checked (ValueError).

    Added beside the types loaded already, never reloading them: ``dronecan.load_dsdl`` would replace every type
    object of the process, the standard ones too, and a handler registered on an old one never fires (a bridge, a
    test's node in the same process). Types that match the tables already are left alone."""
    tables = gen.tables()
    if type_problems(tables) and tables.DRONECAN_DSDL_DIRS:
        add_types([gen.root / folder for folder in tables.DRONECAN_DSDL_DIRS])
    problems = type_problems(tables)
    if problems:
        raise ValueError("the DroneCAN types of " + str(gen.root) + ": " + "; ".join(problems))


def add_types(root_namespace_dirs: list[Path]) -> None:
    """Parse the v0 types under these root namespace folders (their references resolved against dronecan's own
    definitions) and register them as ``dronecan.load_dsdl`` does, without touching the types loaded already."""
    import struct

    import dronecan
    from dronecan import dsdl, transport

    bundled = Path(dronecan.__file__).parent / "dsdl_specs"
    search = [str(p) for p in sorted(bundled.iterdir()) if p.is_dir()] if bundled.is_dir() else []
    for dtype in dsdl.parse_namespaces([str(d) for d in root_namespace_dirs], search):
        def instance(*args: Any, _type: Any = dtype, _mode: str | None = None, **kwargs: Any) -> Any:
            return transport.CompoundValue(_type, _mode, *args, **kwargs)

        dtype._instantiate = instance
        if dtype.kind == dtype.KIND_SERVICE:
            dtype.Request = functools.partial(instance, _mode="request")
            dtype.Response = functools.partial(instance, _mode="response")
        if dtype.default_dtid:
            dtype.base_crc = dsdl.crc16_from_bytes(struct.pack("<Q", dtype.get_data_type_signature()))
            dronecan.DATATYPES[(dtype.default_dtid, dtype.kind)] = dtype
        dronecan.TYPENAMES[dtype.full_name] = dtype
