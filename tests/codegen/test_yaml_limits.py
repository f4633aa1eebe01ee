"""The YAML reader bounds what a spec can cost (issue 20): aliases that expand ("billion laughs") and nesting too deep
to walk are file:line:column errors, found at once, with no traceback, while ordinary anchors, aliases and merge keys
load as PyYAML's safe loader reads them."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
import yaml

from sam_codegen.frontend.loader import load_spec_file
from sam_codegen.frontend.yaml_source import (
    MAX_ALIAS_NODES_FLOOR,
    MAX_ALIAS_NODES_PER_NODE,
    MAX_DEPTH,
    YMap,
    YNode,
    YScalar,
    YSeq,
    load_yaml,
)
from sam_codegen.model.diagnostics import Pos, SpecError
from sam_codegen.validate.resolve import validate

SPECS = Path(__file__).parents[1] / "specs"
MINIMAL = (SPECS / "minimal.yaml").read_text(encoding="utf-8")
DEPTH_ERROR = (f"the YAML nests deeper than {MAX_DEPTH} levels "
               f"(expected at most {MAX_DEPTH} lists and mappings inside each other)")


def _laughs(levels: int) -> str:
    lines = ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, levels)]
    return "\n".join(lines) + "\n"


def _plain(node: YNode) -> Any:
    if isinstance(node, YScalar):
        return node.value
    if isinstance(node, YSeq):
        return [_plain(item) for item in node.items]
    return {key: _plain(value) for key, value in node.entries.items()}


def _ordered(value: Any) -> Any:
    """Dicts as lists of pairs: equality then also checks the order of keys."""
    if isinstance(value, dict):
        return [(key, _ordered(item)) for key, item in value.items()]
    if isinstance(value, list):
        return [_ordered(item) for item in value]
    return value


def _errors(text: str) -> list[str]:
    try:
        load_yaml(text, "s.yaml")
    except SpecError as exc:
        return [str(d) for d in exc.diagnostics]
    return []


# ---- hostile inputs through the command line: exit 1, the error, no traceback, bounded memory --------------------

# Runs the command and reports its exit code and peak resident memory. A separate interpreter, so that
# RUSAGE_CHILDREN holds this one command and none of the other children the test run has waited for.
_MEASURE = """
import resource, subprocess, sys
done = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
sys.stderr.write(done.stderr)
print(done.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""
# Reading and refusing these takes ~25 MB; the unbounded expansion grew by ~70 MB/s until it filled the machine.
_PEAK_KB = 200_000


def _sam_codegen() -> list[str]:
    script = Path(sys.executable).with_name("sam-codegen")
    return [str(script)] if script.exists() else [sys.executable, "-m", "sam_codegen.cli"]


@pytest.mark.parametrize(("name", "text", "at", "message"), [
    ("laughs", _laughs(9), "4:45",
     ("alias *a2 would copy 1111 more nodes, past the 10000 that aliases may add to this spec (8997 so far) "
      "(expected aliases that copy at most 10000 nodes in all, or 10 per node written in a larger spec)")),
    ("brackets", "x: " + "[" * 5000 + "]" * 5000 + "\n", f"1:{4 + MAX_DEPTH - 1}", DEPTH_ERROR),
    ("braces", "x: " + "{a: " * 5000 + "1" + "}" * 5000 + "\n", f"1:{4 + 4 * (MAX_DEPTH - 1)}", DEPTH_ERROR),
    # 2,000 levels: ~4 MB, under the spec file's size limit (8 MiB), so the depth is what refuses it
    ("block", "".join("  " * i + "a:\n" for i in range(2000)) + "  " * 2000 + "b\n",
     f"{MAX_DEPTH + 1}:{2 * MAX_DEPTH + 1}", DEPTH_ERROR),
], ids=lambda v: v if isinstance(v, str) and len(v) < 10 else "")
@pytest.mark.system  # starts a process: not in the unit tier
def test_cli_refuses_at_once(tmp_path: Path, name: str, text: str, at: str, message: str) -> None:
    spec = tmp_path / f"{name}.yaml"
    spec.write_text(text, encoding="utf-8")
    # The timeout only guards against a hang: the refusal itself takes a fraction of a second.
    done = subprocess.run([sys.executable, "-c", _MEASURE, *_sam_codegen(), "validate", "--spec", str(spec)],
                          check=False, capture_output=True, text=True, timeout=120, cwd=tmp_path)
    code, peak_kb = map(int, done.stdout.split())
    assert done.stderr == f"{spec}:{at}: error: {message}\n"
    assert code == 1
    assert peak_kb < _PEAK_KB, f"peak memory {peak_kb} kB"


# ---- the limits, at their edges -----------------------------------------------------------------------------------

def test_nesting_limit_is_exact() -> None:
    assert _errors("[" * MAX_DEPTH + "]" * MAX_DEPTH) == []
    assert _errors("[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1)) == [f"s.yaml:1:{MAX_DEPTH + 1}: error: {DEPTH_ERROR}"]


def test_nested_aliases_count_towards_the_depth() -> None:
    inner = "[" * (MAX_DEPTH - 2) + "]" * (MAX_DEPTH - 2)
    assert _errors(f"a: &a {inner}\nb: [*a]\n") == []  # 1 + 1 + 98 levels
    assert _errors(f"a: &a {inner}\nb: [[*a]]\n") == [
        (f"s.yaml:2:6: error: alias *a nests the YAML deeper than {MAX_DEPTH} levels "
         f"(expected at most {MAX_DEPTH} lists and mappings inside each other)")]


def test_alias_budget_is_exact() -> None:
    # An anchor of 100 nodes (the list and its 99 items) used k times copies 100 k nodes; the document itself is
    # too small for its own share of the budget to count, so the floor is the limit.
    anchor = "a: &a [" + ", ".join(["x"] * 99) + "]\n"
    assert MAX_ALIAS_NODES_FLOOR // 100 == 100
    assert _errors(anchor + "b: [" + ", ".join(["*a"] * 100) + "]\n") == []
    errors = _errors(anchor + "b: [" + ", ".join(["*a"] * 101) + "]\n")
    assert errors == [(f"s.yaml:2:{5 + 4 * 100}: error: alias *a would copy 100 more nodes, past the 10000 that "
                       "aliases may add to this spec (10000 so far) (expected aliases that copy at most 10000 nodes in "
                       "all, or 10 per node written in a larger spec)")]


def test_alias_budget_grows_with_the_document() -> None:
    """A large spec may copy more: the bound is on the growth, 10 copied nodes per node written."""
    anchor = "a: &a [" + ", ".join(["x"] * 99) + "]\n"
    padding = "pad: [" + ", ".join(["y"] * 3000) + "]\n"
    uses = MAX_ALIAS_NODES_PER_NODE * 3000 // 100  # 300 uses: 30,000 copied nodes, well past the floor
    tree = load_yaml(anchor + padding + "b: [" + ", ".join(["*a"] * uses) + "]\n", "s.yaml")
    assert isinstance(tree, YMap) and isinstance(tree.entries["b"], YSeq)
    assert len(tree.entries["b"].items) == uses
    assert len(_errors(anchor + padding + "b: [" + ", ".join(["*a"] * 2 * uses) + "]\n")) == 1


def test_one_error_for_a_runaway_expansion() -> None:
    assert len(_errors(_laughs(9))) == 1


# ---- ordinary anchors, aliases and merge keys ---------------------------------------------------------------------

ORDINARY = """\
defaults: &defaults {type: double, unit: m, min: 0.0, max: 10.0}
qos: &qos {depth: 5, reliability: reliable}
list: &list [a, b, {c: 1}]
scalar: &scalar 42
uses:
  one: {<<: *defaults, default: 1.0}
  overridden: {default: 2.0, <<: *defaults, unit: mm}
  two: {<<: *qos, durability: volatile}
  nested:
    <<: *defaults
    inner: {<<: *qos}
  lists: [*list, *list]
  scalars: [*scalar, *scalar]
  quoted: {"<<": not a merge}
  chained: &chained {<<: *qos, depth: 9}
  again: {<<: *chained}
"""


def test_ordinary_anchors_aliases_and_merges_load_as_pyyaml_does() -> None:
    expected = yaml.load(ORDINARY, Loader=yaml.SafeLoader)
    assert _ordered(_plain(load_yaml(ORDINARY, "s.yaml"))) == _ordered(expected)
    assert expected["uses"]["overridden"] == {"type": "double", "unit": "mm", "min": 0.0, "max": 10.0, "default": 2.0}


def test_in_a_list_of_merged_mappings_the_first_wins() -> None:
    """As https://yaml.org/type/merge.html has it, and PyYAML up to 6.0.3 (6.0.4 lets the last win for keys longer
    than one character, yaml/pyyaml#953: not followed)."""
    text = "a: &a {depth: 5, reliability: reliable}\nb: {<<: [*a, {depth: 1, history: keep_last}], depth_ok: true}\n"
    tree = load_yaml(text, "s.yaml")
    assert isinstance(tree, YMap)
    assert _ordered(_plain(tree.entries["b"])) == [("depth", 5), ("history", "keep_last"), ("reliability", "reliable"),
                                                   ("depth_ok", True)]


def test_an_alias_is_a_copy_at_its_anchor() -> None:
    """Each use is its own tree (nothing downstream can change one use through another); positions are the anchor's,
    where the text of the value is."""
    tree = load_yaml(ORDINARY, "s.yaml")
    assert isinstance(tree, YMap)
    uses = tree.entries["uses"]
    assert isinstance(uses, YMap)
    lists = uses.entries["lists"]
    assert isinstance(lists, YSeq)
    first, second = lists.items
    assert first == second == tree.entries["list"] and first is not second
    assert first.pos == Pos("s.yaml", 3, 7)
    one = uses.entries["one"]
    assert isinstance(one, YMap)
    assert one.key_pos["unit"] == Pos("s.yaml", 1, 36)  # merged: where the key is written
    assert one.key_pos["default"] == Pos("s.yaml", 6, 24)


def test_merged_spec_validates_as_the_written_out_one(tmp_path: Path) -> None:
    written = "  /alarm_level: {type: double, unit: m, default: 2.0, min: 0.0, max: 10.0}"
    assert written in MINIMAL
    text = MINIMAL.replace("  /warn_level: {", "  /warn_level: &warn {", 1)
    text = text.replace(written, "  /alarm_level: {<<: *warn, default: 2.0}")
    plain, merged = tmp_path / "plain.yaml", tmp_path / "merged.yaml"
    plain.write_text(MINIMAL, encoding="utf-8")
    merged.write_text(text, encoding="utf-8")
    a, b = validate(load_spec_file(plain)), validate(load_spec_file(merged))
    assert [(p.name, p.type, p.unit, p.default, p.minimum, p.maximum) for p in a.spec.parameters.values()] == \
        [(p.name, p.type, p.unit, p.default, p.minimum, p.maximum) for p in b.spec.parameters.values()]


def test_real_specs_are_far_below_the_limits() -> None:
    """The limits are chosen far above what a spec needs; if a real spec nears them, revisit the comment at
    MAX_DEPTH in yaml_source."""
    def depth(node: YNode) -> int:
        if isinstance(node, YSeq):
            return 1 + max((depth(item) for item in node.items), default=0)
        if isinstance(node, YMap):
            return 1 + max((depth(value) for value in node.entries.values()), default=0)
        return 0

    for path in [SPECS.parents[1] / "spec" / "interfaces.yaml", *sorted(SPECS.glob("*.yaml"))]:
        assert depth(load_yaml(path.read_text(encoding="utf-8"), str(path))) < 15, path


# ---- nothing later walks deeper than the reader allows ------------------------------------------------------------

DEEP = "[" * (MAX_DEPTH - 6) + "1" + "]" * (MAX_DEPTH - 6)


@pytest.mark.parametrize(("old", "new"), [
    ("  base_link: {}", "  base_link: DEEP"),  # a section the reader checks field by field
    ("{name: level, type: int32,", "{name: level, type: DEEP,"),  # a type name
    ("{name: level, type: int32,", "{name: level, type: 'int32[]', default: DEEP,"),  # a value checked per item
    ("description: Water level.", "description: DEEP"),  # a text
    ("default: 1.0, min: 0.0", "default: DEEP, min: 0.0"),  # a parameter value
    ("source_node_ids: [10]", "source_node_ids: DEEP"),  # a list of numbers
    ("        level: level_mm", "        level: DEEP"),  # a field rule of a mapping
    ("    parameters: [/warn_level]", "    parameters: DEEP"),  # a list of names
], ids=lambda v: v.split(":")[0].strip(" {"))
def test_deepest_allowed_values_are_errors_not_crashes(tmp_path: Path, old: str, new: str) -> None:
    """The deepest YAML the reader accepts, in each kind of place: the rest of validation reports it, never a
    RecursionError."""
    assert old in MINIMAL
    path = tmp_path / "deep.yaml"
    path.write_text(MINIMAL.replace(old, new.replace("DEEP", DEEP), 1), encoding="utf-8")
    with pytest.raises(SpecError) as caught:
        validate(load_spec_file(path))
    assert all(str(d).startswith(str(path)) for d in caught.value.diagnostics)


# ---- types chained in flat YAML: the validators refuse them before any recursive walk -----------------------------

def _chain(base: str, section: str, name: str, first: str, count: int) -> str:
    types = "".join(f"  {name.format(i)}:\n    fields:\n"
                    f"      - {{name: x, type: {name.format(i - 1) if i else first}}}\n" for i in range(count))
    assert f"\n{section}:\n" in base
    return base.replace(f"\n{section}:\n", f"\n{section}:\n{types}", 1)


@pytest.mark.parametrize(("spec", "section", "name", "first", "error"), [
    ("minimal.yaml", "messages", "M{}", "int32",
     "minimal.yaml:103:3: error: message buoy_msgs/M32 nests messages more than 32 levels deep (buoy_msgs/M32 -> "
     "buoy_msgs/M31 -> ... -> buoy_msgs/M0) (expected at most 32 levels of messages inside messages)"),
    ("minimal_v0.yaml", "dronecan_types", "skiff.C{}", "uint8",
     "minimal_v0.yaml:108:3: error: DroneCAN type skiff.C32 nests types more than 32 levels deep (skiff.C32 -> "
     "skiff.C31 -> ... -> skiff.C0) (expected at most 32 levels of types inside types)"),
], ids=["ros", "dronecan"])
def test_types_chained_in_flat_yaml_are_an_error(tmp_path: Path, spec: str, section: str, name: str, first: str,
                                                 error: str) -> None:
    """3000 types each holding the previous one: 2 levels of YAML, 3000 of types, one error and no RecursionError."""
    path = tmp_path / spec
    path.write_text(_chain((SPECS / spec).read_text(encoding="utf-8"), section, name, first, 3000), encoding="utf-8")
    with pytest.raises(SpecError) as caught:
        validate(load_spec_file(path))
    assert [str(d).replace(str(path), spec) for d in caught.value.diagnostics] == [error]
    path.write_text(_chain((SPECS / spec).read_text(encoding="utf-8"), section, name, first, 32), encoding="utf-8")
    validate(load_spec_file(path))  # 32 levels are allowed


# ---- types doubling at each level: every check linear, the flattened size bounded ---------------------------------

def _doubling(base: str, section: str, name: str, first: str, count: int, head: str = "") -> str:
    """`count` types, each holding two fields of the previous one: 2^(count-1) paths, 2 * count fields."""
    types = f"  {name.format(0)}:\n{head}    fields:\n      - {{name: a, type: {first}}}\n"
    types += "".join(f"  {name.format(i)}:\n{head}    fields:\n      - {{name: a, type: {name.format(i - 1)}}}\n"
                     f"      - {{name: b, type: {name.format(i - 1)}}}\n" for i in range(1, count))
    assert f"\n{section}:\n" in base
    return base.replace(f"\n{section}:\n", f"\n{section}:\n{types}", 1)


@pytest.mark.parametrize(("spec", "section", "name", "first", "head", "error"), [
    ("minimal.yaml", "messages", "M{}", "int32", "    description: x.\n",
     "minimal.yaml:76:3: error: message buoy_msgs/M14 flattens to 16,384 fields"),
    ("minimal.yaml", "dsdl_types", "buoy.T{}.0.1", "uint8", "    sealed: true\n",
     "minimal.yaml:82:3: error: DSDL type buoy.T14.0.1 flattens to 16,384 fields"),
    ("minimal_v0.yaml", "dronecan_types", "skiff.T{}", "uint8", "",
     "minimal_v0.yaml:67:3: error: DroneCAN type skiff.T14 flattens to 16,384 fields"),
], ids=["ros", "dsdl", "dronecan"])
def test_types_doubling_are_refused_in_linear_time(tmp_path: Path, spec: str, section: str, name: str, first: str,
                                                   head: str, error: str) -> None:
    """Issue 29 item 8: 30 types each holding two fields of the previous one, used by no topic. The cycle check
    walked every path (2^29; 22 levels took 17 s) and pydsdl's bit-length sets recurse the same way: each type is now
    visited once, and one that flattens to more than MAX_FLAT_FIELDS fields is an exact error before anything
    expands it. 13 levels (4,096 fields) are a valid spec."""
    base = (SPECS / spec).read_text(encoding="utf-8")
    path = tmp_path / spec
    path.write_text(_doubling(base, section, name, first, 30, head), encoding="utf-8")
    start = time.process_time()
    with pytest.raises(SpecError) as caught:
        validate(load_spec_file(path))
    assert time.process_time() - start < 5.0  # CPU time: the machine's load does not count
    assert [str(d).replace(str(path), spec) for d in caught.value.diagnostics] == [
        f"{error} (its nested types and fixed arrays of composites expanded), more than the limit of 10,000 "
        "(expected fewer copies of nested types; an array of primitives counts as one field)"]
    path.write_text(_doubling(base, section, name, first, 13, head), encoding="utf-8")
    start = time.process_time()
    validate(load_spec_file(path))
    assert time.process_time() - start < 5.0


def test_fixed_arrays_of_composites_count_their_elements(tmp_path: Path) -> None:
    """A fixed array multiplies its element's fields (the codecs expand it); an array of primitives counts one."""
    path = tmp_path / "minimal.yaml"
    types = ("  buoy.A.0.1:\n    sealed: true\n    fields:\n      - {name: x, type: 'uint8[65535]'}\n"
             "      - {name: y, type: 'float32[<=100]'}\n"
             "  buoy.B.0.1:\n    sealed: true\n    fields:\n      - {name: a, type: 'buoy.A.0.1[5001]'}\n")
    path.write_text(MINIMAL.replace("\ndsdl_types:\n", f"\ndsdl_types:\n{types}", 1), encoding="utf-8")
    with pytest.raises(SpecError) as caught:
        validate(load_spec_file(path))
    assert [str(d).replace(str(path), "minimal.yaml").split(" (")[0] for d in caught.value.diagnostics] == [
        "minimal.yaml:18:3: error: DSDL type buoy.B.0.1 flattens to 10,002 fields"]


def test_message_cycles_are_found_in_one_pass(tmp_path: Path) -> None:
    """A cycle of two messages and a message holding it: one error per cycle, the shortest cycle named."""
    types = ("  A:\n    description: x.\n    fields:\n      - {name: b, type: buoy_msgs/B}\n"
             "  B:\n    description: x.\n    fields:\n      - {name: a, type: buoy_msgs/A}\n"
             "      - {name: c, type: int8}\n"
             "  C:\n    description: x.\n    fields:\n      - {name: a, type: buoy_msgs/A}\n")
    path = tmp_path / "minimal.yaml"
    path.write_text(MINIMAL.replace("\nmessages:\n", f"\nmessages:\n{types}", 1), encoding="utf-8")
    with pytest.raises(SpecError) as caught:
        validate(load_spec_file(path))
    assert [str(d).replace(str(path), "minimal.yaml") for d in caught.value.diagnostics] == [
        "minimal.yaml:7:3: error: message buoy_msgs/A contains itself: buoy_msgs/A -> buoy_msgs/B -> buoy_msgs/A"]


def test_frame_ancestry_is_checked_in_linear_time(tmp_path: Path) -> None:
    """Each frame walked its whole ancestry (a chain of N frames: N^2 / 2 steps, 20,000 frames ~2 * 10^8): now each
    frame is walked once. Loops are still found, and every frame that reaches one is named."""
    chain = "".join(f"  f{i}: {{parent: f{i - 1}}}\n" for i in range(1, 20_000))
    loop = "  a: {parent: b}\n  b: {parent: a}\n  c: {parent: a}\n"
    path = tmp_path / "minimal.yaml"
    path.write_text(MINIMAL.replace("  base_link: {}\n", f"  base_link: {{}}\n  f0: {{}}\n{chain}{loop}", 1),
                    encoding="utf-8")
    start = time.process_time()
    with pytest.raises(SpecError) as caught:
        validate(load_spec_file(path))
    assert time.process_time() - start < 20.0  # CPU time; the quadratic walk alone took minutes
    assert [d.message for d in caught.value.diagnostics] == [
        "frame 'a' is its own ancestor", "frame 'b' is its own ancestor", "frame 'c' is its own ancestor"]
