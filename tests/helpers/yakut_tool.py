"""yakut, the Cyphal command-line tool users have, as the tests run it: from its own virtual environment (its
pycyphal need not be ours). `nox -s tests` installs it into .nox/tests/yakut and names it in SAM_YAKUT; elsewhere
/tmp/yakut-venv or PATH; the tests that use it skip where there is none."""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

__all__ = ["YakutError", "yakut", "yakut_env", "yakut_exe", "yakut_lock"]


class YakutError(AssertionError):
    """A yakut call that failed: its stderr's tail."""


def yakut_exe() -> str | None:
    exe = os.environ.get("SAM_YAKUT") or "/tmp/yakut-venv/bin/yakut"
    return exe if Path(exe).exists() else shutil.which("yakut")


def _compiled_dir() -> Path:
    return Path(os.environ.get("TMPDIR", "/tmp")) / "yakut-compiled"


@contextlib.contextmanager
def yakut_lock() -> Iterator[None]:
    """Held while yakut runs: its first run compiles the standard types into the shared folder, which two workers'
    yakut must not do at once (the second waits and finds them compiled)."""
    lock = _compiled_dir().with_suffix(".lock")
    with open(lock, "a+b") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def yakut_env(node_id: int, iface: str = "127.0.0.1") -> dict[str, str]:
    """yakut's environment: its own node id on Cyphal/UDP at `iface`, the standard types from the project's search
    path (CYPHAL_PATH or ../shared/dsdl), compiled once per machine into a cache folder of its own."""
    from sam_codegen.project.cyphal_path import default_search_dirs

    dsdl = [str(d) for d in default_search_dirs() if (Path(d) / "uavcan").is_dir()]
    return dict(os.environ, UAVCAN__UDP__IFACE=iface, UAVCAN__NODE__ID=str(node_id), CYPHAL_PATH=":".join(dsdl),
                YAKUT_PATH=str(_compiled_dir()))


def yakut(exe: str, env: dict[str, str], *args: str, timeout: float = 300.0) -> Any:
    """Run `yakut --format json ARGS...` to its end (the first run compiles the DSDL: minutes): its JSON output."""
    with yakut_lock():
        proc = subprocess.run([exe, "--format", "json", *args], env=env, capture_output=True, text=True,
                              timeout=timeout, check=False)
    if proc.returncode != 0:
        raise YakutError(f"yakut {' '.join(args)} exited {proc.returncode}: {proc.stderr[-3000:]}")
    return json.loads(proc.stdout)
