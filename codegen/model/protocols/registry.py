"""The protocols, registered: a new protocol is its own module beside cyphal.py and one line in REGISTERED.

The order is the spec's: the first is the default (a device without `protocol`, tables without layouts)."""

from __future__ import annotations

from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.description import ProtocolDescription
from sam_codegen.model.protocols.dronecan import DRONECAN

__all__ = ["DEFAULT_PROTOCOL", "PROTOCOL_NAMES", "REGISTERED", "UnknownProtocolError", "protocol"]

REGISTERED: tuple[ProtocolDescription, ...] = (CYPHAL, DRONECAN)

DEFAULT_PROTOCOL = REGISTERED[0]
PROTOCOL_NAMES: tuple[str, ...] = tuple(p.name for p in REGISTERED)


class UnknownProtocolError(ValueError):
    """A name no registered protocol has (the spec's validation reports these with their position first)."""


def protocol(name: str) -> ProtocolDescription:
    """The registered protocol called ``name``."""
    for p in REGISTERED:
        if p.name == name:
            return p
    raise UnknownProtocolError(f"unknown protocol {name!r}: expected one of {', '.join(PROTOCOL_NAMES)}")
