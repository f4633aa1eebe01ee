"""Node emitter: a typed ROS 2 base class per node of the spec, and the parameters file.

Output, under generated/:
- ``python/<vehicle>_nodes/<node>.py``: ``<CamelName>Base`` on rclpy's Node, straight-line code per topic,
  parameter and transform (names from validate_nodes), documented in the module docstring. The mechanisms they
  share (parameter descriptors and rule checks, QoS profiles, TF buffer feeding, diagnostics) are in
  ``sam_runtime.node_support``.
- ``python/<vehicle>_nodes/__init__.py``: the nodes (module, base class), the static transforms and
  ``publish_static_transforms(node)`` for the node host.
- ``params/<vehicle>.params.yaml``: every spec parameter's default in ROS 2's ``--params-file`` format for all
  nodes (``/**``): ROS 2 has no global parameters, this file gives them one value across the nodes.

The node and QoS parts of the bridge's tables.py are built by targets/python/tables.py from this module's names
(``nodes_package``, ``params_file``, ``static_transforms``): this module imports no other target.
Every text from the spec reaches a docstring through ``doc``/``doc_wrap`` (inert) and code through ``py_str`` (repr).
"""

from __future__ import annotations

import json
import keyword
import math
import textwrap
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sam_codegen.model.frames import quat_from_rpy
from sam_codegen.model.spec import Parameter, Qos, Spec
from sam_codegen.render.filters import natural_key, one_line, py_number, py_str
from sam_codegen.render.pysource import float_literal
from sam_codegen.render.templating import environment, render
from sam_codegen.validate.nodes import (
    TF_STATIC_TOPIC,
    TF_TOPIC,
    class_name,
    node_topic_qos,
    parameter_identifier,
    ros_parameter_name,
    rule_partners,
    topic_identifier,
    transform_identifier,
)
from sam_codegen.validate.resolve import Resolved

__all__ = ["emit", "nodes_package", "params_file"]

PY_TYPES = {"double": "float", "integer": "int", "bool": "bool", "string": "str"}
# Names the generated modules define or import themselves; a message class of the same name gets an alias.
_MODULE_NAMES = frozenset({"annotations", "Any", "Mapping", "Node", "node_support", "tf_buffer", "NODE_NAME",
                           "PARAMETERS", "PARTNERS", "RULES"})


def nodes_package(spec: Spec) -> str:
    return f"{spec.vehicle}_nodes"


def params_file(spec: Spec) -> str:
    """The parameters file's path under generated/."""
    return f"params/{spec.vehicle}.params.yaml"


DOC_WIDTH = 110


def doc(text: object) -> str:
    r"""Text for a docstring: one line, backslashes and quotes escaped (so neither ends the docstring).

    >>> print(doc('a "b" \\ c\n d'))
    a \"b\" \\ c d
    """
    return _escape(one_line(str(text)))


def _escape(line: str) -> str:
    return line.replace("\\", "\\\\").replace('"', '\\"')


def doc_wrap(text: object, first: str = "", rest: str = "", width: int = DOC_WIDTH) -> str:
    """Docstring text wrapped at `width` (a bullet: first="- ", rest="  "); wrapped, then escaped line by line.

    >>> print(doc_wrap("one two three", "- ", "  ", width=9))
    - one two
      three
    """
    lines = textwrap.wrap(one_line(str(text)), width, initial_indent=first, subsequent_indent=rest,
                          break_on_hyphens=False) or [first.rstrip()]
    return "\n".join(_escape(line) for line in lines)


def qos_args(qos: Qos) -> str:
    """
    >>> qos_args(Qos("reliable", "transient_local", 1))
    '"reliable", "transient_local", 1'
    """
    return f'"{qos.reliability}", "{qos.durability}", {qos.depth}'


def _value_literal(p: Parameter) -> str:
    if p.type == "double":  # NaN only with `allow_nan: true`; spelled as an expression, `nan` is no Python name
        value = float(p.default)
        return py_number(value) if math.isnan(value) else float_literal(value)
    return py_str(p.default) if p.type == "string" else repr(p.default)


def _range_text(p: Parameter) -> str:
    if p.minimum is None and p.maximum is None:
        return ""
    low = "" if p.minimum is None else f"{p.minimum:g}"
    high = "" if p.maximum is None else f"{p.maximum:g}"
    return f"{low} .. {high}"


# ---- per node --------------------------------------------------------------------------------------------------


