"""Cyphal plumbing shared by the generator and the runtime: CYPHAL_PATH, the DSDL compile cache, transports.

Transports exercised here: Cyphal/UDP on 127.0.0.1 and python-can ``virtual`` (Classic CAN and CAN FD),
both in one process. SocketCAN cannot be exercised on these machines (no vcan module).
"""

from __future__ import annotations

import asyncio
import json
import os
import subprocess
import sys
from collections.abc import Awaitable, Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

import pytest

from sam_codegen.project.cyphal_path import CyphalPathError, default_search_dirs, dsdl_lookup_roots, repo_root

pytest.importorskip("pycyphal")
pytest.importorskip("can")

from sam_runtime.cyphal_io.dsdl_cache import DsdlCompileError, compiled_dir_for, ensure_compiled
from sam_runtime.cyphal_io.transport import (
    TransportConfigError,
    aclose,
    make_node,
    make_transport,
    transport_from_env,
)

T = TypeVar("T")

VECTOR3HALF = "# Three half-precision floats.\nfloat16[3] xyz\n@sealed\n"
BLOB = "# A signed 18-bit offset and up to 100 bytes.\nint18 offset\nuint8[<=100] data\n@extent 128 * 8\n"
BLOB_SIZE_MAX = (18 + 8 + 100 * 8 + 7) // 8  # int18, uint8 length prefix, 100 bytes: bit-packed


# ------------------------------------------------------------------------------------------- helpers


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def _make_demo(parent: Path) -> Path:
    ns = parent / "demo"
    _write(ns / "Vector3Half.1.0.dsdl", VECTOR3HALF)
    _write(ns / "Blob.1.0.dsdl", BLOB)
    return ns


def _make_tiny_uavcan(parent: Path) -> Path:
    """A stand-in ``uavcan`` root namespace: compiles in a fraction of the real one's time."""
    _write(parent / "uavcan" / "primitive" / "Empty.1.0.dsdl", "@sealed\n")
    return parent / "uavcan"


@pytest.fixture
def isolated_imports() -> Iterator[None]:
    """Restore sys.path and forget the test's DSDL packages so tests do not see each other's builds."""
    saved_path = list(sys.path)
    saved_modules = set(sys.modules)
    yield
    sys.path[:] = saved_path
    for name in set(sys.modules) - saved_modules:
        if name.split(".")[0] in {"demo", "extra", "unused", "other"}:
            del sys.modules[name]


@pytest.fixture
def tiny_cyphal_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """CYPHAL_PATH pointing at a directory with a tiny uavcan plus two unrelated namespaces."""
    lib = tmp_path / "lib"
    _make_tiny_uavcan(lib)
    _write(lib / "extra" / "Thing.1.0.dsdl", "uint7 value\n@sealed\n")
    _write(lib / "unused" / "Other.1.0.dsdl", "bool flag\n@sealed\n")
    monkeypatch.setenv("CYPHAL_PATH", str(lib))
    return lib


def _run(coro_fn: Callable[[], Awaitable[T]], timeout: float = 10.0) -> T:
    async def bounded() -> T:
        async with asyncio.timeout(timeout):  # no extra task, unlike wait_for()
            return await coro_fn()

    return asyncio.run(bounded())


# ------------------------------------------------------------------------------------------- CYPHAL_PATH


def test_default_lookup_roots_are_the_shared_copy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CYPHAL_PATH", raising=False)
    (default,) = default_search_dirs()
    assert default == (repo_root().parent / "shared" / "dsdl" / "public_regulated_data_types").resolve()
    roots = dsdl_lookup_roots()
    assert [r.name for r in roots] == ["reg", "uavcan"]
    assert all(r.parent == default for r in roots)
    monkeypatch.setenv("CYPHAL_PATH", "")  # set but empty = unset
    assert dsdl_lookup_roots() == roots


