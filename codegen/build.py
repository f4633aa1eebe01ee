"""`sam-codegen build`: spec -> validated model -> every emitter -> generated/, all or nothing."""

from __future__ import annotations

import contextlib
import gc
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pydsdl

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import Diagnostic, Pos, SpecError
from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import DsdlType, split_composite_name
from sam_codegen.project.lock import LockError, ProjectLock, lock_path, optional_lock
from sam_codegen.project.workspace import GENERATED_MARKER, OutDirError, check_out_dir
from sam_codegen.targets.docs.budget import resolved_budgets
from sam_codegen.targets.dsdl import dsdl_path
from sam_codegen.targets.registry import EMITTERS
from sam_codegen.validate.resolve import Resolved, validate

MARKER = GENERATED_MARKER  # marks a directory as ours, so that a rebuild never replaces someone else's folder


class OutputError(OutDirError):
    """The output folder cannot be written (not ours, or a file system error); the spec may well be valid."""


# pydsdl reads about this many of the spec's types per call. Its namespace-wide passes are O(N^2) in the
# definitions of one call: every type it reads filters the whole lookup list (every target and lookup
# definition) for itself and for each type it references, and `_ensure_no_fixed_port_id_collisions` compares
# every pair of targets. Over a whole 1000-type namespace that was 3-5 s, the largest stage of `build`; in batches
# of bounded size the cost per type is constant. Each call also costs ~35 ms to list and resolve the lookup
# namespaces (uavcan, reg), hence batches of 100 rather than smaller. A spec of up to 100 types (SAM has 12) is
# still read in a single call.
DSDL_BATCH = 100


def verify_dsdl(resolved: Resolved, files: dict[str, str], *, batch: int | None = None) -> None:
    """Run pydsdl, the reference DSDL front end, over the emitted DSDL; its complaints become spec errors.

    pydsdl reads every emitted type (syntax, bit lengths, extents, references) in batches of about `batch`
    types (default DSDL_BATCH). A batch reads whole groups of relatives (spec types whose full names differ
    only by letter case or version), and its temporary tree holds its types, the spec types they reference
    (transitively) and the relatives of those: so pydsdl's checks between related definitions (names that
    differ only by letter case; equal extent and sealing across the minor versions of one major version) see
    the same definitions as over the whole namespace. Its one check between unrelated types, fixed port-id
    collisions, cannot fail here: batches are used only when every emitted file is a spec type's
    `Name.MAJOR.MINOR.dsdl`, which carries no fixed port id; any other emitted tree is read in one call.
    """
    dsdl_files = {path: text for path, text in files.items() if path.startswith("dsdl/")}
    if not dsdl_files:
        return
    structs = {struct.name: struct for struct in resolved.dsdl_types}
    path_of = {name: f"dsdl/{dsdl_path(name)}" for name in structs}
    lookup = [str(r) for r in resolved.dsdl.roots]
    with tempfile.TemporaryDirectory(prefix="sam-dsdl-", dir=_scratch_dir()) as tmp:
        if set(path_of.values()) != set(dsdl_files):  # not one port-id-free file per spec type
            _read_dsdl(resolved, Path(tmp, "all"), dsdl_files, list(dsdl_files), lookup)
            return
        relatives: dict[str, list[str]] = {}  # full name in lower case, without version -> spec types
        for name in structs:
            relatives.setdefault(split_composite_name(name)[0].lower(), []).append(name)
        # A batch takes whole groups of relatives, so that pydsdl reads every version of a type in one call.
        size = batch or DSDL_BATCH
        batches: list[list[str]] = [[]]
        for group in relatives.values():
            if batches[-1] and len(batches[-1]) + len(group) > size:
                batches.append([])
            batches[-1].extend(group)
        for k, targets in enumerate(batches):
            needed = _closure(structs, relatives, targets)
            _read_dsdl(resolved, Path(tmp, f"batch{k}"), {path_of[n]: dsdl_files[path_of[n]] for n in needed},
                       [path_of[n] for n in targets], lookup)


def _scratch_dir() -> str | None:
    """Where the DSDL copies for pydsdl go: memory (tmpfs) when the system has it, since creating a file on a
    disk file system cost up to 1 ms each (a second per 1000 types); else the default temporary folder."""
    shm = "/dev/shm"
    return shm if os.path.isdir(shm) and os.access(shm, os.W_OK | os.X_OK) else None