@dataclass
class _Imports:
    """Message classes of one module: `from pkg.msg import Name` (aliased `pkg_Name` on a clash)."""

    reserved: set[str]
    aliases: dict[str, str] = field(default_factory=dict)  # pkg/Name -> local name

    def use(self, full: str) -> str:
        if full not in self.aliases:
            package, name = full.split("/")
            taken = self.reserved | set(self.aliases.values())
            self.aliases[full] = name if name not in taken and not keyword.iskeyword(name) else f"{package}_{name}"
        return self.aliases[full]

    def lines(self, extra: dict[str, list[str]]) -> list[str]:
        """The `from ... import ...` lines, sorted as isort does, with `extra` {module: names} among them."""
        by_module: dict[str, list[str]] = {module: list(names) for module, names in extra.items()}
        for full, local in self.aliases.items():
            package, name = full.split("/")
            by_module.setdefault(f"{package}.msg", []).append(name if local == name else f"{name} as {local}")
        lines = []
        for module in sorted(by_module):
            names = sorted(by_module[module], key=lambda n: (natural_key(n.split(" ")[0]), n))
            line = f"from {module} import {', '.join(names)}"
            if len(line) <= 110:
                lines.append(line)
            else:
                lines.append(f"from {module} import (\n" + "".join(f"    {n},\n" for n in names) + ")")
        return lines


def _parameter_spec(spec: Spec, p: Parameter) -> dict[str, Any]:
    readers = [n.name for n in spec.nodes.values() if p.name in n.parameters]
    args = [f"name={py_str(p.name)}", f"type={py_str(p.type)}", f"default={_value_literal(p)}",
            f"minimum={'None' if p.minimum is None else float_literal(p.minimum)}",
            f"maximum={'None' if p.maximum is None else float_literal(p.maximum)}", f"unit={py_str(p.unit)}"]
    after = ["readers=(" + "".join(f"{py_str(r)}, " for r in readers).rstrip(" ") + ")"]
    return {"args": args, "description_text": p.description, "args_after": after, "name": p.name,
            "ros_name": ros_parameter_name(p.name), "attr": parameter_identifier(p.name), "py_type": PY_TYPES[p.type],
            "unit": p.unit, "range": _range_text(p), "default": _value_literal(p),
            "description": one_line(p.description), "readers": readers}


def _node_context(resolved: Resolved, name: str) -> dict[str, Any]:
    spec = resolved.spec
    node = spec.nodes[name]
    base = class_name(name)
    imports = _Imports(set(_MODULE_NAMES) | {base})
    subscriptions, publications = [], []
    for item in node.subscribe_items:
        topic = spec.topics[item.topic]
        qos = node_topic_qos(spec, item, subscription=True)
        subscriptions.append({
            "topic": item.topic, "ident": topic_identifier(item.topic), "cls": imports.use(topic.type),
            "type": topic.type, "qos": qos_args(qos), "qos_text": qos.describe(),
            "own_qos": item.qos is not None, "description": one_line(topic.description),
        })
    for item in node.publish_items:
        topic = spec.topics[item.topic]
        qos = node_topic_qos(spec, item, subscription=False)
        publications.append({
            "topic": item.topic, "ident": topic_identifier(item.topic), "cls": imports.use(topic.type),
            "type": topic.type, "qos": qos_args(qos), "qos_text": qos.describe(),
            "description": one_line(topic.description),
        })
    tf_qos = spec.topics[TF_TOPIC].qos if TF_TOPIC in spec.topics else None
    static_qos = spec.topics[TF_STATIC_TOPIC].qos if TF_STATIC_TOPIC in spec.topics else None
    # the TF feed subscribes: the subscribers' side
    tf_sub_qos = spec.topics[TF_TOPIC].subscriber_qos if TF_TOPIC in spec.topics else None
    static_sub_qos = spec.topics[TF_STATIC_TOPIC].subscriber_qos if TF_STATIC_TOPIC in spec.topics else None
    descriptions = {(t.parent, t.child): t.description for t in spec.transforms}
    publishes_tf = [{"parent": p, "child": c, "ident": transform_identifier(p, c),
                     "description": one_line(descriptions.get((p, c), ""))} for p, c in node.transforms]
    reads_tf = [{"parent": p, "child": c, "ident": transform_identifier(p, c)} for p, c in node.reads_transforms]
    if publishes_tf:
        imports.use("tf2_msgs/TFMessage")
    own = [spec.parameters[p] for p in node.parameters]
    partners = [spec.parameters[p] for p in rule_partners(spec, node)]
    involved = set(node.parameters)
    rules = [r for r in spec.parameter_rules if r.left in involved or r.right in involved]
    rule_items = [{"args": [f"left={py_str(r.left)}", f"op={py_str(r.op)}", f"right={py_str(r.right)}"],
                   "description_text": r.description, "args_after": [],
                   "text": f"{ros_parameter_name(r.left)} {r.op} {ros_parameter_name(r.right)}",
                   "description": one_line(r.description)} for r in rules]
    return {
        "name": name, "name_literal": py_str(name), "description": one_line(node.description), "base": base,
        "imports": imports.lines({"rclpy.node": ["Node"], "sam_runtime": ["node_support", "tf_buffer"]}),
        "subscriptions": subscriptions, "publications": publications,
        "parameters": [_parameter_spec(spec, p) for p in own], "partners": [_parameter_spec(spec, p) for p in partners],
        "rules": rule_items, "publishes_tf": publishes_tf, "reads_tf": reads_tf,
        "tf_topic": TF_TOPIC, "tf_qos": qos_args(tf_qos) if tf_qos else "",
        "tf_sub_qos": qos_args(tf_sub_qos) if tf_sub_qos else "",
        "static_topic": TF_STATIC_TOPIC if static_qos else None,
        "static_sub_qos": qos_args(static_sub_qos) if static_sub_qos else "",
    }


