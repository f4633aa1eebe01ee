"""pydsdl's check of the emitted DSDL, read in batches (codegen/build.py verify_dsdl): every type is still
checked, a rejection still points at the type's place in the spec, and the checks between types (references,
letter case, minor versions) hold across batch boundaries."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest

from sam_codegen import build
from sam_codegen.build import generate
from sam_codegen.model.diagnostics import SpecError

SPECS = Path(__file__).parents[1] / "specs"
BASE = (SPECS / "minimal.yaml").read_text(encoding="utf-8")


def _spec(tmp_path: Path, extra_types: str) -> Path:
    """minimal.yaml with more DSDL types (unused by devices and mappings) after its own."""
    anchor = "      - {name: open_pct, type: uint8}\n"
    assert anchor in BASE
    path = tmp_path / "minimal.yaml"
    path.write_text(BASE.replace(anchor, anchor + extra_types, 1), encoding="utf-8")
    return path


def _pydsdl_errors(path: Path) -> list[str]:
    with pytest.raises(SpecError) as info:
        generate(path)
    return [str(d).replace(str(path), path.name) for d in info.value.diagnostics]


@pytest.fixture(params=[1, 2, build.DSDL_BATCH], ids=lambda b: f"batch{b}")
def batch(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> int:
    monkeypatch.setattr(build, "DSDL_BATCH", request.param)
    return int(request.param)


# A chain of references across batches: A -> M -> Z (sorted apart, so batches of 1 or 2 split them).
CHAIN = """\
  buoy.a.First.0.1:
    sealed: true
    fields:
      - {name: middle, type: buoy.m.Middle.0.1}
  buoy.m.Middle.0.1:
    sealed: true
    fields:
      - {name: last, type: buoy.z.Last.0.1}
      - {name: stamp, type: uavcan.time.SynchronizedTimestamp.1.0}
  buoy.z.Last.0.1:
    extent: 16
    fields:
      - {name: value, type: uint7}
"""


def test_references_across_batches(tmp_path: Path, batch: int) -> None:
    files = generate(_spec(tmp_path, CHAIN))
    assert "dsdl/buoy/a/First.0.1.dsdl" in files and "dsdl/buoy/z/Last.0.1.dsdl" in files


def test_rejection_points_at_the_type(tmp_path: Path, batch: int) -> None:
    """An extent too small for the fields passes the validator; pydsdl rejects it, at the spec's line of it."""
    path = _spec(tmp_path, CHAIN.replace("extent: 16", "extent: 1").replace("type: uint7}", "type: uint64}"))
    line = path.read_text(encoding="utf-8").splitlines().index("  buoy.z.Last.0.1:") + 1
    errors = _pydsdl_errors(path)
    assert len(errors) == 1, errors
    assert errors[0].startswith(f"minimal.yaml:{line}:3: error: DSDL type buoy.z.Last.0.1 is rejected by pydsdl: "
                                "The specified extent of 8 bits is too small"), errors


def test_minor_versions_must_agree_across_batches(tmp_path: Path, batch: int) -> None:
    """Two minor versions of one major version (above 0) must have the same sealing (pydsdl's check)."""
    extra = """\
  buoy.v.Mode.1.0:
    sealed: true
    fields:
      - {name: mode, type: uint8}
  buoy.a.Other.0.1:
    sealed: true
    fields:
      - {name: x, type: uint8}
  buoy.v.Mode.1.1:
    extent: 1
    fields:
      - {name: mode, type: uint8}
"""
    errors = _pydsdl_errors(_spec(tmp_path, extra))
    assert len(errors) == 1 and "DSDL type buoy.v.Mode.1." in errors[0], errors
    assert "Mixing sealed and delimited types under the same major version" in errors[0], errors


def test_names_differing_only_in_case_across_batches(tmp_path: Path, batch: int) -> None:
    """A reference to a type whose name differs from another only by letter case is ambiguous (pydsdl)."""
    extra = """\
  buoy.c.FooBar.0.1:
    sealed: true
    fields:
      - {name: x, type: uint8}
  buoy.a.User.0.1:
    sealed: true
    fields:
      - {name: foo, type: buoy.c.FooBar.0.1}
  buoy.c.Foobar.0.1:
    sealed: true
    fields:
      - {name: y, type: uint8}
"""
    errors = _pydsdl_errors(_spec(tmp_path, extra))
    assert len(errors) == 1 and "letter case" in errors[0], errors


def test_batches_cover_every_type(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each spec type is a target of exactly one pydsdl call, in calls of at most the batch size."""
    extra = "".join(f"  buoy.g.T{i}.0.1:\n    sealed: true\n    fields:\n      - {{name: x, type: uint8}}\n"
                    for i in range(7))
    calls: list[list[str]] = []
    real = build.pydsdl.read_files

    def spy(targets, *args, **kwargs):  # type: ignore[no-untyped-def]
        if any("sam-dsdl-" in str(t) for t in targets):  # verify_dsdl's calls, not the standard types' catalog
            calls.append([Path(t).name for t in targets])
        return real(targets, *args, **kwargs)

    monkeypatch.setattr(build.pydsdl, "read_files", spy)
    monkeypatch.setattr(build, "DSDL_BATCH", 3)
    files = generate(_spec(tmp_path, extra))
    names = sorted(name for batch in calls for name in batch)
    assert names == sorted(p.rsplit("/", 1)[-1] for p in files if p.startswith("dsdl/"))
    assert len(calls) == 3 and all(len(c) <= 3 for c in calls)
    calls.clear()
    monkeypatch.setattr(build, "DSDL_BATCH", 100)
    generate(SPECS / "rover.yaml")
    assert len(calls) == 1  # a spec of up to DSDL_BATCH types is one call


def test_sigterm_during_a_build_leaves_no_dsdl_copies(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 29 item 11: a build killed by SIGTERM while pydsdl read its copies left /dev/shm/sam-dsdl-* behind.
    SIGTERM now raises Terminated where the build is, and the temporary folder goes. (The signal is sent only once
    the handler is in place: with the default action it would end the test process.)"""
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(build, "_scratch_dir", lambda: str(scratch))
    seen: list[Path] = []

    def killed_while_reading(_resolved: object, tree: Path, files: dict[str, str], *_args: object) -> None:
        for path, text in files.items():  # the copies pydsdl would read
            (tree / path).parent.mkdir(parents=True, exist_ok=True)
            (tree / path).write_text(text, encoding="utf-8")
        seen.extend(scratch.iterdir())
        if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
            raise AssertionError("SIGTERM would end the build without removing its DSDL copies")
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # the signal is handled at the next bytecode: never reached
        raise AssertionError("SIGTERM was not handled")

    monkeypatch.setattr(build, "_read_dsdl", killed_while_reading)
    previous = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        with pytest.raises(build.Terminated) as info:
            build.build(SPECS / "minimal.yaml", tmp_path / "generated")
        assert info.value.code == 128 + signal.SIGTERM
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # restored
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert [p.name.startswith("sam-dsdl-") for p in seen] == [True]
    assert list(scratch.iterdir()) == []
    assert not (tmp_path / "generated").exists()
