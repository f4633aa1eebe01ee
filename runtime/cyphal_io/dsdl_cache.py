"""Compile DSDL root namespaces to Python (pycyphal/nunavut) into a content-addressed cache.

:func:`ensure_compiled` compiles the given root namespaces (e.g. ``generated/dsdl/sam``) together with
``uavcan`` (pycyphal.application cannot work without the whole of it) and any other lookup root that the
compiled types refer to (e.g. ``reg``), all lookup roots from
:func:`sam_codegen.project.cyphal_path.dsdl_lookup_roots` being visible to pydsdl. The output directory is named
by a hash of every ``.dsdl`` file involved (path relative to its root's parent + bytes) and of the
pycyphal/nunavut/pydsdl versions: any DSDL change yields a new directory, an unchanged set is reused at
the cost of hashing (a few ms).

A compile happens in a private temporary directory which is renamed into place atomically, so a crashed
or concurrent compile never leaves a half-written cache entry; concurrent processes additionally serialize
on an ``flock`` so only one of them does the work.

The lookup roots that the caller did not give (``uavcan``, ``reg``: the standard types, ~4 CPU s of the ~4.5 a
compile takes) are compiled once per content into ``roots/<name>-<hash>`` beside the entries and copied into each
entry that needs them: a changed spec recompiles its own namespace only. Such a root's code depends on its own
types and on those it refers to, all in the roots the caller did not give (a root that refers to one the caller
gave is compiled in the entry, not shared); its key hashes every one of those roots.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import os
import shutil
import sys
import tempfile
import time
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path

from sam_codegen.project.cyphal_path import CyphalPathError, dsdl_lookup_roots
from sam_codegen.project.progress import TerminalProgress
from sam_codegen.project.workspace import user_cache_dir
from sam_runtime.cyphal_io.nunavut_fix import FIX_VERSION, fix_support

__all__ = [
    "CACHE_ENV_VAR",
    "DsdlCompileError",
    "compiled_dir_for",
    "default_cache_dir",
    "ensure_compiled",
    "find_compiled",
]

CACHE_ENV_VAR = "SAM_DSDL_CACHE"
# Bump when the layout or the compile rule of a cache entry changes.
_CACHE_FORMAT = f"sam-dsdl-cache-1;nunavut-fix-{FIX_VERSION}"
_COMPLETE_MARKER = ".complete"
_SHARED_ROOTS = "roots"  # the cache's folder of shared library roots (see the module's docstring)
_STALE_TMP_AGE_S = 3600.0
try:
    import fcntl as _fcntl
except ImportError:  # pragma: no cover - non-POSIX: rely on the atomic rename alone
    _fcntl = None  # type: ignore[assignment]
_HAVE_FLOCK = _fcntl is not None


class DsdlCompileError(Exception):
    """A DSDL set could not be compiled; ``str()`` is a readable, traceback-free explanation."""


def default_cache_dir() -> Path:
    """``$SAM_DSDL_CACHE``, else ``dsdl`` in the user's cache directory: the entries are content-addressed, so every
    project (and every install) shares them safely."""
    env = os.environ.get(CACHE_ENV_VAR, "").strip()
    return Path(env).expanduser().resolve() if env else user_cache_dir() / "dsdl"


def _versions() -> str:
    from importlib.metadata import version

    out = []
    for dist in ("pycyphal", "nunavut", "pydsdl"):
        try:
            out.append(f"{dist}={version(dist)}")
        except Exception:  # pragma: no cover - metadata missing: fall back to the module attribute
            mod = importlib.import_module(dist)
            out.append(f"{dist}={getattr(mod, '__version__', '?')}")
    return ";".join(out)


def _dsdl_files(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*.dsdl") if p.is_file())


def _content_hash(targets: Sequence[Path], lookups: Sequence[Path]) -> str:
    # What is compiled (by name) matters, not only what is visible.
    return _hash("targets:" + ",".join(t.name for t in targets), lookups)


def _hash(what: str, roots: Sequence[Path]) -> str:
    """The cache format, the compilers' versions, ``what`` and every byte of every definition in ``roots``."""
    h = hashlib.sha256()
    h.update(_CACHE_FORMAT.encode())
    h.update(_versions().encode())
    h.update(what.encode())
    for root in roots:
        for f in _dsdl_files(root):
            rel = f.relative_to(root.parent).as_posix()
            data = f.read_bytes()
            h.update(b"\0F" + rel.encode() + b"\0" + len(data).to_bytes(8, "little") + data)
    return h.hexdigest()[:24]