def _closure(structs: dict[str, DsdlStruct], relatives: dict[str, list[str]], targets: list[str]) -> list[str]:
    """The spec types a batch needs: its targets, the spec types they reference transitively, and with each the
    types in `relatives` under its name; targets first, then in the order found."""
    seen: dict[str, None] = {}
    stack = list(reversed(targets))
    while stack:
        name = stack.pop()
        if name in seen:
            continue
        seen[name] = None
        stack.extend(relatives[split_composite_name(name)[0].lower()])
        for f in structs[name].fields:
            if isinstance(f.type, DsdlType) and f.type.kind == "composite" and f.type.composite in structs:
                stack.append(f.type.composite)
    return list(seen)


def _read_dsdl(resolved: Resolved, tree: Path, files: dict[str, str], targets: list[str], lookup: list[str]) -> None:
    """Write `files` (paths dsdl/<root>/...) under `tree` and have pydsdl read `targets` with what they use."""
    for path, text in files.items():
        target = tree / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    root = tree / "dsdl" / resolved.spec.dsdl_root
    try:
        pydsdl.read_files([tree / path for path in targets], [root], lookup)
    except pydsdl.FrontendError as exc:
        raise SpecError([_pydsdl_diagnostic(resolved, exc, tree / "dsdl")]) from None


def _pydsdl_diagnostic(resolved: Resolved, exc: pydsdl.FrontendError, dsdl_dir: Path) -> Diagnostic:
    """pydsdl's complaint at the spec position of the type whose file it names."""
    name = ""
    if exc.path:
        try:
            relative = Path(exc.path).resolve().relative_to(dsdl_dir.resolve())
        except ValueError:  # a file outside the emitted tree (a lookup namespace)
            relative = None
        if relative is not None:
            name = ".".join([*relative.parent.parts, relative.name.removesuffix(".dsdl")])
    struct = resolved.spec.dsdl_types.get(name) or resolved.spec.dsdl_services.get(name)  # (a service type too)
    pos = struct.pos if struct else Pos(resolved.spec.file)
    return Diagnostic(pos, f"DSDL type {name or '?'} is rejected by pydsdl: {exc.text}")


class Terminated(SystemExit):
    """SIGTERM arrived during a build: raised where the build was, so that its temporary folders are removed."""


