"""wire_cyphal's generated reader and writer against pycyphal for any DSDL types (tests/test_codec_cyphal.py uses it
for standard types with unions, arrays of delimited composites and padding, which no mapping can reach).

For each type, with seeded random objects: the writer's bytes (every leaf given, variable-length arrays of
composites left empty) equal pycyphal's serialize; the reader's leaves of any serialized object equal pycyphal's;
for every malformed variant of the payload (tests/helpers/codec_support.corruptions) the reader raises WireError
exactly where pycyphal's deserialize gives no object (None, or the assertion a delimited field longer than its
extent trips), and otherwise reads what pycyphal reads. Runs in a process of its own (compiled DSDL on its path).
"""

from __future__ import annotations

import importlib
import os
import random
import subprocess
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent


def check_standard_types(tmp: Path, names: list[str], trials: int = 12) -> None:
    """Run the check in a child process; raises AssertionError with its report when it fails."""
    env_path = [str(HERE.parent), *sys.path]
    proc = subprocess.run([sys.executable, str(Path(__file__)), str(tmp), str(trials), *names],
                          capture_output=True, text=True, timeout=900, check=False,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(p for p in env_path if p)})
    assert proc.returncode == 0, proc.stdout[-6000:] + proc.stderr[-6000:]
    assert proc.stdout.count("ok ") == len(names), proc.stdout


def _main(tmp: Path, trials: int, names: list[str]) -> None:
    from helpers.codec_support import corruptions, same
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.targets import dsdl as emit_dsdl
    from sam_codegen.targets.python.names import LocalNames, py_attr, py_class_name, py_module
    from sam_codegen.targets.wire.cdr_write import Constants
    from sam_codegen.targets.wire.cyphal_read import CYPHAL_PRELUDE, cyphal_reader, cyphal_writer
    from sam_codegen.validate.resolve import validate
    from sam_runtime.cyphal_io.dsdl_cache import ensure_compiled

    # The barge spec's DSDL refers to reg: compiling it brings uavcan and reg.
    resolved = validate(load_spec_file(HERE.parent / "specs" / "barge.yaml"))
    for path, text in emit_dsdl.emit(resolved).items():
        (tmp / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp / path).write_text(text, encoding="utf-8")
    sys.path.insert(0, str(ensure_compiled([tmp / "dsdl" / "barge"], HERE.parents[1] / ".cache" / "dsdl")))
    import pycyphal.dsdl

    lookup = resolved.dsdl.get

    class WireError(ValueError):
        pass

    def cls_of(struct: Any) -> Any:
        return getattr(importlib.import_module(py_module(struct.namespace)), py_class_name(struct))

    def leaves(struct: Any, prefix: tuple = ()) -> list[tuple[tuple, Any]]:
        out: list[tuple[tuple, Any]] = []
        if struct.union:
            return out
        for f in struct.fields:
            t, path = f.type, (*prefix, (f.name, None))
            if t.kind != "composite":
                out.append((path, t))
                continue
            nested = lookup(t.composite)
            if not t.array:
                out += leaves(nested, path)
            elif t.array == "fixed":
                for i in range(t.capacity):
                    out += leaves(nested, (*prefix, (f.name, i)))
        return out

    def value(t: Any, rng: random.Random) -> Any:
        if t.kind == "bool":
            return rng.random() < 0.5
        if t.kind == "float":
            return rng.choice([0.0, -1.5, 2.0 ** (t.bits // 2), float("inf")])
        lo, hi = (0, 255) if t.kind in ("byte", "utf8") else t.range
        return rng.choice([lo, hi, 0, rng.randint(lo, hi)])

    def obj_of(struct: Any, rng: random.Random, composite_arrays: bool) -> Any:
        if struct.union:
            return cls_of(struct)()
        kwargs: dict[str, Any] = {}
        for f in struct.fields:
            t = f.type
            if t.kind == "composite":
                nested = lookup(t.composite)
                if not t.array:
                    kwargs[py_attr(f.name)] = obj_of(nested, rng, composite_arrays)
                    continue
                count = t.capacity if t.array == "fixed" else rng.randint(0, min(3, t.capacity or 0)) \
                    if composite_arrays else 0
                kwargs[py_attr(f.name)] = [obj_of(nested, rng, composite_arrays) for _ in range(count)]
            elif t.kind == "utf8":
                kwargs[py_attr(f.name)] = bytes(rng.randint(0, 127) for _ in range(rng.randint(0, t.capacity)))
            elif t.array:
                n = t.capacity if t.array == "fixed" else rng.randint(0, t.capacity)
                kwargs[py_attr(f.name)] = [value(t.element, rng) for _ in range(n)]
            else:
                kwargs[py_attr(f.name)] = value(t, rng)
        return cls_of(struct)(**kwargs)

    def get(obj: Any, path: tuple) -> Any:
        for name, index in path:
            obj = getattr(obj, py_attr(name))
            if index is not None:
                obj = obj[index]
        return obj.tolist() if hasattr(obj, "tolist") else obj

    def plain(values: list[Any]) -> list[Any]:
        return [v.tobytes() if isinstance(v, memoryview) else v for v in values]

    for name in names:
        struct = lookup(name)
        assert struct is not None, name
        cls, ls = cls_of(struct), leaves(struct)
        consts = Constants()
        read_lines, found = cyphal_reader(struct, [p for p, _ in ls], lookup, LocalNames(set()), consts, "payload")
        write_lines, expr = cyphal_writer(struct, {p: f"v[{i}]" for i, (p, _) in enumerate(ls)}, lookup,
                                          LocalNames(set()), consts)
        source = "\n".join(["import struct as _struct", "from typing import Any", *CYPHAL_PRELUDE, *consts.lines(),
                            "def read(payload):", *("    " + line for line in read_lines),
                            f"    return [{', '.join(found[p] for p, _ in ls)}]",
                            "def write(v):", *("    " + line for line in write_lines), f"    return {expr}"])
        space: dict[str, Any] = {"WireError": WireError}
        exec(compile(source, name, "exec"), space)  # the generated code under test
        read, write = space["read"], space["write"]
        utf8 = [t.kind == "utf8" for _, t in ls]

        def values_of(obj: Any, ls: list = ls, utf8: list = utf8) -> list[Any]:
            return [bytes(get(obj, p)) if u else get(obj, p) for (p, _), u in zip(ls, utf8, strict=True)]

        rng = random.Random(name)
        for _ in range(trials):
            plain_obj = obj_of(struct, rng, composite_arrays=False)
            data = b"".join(bytes(x) for x in pycyphal.dsdl.serialize(plain_obj))
            assert bytes(write(values_of(plain_obj))) == data, (name, "writer")
            obj = obj_of(struct, rng, composite_arrays=True)
            data = b"".join(bytes(x) for x in pycyphal.dsdl.serialize(obj))
            assert same(plain(read(data)), values_of(obj)), (name, "reader")
            noise = bytes(rng.randint(0, 255) for _ in range(rng.randint(1, 12)))
            for case in corruptions(data, noise):
                try:
                    ref = pycyphal.dsdl.deserialize(cls, [memoryview(bytearray(case))])
                except AssertionError:  # pycyphal's bit length check, after an over-long delimited field
                    ref = None
                try:
                    got = plain(read(case))
                except WireError:
                    assert ref is None, (name, case.hex(), "refused what pycyphal reads")
                    continue
                assert ref is not None, (name, case.hex(), "read what pycyphal refuses")
                assert same(got, values_of(ref)), (name, case.hex(), got, values_of(ref))
        print("ok", name)


if __name__ == "__main__":
    _main(Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3:])