def _resolve_roots(namespace_dirs: Sequence[Path]) -> tuple[list[Path], list[Path]]:
    """(explicit targets, all lookup roots): the given dirs win over CYPHAL_PATH roots of the same name."""
    given: list[Path] = []
    for d in namespace_dirs:
        p = Path(d).expanduser().resolve()
        if not p.is_dir():
            raise DsdlCompileError(f"DSDL root namespace directory {p} does not exist")
        if any(g.name == p.name and g != p for g in given):
            raise DsdlCompileError(f"two different directories for root namespace {p.name!r} given")
        if p not in given:
            given.append(p)
    try:
        roots = dsdl_lookup_roots()
    except CyphalPathError as ex:
        raise DsdlCompileError(str(ex)) from None
    names = {g.name for g in given}
    lookups = sorted(given + [r for r in roots if r.name not in names], key=lambda p: p.name)
    targets = list(given)
    if "uavcan" not in names:
        targets.append(next(r for r in lookups if r.name == "uavcan"))
    return targets, lookups


def compiled_dir_for(namespace_dirs: Sequence[Path], cache_dir: Path | None = None) -> Path:
    """The cache entry :func:`ensure_compiled` would use (it may not exist yet). Does not compile."""
    targets, lookups = _resolve_roots(namespace_dirs)
    base = Path(cache_dir).resolve() if cache_dir is not None else default_cache_dir()
    return base / _content_hash(targets, lookups)


def _referenced_roots(models: Sequence[object]) -> set[str]:
    """Root namespace names of every composite type the given pydsdl models use (fields, arrays, services)."""
    import pydsdl

    out: set[str] = set()
    seen: set[int] = set()

    def walk(t: object) -> None:
        if id(t) in seen:
            return
        seen.add(id(t))
        if isinstance(t, pydsdl.ArrayType):
            walk(t.element_type)
        elif isinstance(t, pydsdl.CompositeType):
            out.add(t.root_namespace)
            if isinstance(t, pydsdl.ServiceType):
                walk(t.request_type)
                walk(t.response_type)
            if isinstance(t, pydsdl.DelimitedType):
                walk(t.inner_type)
            for f in t.fields:
                walk(f.data_type)

    for m in models:
        walk(m)
    return out


def _compile_root(root: Path, lookups: Sequence[Path], out_dir: Path) -> set[str] | None:
    """Compile one root namespace into ``out_dir``; the root namespaces its types refer to (None: it is empty)."""
    import pycyphal.dsdl
    import pydsdl

    try:
        with warnings.catch_warnings():
            # nunavut 2.3 templates use pydsdl APIs deprecated in pydsdl 1.25 (string_like): noise only.
            warnings.simplefilter("ignore", DeprecationWarning)
            info = pycyphal.dsdl.compile(root, list(lookups), output_directory=out_dir)
    except pydsdl.InvalidDefinitionError as ex:
        raise DsdlCompileError(f"invalid DSDL in root namespace {root.name!r}: {ex}") from None
    except pydsdl.Error as ex:
        raise DsdlCompileError(f"pydsdl failed on root namespace {root.name!r}: {ex}") from None
    except (OSError, ValueError, TypeError, KeyError, RuntimeError) as ex:
        # nunavut/jinja failures and file-system problems: keep the cause for debugging.
        raise DsdlCompileError(
            f"compiling root namespace {root.name!r} ({root}) failed: {type(ex).__name__}: {ex}"
        ) from ex
    return None if info is None else _referenced_roots(info.models)


