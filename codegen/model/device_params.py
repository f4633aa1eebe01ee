"""A board's settings (a device's `parameters:` in the spec): what each is, its range and default, and the name its
firmware knows it by on each protocol.

On Cyphal a setting is a register (``uavcan.register.Access`` / ``List``); on DroneCAN a parameter
(``uavcan.protocol.param.GetSet``, saved with ``param.ExecuteOpcode``). The spec names a setting once, by a name that
is a valid Cyphal register name and a valid ROS parameter name at the same time (lowercase, digits, ``_`` and ``.``
separators); where a board's firmware uses another name on a protocol, the spec gives it. The rules for names and
values live here, once: the frontend reports against them, the runtime (the boards' parameters as ROS parameters)
and the docs read them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Final, Literal

from sam_codegen.model.diagnostics import NOWHERE, Pos
from sam_codegen.model.protocols.description import ProtocolDescription

__all__ = [
    "FLOAT32_MAX",
    "INT64_MAX",
    "INT64_MIN",
    "PARAM_TYPES",
    "DeviceParameter",
    "ParamType",
    "ParamValue",
    "default_name_on",
    "name_problem",
    "register_name_problem",
]

ParamType = Literal["bool", "integer", "real", "string", "enum"]
PARAM_TYPES: Final[tuple[ParamType, ...]] = ("bool", "integer", "real", "string", "enum")
ParamValue = bool | int | float | str

INT64_MIN: Final = -(2**63)
INT64_MAX: Final = 2**63 - 1
# Reals travel as float32 on both protocols (DroneCAN's real_value; the register's real32[1]).
FLOAT32_MAX: Final = 3.4028234663852886e38

# uavcan.register.Access.1.0: lowercase alphanumerics, '.' and '_'; not starting with a digit; neither starting nor
# ending with '.'; an '_' followed by an alphanumeric only.
_REGISTER_NAME = re.compile(r"[a-z_][a-z0-9_.]*")
_RESERVED_PREFIX = "uavcan."  # the standard registers (node id, port ids, ...): the spec sets those itself


def register_name_problem(name: str, longest: int = 255) -> str | None:
    """Why `name` is not a valid application register name (None: it is).

    >>> register_name_problem("motor.pole_count") is None
    True
    >>> register_name_problem("Motor.poles")
    'a register name holds lowercase letters, digits, "_" and "." only'
    >>> register_name_problem("2nd.gain")
    'a register name does not begin with a digit'
    >>> register_name_problem("gain.")
    'a register name neither begins nor ends with "."'
    >>> register_name_problem("gain_.x")
    'a register name has no "_" before a non-alphanumeric character'
    >>> register_name_problem("uavcan.node.id")
    'names under "uavcan." are the standard registers, set from the spec itself'
    """
    if not name:
        return "a register name is not empty"
    if len(name.encode()) > longest:
        return f"a register name is at most {longest} bytes long"
    if name[0].isdigit():
        return "a register name does not begin with a digit"
    if not _REGISTER_NAME.fullmatch(name):
        return 'a register name holds lowercase letters, digits, "_" and "." only'
    if name.startswith(".") or name.endswith("."):
        return 'a register name neither begins nor ends with "."'
    if ".." in name:
        return 'a register name has no empty segment ("..")'
    if re.search(r"_(?![a-z0-9])", name):
        return 'a register name has no "_" before a non-alphanumeric character'
    if name.startswith(_RESERVED_PREFIX):
        return 'names under "uavcan." are the standard registers, set from the spec itself'
    return None


def name_problem(protocol: ProtocolDescription, name: str) -> str | None:
    """Why `name` cannot name a setting on `protocol` (None: it can): a register name by uavcan.register's rules, or
    a parameter name of printable ASCII without spaces (DroneCAN), within the protocol's longest name.

    >>> from sam_codegen.model.protocols.registry import protocol
    >>> name_problem(protocol("dronecan"), "ESC_NUM_POLES") is None
    True
    >>> name_problem(protocol("dronecan"), "pole count")
    'a DroneCAN parameter name is printable ASCII without spaces'
    >>> name_problem(protocol("cyphal"), "ESC_NUM_POLES")
    'a register name holds lowercase letters, digits, "_" and "." only'
    """
    if protocol.setting_name_style == "register":
        return register_name_problem(name, protocol.setting_name_max)
    what = f"a {protocol.label} {protocol.setting_noun} name"
    if not name:
        return f"{what} is not empty"
    if not all(33 <= ord(c) <= 126 for c in name):
        return f"{what} is printable ASCII without spaces"
    if len(name) > protocol.setting_name_max:
        return f"{what} is at most {protocol.setting_name_max} bytes long"
    return None


def default_name_on(protocol: ProtocolDescription, name: str) -> str:
    """The name on `protocol` of a setting the spec names `name`, unless the spec gives one: the spec's name for a
    register; upper case with "_" for "." for a DroneCAN parameter (the style of DroneCAN firmware: ArduPilot's
    AP_Periph, PX4).

    >>> from sam_codegen.model.protocols.registry import protocol
    >>> [default_name_on(protocol(p), "motor.pole_count") for p in ("dronecan", "cyphal")]
    ['MOTOR_POLE_COUNT', 'motor.pole_count']
    """
    return name.upper().replace(".", "_") if protocol.setting_name_style == "upper" else name


@dataclass(frozen=True)
class DeviceParameter:
    """One setting of a board.

    `minimum`/`maximum` bound an integer or a real (both given for those types); `unit` is a real's (and optionally
    an integer's) unit; `values` are an enum's names with the integers the firmware stores; `max_length` is a
    string's longest value in UTF-8 bytes. `restart`: a change takes effect after the board restarts.
    `names` is the setting's name on each protocol the board speaks (:func:`default_name_on` unless the spec gives
    another).
    """

    name: str
    type: ParamType
    default: ParamValue
    description: str = ""
    minimum: int | float | None = None
    maximum: int | float | None = None
    unit: str = ""
    values: tuple[tuple[str, int], ...] = ()
    max_length: int | None = None
    restart: bool = False
    names: tuple[tuple[str, str], ...] = ()  # (protocol, name on that protocol)
    pos: Pos = NOWHERE

    def name_on(self, protocol: str) -> str:
        """Its name on `protocol` (one the board speaks)."""
        return dict(self.names)[protocol]

    def stored(self, value: ParamValue) -> bool | int | float | str:
        """What a board stores for `value`: an enum's integer, every other value as it is."""
        return dict(self.values)[value] if self.type == "enum" and isinstance(value, str) else value
