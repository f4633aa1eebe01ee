"""DroneCAN interface URIs, and nodes built on them with the receive path of this package.

======================  ===========================================================================================
``mcast-lo:``           the loopback multicast bus 0 (group 239.65.82.0, UDP 57732): :class:`LoopbackMulticastDriver`
``mcast-lo:<bus>``      bus 0..255, the same group and port as dronecan's ``mcast:<bus>``
``mcast-lo:<bus>:<p>``  ... on UDP port ``p`` instead of 57732 (private buses for tests)
``slcan:<device>``      an SLCAN adapter on a serial port: dronecan's SLCAN driver (forks an IO process)
``socketcan:<ifname>``  a SocketCAN interface: dronecan's SocketCAN driver (not its python-can one: see the notes)
======================  ===========================================================================================

``mcast:`` is refused: dronecan's own multicast driver sends every frame and its IGMP reports out of the default
route. A bare name (``can0``, ``/dev/ttyACM0``) is refused too: dronecan would guess a driver, and for ``can0`` it
guesses its broken python-can one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from sam_runtime.dronecan_io.drops import DropCounter
from sam_runtime.dronecan_io.frame_gate import FrameGate
from sam_runtime.dronecan_io.loopback import LoopbackMulticastDriver
from sam_runtime.dronecan_io.mcast_packet import MCAST_PORT

__all__ = ["DEFAULT_BITRATE", "Iface", "IfaceError", "make_driver", "make_node", "parse_iface"]

DEFAULT_BITRATE = 1_000_000
_SCHEMES = ("mcast-lo", "slcan", "socketcan")


class IfaceError(ValueError):
    """An interface URI that names no usable DroneCAN transport."""


@dataclass(frozen=True)
class Iface:
    kind: str
    target: str = ""
    bus: int = 0
    port: int = MCAST_PORT

    def __str__(self) -> str:
        if self.kind == "mcast-lo":
            return f"mcast-lo:{self.bus}" + (f":{self.port}" if self.port != MCAST_PORT else "")
        return f"{self.kind}:{self.target}"


def parse_iface(uri: str) -> Iface:
    """The transport an interface URI names.

    >>> parse_iface("mcast-lo:"), parse_iface("mcast-lo:3:24001")
    (Iface(kind='mcast-lo', target='', bus=0, port=57732), Iface(kind='mcast-lo', target='', bus=3, port=24001))
    >>> str(parse_iface("slcan:/dev/ttyACM0"))
    'slcan:/dev/ttyACM0'
    >>> parse_iface("mcast:0")
    Traceback (most recent call last):
    ...
    sam_runtime.dronecan_io.iface.IfaceError: 'mcast:0': dronecan's mcast: driver sends out of the machine; use ...
    >>> parse_iface("mcast-lo:300")
    Traceback (most recent call last):
    ...
    sam_runtime.dronecan_io.iface.IfaceError: 'mcast-lo:300': bus must be 0..255
    """
    scheme, sep, rest = uri.partition(":")
    if not sep or scheme not in _SCHEMES:
        if scheme == "mcast" and sep:
            raise IfaceError(f"{uri!r}: dronecan's mcast: driver sends out of the machine; use mcast-lo:{rest}")
        raise IfaceError(f"{uri!r}: expected one of {', '.join(s + ':...' for s in _SCHEMES)}")
    if scheme != "mcast-lo":
        if not rest:
            raise IfaceError(f"{uri!r}: {scheme}: needs {'a device' if scheme == 'slcan' else 'an interface'} name")
        return Iface(scheme, rest)
    parts = rest.split(":") if rest else []
    if len(parts) > 2 or not all(p.isdigit() for p in parts):
        raise IfaceError(f"{uri!r}: expected mcast-lo:[<bus>[:<port>]] with decimal numbers")
    bus = int(parts[0]) if parts else 0
    port = int(parts[1]) if len(parts) > 1 else MCAST_PORT
    if bus > 255:
        raise IfaceError(f"{uri!r}: bus must be 0..255")
    if not 1 <= port <= 65535:
        raise IfaceError(f"{uri!r}: port must be 1..65535")
    return Iface("mcast-lo", "", bus, port)


def make_driver(uri: str, *, bitrate: int = DEFAULT_BITRATE, drops: DropCounter | None = None,
                **driver_kwargs: Any) -> Any:
    """A dronecan CAN driver for ``uri``. ``bitrate`` is for SLCAN adapters (the loopback bus has none, a SocketCAN
    interface is configured outside); ``drops`` counts what the loopback driver rejects (the others count nothing:
    their :class:`FrameGate` does)."""
    iface = parse_iface(uri)
    if iface.kind == "mcast-lo":
        return LoopbackMulticastDriver(iface.bus, iface.port, drops=drops, **driver_kwargs)
    if iface.kind == "slcan":
        from dronecan.driver.slcan import SLCAN

        return SLCAN(iface.target, bitrate=bitrate, **driver_kwargs)
    from dronecan.driver.socketcan import SocketCAN

    return SocketCAN(iface.target, **driver_kwargs)


def make_node(uri: str, node_id: int | None, *, bitrate: int = DEFAULT_BITRATE, transfer_timeout: float = 2.0,
              drops: DropCounter | None = None, **node_kwargs: Any) -> Any:
    """A ``dronecan.node.Node`` on ``uri`` behind a :class:`FrameGate`, ready for :class:`~.node_loop.NodeLoop`.

    ``node_kwargs`` go to the Node (``node_status_interval``, ``node_info``, ``mode``). Handler exceptions are not
    caught by dronecan (``catch_handler_exceptions=False``) so that the NodeLoop counts them. Create nodes before
    starting threads: dronecan's SLCAN driver forks.
    """
    import dronecan

    if node_id is not None and not 1 <= node_id <= 127:
        raise ValueError(f"UAVCAN v0 node id must be 1..127 (or None for a passive node), got {node_id}")
    gate = FrameGate(make_driver(uri, bitrate=bitrate, drops=drops), drops=drops, transfer_timeout=transfer_timeout)
    node_kwargs.setdefault("catch_handler_exceptions", False)
    try:
        return dronecan.node.Node(gate, node_id=node_id, **node_kwargs)
    except BaseException:
        gate.close()
        raise
