"""One seam per protocol: a protocol is one registered entry (sam_codegen.model.protocols.registry for the
generator, sam_runtime.protocols for the runtime) that the rest asks; nothing outside the registries compares a
protocol's name, and a protocol registered later (a fake third one here) is asked like the others."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from sam_codegen.contracts.tables_api import TablesModule
from sam_codegen.frontend.bridge import parse_device, parse_layout
from sam_codegen.frontend.traffic import check_enable_services
from sam_codegen.frontend.yaml_source import load_yaml
from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.protocols import registry as codegen_registry
from sam_codegen.model.protocols.description import ProtocolDescription
from sam_runtime import protocols as runtime_registry
from sam_runtime.bridge.backends.part import BridgePart
from sam_runtime.bridge.backends.time_sync_messages import SyncMessage, sync_message
from sam_runtime.bridge.layout import protocols_in_use, select
from sam_runtime.genpkg import GeneratedPackage, GeneratedPackageError
from sam_runtime.recording.recorder import layout_protocols
from sam_runtime.sim.ports import DeviceAdapter

REPO = Path(__file__).resolve().parents[2]
# The modules allowed to know the names: the registries and the entries themselves.
REGISTRY_MODULES = {REPO / "runtime" / "protocols.py", *(REPO / "codegen" / "model" / "protocols").glob("*.py")}


def _names_in(node: ast.AST, names: set[str]) -> bool:
    if isinstance(node, ast.Constant):
        return node.value in names
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return any(_names_in(e, names) for e in node.elts)
    return False


def protocol_name_branches(source: str, names: set[str]) -> list[tuple[int, str]]:
    """Where `source` branches on a protocol's name: a comparison (==, !=, in, not in) or a match case with the name
    as a string literal, or a getattr with a default of one."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare) and any(_names_in(n, names) for n in (node.left, *node.comparators)):
            found.append((node.lineno, ast.unparse(node)))
        elif isinstance(node, ast.match_case) and _names_in(getattr(node.pattern, "value", ast.Pass()), names):
            found.append((node.pattern.lineno, "case " + ast.unparse(node.pattern)))
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "getattr"
              and len(node.args) == 3 and _names_in(node.args[2], names)):
            found.append((node.lineno, ast.unparse(node)))
    return found


def test_the_scan_finds_a_branch() -> None:
    """The check below can fail: each kind of branch on a name is seen."""
    source = ('if p == "cyphal": pass\nif "dronecan" in ps: pass\nx = getattr(m, "protocol", "dronecan")\n'
              'match p:\n    case "cyphal": pass\nif p.v0: pass\n')
    assert [line for line, _ in protocol_name_branches(source, {"cyphal", "dronecan"})] == [1, 2, 3, 5]


def test_no_protocol_name_is_compared_outside_the_registries() -> None:
    names = set(runtime_registry.protocol_names())
    found = [f"{path.relative_to(REPO)}:{line}: {text}"
             for root in ("codegen", "runtime") for path in sorted((REPO / root).rglob("*.py"))
             if path not in REGISTRY_MODULES and "templates" not in path.parts
             for line, text in protocol_name_branches(path.read_text(), names)]
    assert not found, "ask the protocol's entry (its description or runtime part) instead:\n" + "\n".join(found)


def test_no_fallback_for_a_tables_member() -> None:
    """The tables' API (sam_codegen.contracts.tables_api) says what exists: no getattr(tables, name, default)."""
    found = []
    for root in ("codegen", "runtime"):
        for path in sorted((REPO / root).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "getattr"
                        and len(node.args) == 3 and isinstance(node.args[0], ast.Name)
                        and node.args[0].id == "tables"):
                    found.append(f"{path.relative_to(REPO)}:{node.lineno}: {ast.unparse(node)}")
    assert not found, "\n".join(found)


def test_the_two_registries_agree() -> None:
    assert runtime_registry.protocol_names() == codegen_registry.protocol_names() == ("cyphal", "dronecan")
    for entry in runtime_registry.registered():
        assert entry.description is codegen_registry.protocol(entry.name)
    assert runtime_registry.default_protocol().description is codegen_registry.default_protocol()


def _members(protocol_class: type) -> set[str]:
    return {n for n, v in vars(protocol_class).items() if inspect.isfunction(v) and not n.startswith("_")}


@pytest.mark.parametrize("name", runtime_registry.protocol_names())
def test_every_part_resolves(name: str) -> None:
    """Each entry's parts import and have what the bridge and the simulator ask of them."""
    entry = runtime_registry.runtime_protocol(name)
    part = entry.bridge()
    assert _members(BridgePart) <= {n for n in dir(part) if callable(getattr(part, n))}
    adapter = entry.sim()
    assert inspect.isclass(adapter) and _members(DeviceAdapter) <= set(dir(adapter))
    assert adapter.protocol == name


def test_an_unknown_protocol_names_the_known_ones() -> None:
    with pytest.raises(ValueError, match="'canard': expected one of cyphal, dronecan"):
        runtime_registry.runtime_protocol("canard")
    with pytest.raises(ValueError, match="'canard': expected one of cyphal, dronecan"):
        codegen_registry.protocol("canard")


