"""One run of the CPU section (bench/cpu.py) for one protocol, in the network namespace it is started in.

    python -m bench.cpu_rig cyphal|dronecan --warm S --window S --workdir DIR [--lo-up]
                            [--profile PY_SPY --profile-s S [--profile-gil]]

1. starts the bridge (``python -m sam_runtime.cli bridge``, the command the main job runs) and the raw receiver
   (bench/cpu_raw.py), waits for both READY lines, and listens to the bridge's /diagnostics (bench/cpu_diag.py);
2. idle: after ``--warm`` s, CPU (utime + stime of every thread, /proc/PID/stat) and threads (/proc/PID/status)
   of both over ``--window`` s;
3. starts the simulated devices (``python -m sam_runtime.cli sim``, SAM's nominal rates) and waits for READY;
4. nominal: the same after ``--warm`` s, plus the messages the bridge published in the window (its /diagnostics:
   the mappings' ``published`` counters and the bridge's uptime, at both ends);
5. stops everything (SIGTERM, then SIGKILL) and prints ``RESULT {json}``.

``--lo-up`` brings the namespace's loopback up first (``unshare -n`` starts with it down). ``--profile`` runs
py-spy on the bridge during the nominal window (its collapsed stacks in DIR/profile.txt; ``--profile-gil``: only
the thread holding the GIL, i.e. Python at work, in DIR/profile-gil.txt); a profiled run's CPU
figures include py-spy's sampling and are not the section's figures. The children get SIGTERM when this process
dies (PR_SET_PDEATHSIG), without the main job's parent-watcher thread, which would add a thread to what is counted.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import fcntl
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path
from typing import IO, Any

import bench.common  # noqa: F401  (loopback discovery for the children)
from bench.common import REPO
from bench.cpu_diag import DiagnosticsWatch

CLK_TCK = os.sysconf("SC_CLK_TCK")
READY_TIMEOUT_S = 180.0  # a loaded 2-core machine starts rclpy + pycyphal in 5-30 s
STOP_TIMEOUT_S = 10.0
DIAG_TIMEOUT_S = 60.0  # the bridge publishes /diagnostics every second; discovery on a loaded machine takes longer
LAYOUT = {"cyphal": "default", "dronecan": "dronecan"}


def lo_up() -> None:
    """Set the loopback interface up (SIOCGIFFLAGS / SIOCSIFFLAGS), as ``ip link set lo up``."""
    siocgifflags, siocsifflags, iff_up = 0x8913, 0x8914, 0x1
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        flags = struct.unpack("16sh", fcntl.ioctl(s.fileno(), siocgifflags, struct.pack("16sh", b"lo", 0)))[1]
        fcntl.ioctl(s.fileno(), siocsifflags, struct.pack("16sh", b"lo", flags | iff_up))


def cpu_s(pid: int) -> float:
    """utime + stime of the whole process (every thread, live or ended), in seconds."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    fields = stat[stat.rindex(")") + 2:].split()  # after "pid (comm) ": fields[0] is field 3 (state)
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def threads(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("Threads:"):
            return int(line.split()[1])
    return -1


def _die_with_parent() -> None:
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM), 0, 0, 0)  # PR_SET_PDEATHSIG


class Child:
    """A started process whose stdout goes to DIR/NAME.out (READY and DONE lines) and stderr to DIR/NAME.log."""

    def __init__(self, name: str, cmd: list[str], workdir: Path) -> None:
        self.name = name
        self.out_path, self.log_path = workdir / f"{name}.out", workdir / f"{name}.log"
        self._files: list[IO[str]] = [open(self.out_path, "w"), open(self.log_path, "w")]
        self.proc = subprocess.Popen(cmd, stdout=self._files[0], stderr=self._files[1], stdin=subprocess.DEVNULL,
                                     cwd=REPO, preexec_fn=_die_with_parent)
        self.pid = self.proc.pid

    def lines(self) -> list[str]:
        return self.out_path.read_text(errors="replace").splitlines()

    def wait_ready(self, deadline: float) -> str:
        """The READY line; raises when the process ends or the deadline passes first (with its log's tail)."""
        while True:
            ready = next((ln for ln in self.lines() if ln.startswith("READY")), None)
            if ready is not None:
                return ready
            if self.proc.poll() is not None or time.monotonic() > deadline:
                tail = "\n".join(self.log_path.read_text(errors="replace").splitlines()[-15:])
                state = f"exited {self.proc.returncode}" if self.proc.poll() is not None else "not READY in time"
                raise RuntimeError(f"{self.name} {state}:\n{tail}")
            time.sleep(0.1)  # polling a file for a line the child prints: no timing is measured here

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for f in self._files:
            f.close()

    def done(self) -> dict[str, Any] | None:
        line = next((ln for ln in self.lines() if ln.startswith("DONE ")), None)
        try:
            return json.loads(line[5:]) if line else None
        except ValueError:
            return None


