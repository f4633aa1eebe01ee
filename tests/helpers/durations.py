"""Wall time per test folder from pytest's ``--durations=0`` output, as a markdown table (not part of CI).

    python tests/helpers/durations.py before.log [after.log] [--top N]
    python tests/helpers/durations.py before.log .nox/tests/junit.xml
    python tests/helpers/durations.py --cpu .nox/tests/junit.xml --top 30   # CPU seconds instead of wall

With two logs the table has a column for each. The times are pytest's per-phase durations (setup + call +
teardown) summed: in a parallel run that is the work done, not the wall time (which pytest prints at the end).

>>> rows = parse(["12.50s call     tests/system/test_a.py::test_x[1]",
...               "0.50s setup    tests/system/test_a.py::test_x[1]",
...               "3.00s call     codegen/model/x.py::sam_codegen.model.x", "garbage"])
>>> sorted(rows.items())
[('codegen/model/x.py::sam_codegen.model.x', 3.0), ('tests/system/test_a.py::test_x[1]', 13.0)]
>>> by_folder(rows)
{'codegen/model': (1, 3.0), 'tests/system': (1, 13.0)}
"""

from __future__ import annotations

import argparse
import re
import resource
import sys
from collections.abc import Iterable
from pathlib import Path

# The junit property the root conftest.py gives every test: CPU seconds of the worker and of the children it reaped
# during the test (setup to teardown).
CPU_PROPERTY = "cpu_s"
# ... and the xdist worker that ran it and when it ended (s since the epoch): how busy each worker was, and how long
# the last ones ran alone at the end (a long module scheduled late).
WORKER_PROPERTY = "worker"
END_PROPERTY = "end_s"
BUSY_PROPERTY = "busy_s"  # setup to teardown, wall
LINE = re.compile(r"^\s*(\d+(?:\.\d+)?)s\s+(setup|call|teardown)\s+(\S.*?)\s*$")


