"""Property-based fuzzing of the spec front end: random YAML, random edits of the real spec's tree and random
text damage. The only failure ever allowed is the project's own SpecError (with positions), never a traceback,
and a failed build never touches the output folder."""

from __future__ import annotations

import copy
import shutil
from pathlib import Path
from typing import Any

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sam_codegen.build import build
from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.model.diagnostics import SpecError
from sam_codegen.validate.resolve import validate

ROOT = Path(__file__).parents[2]
SPEC_TEXT = (ROOT / "spec" / "interfaces.yaml").read_text(encoding="utf-8")
SPEC_TREE = yaml.safe_load(SPEC_TEXT)
FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                         HealthCheck.too_slow])

scalars = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=20), st.sampled_from(["uint7", "int18", "float16[<=36]", "std_msgs/Header", "/imu",
                                           "sam.sensor.RawIMU.0.1", "auto", "uavcan_to_ros", "{{ x }}", "`"]),
)
documents = st.recursive(
    scalars,
    lambda children: st.one_of(st.lists(children, max_size=4),
                               st.dictionaries(st.text(max_size=12), children, max_size=4)),
    max_leaves=30,
)


def _check(text: str, tmp_path: Path) -> None:
    path = tmp_path / "fuzz.yaml"
    path.write_text(text, encoding="utf-8")
    try:
        validate(load_spec_file(path))
    except SpecError as exc:
        assert exc.diagnostics
        for diagnostic in exc.diagnostics:
            assert str(diagnostic).startswith(str(path)), diagnostic


@FUZZ
@given(documents)
def test_random_yaml(tmp_path: Path, document: Any) -> None:
    _check(yaml.safe_dump(document, allow_unicode=True), tmp_path)


@FUZZ
@given(documents.filter(lambda d: isinstance(d, dict)))
def test_random_top_level_sections(tmp_path: Path, extra: dict[str, Any]) -> None:
    tree = dict(SPEC_TREE)
    keys = list(tree)
    for i, (key, value) in enumerate(extra.items()):
        tree[keys[i % len(keys)] if i % 2 else key] = value
    _check(yaml.safe_dump(tree, allow_unicode=True, sort_keys=False), tmp_path)


def _paths(node: Any, prefix: tuple = ()) -> list[tuple]:
    result = [prefix]
    if isinstance(node, dict):
        for key, value in node.items():
            result.extend(_paths(value, (*prefix, key)))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            result.extend(_paths(value, (*prefix, i)))
    return result


ALL_PATHS = [p for p in _paths(SPEC_TREE) if p]


@st.composite
def mutated_specs(draw: st.DrawFn) -> Any:
    tree = copy.deepcopy(SPEC_TREE)
    for _ in range(draw(st.integers(1, 4))):
        path = draw(st.sampled_from(ALL_PATHS))
        parent = tree
        try:
            for key in path[:-1]:
                parent = parent[key]
            leaf = path[-1]
            action = draw(st.sampled_from(["delete", "replace", "duplicate", "nest"]))
            if action == "delete":
                del parent[leaf]
            elif action == "replace":
                parent[leaf] = draw(scalars)
            elif action == "duplicate" and isinstance(parent, list):
                parent.append(copy.deepcopy(parent[leaf]))
            elif action == "nest":
                parent[leaf] = [parent[leaf]]
        except (KeyError, IndexError, TypeError):
            continue  # an earlier mutation removed the path
    return tree


@FUZZ
@given(mutated_specs())
def test_mutations_of_the_real_spec(tmp_path: Path, tree: Any) -> None:
    _check(yaml.safe_dump(tree, allow_unicode=True, sort_keys=False), tmp_path)


@FUZZ
@given(st.lists(st.tuples(st.integers(0, len(SPEC_TEXT) - 1), st.integers(0, 8), st.text(max_size=4)),
                min_size=1, max_size=3))
def test_text_damage(tmp_path: Path, edits: list[tuple[int, int, str]]) -> None:
    text = SPEC_TEXT
    for at, length, insert in edits:
        at = min(at, len(text))
        text = text[:at] + insert + text[at + length:]
    _check(text, tmp_path)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mutated_specs())
def test_failed_build_leaves_output_untouched(tmp_path_factory: Any, tree: Any) -> None:
    base = tmp_path_factory.mktemp("fuzzbuild")
    out = base / "generated"
    shutil.copytree(ROOT / "generated", out)
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    spec = base / "interfaces.yaml"
    spec.write_text(yaml.safe_dump(tree, allow_unicode=True, sort_keys=False), encoding="utf-8")
    try:
        build(spec, out)
    except SpecError:
        assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
