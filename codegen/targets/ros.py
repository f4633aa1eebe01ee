"""ROS 2 emitter: the spec's messages as an ament_cmake interface package, and one package per package of its
external_messages and of the standard messages the tool knows and the spec uses (catalogs.ros_known: tf2_msgs,
which no wheel provides here).

An external package holds exactly the spec's declarations, written as upstream writes them (no generated
comments: for tf2_msgs/TFMessage the file is byte-identical to ROS 2's), so that its type hash (RIHS01) matches
upstream's and stock ROS 2 tools elsewhere read our topics.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from sam_codegen.catalogs.ros_known import external_messages_to_generate
from sam_codegen.model.spec import RosMessage, RosPackageInfo, RosService, Scalar
from sam_codegen.model.types import RosType
from sam_codegen.render.templating import environment, render
from sam_codegen.validate.resolve import Resolved


def msg_type(t: RosType, package: str) -> str:
    """A field type as written in a .msg of `package` (same-package types stay qualified; rosidl accepts it).

    >>> msg_type(RosType("std_msgs/Header"), "p"), msg_type(RosType("float32", "bounded", 3), "p")
    ('std_msgs/Header', 'float32[<=3]')
    """
    return str(t)


def upstream_msg_type(t: RosType, package: str) -> str:
    """A field type as ROS 2's own packages write it: types of the same package without their package.

    >>> upstream_msg_type(RosType("tf2_msgs/TF2Error"), "tf2_msgs"), upstream_msg_type(RosType("a/B", "dynamic"), "c")
    ('TF2Error', 'a/B[]')
    """
    text = str(t)
    return text.removeprefix(f"{package}/") if t.package == package else text


def msg_literal(value: Scalar) -> str:
    """A constant or default as rosidl reads it.

    >>> msg_literal(True), msg_literal(-1), msg_literal(0.5), msg_literal("a'b")
    ('true', '-1', '0.5', '"a\\'b"')
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    return repr(value)


def _dependencies(messages: list[RosMessage], package: str) -> list[str]:
    found: set[str] = set()
    for message in messages:
        for f in message.fields:
            assert isinstance(f.type, RosType)
            if f.type.package and f.type.package != package:
                found.add(f.type.package)
    return sorted(found)


def external_packages(resolved: Resolved) -> dict[str, list[RosMessage]]:
    """The packages of the spec's external_messages and of the known messages it uses, each with its messages
    sorted by name (a package of external_services only: no messages)."""
    packages: dict[str, list[RosMessage]] = {srv.package: [] for srv in external_services(resolved)}
    for message in external_messages_to_generate(resolved.spec).values():
        packages.setdefault(message.package, []).append(message)
    return {name: sorted(messages, key=lambda m: m.name) for name, messages in sorted(packages.items())}


def own_services(resolved: Resolved) -> list[RosService]:
    """The srvs of the spec's own package."""
    return [s for s in resolved.services if not s.external]


def external_services(resolved: Resolved, package: str | None = None) -> list[RosService]:
    """The spec's `external_services` (of `package`), by name: generated into their own package."""
    return sorted((s for s in resolved.services if s.external and package in (None, s.package)),
                  key=lambda s: s.name)


def _srv_parts(services: list[RosService]) -> list[RosMessage]:
    """A .srv's fields are a message's for the dependencies (its two halves become Request and Response messages)."""
    return [RosMessage(s.package, s.name, [*s.request, *s.response]) for s in services]


def build_order(resolved: Resolved) -> list[str]:
    """Every generated ROS package, each after the generated packages it depends on (then by name)."""
    spec = resolved.spec
    depends = {name: set(_dependencies([*messages, *_srv_parts(external_services(resolved, name))], name))
               for name, messages in external_packages(resolved).items()}
    depends[spec.ros.name] = set(_dependencies([*resolved.messages, *_srv_parts(own_services(resolved))],
                                               spec.ros.name))
    order: list[str] = []
    while len(order) < len(depends):
        ready = sorted(n for n, deps in depends.items() if n not in order and deps & set(depends) <= set(order))
        if not ready:  # a cycle between packages: rosidl cannot build it either; keep a stable order
            ready = sorted(n for n in depends if n not in order)
        order.extend(ready)
    return order


def external_package_info(resolved: Resolved, package: str, messages: list[RosMessage],
                          services: list[RosService] | None = None) -> RosPackageInfo:
    spec = resolved.spec
    if services:  # a package of the spec's external_services (and messages, if any)
        names = ", ".join([*(m.name for m in messages), *(s.name for s in services)])
        return RosPackageInfo(
            package, spec.ros.version,
            f"The {package} interfaces {names} as the spec declares them, generated by sam-codegen from the "
            f"external_messages and external_services of {Path(spec.file).name} (no installed package provides "
            "them).", spec.ros.maintainer, spec.ros.maintainer_email, "BSD-3-Clause")
    names = ", ".join(m.name for m in messages)
    declared = any(m.full_name in spec.external_messages for m in messages)
    source = f"the external_messages of {Path(spec.file).name}" if declared else \
        f"its built-in copy of the upstream definitions, for {Path(spec.file).name}"
    return RosPackageInfo(
        package, spec.ros.version,
        f"The {package} messages {names} as ROS 2 defines them, generated by sam-codegen from {source} "
        "(no installed package provides them).",
        spec.ros.maintainer, spec.ros.maintainer_email, "BSD-3-Clause",
    )


def emit(resolved: Resolved) -> dict[str, str]:
    env = environment()
    env.filters.setdefault("msg_type", msg_type)
    env.filters.setdefault("msg_literal", msg_literal)
    env.filters.setdefault("upstream_msg_type", upstream_msg_type)
    spec = resolved.spec
    package = spec.ros.name
    spec_name = Path(spec.file).name
    root = f"ros/{package}"
    files: dict[str, str] = {}
    for message in resolved.messages:
        files[f"{root}/msg/{message.name}.msg"] = render(
            "ros/message.msg.j2", message=message, spec_name=spec_name
        )
    # catkin_pkg refuses an empty <description> (the package would not build): a spec without one gets this.
    info = spec.ros if spec.ros.description.strip() else replace(
        spec.ros, description=f"The ROS 2 messages of {spec.vehicle or package}, generated by sam-codegen from "
        f"{spec_name}.")
    for srv in own_services(resolved):
        files[f"{root}/srv/{srv.name}.srv"] = render("ros/service.srv.j2", srv=srv, spec_name=spec_name)
    context = {"package": info, "messages": [m.name for m in resolved.messages],
               "services": [s.name for s in own_services(resolved)],
               "dependencies": _dependencies([*resolved.messages, *_srv_parts(own_services(resolved))], package)}
    files[f"{root}/package.xml"] = render("ros/package.xml.j2", **context)
    files[f"{root}/CMakeLists.txt"] = render("ros/CMakeLists.txt.j2", **context)
    for name, messages in external_packages(resolved).items():
        for message in messages:
            files[f"ros/{name}/msg/{message.name}.msg"] = render("ros/external_message.msg.j2", message=message)
        services = external_services(resolved, name)
        for srv in services:
            files[f"ros/{name}/srv/{srv.name}.srv"] = render("ros/service.srv.j2", srv=srv, spec_name=spec_name)
        context = {"package": external_package_info(resolved, name, messages, services),
                   "messages": [m.name for m in messages], "services": [s.name for s in services],
                   "dependencies": _dependencies([*messages, *_srv_parts(services)], name)}
        files[f"ros/{name}/package.xml"] = render("ros/package.xml.j2", **context)
        files[f"ros/{name}/CMakeLists.txt"] = render("ros/CMakeLists.txt.j2", **context)
    return files