def cpu_seconds() -> float:
    """User + system CPU seconds of this process and of its reaped children so far."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def parse_junit(path: Path, what: str = "time") -> dict[str, float]:
    """Seconds per test id from a JUnit XML report (pytest's ``--junitxml``, what ``nox -s tests`` writes to
    .nox/tests/junit.xml); the id's file part comes from the test case's dotted class name. `what` is "time"
    (wall) or :data:`CPU_PROPERTY` (CPU, the property the root conftest.py records).

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "j.xml"
    ...     _ = p.write_text('<testsuites><testsuite><testcase classname="tests.system.test_a" name="test_x[1]" '
    ...                      'time="13.0"><properties><property name="cpu_s" value="4.5"/></properties>'
    ...                      '</testcase></testsuite></testsuites>')
    ...     parse_junit(p), parse_junit(p, CPU_PROPERTY)
    ({'tests/system/test_a.py::test_x[1]': 13.0}, {'tests/system/test_a.py::test_x[1]': 4.5})
    """
    import xml.etree.ElementTree as ET

    out: dict[str, float] = {}
    for case in ET.parse(path).getroot().iter("testcase"):
        module = (case.get("classname") or "").replace(".", "/")
        test_id = f"{module}.py::{case.get('name')}"
        if what == "time":
            seconds = float(case.get("time") or 0.0)
        else:
            seconds = sum(float(p.get("value") or 0.0) for p in case.iter("property") if p.get("name") == what)
        out[test_id] = out.get(test_id, 0.0) + seconds
    return out


def workers(path: Path) -> str:
    """Per xdist worker of a JUnit report: tests, busy seconds (setup to teardown, summed) and when its last test
    ended, counted from the first test's start; the gap between the first and the last worker to end is the run's
    tail, when some cores had nothing left to do."""
    import xml.etree.ElementTree as ET

    rows: dict[str, list[float]] = {}
    starts: list[float] = []
    for case in ET.parse(path).getroot().iter("testcase"):
        props = {p.get("name"): p.get("value") or "" for p in case.iter("property")}
        if END_PROPERTY not in props:
            continue
        end, busy = float(props[END_PROPERTY]), float(props.get(BUSY_PROPERTY) or case.get("time") or 0.0)
        row = rows.setdefault(props.get(WORKER_PROPERTY) or "-", [0, 0.0, 0.0])
        row[0], row[1], row[2] = row[0] + 1, row[1] + busy, max(row[2], end)
        starts.append(end - busy)
    if not rows:
        return "(no worker properties in this report)"
    t0 = min(starts)
    lines = ["| worker | tests | busy s | last end s |", "|---|---:|---:|---:|"]
    lines += [f"| {w} | {n:.0f} | {busy:.0f} | {end - t0:.0f} |" for w, (n, busy, end) in sorted(rows.items())]
    return "\n".join(lines)


def parse(lines: Iterable[str]) -> dict[str, float]:
    """Seconds per test id (its phases summed)."""
    out: dict[str, float] = {}
    for line in lines:
        m = LINE.match(line)
        if m:
            out[m.group(3)] = out.get(m.group(3), 0.0) + float(m.group(1))
    return out


def folder_of(test_id: str) -> str:
    return str(Path(test_id.split("::", 1)[0]).parent)


def by_folder(rows: dict[str, float]) -> dict[str, tuple[int, float]]:
    """Folder -> (tests, seconds)."""
    out: dict[str, tuple[int, float]] = {}
    for test_id, seconds in rows.items():
        n, total = out.get(folder_of(test_id), (0, 0.0))
        out[folder_of(test_id)] = (n + 1, total + seconds)
    return dict(sorted(out.items()))


def table(logs: list[tuple[str, dict[str, float]]]) -> str:
    folders = sorted({f for _, rows in logs for f in by_folder(rows)},
                     key=lambda f: -max(by_folder(rows).get(f, (0, 0.0))[1] for _, rows in logs))
    head = "| folder | " + " | ".join(f"{name}: tests | {name}: s" for name, _ in logs) + " |"
    lines = [head, "|---|" + "---:|---:|" * len(logs)]
    sums = [by_folder(rows) for _, rows in logs]
    for f in folders:
        cells = [f"{s.get(f, (0, 0.0))[0]} | {s.get(f, (0, 0.0))[1]:.0f}" for s in sums]
        lines.append(f"| {f} | " + " | ".join(cells) + " |")
    totals = [f"{sum(n for n, _ in s.values())} | {sum(t for _, t in s.values()):.0f}" for s in sums]
    lines.append("| **all** | " + " | ".join(totals) + " |")
    return "\n".join(lines)


def slowest(rows: dict[str, float], n: int) -> str:
    lines = ["| test | s |", "|---|---:|"]
    lines += [f"| {t} | {s:.1f} |" for t, s in sorted(rows.items(), key=lambda kv: -kv[1])[:n]]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("logs", nargs="+", type=Path,
                        help="pytest outputs with --durations=0, or JUnit XML reports (before, after)")
    parser.add_argument("--top", type=int, default=0, help="also list the N slowest tests of the last log")
    parser.add_argument("--cpu", action="store_true",
                        help="CPU seconds (JUnit reports of this suite) instead of wall seconds")
    parser.add_argument("--workers", action="store_true",
                        help="per xdist worker of the last (JUnit) report: busy time and when it ended")
    args = parser.parse_args(argv)
    what = CPU_PROPERTY if args.cpu else "time"
    logs = [(p.stem, parse_junit(p, what) if p.suffix == ".xml" else parse(p.read_text(errors="replace").splitlines()))
            for p in args.logs]
    print(table(logs))
    if args.workers:
        print()
        print(workers(args.logs[-1]))
    if args.top:
        print()
        print(slowest(logs[-1][1], args.top))
    return 0


if __name__ == "__main__":
    sys.exit(main())