def _shared_root(root: Path, lookups: Sequence[Path], library: Sequence[Path], base: Path,
                 out_dir: Path) -> tuple[bool, set[str] | None]:
    """Put the compiled ``root`` (one of ``library``, the roots the caller did not give) into ``out_dir`` from its
    shared compile under ``base``/roots, compiling that first if there is none. Returns (shared, the roots it
    refers to); not shared (nothing copied) when it refers to a root outside ``library``."""
    shared = base / _SHARED_ROOTS
    key = f"{root.name}-{_hash('root:' + root.name, library)}"
    entry = shared / key
    names = {r.name for r in library}
    if not (entry / _COMPLETE_MARKER).is_file():
        shared.mkdir(parents=True, exist_ok=True)
        with _flock(shared / f".lock-{key}"):
            if not (entry / _COMPLETE_MARKER).is_file():
                _rmtree(entry)
                _sweep_stale_tmp(shared, key)
                tmp = Path(tempfile.mkdtemp(prefix=f".tmp-{key}-", dir=shared))
                try:
                    refs = _compile_root(root, lookups, tmp)
                    if refs is not None and not refs - {root.name} <= names:
                        return False, None  # its code depends on a root the caller gave: compiled in the entry
                    (tmp / _COMPLETE_MARKER).write_text(
                        "references=" + ("-" if refs is None else ",".join(sorted(refs))) + "\n")
                    os.rename(tmp, entry)
                finally:
                    if tmp.exists():
                        _rmtree(tmp)
    line = (entry / _COMPLETE_MARKER).read_text().splitlines()[0].split("=", 1)[1]
    if line == "-":
        return True, None
    if (entry / root.name).is_dir():
        shutil.copytree(entry / root.name, out_dir / root.name)
    return True, set(line.split(",")) if line else set()


def _compile_into(out_dir: Path, targets: Sequence[Path], lookups: Sequence[Path], *,
                  given: Sequence[str] = (), base: Path | None = None) -> list[str]:
    """Compile targets, then every further lookup root they reference, transitively (a root not ``given``, from
    its shared compile under ``base`` when one is given). Returns the names."""
    by_name = {r.name: r for r in lookups}
    library = [r for r in lookups if r.name not in given]
    queue = list(targets)
    done: list[str] = []
    while queue:
        root = queue.pop(0)
        if root.name in done:
            continue
        shared, refs = (False, None)
        if base is not None and root.name not in given:
            shared, refs = _shared_root(root, lookups, library, base, out_dir)
        if not shared:
            refs = _compile_root(root, lookups, out_dir)
        done.append(root.name)
        if refs is None:  # empty namespace: pycyphal generates nothing
            continue
        for name in sorted(refs - set(done)):
            if name in by_name:
                queue.append(by_name[name])
    # compile() of an empty namespace does not emit nunavut_support; make sure it exists.
    if not (out_dir / "nunavut_support.py").exists():
        import pycyphal.dsdl

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            pycyphal.dsdl.compile(None, output_directory=out_dir)
    fix_support(out_dir / "nunavut_support.py")  # narrow signed integer arrays under numpy 2
    return done


@contextlib.contextmanager
def _flock(path: Path) -> Iterator[None]:
    if _fcntl is None:  # pragma: no cover
        yield
        return
    with open(path, "a+b") as fh:
        _fcntl.flock(fh.fileno(), _fcntl.LOCK_EX)
        try:
            yield
        finally:
            _fcntl.flock(fh.fileno(), _fcntl.LOCK_UN)


def _rmtree(p: Path) -> None:
    shutil.rmtree(p, ignore_errors=True)


