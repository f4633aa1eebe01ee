"""ROS graph names as the spec writes them: validation by rcl's rules and resolution under a namespace.

Shared by the generator (which checks the spec's topic and parameter names) and the runtime (which checks
``--namespace`` and resolves names for its views and probes), so the rules exist once.

Invariants:

- A name is absolute (``/core/imu``: the same topic whatever the namespace) or relative (``core/imu``: resolved
  under the node's namespace at run time, ``/sam1/core/imu`` under ``/sam1``, ``/core/imu`` under ``/``). The spec
  and everything generated from it keep the name as written; only rclpy (the node's ``namespace``) resolves it.
- The rules are rcl's (rcl_validate_topic_name, rmw_validate_namespace) without substitutions (``{node}``) and
  without private names (``~``), which the spec refuses with its own message: every token starts with a letter or
  an underscore and holds letters, digits and underscores; no empty token (``//``), no trailing ``/``.
- :func:`ros_name_problem` returns the first broken rule as a short phrase (for ``... is not a valid ROS name:
  <phrase>``), None for a valid name; it never raises.
"""

from __future__ import annotations

import re

__all__ = ["NAME_RULES", "namespace_problem", "normalize_namespace", "resolve_name", "ros_name_problem"]

_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
NAME_RULES = ("an absolute name /segment/... or a relative one segment/... (resolved under the namespace), each "
              "segment a letter or underscore then letters, digits, underscores")


def ros_name_problem(name: str) -> str | None:
    """Why ``name`` is not a valid topic (or parameter) name of a spec, None when it is.

    >>> [ros_name_problem(n) for n in ("/imu", "core/imu", "core//imu", "2d/imu", "imu/", "~/x", "a-b")]
    [None, None, "it has an empty segment ('//')", "segment '2d' starts with a digit", "it ends with '/'", \
"private names ('~') are not supported", "segment 'a-b' has a character other than letters, digits and '_'"]
    """
    if not name:
        return "it is empty"
    if name == "/":
        return "it is the root namespace, not a name"
    if "~" in name:
        return "private names ('~') are not supported"
    if "{" in name or "}" in name:
        return "substitutions ('{...}') are not supported"
    if name.endswith("/"):
        return "it ends with '/'"
    if "//" in name:
        return "it has an empty segment ('//')"
    for token in name.lstrip("/").split("/"):
        if token[:1].isdigit():
            return f"segment {token!r} starts with a digit"
        if not _TOKEN.fullmatch(token):
            return f"segment {token!r} has a character other than letters, digits and '_'"
    return None


def namespace_problem(namespace: str) -> str | None:
    """Why ``namespace`` (``--namespace``, ``__ns:=``) is not a valid absolute ROS namespace, None when it is.

    >>> namespace_problem("/sam1"), namespace_problem("/"), namespace_problem("sam1"), namespace_problem("/1sam")
    (None, None, "it must be absolute (start with '/')", "segment '1sam' starts with a digit")
    """
    if namespace == "/":
        return None
    if not namespace.startswith("/"):
        return "it must be absolute (start with '/')"
    return ros_name_problem(namespace)


def normalize_namespace(namespace: str | None) -> str:
    """``None``/``""`` -> ``/``; a relative one gets its leading ``/`` (as rcl does for a node's namespace); a
    trailing ``/`` goes. ValueError (one line) for a namespace that is still not valid.

    >>> normalize_namespace(None), normalize_namespace("sam1"), normalize_namespace("/sam1/")
    ('/', '/sam1', '/sam1')
    """
    ns = (namespace or "/").strip()
    if not ns.startswith("/"):
        ns = "/" + ns
    if len(ns) > 1:
        ns = ns.rstrip("/") or "/"
    why = namespace_problem(ns)
    if why is not None:
        raise ValueError(f"namespace {namespace!r} is not a valid ROS namespace: {why}")
    return ns


def resolve_name(name: str, namespace: str | None) -> str:
    """The fully qualified name rclpy gives ``name`` in a node of ``namespace`` (absolute names stay).

    >>> resolve_name("core/imu", "/sam1"), resolve_name("/tf", "/sam1"), resolve_name("imu", None)
    ('/sam1/core/imu', '/tf', '/imu')
    """
    if name.startswith("/"):
        return name
    ns = normalize_namespace(namespace)
    return f"{ns.rstrip('/')}/{name}"