# ---- the package and the parameters file ----------------------------------------------------------------------


def static_transforms(spec: Spec) -> list[tuple[str, str, tuple[float, float, float], tuple[float, ...]]]:
    """(parent, child, xyz, quaternion xyzw) of every static child frame, in spec order."""
    return [(f.parent, f.name, f.xyz, quat_from_rpy(*f.rpy)) for f in spec.frames.values() if f.parent is not None]


def _package_context(resolved: Resolved) -> dict[str, Any]:
    spec = resolved.spec
    package = nodes_package(spec)
    static = [{"parent": p, "child": c, "xyz": ", ".join(float_literal(v) for v in xyz),
               "rotation": ", ".join(float_literal(v) for v in q)} for p, c, xyz, q in static_transforms(spec)]
    static_qos = spec.topics[TF_STATIC_TOPIC].qos if TF_STATIC_TOPIC in spec.topics else None
    return {
        "package": package, "vehicle": spec.vehicle, "params_file": params_file(spec),
        "nodes": [{"name": n.name, "module": f"{package}.{n.name}", "base": class_name(n.name),
                   "description": one_line(n.description)} for n in spec.nodes.values()],
        "static": static, "static_topic": TF_STATIC_TOPIC if static_qos else None,
        "static_qos": qos_args(static_qos) if static_qos else "",
    }


def _yaml_scalar(p: Parameter) -> str:
    """A value as rcl_yaml_param_parser reads it with the parameter's type (a double always has a point)."""
    value = p.default
    if p.type == "double":
        value = float(value)
        if math.isnan(value):
            return ".nan"
        if math.isinf(value):
            return ".inf" if value > 0 else "-.inf"
        text = repr(value)
        return text if any(c in text for c in ".e") else text + ".0"
    if p.type == "bool":
        return "true" if value else "false"
    if p.type == "integer":
        return str(int(value))
    return json.dumps(str(value), ensure_ascii=False)  # a double-quoted YAML scalar


def emit(resolved: Resolved) -> dict[str, str]:
    env = environment()
    env.filters.setdefault("doc", doc)
    env.filters.setdefault("doc_wrap", doc_wrap)
    spec = resolved.spec
    package = nodes_package(spec)
    common = {"spec_name": Path(spec.file).name}
    files = {f"python/{package}/__init__.py": render("python/nodes/__init__.py.j2", **common,
                                                     **_package_context(resolved))}
    for name in spec.nodes:
        files[f"python/{package}/{name}.py"] = render("python/nodes/node.py.j2", **common,
                                                      **_node_context(resolved, name))
    parameters = [(ros_parameter_name(p.name), _yaml_scalar(p), one_line(p.description), p.unit)
                  for p in spec.parameters.values()]
    files[params_file(spec)] = render("params/params.yaml.j2", **common, vehicle=spec.vehicle,
                                      parameters=parameters)
    return files
