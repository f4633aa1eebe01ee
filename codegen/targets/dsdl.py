"""Cyphal DSDL emitter: the spec's own types, one file per type under dsdl/<root namespace>/."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

from sam_codegen.model.spec import Scalar
from sam_codegen.render.templating import environment, render
from sam_codegen.validate.resolve import Resolved


def dsdl_literal(value: Scalar | Fraction) -> str:
    """A constant's value in DSDL syntax.

    >>> dsdl_literal(True), dsdl_literal(3), dsdl_literal(0.25)
    ('true', '3', '0.25')
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


def dsdl_path(name: str) -> str:
    """`sam.sensor.RawIMU.0.1` -> `sam/sensor/RawIMU.0.1.dsdl`.

    >>> dsdl_path("sam.sensor.RawIMU.0.1")
    'sam/sensor/RawIMU.0.1.dsdl'
    """
    parts = name.split(".")
    return "/".join(parts[:-3]) + "/" + ".".join(parts[-3:]) + ".dsdl"


def emit(resolved: Resolved) -> dict[str, str]:
    environment().filters.setdefault("dsdl_literal", dsdl_literal)
    spec_name = Path(resolved.spec.file).name
    files = {
        f"dsdl/{dsdl_path(struct.name)}": render("dsdl/type.dsdl.j2", struct=struct, spec_name=spec_name)
        for struct in resolved.dsdl_types
    }
    for service in resolved.dsdl_services:  # request, `---`, response: each half sealed or with the extent
        files[f"dsdl/{dsdl_path(service.name)}"] = render("dsdl/service.dsdl.j2", service=service,
                                                          spec_name=spec_name)
    return files
