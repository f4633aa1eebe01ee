"""The processes of a service system test: the devices (a simulator or a plain peer), the bridge with its stats file,
and an independent rclpy client (tests/helpers/ros_service_client.py) that writes what it got as JSON.

Invariants: every process started through a ServiceRun is stopped when its `with` block ends, the last started
first (the client, then the bridge, then the devices), whether the block passed or failed; every wait has a
deadline.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from types import TracebackType
from typing import Any

from helpers.runtime_support import Proc, helper_cmd, poll_until, read_json, runtime_cmd


class ServiceRun:
    def __init__(self, env: dict[str, str], d: Path) -> None:
        self.env, self.d = env, d
        self.procs: list[Proc] = []
        self.stats_file = d / "bridge.json"

    def __enter__(self) -> ServiceRun:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        for p in reversed(self.procs):
            p.stop()

    def start(self, name: str, cmd: Sequence[str]) -> Proc:
        p = Proc(name, cmd, self.env, self.d)
        self.procs.append(p)
        return p

    def bridge(self, *args: str) -> Proc:
        """The bridge (`sam-codegen bridge` with these arguments), writing its stats to bridge.json."""
        self.bridge_proc = self.start("bridge", runtime_cmd("bridge", *args, "--stats-file", str(self.stats_file)))
        return self.bridge_proc

    def client(self, *args: str, timeout: float = 120.0) -> dict[str, Any]:
        """Run ros_service_client.py with these arguments to its end (it must exit 0): the JSON it wrote."""
        out = self.d / "client.json"
        client = self.start("client", helper_cmd("ros_service_client.py", "--out", str(out), *args))
        assert client.wait(timeout) == 0, client.stderr_tail()
        result: dict[str, Any] = json.loads(out.read_text())
        return result

    def param_client(self, *args: str, timeout: float = 120.0) -> dict[str, Any]:
        """Run param_client.py (the standard parameter services) with these arguments to its end (it must exit 0):
        the JSON it wrote."""
        out = self.d / "params.json"
        out.unlink(missing_ok=True)
        client = self.start("client", helper_cmd("param_client.py", "--out", str(out), *args))
        assert client.wait(timeout) == 0, (client.stderr_tail(), out.read_text() if out.exists() else "")
        result: dict[str, Any] = json.loads(out.read_text())
        self.procs.remove(client)
        return result

    def assert_bridge_alive(self) -> None:
        assert self.bridge_proc.proc.poll() is None, self.bridge_proc.stderr_tail()  # nothing raised into the bridge

    def duties(self, package: str, device: int, not_device: int, reboot_evidence: str) -> dict[str, Any]:
        """The client's `duties` scenario (tests/helpers/ros_service_client.py) against the device and a node id
        that is no device, the reboot seen by `reboot_evidence` (uptime or transfers_tx): its JSON, once the
        bridge's stats file (which follows its counters) has every get_node_info call it made and the bridge is
        still running."""
        result = self.client("duties", "--package", package, "--device", str(device), "--not-device",
                             str(not_device), "--reboot-evidence", reboot_evidence)
        calls = 3 + len(result.get("after_restart", []))  # info, info_not_device, before_restart (at least)
        poll_until(lambda: ((self.bridge_stats() or {}).get("services", {})
                            .get("node_services.get_node_info", {}).get("calls", 0)) >= calls, 20,
                   "the bridge's counts of the calls")
        self.assert_bridge_alive()
        return result

    def outcome(self) -> dict[str, Any]:
        """What the bridge left: its last stats and its stderr."""
        return {"bridge_stats": self.bridge_stats(), "bridge_stderr": self.bridge_stderr()}

    def bridge_stats(self) -> Any:
        return read_json(self.stats_file)

    def bridge_stderr(self) -> str:
        log = self.d / "bridge.stderr"
        return log.read_text() if log.exists() else ""


def requests_seen(peer: Proc) -> list[dict[str, Any]]:
    """The requests a peer printed (`REQUEST <json>` lines), in order."""
    return [json.loads(line.split(" ", 1)[1]) for line in peer.lines if line.startswith("REQUEST ")]
