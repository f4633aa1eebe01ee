"""ROS message definitions: the ones validation derived, the spec's own, the spec's external ones, the standard ones
the tool knows (catalogs.ros_known: tf2_msgs/TFMessage) and the installed packages' .msg files, in that order.

Invariant: a catalog never changes the spec nor a message it returns; what it reads from disk it caches, so one
name gives one message object for the catalog's life.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Mapping
from pathlib import Path

from sam_codegen.catalogs.ros_known import known_message
from sam_codegen.model.diagnostics import Pos
from sam_codegen.model.spec import Constant, Field, RosMessage, Scalar, Spec
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES, parse_ros_type

_CONSTANT = re.compile(r"^(?P<type>\S+)\s+(?P<name>[A-Za-z][A-Za-z0-9_]*)\s*=\s*(?P<value>.*)$")
_FIELD = re.compile(r"^(?P<type>\S+)\s+(?P<name>[A-Za-z][A-Za-z0-9_]*)(?:\s+(?P<default>.+))?$")


def _literal(type_name: str, text: str) -> Scalar:
    text = text.strip()
    if type_name in ROS_INT_RANGES:
        return int(text, 0)
    if type_name in ROS_FLOAT_BITS:
        return float(text)
    if type_name == "bool":
        return text.lower() in ("true", "1")
    return text.strip("'\"")


def parse_msg(text: str, package: str, name: str, file: str = "", external: bool = False) -> RosMessage:
    """Parse a .msg file (comments kept per field, defaults and constants read); `external`: it is not the spec's.

    >>> m = parse_msg("int8 A=1  # first\\nfloat64[9] cov # row major\\nint8 s -2", "p", "M")
    >>> [(f.name, str(f.type), f.default, f.comment) for f in m.fields], m.constants[0].value
    ([('cov', 'float64[9]', None, 'row major'), ('s', 'int8', -2, '')], 1)
    """
    fields: list[Field] = []
    constants: list[Constant] = []
    for number, raw in enumerate(text.splitlines(), 1):
        line, _, comment = raw.partition("#")
        line = line.strip()
        if not line:
            continue
        pos = Pos(file, number, 1)
        constant = _CONSTANT.match(line)
        if constant:
            type_ = parse_ros_type(constant["type"], package)
            constants.append(
                Constant(constant["name"], type_, _literal(type_.base, constant["value"]), comment.strip(), pos)
            )
            continue
        match = _FIELD.match(line)
        if not match:
            raise ValueError(f"{file}:{number}: cannot parse {line!r}")
        type_ = parse_ros_type(match["type"], package)
        default = None
        if match["default"] and not type_.array:
            default = _literal(type_.base, match["default"])
        fields.append(Field(match["name"], type_, comment.strip(), pos, default))
    return RosMessage(package, name, fields, constants, external=external, pos=Pos(file))


def ros_share_dirs() -> list[Path]:
    """Where installed ROS packages keep share/<pkg>/msg: AMENT_PREFIX_PATH, then this interpreter's prefix."""
    prefixes = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    prefixes.append(Path(sys.prefix))
    seen: list[Path] = []
    for prefix in prefixes:
        share = prefix / "share"
        if share.is_dir() and share not in seen:
            seen.append(share)
    return seen


class RosCatalog:
    """Looks ROS message definitions up by `pkg/Name`, caching what it reads.

    `derived` overlays the spec's messages: the messages validation derived from DSDL types (`derive_from`), by
    full name, which replace the spec's declarations of them.
    """

    def __init__(self, spec: Spec, share_dirs: list[Path] | None = None,
                 derived: Mapping[str, RosMessage] | None = None) -> None:
        self._spec = spec
        self._share_dirs = ros_share_dirs() if share_dirs is None else share_dirs
        self._derived = dict(derived or {})
        self._cache: dict[str, RosMessage | None] = {}

    @property
    def messages(self) -> dict[str, RosMessage]:
        """The spec's own messages by full name, in spec order, each as derived where it is."""
        return {name: self._derived.get(name, message) for name, message in self._spec.messages.items()}

    def get(self, full_name: str) -> RosMessage | None:
        if full_name in self._derived:
            return self._derived[full_name]
        if full_name in self._spec.messages:
            return self._spec.messages[full_name]
        if full_name in self._spec.external_messages:
            return self._spec.external_messages[full_name]
        known = known_message(full_name)  # the standard messages the tool knows (tf2_msgs/TFMessage)
        if known is not None:
            return known
        if full_name not in self._cache:
            self._cache[full_name] = self.read_installed(full_name)
        return self._cache[full_name]

    def read_installed(self, full_name: str) -> RosMessage | None:
        """The installed definition of `pkg/Name` (read anew, not cached), whatever the spec declares."""
        package, _, name = full_name.partition("/")
        for share in self._share_dirs:
            path = share / package / "msg" / f"{name}.msg"
            if path.is_file():
                return parse_msg(path.read_text(encoding="utf-8"), package, name, str(path), external=True)
        return None