def _sweep_stale_tmp(base: Path, entry_name: str) -> None:
    """Remove temp dirs of crashed compiles: those of this entry at once (we hold its lock, so their owner
    is gone), any other after an hour."""
    now = time.time()
    for p in base.glob(".tmp-*"):
        try:
            mine = _HAVE_FLOCK and p.name.startswith(f".tmp-{entry_name}-")
            if mine or now - p.stat().st_mtime > _STALE_TMP_AGE_S:
                _rmtree(p)
        except OSError:
            pass


def _activate(out: Path) -> Path:
    s = str(out)
    if s not in sys.path:
        sys.path.insert(0, s)
        importlib.invalidate_caches()
    return out


def ensure_compiled(namespace_dirs: Sequence[Path], cache_dir: Path | None = None) -> Path:
    """Compile ``namespace_dirs`` + ``uavcan`` (+ referenced lookup roots) unless cached; put it on sys.path.

    :param namespace_dirs: DSDL root namespace directories (the last path component is the namespace name),
        e.g. ``[Path("generated/dsdl/sam")]``. May be empty: then only ``uavcan`` is compiled.
    :param cache_dir: parent of the cache entries; default ``$SAM_DSDL_CACHE`` or ``$XDG_CACHE_HOME/sam-codegen/dsdl``.
    :returns: the cache entry directory (holding ``uavcan/``, the given namespaces, ``nunavut_support.py``),
        inserted at ``sys.path[0]`` if it was not on ``sys.path`` yet.
    :raises DsdlCompileError: invalid DSDL, no ``uavcan`` on CYPHAL_PATH, missing directory, write failure.

    Modules already imported (``sys.modules``) are not reloaded: one process should call this once with
    every namespace it needs, before importing any of them (or pycyphal.application).
    """
    targets, lookups = _resolve_roots(namespace_dirs)
    base = Path(cache_dir).resolve() if cache_dir is not None else default_cache_dir()
    out = base / _content_hash(targets, lookups)
    if (out / _COMPLETE_MARKER).is_file():
        return _activate(out)

    try:
        base.mkdir(parents=True, exist_ok=True)
    except OSError as ex:
        raise DsdlCompileError(f"cannot create the DSDL cache directory {base}: {ex}") from None
    with _flock(base / f".lock-{out.name}"):
        if (out / _COMPLETE_MARKER).is_file():  # another process finished while we waited
            return _activate(out)
        if out.exists():  # no marker: not ours to trust (should not happen given the rename)
            _rmtree(out)
        _sweep_stale_tmp(base, out.name)
        tmp = Path(tempfile.mkdtemp(prefix=f".tmp-{out.name}-", dir=base))
        try:
            started = time.monotonic()
            # the first compile takes tens of seconds: a progress line on a terminal (issue 30)
            with TerminalProgress(f"compiling DSDL ({', '.join(t.name for t in targets) or 'uavcan'})"):
                given = [Path(d).expanduser().resolve().name for d in namespace_dirs]
                done = _compile_into(tmp, targets, lookups, given=given, base=base)
            (tmp / _COMPLETE_MARKER).write_text(
                f"namespaces={','.join(done)}\nseconds={time.monotonic() - started:.2f}\n{_versions()}\n"
            )
            try:
                os.rename(tmp, out)
            except OSError:
                # Lost a race with a process that does not share our lock (e.g. another file system view).
                if not (out / _COMPLETE_MARKER).is_file():
                    raise
        except OSError as ex:
            raise DsdlCompileError(f"cannot write the DSDL cache entry {out}: {ex}") from None
        finally:
            if tmp.exists():
                _rmtree(tmp)
    return _activate(out)


def find_compiled(namespace: str) -> Path | None:
    """The sys.path entry holding a compiled ``namespace`` package, without importing anything.

    (``importlib.util.find_spec`` would consult pycyphal's DSDL import hook, which may start compiling into
    ``~/.pycyphal`` when CYPHAL_PATH is set.)
    """
    for entry in sys.path:
        if isinstance(entry, str) and entry and (Path(entry) / namespace / "__init__.py").is_file():
            return Path(entry)
    return None
