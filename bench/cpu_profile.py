"""Where the bridge's CPU goes at nominal traffic: py-spy on ``sam-codegen bridge``, summarised per subsystem.

    python -m bench.cpu_profile --py-spy PATH [--seconds 20] [--protocols cyphal,dronecan] [--out DIR]
    python -m bench.cpu_profile --summarise FILE       (a py-spy ``--format raw`` file: print its summary)

Each protocol gets two runs of its own (bench/cpu_rig.py with ``--profile``: the bridge, the raw receiver and the
sim as in the CPU section, py-spy ``record --format raw --threads --nonblocking`` for ``--seconds`` of the nominal
window): ``active``, every thread that is not sleeping, and ``gil``, only the thread holding the GIL (``--gil``:
Python at work, without the time in system calls and in the run queue). py-spy is not a dependency of the
project: install it anywhere (``python3 -m pip install py-spy``) and give its path. The summary goes into the CPU
section of DIR/results.json and results.md (default bench/results); the full listing is printed.

A sample is one running thread at one instant (py-spy leaves out threads it sees idle). A thread woken up but
waiting for a core, or for the GIL, is not idle to py-spy: on a loaded machine samples / (seconds x rate) is well
above the process's CPU (both are recorded), which is why the ``gil`` view is taken beside it. Each sample is
charged to the subsystem of its innermost frame that one of ``RULES`` names (a leaf in the standard library is
charged to its caller's subsystem), or to ``waiting`` when the innermost line is a select/poll/wait call (a thread
woken up, or its polling timeout).
"""

from __future__ import annotations

import argparse
import json
import linecache
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path
from typing import Any

from bench.common import RESULTS, log

RATE_HZ = 100
FRAME = re.compile(r"^(?P<func>.*) \((?P<file>[^():]+):(?P<line>\d+)\)$")
WAIT_CALL = re.compile(r"(\bselect\.select|\.select|\.poll|\bpoll|\.wait|\bwait_for_ready_callbacks|\bsleep)\(")
# (subsystem, pattern on "func (file:line)"), first match from the innermost frame outwards
RULES: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("codec / converters (generated)", re.compile(r"sam_bridge/(codec|codec_v0|convert|convert_v0|"
                                                  r"conversion_support)\.py")),
    ("rclpy publish", re.compile(r"rclpy/publisher\.py|Publisher\.publish")),
    ("diagnostics", re.compile(r"(?:sam_)?runtime/bridge/(diagnostics|reporting|health|liveness|silence)\.py|"
                                           r"write_json_atomic|Bridge\.stats|(?:sam_)?runtime/bridge/counters\.py")),
    ("time sync", re.compile(r"(?:sam_)?runtime/bridge/time_sync\.py")),
    ("transport receive (pycyphal UDP / dronecan driver, FrameGate)",
     re.compile(r"pycyphal/transport/|dronecan_io/(loopback|frame_gate|mcast_packet|can_id|wire)\.py|"
                r"cyphal_io/(udp_receiver|crc32c|multicast)\.py|dronecan/driver/")),
    ("library decoding (pycyphal DSDL / dronecan transfers)",
     re.compile(r"pycyphal/dsdl|nunavut|/uavcan/|dronecan/(transport|dsdl)|dronecan/node\.py")),
    ("pycyphal presentation / application", re.compile(r"pycyphal/(presentation|application)")),
    # (sam_)runtime/: the runtime as installed (sam_runtime/) or editable from the checkout (runtime/)
    ("bridge inbound / outbound", re.compile(r"(?:sam_)?runtime/(bridge|dronecan_io|cyphal_io)/")),
    ("rclpy executor", re.compile(r"rclpy/")),
    ("asyncio event loop", re.compile(r"asyncio/|selectors\.py")),
)


def _source_line(path: str, line: int) -> str:
    """The text of a frame's line (py-spy gives paths relative to a sys.path entry)."""
    for root in ["", *sys.path]:
        p = Path(root) / path if root else Path(path)
        if p.is_file():
            return linecache.getline(str(p), line)
    return ""


def subsystem(frames: list[str]) -> str:
    """The subsystem a sample is charged to (frames from the outermost to the innermost)."""
    leaf = FRAME.match(frames[-1]) if frames else None
    if leaf and WAIT_CALL.search(_source_line(leaf["file"], int(leaf["line"]))):
        return "waiting (select/poll/wait: wake-ups, polling timeouts)"
    for frame in reversed(frames):
        for name, pat in RULES:
            if pat.search(frame):
                return name
    return "other"


