"""Shared by the DroneCAN transport tests: private buses, frames, deadlines, helper processes."""

from __future__ import annotations

import asyncio
import itertools
import json
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from helpers.runtime_support import HELPERS

if TYPE_CHECKING:  # dronecan is imported when used: collecting this module must not need it
    from dronecan.driver.common import CANFrame

_bus_numbers = itertools.count()


def private_iface() -> str:
    """A loopback bus no other test session uses: bus and port from the pid, a new port per call."""
    pid = os.getpid()
    return f"mcast-lo:{pid % 250 + 1}:{20000 + (pid % 1000) * 10 + next(_bus_numbers) % 10}"


def frames_of(msg: Any, source: int, transfer_id: int) -> list[CANFrame]:
    """The CAN frames dronecan makes of one broadcast of ``msg``."""
    from dronecan import transport
    from dronecan.driver.common import CANFrame

    t = transport.Transfer(payload=msg, source_node_id=source, transfer_id=transfer_id, transfer_priority=20)
    return [CANFrame(f.message_id, bytearray(f.bytes), True) for f in t.to_frames()]


async def until(pred: Callable[[], Any], timeout: float, what: str) -> Any:
    deadline = time.monotonic() + timeout
    while not (value := pred()):
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
        await asyncio.sleep(0.02)
    return value


class Child:
    """A helper program in its own session: stdout lines collected, stdin closed to ask it to finish."""

    def __init__(self, name: str, script: str, args: list[str], log_dir: Path) -> None:
        self.name = name
        self.log = log_dir / f"{name}.stderr"
        with open(self.log, "w") as err:
            self.proc = subprocess.Popen([sys.executable, str(HELPERS / script), *args], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=err, text=True, start_new_session=True)
        self.lines: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def line(self, prefix: str) -> str | None:
        return next((ln for ln in self.lines if ln.startswith(prefix)), None)

    async def wait_line(self, prefix: str, timeout: float) -> str:
        def found() -> str | None:
            if self.proc.poll() is not None and self.line(prefix) is None:
                raise AssertionError(f"{self.name} exited ({self.proc.returncode}) without {prefix!r}: "
                                     f"{self.stderr_tail()}")
            return self.line(prefix)
        return await until(found, timeout, f"{self.name}: {prefix!r}")

    async def finish(self, prefix: str, timeout: float = 30.0) -> dict[str, Any]:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        line = await self.wait_line(prefix, timeout)
        await until(lambda: self.proc.poll() is not None, timeout, f"{self.name} to exit")
        assert self.proc.returncode == 0, self.stderr_tail()
        return json.loads(line.split(" ", 1)[1])

    def stderr_tail(self) -> str:
        return self.log.read_text(errors="replace")[-3000:]

    def group_alive(self) -> list[int]:
        """Processes left in this child's process group (its forked helpers), zombies aside."""
        alive = []
        for entry in Path("/proc").iterdir():
            if entry.name.isdigit():
                try:
                    fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
                except OSError:
                    continue
                if int(fields[2]) == self.proc.pid and fields[0] != "Z":
                    alive.append(int(entry.name))
        return alive

    def kill(self) -> None:
        if self.group_alive():
            os.killpg(self.proc.pid, signal.SIGKILL)
        if self.proc.poll() is None:
            self.proc.wait(timeout=10)


class PlainPeer:
    """A plain dronecan node in its own thread (dronecan nodes are single-threaded): broadcasts what it is given,
    records every message it receives as (type name, source node id, message)."""

    def __init__(self, iface: str, node_id: int) -> None:
        import dronecan

        from sam_runtime.dronecan_io import LoopbackMulticastDriver, parse_iface

        it = parse_iface(iface)
        self.node = dronecan.node.Node(LoopbackMulticastDriver(it.bus, it.port), node_id=node_id)
        self.node.node_info.name = f"org.test.peer{node_id}".encode()
        self.received: list[tuple[str, int, Any]] = []
        self._todo: queue.Queue[Any] = queue.Queue()
        self._stop = threading.Event()
        for name in ("uavcan.equipment.esc.RPMCommand", "uavcan.equipment.actuator.ArrayCommand",
                     "uavcan.protocol.Panic", "uavcan.protocol.GlobalTimeSync"):
            self.watch(name)
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            self.node.spin(0.01)
            while True:
                try:
                    self.node.broadcast(self._todo.get_nowait())
                except queue.Empty:
                    break

    def broadcast(self, msg: Any) -> None:
        self._todo.put(msg)

    def got(self, name: str) -> list[tuple[int, Any]]:
        return [(src, m) for n, src, m in list(self.received) if n == name]

    def watch(self, name: str) -> None:
        """Record the messages of one more data type (before anything of it is sent)."""
        import dronecan

        self.node.add_handler(dronecan.TYPENAMES[name], lambda e: self.received.append(
            (name, e.transfer.source_node_id, e.message)))

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self.node.close()
