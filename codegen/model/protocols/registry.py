"""The protocols, registered: a new protocol is its own module beside cyphal.py and one line in REGISTERED.

The order is the spec's: the first is the default (a device without `protocol`, tables without layouts)."""

from __future__ import annotations

from sam_codegen.model.protocols.cyphal import CYPHAL
from sam_codegen.model.protocols.description import ProtocolDescription
from sam_codegen.model.protocols.dronecan import DRONECAN

__all__ = ["REGISTERED", "UnknownProtocolError", "default_protocol", "protocol", "protocol_names", "registered"]

REGISTERED: tuple[ProtocolDescription, ...] = (CYPHAL, DRONECAN)


# Read at every call, never copied at import: what asks the registry sees a protocol registered later (a test's).
def registered() -> tuple[ProtocolDescription, ...]:
    return REGISTERED


def protocol_names() -> tuple[str, ...]:
    return tuple(p.name for p in REGISTERED)


def default_protocol() -> ProtocolDescription:
    return REGISTERED[0]


class UnknownProtocolError(ValueError):
    """A name no registered protocol has (the spec's validation reports these with their position first)."""


def protocol(name: str) -> ProtocolDescription:
    """The registered protocol called ``name``."""
    for p in REGISTERED:
        if p.name == name:
            return p
    raise UnknownProtocolError(f"unknown protocol {name!r}: expected one of {', '.join(protocol_names())}")
