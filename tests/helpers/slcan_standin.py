"""An SLCAN adapter stand-in on a pty, bridged to the loopback multicast bus.

python slcan_standin.py --bus mcast-lo:<bus>:<port>

Opens a pty pair and prints ``PTY /dev/pts/N``: open that with dronecan's SLCAN driver (``slcan:/dev/pts/N``).
Answers the adapter commands the driver sends at init (``C``, ``S<n>``, ``O``, ``F``: dronecan waits for each ACK,
so a bare pty pair fails with "SLCAN ACK timeout"), puts the frames the driver transmits on the bus and writes the
bus's frames to the driver. Runs until stdin closes or SIGTERM; then prints ``STATS {...}`` and exits 0.
"""

from __future__ import annotations

import argparse
import json
import os
import selectors
import signal
import sys
import tty
from typing import Any


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--bus", required=True, help="mcast-lo:<bus>:<port>")
    args = p.parse_args()

    from sam_runtime.dronecan_io import make_driver
    from sam_runtime.dronecan_io.slcan import SlcanAdapter

    bus = make_driver(args.bus)
    master, slave = os.openpty()
    # Raw before the client opens it: no echo of what we write back into what we read, no CR/LF translation.
    tty.setraw(slave)
    os.set_blocking(master, False)
    adapter = SlcanAdapter()
    stats: dict[str, Any] = {"to_bus": 0, "to_host": 0, "dropped_closed": 0}
    out = bytearray()
    running = [True]

    def on_term(*_: object) -> None:
        running[0] = False

    signal.signal(signal.SIGTERM, on_term)
    sel = selectors.DefaultSelector()
    sel.register(master, selectors.EVENT_READ, "pty")
    sel.register(bus.fileno(), selectors.EVENT_READ, "bus")
    sel.register(sys.stdin.fileno(), selectors.EVENT_READ, "stdin")
    print(f"PTY {os.ttyname(slave)}", flush=True)

    while running[0]:
        want = selectors.EVENT_READ | (selectors.EVENT_WRITE if out else 0)
        sel.modify(master, want, "pty")
        for key, events in sel.select(timeout=0.5):
            if key.data == "stdin":
                if not os.read(sys.stdin.fileno(), 4096):
                    running[0] = False
            elif key.data == "bus":
                while (frame := bus.receive(0)) is not None:
                    line = adapter.to_host(frame)
                    if line:
                        out += line
                        stats["to_host"] += 1
                    else:
                        stats["dropped_closed"] += 1
            elif events & selectors.EVENT_READ:
                try:
                    data = os.read(master, 65536)
                except (BlockingIOError, OSError):  # EIO: no process has the slave open right now
                    data = b""
                replies, frames = adapter.feed(data)
                out += replies
                for frame in frames:
                    bus.send_frame(frame)
                    stats["to_bus"] += 1
        if out:  # the driver's reader may be slow: keep the rest and wait for EVENT_WRITE
            try:
                del out[:os.write(master, out)]
            except BlockingIOError:
                pass
    stats.update(rejected_lines=adapter.rejected_lines, bitrate=adapter.bitrate, open=adapter.is_open,
                 bus_drops=bus.drops.snapshot())
    bus.close()
    os.close(master)
    os.close(slave)
    print("STATS " + json.dumps(stats), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
