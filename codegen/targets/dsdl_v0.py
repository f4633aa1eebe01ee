"""UAVCAN v0 (DroneCAN) DSDL emitter: the spec's `dronecan_types`, one file per type, in the layout
`dronecan.load_dsdl()` reads: dsdl_v0/<root namespace>/<namespace...>/<data type id>.<Name>.uavcan."""

from __future__ import annotations

from pathlib import Path

from sam_codegen.model.spec import V0Struct
from sam_codegen.render.templating import environment, render
from sam_codegen.targets.dsdl import dsdl_literal
from sam_codegen.validate.resolve import Resolved

ROOT = "dsdl_v0"


def v0_path(struct: V0Struct) -> str:
    """`sam.actuator.PositionFeedback` with id 20102 -> `sam/actuator/20102.PositionFeedback.uavcan`.

    >>> v0_path(V0Struct("sam.actuator.PositionFeedback", [], data_type_id=20102))
    'sam/actuator/20102.PositionFeedback.uavcan'
    """
    return "/".join(struct.namespace.split(".")) + "/" + struct.file_name


def load_dirs(resolved: Resolved) -> list[str]:
    """The folders (under generated/) to give dronecan.load_dsdl(): one per root namespace of the spec's types."""
    return sorted({f"{ROOT}/{struct.name.split('.')[0]}" for struct in resolved.dronecan_types})


def emit(resolved: Resolved) -> dict[str, str]:
    environment().filters.setdefault("dsdl_literal", dsdl_literal)
    spec_name = Path(resolved.spec.file).name
    return {
        f"{ROOT}/{v0_path(struct)}": render("dsdl/type.uavcan.j2", struct=struct, spec_name=spec_name)
        for struct in resolved.dronecan_types
    }