def window(children: dict[str, Child], warm_s: float, window_s: float, watch: DiagnosticsWatch,
           profile: tuple[str, float, Path, bool] | None = None) -> dict[str, Any]:
    """Warm up, then CPU and threads of each child over the window, and the messages the bridge published."""
    time.sleep(warm_s)  # the measurement's warm-up (start-up transients out of the window), not a wait for an event
    b0 = watch.next(DIAG_TIMEOUT_S)  # first: its wait (up to the 1 s period) stays out of the CPU window
    load_before = os.getloadavg()
    t0 = time.monotonic()
    c0 = {n: cpu_s(c.pid) for n, c in children.items()}
    spy = None
    if profile is not None:
        exe, seconds, out, gil = profile
        spy = subprocess.Popen([exe, "record", "--pid", str(children["bridge"].pid), "--format", "raw", "--threads",
                                "--nonblocking", *(["--gil"] if gil else []), "--rate", "100",
                                "--duration", str(int(seconds)), "-o", str(out)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(window_s)  # the measurement window itself
    c1 = {n: cpu_s(c.pid) for n, c in children.items()}
    wall = time.monotonic() - t0
    b1 = watch.next(DIAG_TIMEOUT_S)
    out_: dict[str, Any] = {"window_s": round(wall, 3), "loadavg_before": [round(x, 2) for x in load_before],
                            "loadavg_after": [round(x, 2) for x in os.getloadavg()]}
    for n, c in children.items():
        out_[n] = {"cpu_s": round(c1[n] - c0[n], 3), "cpu_percent": round(100.0 * (c1[n] - c0[n]) / wall, 3),
                   "threads": threads(c.pid)}
    rate = (b1.published - b0.published) / (b1.uptime_s - b0.uptime_s) if b1.uptime_s > b0.uptime_s else 0.0
    msgs = rate * wall
    out_["bridged_per_s"] = round(rate, 2)
    out_["bridged_in_window"] = round(msgs)
    out_["dropped_in_window"] = b1.dropped - b0.dropped
    for n in children:
        if n != "sim":
            out_[n]["us_per_message"] = round(1e6 * out_[n]["cpu_s"] / msgs, 1) if msgs else None
    if spy is not None:
        try:
            _, err = spy.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            spy.kill()
            _, err = spy.communicate()
        out_["profile_rc"] = spy.returncode
        if spy.returncode:
            out_["profile_error"] = err[-2000:]
    return out_


def run(protocol: str, warm_s: float, window_s: float, workdir: Path,
        profile: tuple[str, float, bool] | None = None) -> dict[str, Any]:
    workdir.mkdir(parents=True, exist_ok=True)
    py = [sys.executable, "-m", "sam_runtime.cli"]
    common = ["--generated", str(REPO / "generated"), "--transport", "udp", "--iface", "127.0.0.1",
              "--dronecan-iface", "mcast-lo:", "--layout", LAYOUT[protocol]]
    started: list[Child] = []
    watch: DiagnosticsWatch | None = None
    res: dict[str, Any] = {"protocol": protocol, "layout": LAYOUT[protocol], "counted_from": "/diagnostics"}
    try:
        deadline = time.monotonic() + READY_TIMEOUT_S
        started.append(Child("bridge", [*py, "bridge", *common], workdir))
        started.append(Child("raw", [sys.executable, "-m", "bench.cpu_raw", protocol, "--layout", LAYOUT[protocol]],
                             workdir))
        res["ready"] = {c.name: c.wait_ready(deadline) for c in started}
        pair = {c.name: c for c in started}
        watch = DiagnosticsWatch()
        if profile is None:
            res["idle"] = window(pair, warm_s, window_s, watch)
        sim = Child("sim", [*py, "sim", *common], workdir)
        started.append(sim)
        res["ready"]["sim"] = sim.wait_ready(time.monotonic() + READY_TIMEOUT_S)
        prof = None if profile is None else (profile[0], profile[1],
                                             workdir / ("profile-gil.txt" if profile[2] else "profile.txt"), profile[2])
        res["nominal"] = window({**pair, "sim": sim}, warm_s, window_s, watch, prof)
    finally:
        for c in reversed(started):
            c.stop()
        if watch is not None:
            watch.close()
    res["raw_done"] = started[1].done() if len(started) > 1 else None
    return res


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.cpu_rig", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("protocol", choices=sorted(LAYOUT))
    ap.add_argument("--warm", type=float, default=15.0)
    ap.add_argument("--window", type=float, default=40.0)
    ap.add_argument("--workdir", type=Path, required=True)
    ap.add_argument("--lo-up", action="store_true")
    ap.add_argument("--profile", default=None, help="py-spy executable: profile the bridge in the nominal window")
    ap.add_argument("--profile-s", type=float, default=20.0)
    ap.add_argument("--profile-gil", action="store_true", help="py-spy --gil: only the thread holding the GIL")
    args = ap.parse_args(argv)
    if args.lo_up:
        lo_up()
    try:
        res = run(args.protocol, args.warm, args.window, args.workdir,
                  None if args.profile is None else (args.profile, args.profile_s, args.profile_gil))
    except RuntimeError as ex:
        res = {"protocol": args.protocol, "error": str(ex)}
    print("RESULT " + json.dumps(res), flush=True)
    return 0 if "error" not in res else 1


if __name__ == "__main__":
    sys.exit(main())
