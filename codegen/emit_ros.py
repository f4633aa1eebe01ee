"""ROS 2 emitter: the spec's messages as an ament_cmake interface package."""

from __future__ import annotations

from pathlib import Path

from .model import Scalar
from .templating import environment, render
from .typesys import RosType
from .validate import Resolved


def msg_type(t: RosType, package: str) -> str:
    """A field type as written in a .msg of `package` (same-package types stay qualified; rosidl accepts it).

    >>> msg_type(RosType("std_msgs/Header"), "p"), msg_type(RosType("float32", "bounded", 3), "p")
    ('std_msgs/Header', 'float32[<=3]')
    """
    return str(t)


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


def emit(resolved: Resolved) -> dict[str, str]:
    env = environment()
    env.filters.setdefault("msg_type", msg_type)
    env.filters.setdefault("msg_literal", msg_literal)
    spec = resolved.spec
    package = spec.ros.name
    spec_name = Path(spec.file).name
    root = f"ros/{package}"
    files: dict[str, str] = {}
    dependencies: set[str] = set()
    for message in resolved.messages:
        files[f"{root}/msg/{message.name}.msg"] = render(
            "ros/message.msg.j2", message=message, spec_name=spec_name
        )
        for f in message.fields:
            assert isinstance(f.type, RosType)
            if f.type.package and f.type.package != package:
                dependencies.add(f.type.package)
    context = {"package": spec.ros, "messages": [m.name for m in resolved.messages],
               "dependencies": sorted(dependencies)}
    files[f"{root}/package.xml"] = render("ros/package.xml.j2", **context)
    files[f"{root}/CMakeLists.txt"] = render("ros/CMakeLists.txt.j2", **context)
    return files