@contextlib.contextmanager
def terminate_cleanly() -> Iterator[None]:
    """While the block runs, SIGTERM raises Terminated (exit status 143) instead of ending the process at once, so
    that `with tempfile.TemporaryDirectory()` and the staging folder's clean-up run: a build killed by SIGTERM left
    its DSDL copies in /dev/shm/sam-dsdl-*. SIGINT already raises KeyboardInterrupt. Only in the main thread and
    only over the default action: a program that handles SIGTERM itself (the main job) keeps its handler."""
    if threading.current_thread() is not threading.main_thread() \
            or signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return

    def raise_terminated(signum: int, _frame: object) -> None:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)  # a second SIGTERM ends the process as it always did
        raise Terminated(128 + signum)

    signal.signal(signal.SIGTERM, raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def generate(spec_path: Path, *, report: Callable[[str], None] | None = None) -> dict[str, str]:
    """Every generated file as {path relative to generated/: text}; raises SpecError. ``report`` gets the bus budget:
    one line per layout, then a `file:line:col: warning: ...` line for each layout above its warning threshold."""
    # The model is built once and kept: the cyclic collector's full passes over it only made large specs
    # superlinear (2.5x slower at 1000 types), so it is paused for the run.
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        with terminate_cleanly():
            return _generate(spec_path, report)
    finally:
        if was_enabled:
            gc.enable()


def _generate(spec_path: Path, report: Callable[[str], None] | None) -> dict[str, str]:
    resolved = validate(load_spec_file(spec_path))
    if report is not None:  # validate refused a layout its bus cannot carry; here the figures and warnings
        budgets = resolved_budgets(resolved)
        for budget in budgets:
            report(f"bus budget: {budget.summary()}")
        for warning in (b.warning() for b in budgets):
            if warning is not None:
                report(warning)
    files: dict[str, str] = {}
    for emit in EMITTERS:
        for path, text in emit(resolved).items():
            if path in files:
                raise AssertionError(f"two emitters write {path}")
            files[path] = text
    verify_dsdl(resolved, files)
    files[MARKER] = (
        "This folder is generated by `sam-codegen build` from the spec; edit the spec, not these files.\n"
    )
    return dict(sorted(files.items()))


@dataclass
class Staleness:
    changed: list[str]
    missing: list[str]
    extra: list[str]

    def __bool__(self) -> bool:
        return bool(self.changed or self.missing or self.extra)

    def lines(self) -> list[str]:
        return ([f"changed: {p}" for p in self.changed] + [f"missing: {p}" for p in self.missing]
                + [f"not generated by the spec: {p}" for p in self.extra])


def _existing(out_dir: Path) -> dict[str, Path]:
    if not out_dir.is_dir():
        return {}
    return {
        path.relative_to(out_dir).as_posix(): path
        for path in out_dir.rglob("*")
        if path.is_file() and "__pycache__" not in path.parts
    }


def compare(files: dict[str, str], out_dir: Path) -> Staleness:
    existing = _existing(out_dir)
    changed = [p for p, text in files.items() if p in existing and existing[p].read_bytes() != text.encode()]
    return Staleness(changed, sorted(set(files) - set(existing)), sorted(set(existing) - set(files)))


def write_atomically(files: dict[str, str], out_dir: Path) -> None:
    """Write the whole tree beside out_dir, then swap it in: a failure leaves the old tree as it was."""
    # Resolved first: the staging and backup folders are named after out_dir's own name, which `.` or `..` lack.
    out_dir = Path(out_dir).resolve()
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputError(f"{out_dir} is not a folder; choose an empty or generated output folder")
    if out_dir.exists() and any(out_dir.iterdir()) and not (out_dir / MARKER).exists():
        raise OutputError(f"refusing to replace {out_dir}: sam-codegen did not generate it (no {MARKER} "
                          "marker); choose an empty or generated output folder")
    try:
        out_dir.parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}-new-", dir=out_dir.parent))
    except OSError as exc:
        raise OutputError(f"cannot write {out_dir}: {exc}") from None
    old = out_dir.with_name(f".{out_dir.name}-old-{os.getpid()}")
    moved = False
    try:
        for path, text in files.items():
            target = staging / path
            target.parent.mkdir(parents=True, exist_ok=True)
            with open(target, "w", encoding="utf-8", newline="\n") as handle:
                handle.write(text)
        if out_dir.exists():
            os.rename(out_dir, old)
            moved = True
        os.rename(staging, out_dir)
    except BaseException as exc:
        if moved and not out_dir.exists():
            with contextlib.suppress(OSError):
                os.rename(old, out_dir)  # the old tree back in place
        shutil.rmtree(staging, ignore_errors=True)
        if isinstance(exc, OSError):
            raise OutputError(f"cannot write {out_dir}: {exc}") from None
        raise
    shutil.rmtree(old, ignore_errors=True)


def build(spec_path: Path, out_dir: Path, *, check: bool = False,
          report: Callable[[str], None] | None = None, say: Callable[[str], None] | None = None,
          wait_timeout: float | None = None, cancelled: Callable[[], bool] | None = None) -> Staleness:
    """Generate from spec_path. With check, compare only; otherwise write when anything differs. ``report`` gets the
    bus budget's lines (see generate).

    The comparison and the write hold out_dir's lock (sam_codegen.project.lock): a second build of the same folder
    started meanwhile waits (``say`` gets its waiting lines; ``wait_timeout``, ``cancelled``: see ProjectLock), then
    compares again and finds it current. The generation itself, which reads only the spec, runs unlocked.

    Raises OutDirError, before reading anything, for an out_dir that is or holds the spec (a rebuild replaces it);
    OutputError when out_dir cannot be written or its lock not had.
    """
    out_dir = Path(out_dir).resolve()
    check_out_dir(Path(spec_path).resolve(), out_dir)
    files = generate(spec_path, report=report)  # as given: the spec's diagnostics name it the way the user did
    try:
        with terminate_cleanly(), optional_lock(_generated_lock(out_dir, check, say, wait_timeout, cancelled)):
            try:
                stale = compare(files, out_dir)
            except OSError as exc:
                raise OutputError(f"cannot read {out_dir}: {exc}") from None
            if stale and not check:
                write_atomically(files, out_dir)
    except LockError as exc:
        raise OutputError(str(exc)) from exc
    return stale


def _generated_lock(out_dir: Path, check: bool, say: Callable[[str], None] | None, timeout: float | None,
                    cancelled: Callable[[], bool] | None) -> ProjectLock | None:
    """The lock of out_dir; None for a check where no lock file can be made at all (it only reads, and where
    nothing can be written no build can be writing either)."""
    try:
        path = lock_path("generated", out_dir)
    except LockError:
        if check:
            return None
        raise
    return ProjectLock(path, f"the generated folder {out_dir}", say=say, timeout=timeout, cancelled=cancelled)
