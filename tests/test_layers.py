"""The architecture, enforced: imports run one way through the layers of both packages, no cycle, no private name
crosses a module, and first-party imports inside functions exist only for an optional extra.

The layers (top -> bottom; a module may import its own layer's modules unless they are declared independent, and any
layer below):

sam_codegen: cli > build > targets > conversion_plan | render > validate > catalogs | frontend > model | project
             > contracts
sam_runtime: cli | cli_support | main_job > bridge | sim | nodes | recording | report
             > genpkg | protocols | node_support | tf_buffer | nav > cyphal_io | dronecan_io | physics > common

Inside targets/ the sibling edges run one way: wire -> python -> {nodes, ros, dsdl_v0}, dsdl_v0 -> dsdl, docs -> nodes,
and registry (the list of emitters) above them all. sam_runtime may import sam_codegen (the spec, the project, the
build); sam_codegen imports sam_runtime only in cli, inside the commands that need the runtime extra.

The graph is read from the source with ast (every import statement, at module level, in functions and under
TYPE_CHECKING), so it also sees what a lazy import would hide from a run.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGES = {"sam_codegen": REPO / "codegen", "sam_runtime": REPO / "runtime"}

# (layer index, group): lower index = higher layer. Groups of one layer are independent of each other when the
# layer is marked so.
LAYERS: dict[str, list[tuple[str, ...]]] = {
    "sam_codegen": [("cli",), ("build",), ("targets",), ("conversion_plan", "render"), ("validate",),
                    ("catalogs", "frontend"), ("model", "project"), ("contracts",)],
    "sam_runtime": [("cli", "cli_support", "main_job"), ("bridge", "sim", "nodes", "recording", "report"),
                    ("genpkg", "protocols", "node_support", "tf_buffer", "nav"),
                    ("cyphal_io", "dronecan_io", "physics"),
                    ("common",)],
}
INDEPENDENT: dict[str, set[frozenset[str]]] = {
    "sam_codegen": {frozenset({"conversion_plan", "render"}), frozenset({"catalogs", "frontend"}),
                    frozenset({"model", "project"})},
    "sam_runtime": {frozenset({"bridge", "sim", "nodes", "recording", "report"}),
                    frozenset({"cyphal_io", "dronecan_io", "physics"})},
}
# Sibling edges allowed inside sam_codegen.targets (importer part -> imported part).
TARGET_EDGES = {("wire", "python"), ("python", "nodes"), ("python", "ros"), ("python", "dsdl_v0"),
                ("dsdl_v0", "dsdl"), ("docs", "nodes")}
# First-party imports allowed inside a function, each for an optional extra: (importer, imported prefix).
LAZY_FIRST_PARTY = {
    ("sam_codegen.cli", "sam_runtime"),  # the runtime commands need the `runtime` extra (rclpy, pycyphal)
    # The DroneCAN side imports dronecan, which parses its whole DSDL set at import (~0.4 s): a vehicle without
    # DroneCAN devices never loads it.
    ("sam_runtime.genpkg", "sam_runtime.dronecan_io"),
    # (sam_runtime.protocols names each protocol's simulated devices and bridge part by module path, imported when
    # a device or a bridge runs that protocol)
    ("sam_runtime.bridge.backends.dronecan_part", "sam_runtime.bridge.backends.dronecan"),
}
# The entry points import a command's implementation when that command runs: `sam-codegen validate` must not load
# rclpy or pycyphal, nor `sam-bridge --help` the simulator.
ENTRY_POINTS = {"sam_codegen.cli", "sam_runtime.cli", "sam_runtime.cli_support"}


@dataclass(frozen=True)
class Import:
    importer: str
    target: str
    names: tuple[str, ...]
    line: int
    in_function: bool


def module_name(package: str, path: Path) -> str:
    rel = path.relative_to(PACKAGES[package]).with_suffix("")
    parts = [package, *rel.parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def modules() -> dict[str, Path]:
    found = {}
    for package, root in PACKAGES.items():
        for path in root.rglob("*.py"):
            if "templates" not in path.relative_to(root).parts:
                found[module_name(package, path)] = path
    return found


def _resolve(importer: str, is_package: bool, level: int, module: str | None) -> str:
    if level == 0:
        return module or ""
    base = importer.split(".") if is_package else importer.split(".")[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join([*base, module] if module else base)


@cache
def imports() -> tuple[Import, ...]:
    found: list[Import] = []
    mods = modules()
    for name, path in mods.items():
        tree = ast.parse(path.read_text(), str(path))
        functions = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]
        nested = {id(n) for f in functions for n in ast.walk(f) if n is not f}
        for node in ast.walk(tree):
            in_function = id(node) in nested
            if isinstance(node, ast.Import):
                for alias in node.names:
                    found.append(Import(name, alias.name, (), node.lineno, in_function))
            elif isinstance(node, ast.ImportFrom):
                base = _resolve(name, path.name == "__init__.py", node.level, node.module)
                for alias in node.names:
                    target = f"{base}.{alias.name}"
                    if target in mods:  # `from package import module`
                        found.append(Import(name, target, (), node.lineno, in_function))
                    else:
                        found.append(Import(name, base, (alias.name,), node.lineno, in_function))
    return tuple(i for i in found if i.target.split(".")[0] in PACKAGES)


def first_party_edges() -> set[tuple[str, str]]:
    mods = modules()
    edges = set()
    for i in imports():
        target = i.target
        while target not in mods and "." in target:
            target = target.rsplit(".", 1)[0]
        if target in mods and target != i.importer:
            edges.add((i.importer, target))
    return edges


def part(module: str) -> tuple[str, str]:
    """(package, top-level part): ('sam_codegen', 'targets') for sam_codegen.targets.wire.codec."""
    pieces = module.split(".")
    return pieces[0], pieces[1] if len(pieces) > 1 else ""


def layer_of(module: str) -> tuple[int, str] | None:
    package, top = part(module)
    for index, group in enumerate(LAYERS[package]):
        if top in group:
            return index, top
    return None


def test_every_module_has_a_layer() -> None:
    missing = [m for m in modules() if m not in PACKAGES and layer_of(m) is None]
    assert not missing, f"modules in no layer (add them to LAYERS): {missing}"


def test_imports_run_down_the_layers() -> None:
    wrong = []
    for importer, target in sorted(first_party_edges()):
        if target in PACKAGES:
            wrong.append(f"{importer} -> {target}: import the module that holds the name, not the package root")
            continue
        if importer in PACKAGES or any(importer == a and target.startswith(b + ".") for a, b in LAZY_FIRST_PARTY):
            continue
        (src_pkg, _), (dst_pkg, _) = part(importer), part(target)
        if src_pkg != dst_pkg:
            if src_pkg == "sam_codegen":
                wrong.append(f"{importer} -> {target}: sam_codegen may not import sam_runtime")
            continue
        src, dst = layer_of(importer), layer_of(target)
        assert src and dst
        if dst[0] < src[0]:
            wrong.append(f"{importer} -> {target}: up the layers ({src[1]} is below {dst[1]})")
        elif dst[0] == src[0] and src[1] != dst[1] and any(
                src[1] in g and dst[1] in g for g in INDEPENDENT[src_pkg]):
            wrong.append(f"{importer} -> {target}: {src[1]} and {dst[1]} are independent")
    assert not wrong, "\n".join(wrong)


def test_target_siblings_import_one_way() -> None:
    wrong = []
    for importer, target in sorted(first_party_edges()):
        a, b = importer.split("."), target.split(".")
        if a[:2] == b[:2] == ["sam_codegen", "targets"] and len(a) > 2 and len(b) > 2 and a[2] != b[2]:
            if a[2] != "registry" and (a[2], b[2]) not in TARGET_EDGES:
                wrong.append(f"{importer} -> {target}")
    assert not wrong, "target siblings importing outside " + f"{sorted(TARGET_EDGES)}:\n" + "\n".join(wrong)


def _cycles(edges: set[tuple[str, str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    graph: dict[str, list[str]] = {}
    for a, b in edges:
        graph.setdefault(a, []).append(b)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, []):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_import_cycles() -> None:
    """Package __init__ modules count too: a module that imports its own package's __init__, which imports it back,
    is a cycle."""
    assert not _cycles(first_party_edges())


def test_cycle_finder_finds_a_cycle() -> None:
    assert _cycles({("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")}) == [["a", "b", "c"]]


def test_no_private_name_crosses_a_module() -> None:
    crossing = [f"{i.importer}:{i.line} imports {n} from {i.target}"
                for i in imports() for n in i.names if n.startswith("_") and not n.startswith("__")]
    assert not crossing, "\n".join(crossing)


def test_tests_and_benchmarks_use_only_public_names() -> None:
    """A private name is free to change: no test or benchmark may depend on one."""
    crossing = []
    for path in sorted([*(REPO / "tests").rglob("*.py"), *(REPO / "bench").rglob("*.py")]):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] in PACKAGES:
                crossing += [f"{path.relative_to(REPO)}:{node.lineno} imports {a.name} from {node.module}"
                             for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
    assert not crossing, "\n".join(crossing)


def test_first_party_imports_in_functions_only_for_optional_extras() -> None:
    def allowed(i: Import) -> bool:
        return i.importer in ENTRY_POINTS or any(
            i.importer == a and (i.target == b or i.target.startswith(b + ".")) for a, b in LAZY_FIRST_PARTY)

    lazy = [f"{i.importer}:{i.line} imports {i.target} inside a function"
            for i in imports() if i.in_function and not allowed(i)]
    assert not lazy, "\n".join(lazy)


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_the_graph_is_read(package: str) -> None:
    """The checks above see the real graph: many first-party edges, and the known entry points among the modules."""
    assert sum(1 for a, _ in first_party_edges() if a.startswith(package)) > 100
    assert f"{package}.cli" in modules()
