"""What the device stand-ins written against the plain ``dronecan`` API share (esc_status_peer.py,
leak_sensor_peer.py, power_board.py, trawler_panel.py): a node on a loopback ``mcast-lo:`` bus, waiting until the
bridge is heard, paced broadcasts, and the serve loop that publishes once a start file exists and ends on SIGTERM.

Each stand-in runs as a script (tests/helpers is its sys.path[0]) and imports this module by its bare name; dronecan
is imported when a function runs, so collecting the tests needs no dronecan. The stand-ins' output lines (``READY``,
``PUBLISHED``, ``SUMMARY``, ``TIMEOUT``) are the tests' protocol and stay in the scripts, except ``TIMEOUT``, which
`wait_until_heard` prints.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any


def loopback_node(iface: str, node_id: int) -> Any:
    """A dronecan node on ``iface`` (``mcast-lo:<bus>:<port>``) with a static id, sending NodeStatus every 0.5 s."""
    import dronecan

    from sam_runtime.dronecan_io import LoopbackMulticastDriver, parse_iface

    spec = parse_iface(iface)
    return dronecan.node.Node(LoopbackMulticastDriver(spec.bus, spec.port), node_id=node_id,
                              node_status_interval=0.5, mode=0)


def with_spec_types(generated: str) -> Any:
    """dronecan, knowing the spec's own types the way the runtime gives them to it (dronecan_io.types.ensure_types)."""
    import dronecan

    from sam_runtime.dronecan_io.types import ensure_types
    from sam_runtime.genpkg import GeneratedPackage

    ensure_types(GeneratedPackage(Path(generated)))
    return dronecan


def wait_until_heard(node: Any, node_id: int, end: float) -> bool:
    """Spin until a NodeStatus of ``node_id`` arrives (True), or print ``TIMEOUT ...`` at ``end`` (False)."""
    import dronecan

    seen: set[int] = set()
    node.add_handler(dronecan.uavcan.protocol.NodeStatus, lambda e: seen.add(e.transfer.source_node_id))
    while node_id not in seen:
        if time.monotonic() > end:
            print(f"TIMEOUT waiting for node {node_id}", flush=True)
            return False
        node.spin(0.05)
    return True


def broadcast_paced(node: Any, messages: Iterable[Any], rate: float, end: float) -> int:
    """Broadcast each message then spin 1/``rate`` s, until ``end``; then 0.2 s more for the last frames.
    Returns how many were sent."""
    sent = 0
    for message in messages:
        if time.monotonic() >= end:
            break
        node.broadcast(message)
        sent += 1
        node.spin(1.0 / rate)
    node.spin(0.2)  # the last frames out
    return sent


def stop_on_sigterm() -> threading.Event:
    """An event that SIGTERM sets (install it before printing READY: the test may stop the process any time after)."""
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    return stop


def serve(node: Any, stop: threading.Event, max_life: float, start_file: str, publish: Callable[[], None]) -> None:
    """Spin until ``stop`` or ``max_life`` s; ``publish`` once, as soon as ``start_file`` exists. Closes the node."""
    published = False
    end = time.monotonic() + max_life
    try:
        while not stop.is_set() and time.monotonic() < end:
            node.spin(0.05)
            if not published and Path(start_file).exists():
                published = True
                publish()
    finally:
        node.close()