def test_cyphal_path_parsing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    _make_tiny_uavcan(a)
    _write(a / "foo" / "X.1.0.dsdl", "@sealed\n")
    _write(b / "foo" / "X.1.0.dsdl", "@sealed\n")  # shadowed by a/foo
    _write(b / "bar" / "sub" / "Y.1.0.dsdl", "@sealed\n")  # definitions only in a sub-namespace still count
    _write(b / ".git" / "Z.1.0.dsdl", "@sealed\n")  # not an identifier
    _write(b / "docs" / "README.md", "no definitions here\n")  # no .dsdl: not a namespace
    _write(b / "notes.dsdl", "@sealed\n")  # a file, not a directory
    missing = tmp_path / "missing"

    monkeypatch.setenv("CYPHAL_PATH", os.pathsep.join([str(a), "", str(missing), str(b), str(a)]))
    roots = dsdl_lookup_roots()
    assert [(r.name, r.parent) for r in roots] == [("bar", b), ("foo", a), ("uavcan", a)]

    monkeypatch.setenv("CYPHAL_PATH", f"{b};{a}")  # ';' accepted as well (pycyphal/yakut do)
    assert [(r.name, r.parent) for r in dsdl_lookup_roots()] == [("bar", b), ("foo", b), ("uavcan", a)]

    # An explicit mapping can be passed instead of the process environment.
    assert [r.name for r in dsdl_lookup_roots({"CYPHAL_PATH": str(a)})] == ["foo", "uavcan"]