# ------------------------------------------------------------------ a third protocol, registered
CANARD = ProtocolDescription(
    name="canard", label="Canard", v0=False, mappings_key="canard_mappings", mapping_noun="Canard mapping",
    liveness_type="canard.Heartbeat", node_ids=range(1, 64), transfer_id_modulo=16, codec_package="codec_canard",
    mappings_table="CANARD_MAPPINGS", devices_table="CANARD_DEVICES", device_stamped_table="CANARD_STAMPED",
    layout_mappings_field="canard_mappings", can_fd=False)


class CanardPart:
    """The bridge part of the fake protocol (only what these tests ask)."""

    def sync_message(self) -> SyncMessage:
        return SyncMessage("canard.TimeSync", 99, object, lambda us: us, 2.0)


CANARD_PART = CanardPart()


@pytest.fixture
def canard(monkeypatch: pytest.MonkeyPatch) -> runtime_registry.RuntimeProtocol:
    entry = runtime_registry.RuntimeProtocol(CANARD, f"{__name__}:CANARD_PART", f"{__name__}:CanardPart")
    monkeypatch.setattr(codegen_registry, "REGISTERED", (*codegen_registry.REGISTERED, CANARD))
    monkeypatch.setattr(runtime_registry, "REGISTERED", (*runtime_registry.REGISTERED, entry))
    return entry


def _tables() -> Any:
    """Generated tables of a vehicle whose thruster runs the fake protocol in layout `fleet`."""
    def device(name: str, node_id: int) -> SimpleNamespace:
        return SimpleNamespace(name=name, node_id=node_id)

    def mapping(name: str) -> SimpleNamespace:
        return SimpleNamespace(name=name)

    fleet = SimpleNamespace(name="fleet", cyphal_mappings=("imu",), dronecan_mappings=(),
                            canard_mappings=("thrust",), protocols={"imu": "cyphal", "thruster": "canard"},
                            devices=lambda p: [d for d, q in fleet.protocols.items() if q == p])
    return SimpleNamespace(
        LAYOUTS=(fleet,), DEFAULT_LAYOUT="fleet", NODES=(), TOPICS=(),
        DEVICES=(device("imu", 11),), MAPPINGS=(mapping("imu"),),
        DRONECAN_DEVICES=(), DRONECAN_MAPPINGS=(),
        CANARD_DEVICES=(device("thruster", 21), device("spare", 22)),
        CANARD_MAPPINGS=(mapping("thrust"), mapping("unused")), CANARD_STAMPED=frozenset({"thrust"}))


def test_the_runtime_asks_a_registered_protocol(canard: runtime_registry.RuntimeProtocol) -> None:
    tables = _tables()
    assert protocols_in_use(tables, "fleet") == ["cyphal", "canard"]
    assert layout_protocols(tables, None) == ("fleet", ["cyphal", "canard"])  # the recorder's
    sel = select(tables, "fleet", "canard")
    assert (sel.protocol, [m.name for m in sel.mappings], sel.devices, sel.shared) == (
        "canard", ["thrust"], {21: "thruster"}, True)
    assert canard.device_stamped(tables) == {"thrust"}
    assert sync_message("canard").label == "canard.TimeSync"  # its bridge part, imported by module path
    assert canard.sim() is CanardPart


def test_the_frontend_asks_a_registered_protocol(canard: runtime_registry.RuntimeProtocol) -> None:
    diag = Diagnostics()
    device = parse_device("thruster", Pos("t.yaml"), load_yaml("node_id: 21\nprotocol: canard\n", "t.yaml"), diag)
    assert not diag and device.protocol == "canard"
    parse_layout("fleet", Pos("t.yaml"), load_yaml("devices: {thruster: canard, imu: nope}\n", "t.yaml"), diag)
    assert [(d.message, d.expected) for d in diag.items] == [
        ("protocol 'nope' of device 'imu' in layout 'fleet' is unknown", "cyphal or dronecan or canard")]
    twice = [SimpleNamespace(name=n, enable_service_name="enable_thrust", pos=Pos("t.yaml", i + 1))
             for i, n in enumerate(("thrust", "thrust_aft"))]
    diag = Diagnostics()
    check_enable_services(twice, "canard", diag)  # type: ignore[arg-type]
    assert "of Canard mapping 'thrust_aft'" in diag.items[0].message


def test_tables_of_an_older_build_are_refused(tmp_path: Path) -> None:
    """Every member the contract names must be there (no fallbacks at the readers): an older build is rebuilt."""
    package = tmp_path / "python" / "seam28_old_bridge"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    members = [n for n in TablesModule.__annotations__ if n != "TIME_SYNC_PERIOD_S"]
    (package / "tables.py").write_text("".join(f"{n} = None\n" for n in members))
    with pytest.raises(GeneratedPackageError, match=r"lacks TIME_SYNC_PERIOD_S: .*run `sam-codegen build`"):
        GeneratedPackage(tmp_path, "seam28_old_bridge").tables()
