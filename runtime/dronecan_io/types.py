"""The spec's own UAVCAN v0 types made known to ``dronecan`` without reloading the others.

``dronecan.load_dsdl`` replaces every type object of the process, the standard ones too: a handler registered on an
old one never fires again, and a message built from an old one no longer matches (a bridge, a simulated device or a
test's node in the same process). :func:`ensure_types` parses only the spec's folders (their references resolved
against dronecan's bundled definitions) and registers the new types beside the loaded ones, as ``load_dsdl`` would.

Which of dronecan's own definitions a spec uses is its choice (the tables' ``DRONECAN_NAMESPACES``; None: all of
them): :func:`select_types` makes ``dronecan.DATATYPES``, what dronecan decodes a transfer by, hold the types of those
namespaces, then the types added here for other specs of the process where their ids are free, then the spec's own
types, which win. So a transfer with data type id 20100 decodes as the spec's type when the spec does not load
com.hobbywing (whose RawCommand has 20100), and one of a namespace the spec does not load is an unknown data type
(counted, as any other). ``TYPENAMES`` keeps every type by name: names do not clash.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sam_codegen.contracts.tables_api import TablesModule


__all__ = ["DRONECAN_ROOTS", "add_types", "ensure_types", "select_types", "type_problems"]

# The root namespaces of dronecan's own definitions (what dronecan.load_dsdl() loads of its dsdl_specs/).
DRONECAN_ROOTS = ("uavcan", "dronecan", "ardupilot", "com", "cuav")
_ADDED: set[str] = set()  # full names of the types add_types registered (the specs' own)


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
    """The spec's own v0 types known to dronecan, ``DATATYPES`` made the spec's (:func:`select_types`: the
    namespaces it uses and its own types), then every type of the tables checked (ValueError).

    Added beside the types loaded already, never reloading them: ``dronecan.load_dsdl`` would replace every type
    object of the process, the standard ones too, and a handler registered on an old one never fires (a bridge, a
    test's node in the same process). Types that match the tables already are left alone."""
    tables = gen.tables()
    if type_problems(tables) and tables.DRONECAN_DSDL_DIRS:
        add_types([gen.root / folder for folder in tables.DRONECAN_DSDL_DIRS])
    select_types(tables.DRONECAN_NAMESPACES, {t.name for t in tables.DRONECAN_TYPES if t.custom})
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
    # The spec's files only, parsed as dsdl.parse_namespaces does but without its check that no two definitions of
    # all the folders share a data type id: the spec's own may reuse one of a namespace it does not load.
    parser = dsdl.parser.Parser([str(d) for d in root_namespace_dirs] + search)
    files = sorted(str(f) for d in root_namespace_dirs for f in Path(d).rglob("*.uavcan"))
    for dtype in (parser.parse(f) for f in files):
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
        _ADDED.add(dtype.full_name)


def select_types(namespaces: tuple[str, ...] | None, own: set[str]) -> None:
    """``dronecan.DATATYPES`` rebuilt in place: dronecan's own types of ``namespaces`` (None: every one), then the
    others (other specs' types added before; types loaded some other way) where their ids are free, then ``own`` (the
    spec's types, by full name)."""
    import dronecan

    def chosen(name: str) -> bool:
        return namespaces is None or any(name.startswith(ns + ".") for ns in namespaces)

    table: dict[tuple[int, int], Any] = {}
    others = []
    for name, t in dronecan.TYPENAMES.items():
        if not t.default_dtid or name in own:
            continue
        if name.split(".")[0] in DRONECAN_ROOTS and name not in _ADDED:
            if chosen(name):
                table.setdefault((t.default_dtid, t.kind), t)
        else:
            others.append(t)
    for t in others:
        table.setdefault((t.default_dtid, t.kind), t)
    for name in sorted(own):
        t = dronecan.TYPENAMES.get(name)
        if t is not None and t.default_dtid:
            table[(t.default_dtid, t.kind)] = t
    dronecan.DATATYPES.clear()
    dronecan.DATATYPES.update(table)
