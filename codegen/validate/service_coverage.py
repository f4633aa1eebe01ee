"""What a service mapping or a device duty writes into its srv's response, checked whole (issue 27): a response
field may be nested (`status.uptime_sec`, a field of a message field of the response), and every leaf of the
response must be written by a line (or the duty, or the bridge's failure fields `success` / `message`) or be listed
in `response_defaults` (a leaf, or a message field: what nothing writes under it). A field nothing writes would
answer 0 / false / '' forever, as a topic mapping's would (validate.mapping_coverage): an error, never a silent
zero.

Invariants: leaves are the primitive fields of the response, descending into non-array fields of message types the
ROS catalog knows (an array of messages, or a message the catalog does not know, is one leaf); paths are dotted
field names.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import Field, RosMessage, RosService
from sam_codegen.model.types import RosType

__all__ = ["Lookup", "check_response_written", "response_leaf", "response_leaves"]

Lookup = Callable[[str], RosMessage | None]


def _composite(t: RosType, lookup: Lookup) -> RosMessage | None:
    if t.is_primitive or t.array:
        return None
    return lookup(t.base)


def response_leaf(srv: RosService, path: str, lookup: Lookup) -> Field | None:
    """The field a dotted response path names (`status.uptime_sec`), None when there is none."""
    fields = {f.name: f for f in srv.response}
    found: Field | None = None
    for i, name in enumerate(path.split(".")):
        found = fields.get(name)
        if found is None:
            return None
        if i < path.count("."):
            assert isinstance(found.type, RosType)
            message = _composite(found.type, lookup)
            if message is None:
                return None
            fields = {f.name: f for f in message.fields}
    return found


def response_leaves(srv: RosService, lookup: Lookup) -> list[tuple[str, RosType, Pos]]:
    """Every leaf of the response, in declaration order, as (dotted path, type, position of the response's own
    field it is in)."""
    out: list[tuple[str, RosType, Pos]] = []

    def walk(prefix: str, fields: Iterable[Field], depth: int, pos: Pos | None) -> None:
        for f in fields:
            assert isinstance(f.type, RosType)
            message = _composite(f.type, lookup) if depth < 8 else None
            if message is not None and message.fields:
                walk(f"{prefix}{f.name}.", message.fields, depth + 1, pos or f.pos)
            else:
                out.append((f"{prefix}{f.name}", f.type, pos or f.pos))

    walk("", srv.response, 0, None)
    return out


def check_response_written(diag: Diagnostics, pos: Pos, srv: RosService, written: set[str],
                           defaults: Iterable[str], what: str, expected: str, lookup: Lookup,
                           at_field: bool = False) -> bool:
    """Report each response leaf nothing writes and `response_defaults` does not list (at `pos`, or with
    `at_field` at the srv's field when it has a position: a duty on by default has none of its own), and each bad
    default; True when there was nothing to report."""
    ok = True
    kept: list[str] = []
    for path in defaults:
        if response_leaf(srv, path, lookup) is None:
            diag.error(pos, f"response_defaults of {what}: {path!r} is not a field of the response of "
                       f"{srv.full_name}", ", ".join(f.name for f in srv.response) or "none: the response is empty")
            ok = False
        elif path in written:
            diag.error(pos, f"ROS response field {path!r} is in response_defaults of {what} but it is written",
                       "response_defaults lists only fields nothing writes")
            ok = False
        else:
            kept.append(path)
    for path, t, field_pos in response_leaves(srv, lookup):
        if path in written or any(path == k or path.startswith(k + ".") for k in kept):
            continue
        diag.error(field_pos if at_field and field_pos.line else pos,
                   f"ROS response field {path!r} ({t}) of {srv.full_name} is written by nothing in {what}",
                   f"{expected}, or `response_defaults: [{path}]` to keep its default")
        ok = False
    return ok
