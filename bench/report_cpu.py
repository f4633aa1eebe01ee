"""results.md's CPU section (bench/cpu.py): the table, the runs, the guard's verdict, the profile summary; and the
splice that puts it into an existing results.md without touching the other sections."""

from __future__ import annotations

import re
from typing import Any

from bench.cpu import PROTOCOL_LABEL, guard_lines
from bench.report_fmt import table

HEADING = "## Bridge CPU at nominal traffic"


def _mm(f: dict[str, Any] | None, digits: int = 2) -> str:
    """median [min-max] of a figure."""
    if not f or f.get("median") is None:
        return "-"
    fmt = f"{{:.{digits}f}}"
    m = fmt.format(f["median"])
    return m if f["min"] == f["max"] else f"{m} [{fmt.format(f['min'])}-{fmt.format(f['max'])}]"


def cpu_markdown(cpu: dict[str, Any]) -> list[str]:
    meth, code, m = cpu["method"], cpu["code"], cpu["machine"]
    ns = ("each run in a network namespace of its own (`unshare -n`, loopback up)" if meth["netns"] else
          f"in the machine's network namespace ({meth['netns_unavailable']})")
    label = f"**{cpu['label']}**. " if cpu.get("label") else ""
    lines = [HEADING, "",
             f"{label}Taken {m['date']}, code of commit {code['commit']} (runtime/ tree {code['runtime_tree']}, "
             f"generated/ tree {code['generated_tree']}"
             f"{', with uncommitted changes' if code['uncommitted_changes'] else ''}) on {m['cpu']}, {m['cores']} "
             f"cores. Load average before/after: {cpu['loadavg_before']} / {cpu['loadavg_after']}; section wall "
             f"time {cpu['wall_s']:.0f} s. The section alone: `python -m bench.run --parts cpu` (bench/cpu.py).", "",
             "`sam-codegen bridge` (its messages counted from its /diagnostics) beside a raw receiver "
             "(bench/cpu_raw.py: a pycyphal node, resp. a dronecan node on the project's `mcast-lo:` driver, "
             "subscribed to the same ports, doing nothing), " + ns + ": both idle (no devices) for "
             f"{meth['window_s']:g} s after {meth['warm_s']:g} s of warm-up, then `sam-codegen sim` started (SAM's "
             f"nominal rates: {', '.join(f'{k} {v:g} msg/s' for k, v in meth['nominal_msg_per_s'].items())} to ROS) "
             f"and both measured again the same way. CPU = utime + stime of every thread (/proc/PID/stat) over the "
             f"window, % of one core; us per message = the process's CPU over the messages the bridge published in "
             f"the window. Median of {meth['runs']} run(s), [min-max] when they differ.", ""]
    rows = []
    for proto, p in cpu["protocols"].items():
        for cond in ("nominal", "idle"):
            f = p["figures"].get(cond, {})
            rows.append([PROTOCOL_LABEL.get(proto, proto), cond, _mm(f.get("bridge_percent")),
                         _mm(f.get("raw_percent")), _mm(f.get("ratio")), _mm(f.get("us_per_message"), 0),
                         _mm(f.get("raw_us_per_message"), 0), _mm(f.get("bridge_threads"), 0),
                         _mm(f.get("raw_threads"), 0), _mm(f.get("bridged_per_s"), 0)])
    lines.append(table(["protocol", "traffic", "bridge % of a core", "raw receiver %", "bridge / raw",
                        "bridge us/msg", "raw us/msg", "bridge threads", "raw threads", "bridged msg/s"], rows))
    run_rows = []
    for proto, p in cpu["protocols"].items():
        for i, r in enumerate(p["runs"]):
            if "error" in r:
                run_rows.append([proto, str(i + 1), "failed: " + r["error"].splitlines()[0][:120], "", "", "", ""])
                continue
            n, d = r["nominal"], r["idle"]
            run_rows.append([proto, str(i + 1), f"{n['bridge']['cpu_percent']:.2f}", f"{n['raw']['cpu_percent']:.2f}",
                             f"{d['bridge']['cpu_percent']:.2f}", f"{d['raw']['cpu_percent']:.2f}",
                             f"{d['loadavg_before'][0]:.2f} / {n['loadavg_after'][0]:.2f}"])
    lines += ["", "Runs (bridge and raw receiver % of a core; 1-minute load average at the idle window's start / the "
              "nominal window's end):", "",
              table(["protocol", "run", "bridge nominal", "raw nominal", "bridge idle", "raw idle", "load"], run_rows),
              "", *guard_lines(cpu["guard"])]
    prof = cpu.get("profile")
    if prof:
        lines += ["", *profile_markdown(prof)]
    return lines


