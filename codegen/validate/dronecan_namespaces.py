"""`dronecan_namespaces`: which namespaces of the standard v0 definitions a spec uses, and a data type id of the spec's
own types that one of them takes.

The catalog (catalogs.dronecan.V0Catalog) knows only the definitions inside the chosen namespaces; here the choice
itself is checked (each entry a namespace the standard definitions have, none twice), and a clash of a spec type's
id with a standard type is worded so that it names the namespace that brings the standard type in and whether the
spec chose it or the default did.
"""

from __future__ import annotations

from sam_codegen.catalogs.dronecan import V0Catalog
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import Spec

__all__ = ["check_namespaces", "clash_message", "outside_message"]

_SHOWN = 12  # namespaces named in the error's expectation, at most


def check_namespaces(spec: Spec, catalog: V0Catalog, diag: Diagnostics) -> None:
    """Each entry of `dronecan_namespaces` a namespace of the standard definitions, none twice."""
    chosen = spec.dronecan_namespaces
    if chosen is None or not catalog.roots:  # no definitions at all: reported where a type is looked up
        return
    known = catalog.known_namespaces()
    roots = sorted(r.name for r in catalog.roots)
    seen: dict[str, Pos] = {}
    for name, pos in zip(chosen, spec.dronecan_namespaces_pos, strict=True):
        if name in seen:
            diag.error(pos, f"DroneCAN namespace {name!r} appears twice in dronecan_namespaces "
                       f"(first at line {seen[name].line})", "each namespace once")
            continue
        seen[name] = pos
        if name not in known:
            inside = sorted(k for k in known if k.count(".") == 1 and k.split(".")[0] == name.split(".")[0])
            hint = f"; inside {name.split('.')[0]}: {', '.join(inside[:_SHOWN])}" if inside else ""
            diag.error(pos, f"unknown DroneCAN namespace {name!r} in dronecan_namespaces",
                       f"a namespace of the standard definitions: {', '.join(roots)}, or one inside them, "
                       f"e.g. com.hobbywing{hint}")


def clash_message(spec: Spec, catalog: V0Catalog, dtid: int, what: str, standard: str) -> tuple[str, str]:
    """The error and expectation of a spec type `what` whose data type id `dtid` the standard type `standard` has."""
    namespace = next((ns for ns in sorted(catalog.namespaces, key=len, reverse=True)
                      if standard.startswith(ns + ".")), standard.split(".")[0])
    how = "which dronecan_namespaces loads" if spec.dronecan_namespaces is not None else \
        "loaded by default (no dronecan_namespaces: every namespace)"
    message = f"data type id {dtid} of {what} is taken by the standard type {standard} of namespace {namespace}, {how}"
    if namespace == "uavcan":
        return message, "a free vendor-specific id, e.g. in 20101..20199"
    return message, (f"a free vendor-specific id, e.g. in 20101..20199, or dronecan_namespaces without "
                     f"{namespace} if the vehicle never uses it")


def outside_message(catalog: V0Catalog, name: str, what: str) -> tuple[str, str] | None:
    """The error and expectation for a standard type `name` that exists but lies outside the namespaces the spec
    uses; None when no standard definition has that name."""
    if name not in catalog.all_files():
        return None
    root, namespace = name.split(".")[0], name.rsplit(".", 1)[0]
    either = root if namespace == root else f"{root} or {namespace}"
    return (f"DroneCAN type {name} of {what} is in namespace {root}, which dronecan_namespaces does not load",
            f"{either} in dronecan_namespaces")