def thread_group(name: str) -> str:
    if "InputSession" in name:
        return "pycyphal input-session reader threads"
    if name.startswith("MainThread"):
        return "main thread (asyncio loop)"
    return re.sub(r"\s*\(\d+\)$", "", name)


def summarise(path: Path, seconds: float, rate_hz: float = RATE_HZ) -> dict[str, Any]:
    by_sub: Counter[str] = Counter()
    by_thread: Counter[str] = Counter()
    own: Counter[str] = Counter()
    threads: set[str] = set()
    total = 0
    for raw in path.read_text(errors="replace").splitlines():
        stack, _, count = raw.rpartition(" ")
        if not stack or not count.isdigit():
            continue
        n = int(count)
        head, *frames = stack.split(";")
        tid, _, tname = head.partition(": ")
        threads.add(tid)
        total += n
        by_sub[subsystem(frames)] += n
        by_thread[thread_group(tname)] += n
        own[frames[-1] if frames else head] += n

    def pct(c: Counter[str]) -> dict[str, float]:
        n = sum(c.values())
        return {k: round(100.0 * v / n, 1) for k, v in c.most_common()} if n else {}

    working = Counter({k: v for k, v in by_sub.items() if not k.startswith("waiting")})
    return {"samples": total, "cpu_percent_est": round(100.0 * total / (seconds * rate_hz), 1) if seconds else None,
            "threads_seen": len(threads), "by_subsystem_percent": pct(by_sub),
            "working_by_subsystem_percent": pct(working), "by_thread_percent": pct(by_thread),
            "top_own_percent": dict(list(pct(own).items())[:15])}


def listing(proto: str, s: dict[str, Any]) -> str:
    out = [f"== {proto}: {s['samples']} samples, ~{s['cpu_percent_est']} % of a core, {s['threads_seen']} threads "
           "sampled", "by subsystem (innermost frame):"]
    out += [f"  {v:5.1f} %  {k}" for k, v in s["by_subsystem_percent"].items()]
    out.append("the samples not waiting, by subsystem:")
    out += [f"  {v:5.1f} %  {k}" for k, v in s["working_by_subsystem_percent"].items()]
    out.append("by thread:")
    out += [f"  {v:5.1f} %  {k}" for k, v in s["by_thread_percent"].items()]
    out.append("innermost frames:")
    out += [f"  {v:5.1f} %  {k}" for k, v in s["top_own_percent"].items()]
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.cpu_profile", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--py-spy", default="py-spy")
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--warm", type=float, default=15.0)
    ap.add_argument("--protocols", default="cyphal,dronecan")
    ap.add_argument("--out", type=Path, default=RESULTS)
    ap.add_argument("--summarise", type=Path, default=None)
    args = ap.parse_args(argv)
    if args.summarise:
        print(listing(args.summarise.name, summarise(args.summarise, args.seconds)))
        return 0
    from bench.cpu import profile
    from bench.report_cpu import cpu_markdown, splice

    version = subprocess.run([args.py_spy, "--version"], capture_output=True, text=True).stdout.split()[-1:]
    prof: dict[str, Any] = {"seconds": args.seconds, "rate_hz": RATE_HZ, "py_spy_version": "".join(version),
                            "protocols": {}}
    for proto in [p.strip() for p in args.protocols.split(",") if p.strip()]:
        views: dict[str, Any] = {}
        for view in ("active", "gil"):
            log(f"profile: {proto}, {view}, {args.seconds:g} s")
            r = profile(proto, args.seconds, args.py_spy, args.warm, gil=view == "gil")
            f = Path(r["profile_file"])
            if "error" in r or not f.is_file() or r.get("nominal", {}).get("profile_rc"):
                err = r.get("error") or r.get("nominal", {}).get("profile_error") or "no profile written"
                views[view] = {"error": err}
                log(f"profile: {proto} {view} failed: {err}")
                continue
            s = summarise(f, args.seconds)
            s["bridge_cpu_percent_in_run"] = r["nominal"]["bridge"]["cpu_percent"]
            views[view] = s
            print(listing(f"{proto} ({view})", s), flush=True)
        prof["protocols"][proto] = views
    res_path = args.out / "results.json"
    res = json.loads(res_path.read_text()) if res_path.is_file() else {}
    if not res.get("cpu"):
        log(f"no CPU section in {res_path}: the profile is printed only (run python -m bench.run --parts cpu first)")
        return 0
    res["cpu"]["profile"] = prof
    res_path.write_text(json.dumps(res, indent=1, default=str) + "\n")
    md_path = args.out / "results.md"
    md = md_path.read_text() if md_path.is_file() else ""
    md_path.write_text(splice(md, cpu_markdown(res["cpu"])))
    log(f"wrote the profile summary into {res_path} and {md_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