def profile_markdown(prof: dict[str, Any]) -> list[str]:
    """The py-spy summary (bench/cpu_profile.py), short: per protocol and view, the share of the bridge's samples
    per subsystem, and per thread."""
    views = [(proto, view, v.get(view, {})) for proto, v in prof["protocols"].items() for view in ("active", "gil")]
    views = [(p, w, s) for p, w, s in views if "samples" in s]
    failed = [f"{p}: {str(v.get(w, {}).get('error', ''))[:200]}" for p, v in prof["protocols"].items()
              for w in ("active", "gil") if "samples" not in v.get(w, {})]
    lines = [f"Profile at nominal traffic: py-spy {prof.get('py_spy_version', '')} `record --format raw --threads "
             f"--nonblocking` on the bridge for {prof['seconds']:g} s at {prof['rate_hz']:g} Hz, in runs of their "
             "own (bench/cpu_profile.py). `active`: every thread not asleep; `gil`: only the thread holding the GIL "
             "(py-spy `--gil`: Python at work). A sample is charged to the subsystem of its innermost frame; "
             "`waiting` = inside a select/poll/wait call: a wake-up, a polling timeout, or a woken thread waiting "
             "for a core or the GIL (py-spy counts those as running: on a loaded machine the active samples add up "
             "to well above the CPU that /proc gives for the same run, last row; the GIL view, below it, leaves out "
             "the time outside Python: system calls, DDS's own threads)."]
    if failed:
        lines.append("No profile: " + "; ".join(failed) + ".")
    if not views:
        return lines
    subs = list(dict.fromkeys(k for _, _, s in views for k in s["by_subsystem_percent"]))
    rows = [[k, *(f"{s['by_subsystem_percent'].get(k, 0.0):.0f}" for _, _, s in views)] for k in subs]
    rows.append(["samples (~% of a core; /proc %)",
                 *(f"{s['samples']} ({s['cpu_percent_est']:.0f}; {s['bridge_cpu_percent_in_run']:.0f})"
                   for _, _, s in views)])
    lines += ["", table(["% of the samples", *(f"{p} {w}" for p, w, _ in views)], rows), ""]
    lines += ["Samples by thread (active): " + " ".join(
        f"{p}: " + ", ".join(f"{k} {v:.0f} %" for k, v in s["by_thread_percent"].items() if v >= 1.0) + "."
        for p, w, s in views if w == "active")]
    return lines


def splice(md: str, section: list[str]) -> str:
    """``md`` with its CPU section replaced by ``section`` (up to the next ``## `` heading), or the section inserted
    before "## What limits the figures" (else at the end) when it has none; every other line kept as it was."""
    text = "\n".join(section).rstrip() + "\n"
    start = md.find(HEADING + "\n")
    if start >= 0:
        nxt = re.search(r"^## ", md[start + len(HEADING):], flags=re.M)
        end = len(md) if nxt is None else start + len(HEADING) + nxt.start()
        return md[:start] + text + ("\n" + md[end:] if end < len(md) else "")
    anchor = md.find("## What limits the figures")
    if anchor >= 0:
        return md[:anchor] + text + "\n" + md[anchor:]
    return md.rstrip() + "\n\n" + text
