"""The bridge's Cyphal ports as named ports with standard registers (issue 11, defect 12).

The Cyphal convention (Specification, section "Register interface"; pycyphal.application's
``node.make_publisher(Type, "port_name")``): a node's port named ``P`` has the registers ``uavcan.pub.P.id`` /
``uavcan.sub.P.id`` (natural16, the subject id; 65535 = not configured) and ``uavcan.pub.P.type`` /
``uavcan.sub.P.type`` (string, the data type), and a register ``uavcan.node.id``. Register values come from the
environment as usual: ``UAVCAN__SUB__IMU__ID=1234`` sets ``uavcan.sub.imu.id``.

The bridge names its ports after its mappings (``uavcan.sub.imu``, ``uavcan.pub.thruster_1_rpm``) with the
spec's subject ids as defaults. Several UAVCAN -> ROS mappings of one subject share one subscription, named after
the first of them in the spec (SAM: ``battery_state`` serves ``battery_info`` too).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from sam_codegen.model.spec import UAVCAN_TO_ROS

__all__ = ["SUBJECT_ID_MAX", "PortConfigError", "register_environment", "register_node_id", "resolve_subject",
           "subscription_names"]

SUBJECT_ID_MAX = 8191


class PortConfigError(ValueError):
    """A port register holds no usable subject id."""


def subscription_names(mappings: Iterable[Any]) -> dict[int, str]:
    """Subject id -> port name of the UAVCAN -> ROS subscriptions: the first mapping of each subject.

    >>> from types import SimpleNamespace as S
    >>> subscription_names([S(name="b_state", direction="uavcan_to_ros", port=S(subject_id=7)),
    ...                     S(name="cmd", direction="ros_to_uavcan", port=S(subject_id=8)),
    ...                     S(name="b_info", direction="uavcan_to_ros", port=S(subject_id=7))])
    {7: 'b_state'}
    """
    out: dict[int, str] = {}
    for m in mappings:
        if m.direction == UAVCAN_TO_ROS:
            pid = m.data_type.data_type_id if hasattr(m, "data_type") else m.port.subject_id  # DroneCAN: by type
            out.setdefault(int(pid), str(m.name))
    return out


def resolve_subject(registry: Any, kind: str, name: str, dtype: type, default: int) -> int:
    """The subject id of port ``name`` (kind ``pub`` or ``sub``): register ``uavcan.<kind>.<name>.id``, created
    with ``default`` unless it exists (the registry's environment variables override it on creation), and its
    ``.type`` register; as pycyphal.application's Node.make_publisher/make_subscriber do for a named port."""
    import pycyphal.application.register as reg
    import pycyphal.dsdl

    id_name, type_name = f"uavcan.{kind}.{name}.id", f"uavcan.{kind}.{name}.type"
    env = id_name.upper().replace(".", "__")
    try:
        subject = int(registry.setdefault(id_name, reg.Value(natural16=reg.Natural16([int(default)]))))
    except (TypeError, ValueError, OverflowError):  # pycyphal's ValueConversionError is a ValueError
        raw = registry.environment_variables.get(env, b"")
        raw = raw.decode(errors="replace") if isinstance(raw, bytes) else str(raw)
        raise PortConfigError(f"{env}={raw!r} is not a subject id (0..{SUBJECT_ID_MAX}): register {id_name}") from None
    model = str(pycyphal.dsdl.get_model(dtype))
    registry[type_name] = lambda: reg.Value(string=reg.String(model))
    if not 0 <= subject <= SUBJECT_ID_MAX:
        raise PortConfigError(f"register {id_name} = {subject} is not a subject id (0..{SUBJECT_ID_MAX}; 65535 = "
                              f"not configured): the bridge needs this port; unset {env} or give it a subject id")
    return subject


def register_node_id(registry: Any, node_id: int) -> None:
    """``uavcan.node.id``: the node id the bridge runs with (pycyphal creates it only when it builds the
    transport itself from registers)."""
    import pycyphal.application.register as reg

    registry["uavcan.node.id"] = reg.Value(natural16=reg.Natural16([int(node_id)]))


def register_environment(environ: Mapping[str, str]) -> dict[str, str]:
    """The UAVCAN__* variables that configure registers, without the node id (the bridge decides it).

    >>> register_environment({"UAVCAN__SUB__IMU__ID": "5", "UAVCAN__NODE__ID": "7", "HOME": "/root"})
    {'UAVCAN__SUB__IMU__ID': '5'}
    """
    return {k: str(v) for k, v in environ.items() if k.startswith("UAVCAN__") and k != "UAVCAN__NODE__ID"}