def test_cyphal_path_without_uavcan(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _write(tmp_path / "only" / "foo" / "X.1.0.dsdl", "@sealed\n")
    value = os.pathsep.join([str(tmp_path / "only"), str(tmp_path / "nowhere")])
    monkeypatch.setenv("CYPHAL_PATH", value)
    with pytest.raises(CyphalPathError) as ei:
        dsdl_lookup_roots()
    msg = str(ei.value)
    assert "uavcan" in msg and str(tmp_path / "only") in msg and "(missing)" in msg
    assert f"CYPHAL_PATH={value!r}" in msg
    # The runtime reports the same problem as a compile error.
    with pytest.raises(DsdlCompileError, match="no DSDL root namespace 'uavcan'"):
        ensure_compiled([], tmp_path / "cache")


# ------------------------------------------------------------------------------------------- compile cache


def test_compile_cache_reuse_and_invalidation(
    tmp_path: Path, tiny_cyphal_path: Path, isolated_imports: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    import pycyphal.dsdl

    import sam_runtime.cyphal_io.dsdl_cache

    demo = _make_demo(tmp_path / "src")
    cache = tmp_path / "cache"

    out1 = ensure_compiled([demo], cache)
    assert out1.parent == cache.resolve()
    assert sys.path[0] == str(out1)
    assert {p.name for p in out1.iterdir()} >= {"demo", "uavcan", "nunavut_support.py"}
    assert not (out1 / "extra").exists() and not (out1 / "unused").exists()  # not referenced
    marker_mtime = (out1 / ".complete").stat().st_mtime_ns

    import demo as demo_pkg

    v = demo_pkg.Vector3Half_1_0(xyz=[1.0, -2.5, 9.81])
    # serialize() yields fragments lazily; deserialize() needs a sequence (len()), hence list().
    v2 = pycyphal.dsdl.deserialize(demo_pkg.Vector3Half_1_0, list(pycyphal.dsdl.serialize(v)))
    assert v2 is not None and list(v2.xyz) == [1.0, -2.5, 9.8125]  # float16 precision
    b = demo_pkg.Blob_1_0(offset=-(2**17), data=bytes(range(100)))
    wire = b"".join(pycyphal.dsdl.serialize(b))
    assert len(wire) == BLOB_SIZE_MAX  # top level: no delimiter header (only when nested)
    b2 = pycyphal.dsdl.deserialize(demo_pkg.Blob_1_0, [memoryview(wire)])
    assert b2 is not None and b2.offset == -(2**17) and bytes(b2.data) == bytes(range(100))
    with pytest.raises(ValueError):
        demo_pkg.Blob_1_0(offset=2**17)  # int18 range is [-131072, 131071]
    with pytest.raises(ValueError):
        demo_pkg.Blob_1_0(data=bytes(101))  # bounded array capacity

    # Unchanged sources: same directory, nothing recompiled (the compiler is not even called).
    with monkeypatch.context() as m:
        m.setattr(sam_runtime.cyphal_io.dsdl_cache, "_compile_into",
                  lambda *a: pytest.fail(f"a cache hit compiled again: {a}"))
        again = ensure_compiled([demo], cache)
    assert again == out1 and (out1 / ".complete").stat().st_mtime_ns == marker_mtime
    assert compiled_dir_for([demo], cache) == out1

    # Any byte of any involved definition changes the entry - even a comment, even in a lookup root.
    (demo / "Blob.1.0.dsdl").write_text(BLOB.replace("up to 100 bytes", "at most 100 bytes"))
    out2 = ensure_compiled([demo], cache)
    assert out2 != out1 and sys.path[0] == str(out2) and out1.is_dir()
    _write(tiny_cyphal_path / "unused" / "Other.1.0.dsdl", "bool flag\n# changed\n@sealed\n")
    out3 = ensure_compiled([demo], cache)
    assert out3 not in (out1, out2)
    # No half-written or temporary entries are left behind.
    assert not [p for p in cache.iterdir() if p.name.startswith(".tmp-")]
    assert all((p / ".complete").is_file() for p in cache.iterdir() if p.is_dir() and p.name != "roots")
    assert all((p / ".complete").is_file() for p in (cache / "roots").iterdir() if p.is_dir())


def test_the_roots_not_given_are_compiled_once_and_shared(
    tmp_path: Path, tiny_cyphal_path: Path, isolated_imports: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two specs' namespaces in one cache: uavcan and a referenced library root compile once (roots/<name>-<hash>)
    and each entry gets a copy; a changed library root compiles anew."""
    import sam_runtime.cyphal_io.dsdl_cache as dc

    compiled: list[str] = []
    real = dc._compile_root
    monkeypatch.setattr(dc, "_compile_root", lambda root, *a: compiled.append(root.name) or real(root, *a))
    cache = tmp_path / "cache"
    first = _write(tmp_path / "a" / "demo" / "UsesExtra.1.0.dsdl", "extra.Thing.1.0 thing\n@sealed\n").parent
    second = _write(tmp_path / "b" / "other" / "UsesExtra.1.0.dsdl", "extra.Thing.1.0 thing\n@sealed\n").parent
    out1 = ensure_compiled([first], cache)
    out2 = ensure_compiled([second], cache)
    assert out1 != out2 and sorted(compiled) == ["demo", "extra", "other", "uavcan"], compiled
    for out in (out1, out2):
        assert (out / "uavcan" / "primitive").is_dir() and (out / "extra" / "__init__.py").is_file()
        assert (out / "nunavut_support.py").is_file()
    shared = sorted(p.name.split("-")[0] for p in (cache / "roots").iterdir() if p.is_dir())
    assert shared == ["extra", "uavcan"], shared

    import other

    assert other.UsesExtra_1_0().thing.value == 0

    _write(tiny_cyphal_path / "extra" / "Thing.1.0.dsdl", "uint7 value\n# changed\n@sealed\n")
    compiled.clear()
    ensure_compiled([first], cache)
    assert sorted(compiled) == ["demo", "extra", "uavcan"], compiled  # the key hashes every library root


def test_leftovers_of_a_crashed_compile_are_replaced(tmp_path: Path, tiny_cyphal_path: Path) -> None:
    demo = _make_demo(tmp_path / "src")
    cache = tmp_path / "cache"
    entry = compiled_dir_for([demo], cache)
    # What a compile killed mid-way could leave: its temp dir, or (without the rename) an unmarked entry.
    _write(cache / f".tmp-{entry.name}-dead" / "demo" / "__init__.py", "raise ImportError('half')\n")
    _write(entry / "demo" / "__init__.py", "raise ImportError('half')\n")
    saved = list(sys.path)
    try:
        assert ensure_compiled([demo], cache) == entry
    finally:
        sys.path[:] = saved
    assert (entry / ".complete").is_file() and "half" not in (entry / "demo" / "__init__.py").read_text()
    assert sorted(p.name for p in cache.iterdir()) == sorted([entry.name, f".lock-{entry.name}", "roots"])


def test_referenced_lookup_root_is_compiled(
    tmp_path: Path, tiny_cyphal_path: Path, isolated_imports: None
) -> None:
    user = _write(tmp_path / "src" / "demo" / "UsesExtra.1.0.dsdl", "extra.Thing.1.0 thing\n@sealed\n").parent
    out = ensure_compiled([user], tmp_path / "cache")
    names = {p.name for p in out.iterdir()}
    assert {"demo", "extra", "uavcan"} <= names and "unused" not in names

    import demo

    msg = demo.UsesExtra_1_0()
    msg.thing.value = 127
    import pycyphal.dsdl

    assert b"".join(pycyphal.dsdl.serialize(msg)) == b"\x7f"


def test_broken_dsdl_gives_readable_error(tmp_path: Path, tiny_cyphal_path: Path) -> None:
    ns = tmp_path / "src" / "demo"
    _write(ns / "Vector3Half.1.0.dsdl", VECTOR3HALF)
    _write(ns / "Broken.1.0.dsdl", "# ok\ntruncated int3 x\n@sealed\n")  # truncated only for unsigned/float
    cache = tmp_path / "cache"
    with pytest.raises(DsdlCompileError) as ei:
        ensure_compiled([ns], cache)
    msg = str(ei.value)
    assert "Broken.1.0.dsdl:2:" in msg and "demo" in msg and "Traceback" not in msg
    assert ei.value.__cause__ is None and ei.value.__suppress_context__
    assert not [p for p in cache.iterdir() if not p.name.startswith(".lock-")]  # nothing half-written

    with pytest.raises(DsdlCompileError, match="does not exist"):
        ensure_compiled([tmp_path / "nope"], cache)


_RACE_SCRIPT = """
import json, sys
from pathlib import Path
from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled
out = ensure_compiled([Path(sys.argv[1])], Path(sys.argv[2]))
import demo
print(json.dumps({"out": str(out), "demo": demo.__file__}))
"""


@pytest.mark.system  # starts a process: not in the unit tier
def test_concurrent_compiles_share_one_entry(tmp_path: Path, tiny_cyphal_path: Path) -> None:
    demo = _make_demo(tmp_path / "src")
    cache = tmp_path / "cache"
    env = {**os.environ, "CYPHAL_PATH": str(tiny_cyphal_path), "PYCYPHAL_NO_IMPORT_HOOK": "1"}
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", _RACE_SCRIPT, str(demo), str(cache)],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(3)
    ]
    results = []
    for p in procs:
        out, err = p.communicate(timeout=60)
        assert p.returncode == 0, err
        results.append(json.loads(out.strip().splitlines()[-1]))
    assert len({r["out"] for r in results}) == 1
    entry = Path(results[0]["out"])
    assert all(r["demo"].startswith(str(entry)) for r in results)
    assert [p for p in cache.iterdir() if not p.name.startswith(".lock-") and p.name != "roots"] == [entry]
    shared = [p for p in (cache / "roots").iterdir() if not p.name.startswith(".lock-")]
    assert [p.name.split("-")[0] for p in shared] == ["uavcan"]  # one compile of it, no temporary left


# ------------------------------------------------------------------------------------------- transports


@pytest.fixture(scope="module")
def real_dsdl(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    """The real uavcan namespace (pycyphal.application needs it) + demo, compiled once for this module."""
    saved = list(sys.path)
    base = tmp_path_factory.mktemp("dsdl")
    mp = pytest.MonkeyPatch()
    mp.delenv("CYPHAL_PATH", raising=False)  # the shared public regulated data types
    try:
        ensure_compiled([_make_demo(base / "src")], base / "cache")
    finally:
        mp.undo()
    sys.modules.pop("demo", None)
    import demo

    yield demo
    sys.path[:] = saved
    for name in [n for n in sys.modules if n.split(".")[0] == "demo"]:
        del sys.modules[name]


async def _receive_until(sub: Any, deadline: float, pred: Callable[[Any, Any], bool]) -> Any:
    loop = asyncio.get_running_loop()
    while loop.time() < deadline:
        got = await sub.receive(min(deadline, loop.time() + 0.2))
        if got is not None and pred(*got):
            return got
    return None


@pytest.mark.parametrize(
    ("kind", "iface", "mtu", "min_frames"),
    [
        ("udp", "127.0.0.1", None, 1),
        ("can", "virtual:sam-test-classic", 8, 15),  # 104 B + 2 B CRC in 7-byte frame payloads
        ("can", "virtual:sam-test-fd", 64, 2),
    ],
    ids=["udp", "can-classic", "can-fd"],
)
def test_pubsub_between_two_nodes(
    real_dsdl: Any, kind: str, iface: str, mtu: int | None, min_frames: int
) -> None:
    demo = real_dsdl
    subject_id = 1234
    msg = demo.Blob_1_0(offset=-123456, data=bytes(range(100)))

    async def scenario() -> None:
        import uavcan.node

        loop = asyncio.get_running_loop()
        pub_node = make_node("org.sam.test.pub", 10, kind, iface=iface, mtu=mtu)
        sub_node = make_node("org.sam.test.sub", 11, kind, iface=iface, mtu=mtu)
        ports: list[Any] = []  # closed before the nodes, so no port proxy outlives its node
        try:
            if kind == "can":
                media = pub_node.presentation.transport._maybe_media  # no public accessor in pycyphal 1.27
                assert media.mtu == mtu and media.is_fd == (mtu > 8)
            pub = pub_node.make_publisher(demo.Blob_1_0, subject_id)
            sub = sub_node.make_subscriber(demo.Blob_1_0, subject_id)
            ports += [pub, sub]
            # Discovery-free transports, but subscriptions take effect asynchronously: publish until received.
            deadline = loop.time() + 5.0
            got = None
            while got is None and loop.time() < deadline:
                assert await pub.publish(msg)
                got = await sub.receive(loop.time() + 0.1)
            assert got is not None, f"nothing received over {kind} within 5 s"
            rx, transfer = got
            assert rx.offset == -123456 and bytes(rx.data) == bytes(range(100))
            assert transfer.source_node_id == 10
            assert len(transfer.fragmented_payload) >= min_frames

            # The application layer works too: heartbeat from the publisher, GetInfo answered.
            hb_sub = sub_node.make_subscriber(uavcan.node.Heartbeat_1_0)
            ports.append(hb_sub)
            hb = await _receive_until(hb_sub, loop.time() + 3.0, lambda _m, t: t.source_node_id == 10)
            assert hb is not None, "no heartbeat from node 10"
            client = sub_node.make_client(uavcan.node.GetInfo_1, 10)
            ports.append(client)
            client.response_timeout = 2.0
            info = await client(uavcan.node.GetInfo_1.Request())  # the response object, or None on timeout
            assert info is not None
            assert info.name.tobytes().decode() == "org.sam.test.pub"
        finally:
            await aclose(*ports, pub_node, sub_node)
        others = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
        assert not others, f"tasks left running after aclose(): {others}"

    _run(scenario, timeout=15.0)


def test_make_transport_and_env(real_dsdl: Any) -> None:
    async def scenario() -> None:
        t = make_transport("can", node_id=5, iface="virtual:sam-test-mk", mtu=8)
        assert t.local_node_id == 5 and t.protocol_parameters.mtu == 7 and not t._maybe_media.is_fd
        t.close()
        t = make_transport("can", node_id=None, iface="virtual:sam-test-mk")
        assert t.local_node_id is None and t.protocol_parameters.mtu == 63  # CAN FD by default
        t.close()
        t = make_transport("udp", node_id=300)
        assert t.local_node_id == 300 and "127.0.0.1" in repr(t)
        t.close()
        t = make_transport("loopback", node_id=1)
        t.close()

        env = {
            "UAVCAN__CAN__IFACE": "virtual:sam-test-env",
            "UAVCAN__CAN__MTU": "8",
            "UAVCAN__NODE__ID": "42",
        }
        t = transport_from_env(env)
        assert t.local_node_id == 42 and t.protocol_parameters.mtu == 7 and not t._maybe_media.is_fd
        t.close()
        t = transport_from_env({"UAVCAN__UDP__IFACE": "127.0.0.1", "UAVCAN__NODE__ID": "1000"})
        assert t.local_node_id == 1000
        t.close()
        t = transport_from_env({"UAVCAN__UDP__IFACE": "127.0.0.1", "UAVCAN__NODE__ID": "65535"})
        assert t.local_node_id is None  # 65535 = unset = anonymous, per the standard register
        t.close()
        with pytest.raises(TransportConfigError, match="UAVCAN__UDP__IFACE"):
            transport_from_env({"UAVCAN__NODE__ID": "3"})
        with pytest.raises(TransportConfigError, match="InvalidMediaConfigurationError"):
            make_transport("can", node_id=1, iface="nosuchiface:x")
        with pytest.raises(TransportConfigError, match="IPv4"):
            make_transport("udp", node_id=1, iface="not-an-ip")

    _run(scenario)
    with pytest.raises(TransportConfigError, match="unknown transport kind"):
        make_transport("serial", node_id=1)
    with pytest.raises(TransportConfigError, match="out of range for can"):
        make_transport("can", node_id=128, iface="virtual:x")
    with pytest.raises(TransportConfigError, match="MTU"):
        make_transport("can", node_id=1, iface="virtual:x", mtu=10)
    with pytest.raises(TransportConfigError, match="interface:channel"):
        make_transport("can", node_id=1, iface="can0")


def test_make_node_writes_no_register_file(
    real_dsdl: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("UAVCAN__NODE__ID", "99")  # the process environment is not consulted by make_node

    async def scenario() -> None:
        node = make_node(
            "org.sam.test.regs", 12, "udp", environ={"UAVCAN__PUB__BLOB__ID": "777"}, start=False
        )
        pub = None
        try:
            assert node.id == 12
            pub = node.make_publisher(real_dsdl.Blob_1_0, "blob")
            assert pub.port_id == 777  # port-ID from the register override
            assert int(node.registry["uavcan.pub.blob.id"]) == 777
        finally:
            await aclose(pub, node)

    _run(scenario)
    assert list(tmp_path.iterdir()) == []
    assert not list(repo_root().glob("*.db"))


@pytest.mark.skipif(not Path("/sys/class/net/vcan0").exists(), reason="no SocketCAN vcan0 on this machine")
def test_socketcan_vcan0_pubsub(real_dsdl: Any) -> None:
    """Real SocketCAN (pycyphal's native media) where a vcan0 exists; these machines have no vcan module."""
    demo = real_dsdl

    async def scenario() -> None:
        loop = asyncio.get_running_loop()
        a = make_node("org.sam.test.a", 20, "can", iface="socketcan:vcan0", mtu=8)
        b = make_node("org.sam.test.b", 21, "can", iface="socketcan:vcan0", mtu=8)
        pub = a.make_publisher(demo.Blob_1_0, 1235)
        sub = b.make_subscriber(demo.Blob_1_0, 1235)
        try:
            got = None
            deadline = loop.time() + 5.0
            while got is None and loop.time() < deadline:
                assert await pub.publish(demo.Blob_1_0(offset=7, data=bytes(50)))
                got = await sub.receive(loop.time() + 0.1)
            assert got is not None and got[0].offset == 7
        finally:
            await aclose(pub, sub, a, b)

    _run(scenario)
