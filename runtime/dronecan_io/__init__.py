"""DroneCAN (UAVCAN v0) transport groundwork: drivers, the receive path, an asyncio runner, bus accounting.

- :class:`LoopbackMulticastDriver` (``mcast-lo:``): dronecan's ``mcast:`` packet format on 127.0.0.1 only; an
  :class:`Acceptance` filter in the kernel for nodes that listen to little.
- :class:`FrameGate`: between any dronecan driver and its Node; passes whole v0 transfers, counts the rest.
- :class:`NodeLoop`: runs a Node in the asyncio loop's thread; every ``spin()`` exception counted, never raised.
- :class:`DropCounter` / :class:`DropReason`: what was dropped and why.
- :mod:`.bus_load`: frames and bits per transfer; the share of a classic 1 Mbit/s CAN bus.
- :mod:`.slcan`: SLCAN lines and the adapter side of the protocol.
- :func:`make_node` / :func:`parse_iface`: nodes from interface URIs (``mcast-lo:``, ``slcan:``, ``socketcan:``).

The ``dronecan`` package is imported by these modules: install the ``runtime`` extra.
"""

from sam_runtime.dronecan_io.bus_load import BusLoadMeter, TransferCost, frame_bits, payload_length, transfer_cost
from sam_runtime.dronecan_io.drops import DropCounter, DropKey, DropLog, DropReason
from sam_runtime.dronecan_io.frame_gate import FrameGate
from sam_runtime.dronecan_io.iface import Iface, IfaceError, make_driver, make_node, parse_iface
from sam_runtime.dronecan_io.loopback import Acceptance, LoopbackMulticastDriver
from sam_runtime.dronecan_io.mcast_packet import MCAST_PORT, group_for_bus
from sam_runtime.dronecan_io.node_loop import HandlerError, NodeLoop, classify_spin_error, close_node

__all__ = [
    "MCAST_PORT",
    "Acceptance",
    "BusLoadMeter",
    "DropCounter",
    "DropKey",
    "DropLog",
    "DropReason",
    "FrameGate",
    "HandlerError",
    "Iface",
    "IfaceError",
    "LoopbackMulticastDriver",
    "NodeLoop",
    "TransferCost",
    "classify_spin_error",
    "close_node",
    "frame_bits",
    "group_for_bus",
    "make_driver",
    "make_node",
    "parse_iface",
    "payload_length",
    "transfer_cost",
]
