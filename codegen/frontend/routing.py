"""Reading a mapping's routing keys: node id lists that may instead say `any`, and `shares_data_type`.

Invariant: `any` is only ever the literal word (a YAML string); anything else goes through the ordinary node id
list reader, so a typo (`anyy`, `all`) is the usual "must be a list" error, never a silent opt-out of the static
routing the design document asks for.
"""

from __future__ import annotations

from sam_codegen.frontend.reading import Reader, int_list
from sam_codegen.frontend.yaml_source import YScalar
from sam_codegen.model.diagnostics import NOWHERE, Diagnostics, Pos

__all__ = ["ANY_NODE", "node_ids_or_any"]

ANY_NODE = "any"


def node_ids_or_any(r: Reader, key: str, what: str, diag: Diagnostics) -> tuple[list[int], bool, Pos]:
    """`key` of the mapping read by `r`: (node ids, whether it said `any`, where it said it). Another word is an
    error here, returned as `any` so that the mapping is not also reported as having no node ids."""
    node = r.node(key)
    if isinstance(node, YScalar) and node.value == ANY_NODE:
        return [], True, r.key_pos(key)
    if isinstance(node, YScalar) and isinstance(node.value, str):
        diag.error(node.pos, f"{key} of {what} must be a list of node ids or `{ANY_NODE}`, found {node.value!r}",
                   f"a list of node ids, or `{ANY_NODE}` for every node")
        return [], True, r.key_pos(key)
    return int_list(node, key, what, diag), False, NOWHERE
