"""The firmware headers (sam_codegen.targets.firmware, issue 28 part 4): every board's header of SAM's spec and of
two test specs (glider: Cyphal, lolo_v0: DroneCAN) compiles with `cc -std=c99 -Wall -Wextra -Werror`, all of a
spec's headers in one file (no name clashes between boards), and a tiny C main prints every constant, which must be
the spec's: node id, subject ids, data type ids and signatures (dronecan's own for the standard types), the
interface hash (as a number and as its 8 bytes), the settings' names on each protocol, defaults, ranges and enum
values.

It starts `cc` and the compiled program: a system test.
"""

from __future__ import annotations

import re
import shutil
import struct
import subprocess
from pathlib import Path
from typing import Any

import pytest

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.spec import Device
from sam_codegen.targets import firmware
from sam_codegen.validate.interface_version import interface_versions
from sam_codegen.validate.resolve import Resolved, validate

pytestmark = pytest.mark.system

ROOT = Path(__file__).resolve().parents[2]
SPECS = {"sam": ROOT / "spec" / "interfaces.yaml", "glider": ROOT / "tests" / "specs" / "glider.yaml",
         "lolo_v0": ROOT / "tests" / "specs" / "lolo_v0.yaml"}


def ident(text: str) -> str:
    return re.sub(r"[^A-Z0-9]", "_", text.upper())


def float32(value: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", value))[0])


def standard_v0(name: str) -> tuple[int, int] | None:
    """(data type id, signature) of a standard DroneCAN type as dronecan itself computes them."""
    import dronecan  # heavy (parses every definition at import): only this test needs it

    t = dronecan.TYPENAMES.get(name)
    return None if t is None else (t.default_dtid, t.get_data_type_signature())


# (macro, printf format, C cast, expected value as printed)
Check = tuple[str, str, str, str]


def device_checks(resolved: Resolved, name: str, device: Device) -> list[Check]:
    prefix = f"{ident(resolved.spec.vehicle)}_{ident(name)}"
    value = interface_versions(resolved).of(name)
    checks: list[Check] = [
        (f"{prefix}_NODE_ID", "%u", "unsigned", str(device.node_id)),
        (f"{prefix}_INTERFACE_HASH", "%016llx", "unsigned long long", f"{value:016x}"),
        (f"{prefix}_SPEC_INTERFACE_HASH", "%016llx", "unsigned long long",
         f"{interface_versions(resolved).whole:016x}"),
    ]
    seen: dict[str, int] = {}

    def port_base(kind: str, type_name: str) -> str:
        base = f"{prefix}_{kind}_{ident(type_name)}"
        seen[base] = seen.get(base, 0) + 1
        return base if seen[base] == 1 else f"{base}_{seen[base]}"

    if "cyphal" in device.protocols:
        for kind, ports in (("CYPHAL_PUB", device.publishes), ("CYPHAL_SUB", device.subscribes)):
            for port in ports:
                base = port_base(kind, port.type.rsplit(".", 2)[0])
                checks += [(f"{base}_SUBJECT_ID", "%u", "unsigned", str(port.subject_id)),
                           (f"{base}_TYPE", "%s", "const char *", port.type)]
    if "dronecan" in device.protocols:
        assert resolved.dronecan is not None
        for kind, v0_ports in (("DRONECAN_PUB", device.dronecan_publishes),
                               ("DRONECAN_SUB", device.dronecan_subscribes)):
            for v0 in v0_ports:
                expected = standard_v0(v0.type)
                if expected is None:  # the spec's own type: dronecan knows it only after load_dsdl
                    signed = resolved.dronecan.signed(v0.type)
                    assert signed is not None and signed.data_type_id is not None
                    expected = (signed.data_type_id, signed.signature)
                base = port_base(kind, v0.type)
                checks += [(f"{base}_DATA_TYPE_ID", "%u", "unsigned", str(expected[0])),
                           (f"{base}_SIGNATURE", "%016llx", "unsigned long long", f"{expected[1]:016x}")]
    for p in device.parameters:
        base = f"{prefix}_PARAM_{ident(p.name)}"
        checks += [(f"{base}_{ident(protocol)}_NAME", "%s", "const char *", on_name) for protocol, on_name in p.names]
        for label, v in (("DEFAULT", p.stored(p.default)), ("MIN", p.minimum), ("MAX", p.maximum)):
            if v is None:
                continue
            if p.type == "real":
                checks.append((f"{base}_{label}", "%.9g", "double", repr(float32(float(v)))))
            elif isinstance(v, str):
                checks.append((f"{base}_{label}", "%s", "const char *", v))
            else:
                checks.append((f"{base}_{label}", "%lld", "long long", str(int(v))))
        checks += [(f"{base}_{ident(n)}", "%lld", "long long", str(stored)) for n, stored in p.values]
    return checks


def c_string(text: str) -> str:
    return '"' + "".join(f"\\{b:03o}" for b in text.encode()) + '"'


@pytest.mark.parametrize("spec", list(SPECS))
def test_headers_compile_and_hold_the_spec(spec: str, tmp_path: Path) -> None:
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc)")
    resolved = validate(load_spec_file(SPECS[spec]))
    headers = firmware.emit(resolved)
    assert set(headers) == {f"firmware/{d}.h" for d in resolved.spec.devices}
    checks: list[Check] = []
    hash_bytes: list[tuple[str, str]] = []
    for path, text in headers.items():
        (tmp_path / Path(path).name).write_text(text, encoding="utf-8")
    for name, device in resolved.spec.devices.items():
        checks += device_checks(resolved, name, device)
        hash_bytes.append((f"{ident(resolved.spec.vehicle)}_{ident(name)}_INTERFACE_HASH_BYTES",
                           f"{interface_versions(resolved).of(name):016x}"))
    lines = ["#include <stdio.h>", "#include <stdint.h>", "#include <string.h>"]
    lines += [f'#include "{Path(p).name}"' for p in headers]
    lines += [f'#include "{Path(p).name}"' for p in headers]  # twice: the include guards hold
    lines.append("int main(void) {")
    for macro, fmt, cast, _ in checks:
        lines.append(f'    printf({c_string(macro + "=")} "{fmt}\\n", ({cast}){macro});')
    for i, (macro, _) in enumerate(hash_bytes):
        lines += [f"    static const uint8_t b{i}[8] = {macro};",
                  f'    printf({c_string(macro + "=")}); for (int k = 0; k < 8; k++) printf("%02x", b{i}[k]);'
                  ' printf("\\n");']
    lines += ["    return 0;", "}"]
    (tmp_path / "main.c").write_text("\n".join(lines) + "\n", encoding="utf-8")
    program = tmp_path / "main"
    subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-o", str(program),
                    str(tmp_path / "main.c")], check=True, capture_output=True, timeout=120)
    out = subprocess.run([str(program)], check=True, capture_output=True, text=True, timeout=60).stdout
    printed: dict[str, Any] = dict(line.split("=", 1) for line in out.splitlines())
    expected = {macro: (fmt, value) for macro, fmt, _, value in checks} | {m: ("", v) for m, v in hash_bytes}
    assert len(expected) == len(checks) + len(hash_bytes)  # every macro name once
    for macro, (fmt, value) in expected.items():
        if fmt == "%.9g":  # a real: the float32 nearest the spec's value (9 digits give a float32 back exactly)
            assert float32(float(printed[macro])) == float(value), macro
        else:
            assert printed[macro] == value, macro
    assert any("_PARAM_" in m for m in expected), "every spec here has settings"
