"""Types inside types, walked once: cycles, nesting depth and flattened size, each in time linear in the types.

A walk of every path through the types is exponential in a hostile spec: 30 messages each holding two fields of the
previous one are 2^30 paths (`validate` took 17 s at 22). Here each type is visited once (Tarjan's strongly connected
components, iteratively, then one pass children first), so the cycle and depth checks of ROS messages and DroneCAN
types cost O(types + fields); and a type whose flattened size passes MAX_FLAT_FIELDS is refused before anything
that expands types (the converters, the codecs, pydsdl's bit-length sets, which recurse the same way) sees it.

The flattened size of a type is the number of fields once its nested types are expanded: a primitive field or an
array of primitives counts 1 (the codecs and pydsdl handle such an array as one run), a composite field its type's
size, a fixed-size array of composites its capacity times that, a variable-size one a single element's size.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from sam_codegen.model.diagnostics import Diagnostics, Pos
from sam_codegen.model.spec import DsdlStruct, RosMessage, Spec, V0Struct
from sam_codegen.model.types import DsdlType, RosType

if TYPE_CHECKING:
    from sam_codegen.catalogs.cyphal import DsdlCatalog
    from sam_codegen.catalogs.dronecan import V0Catalog
    from sam_codegen.catalogs.ros import RosCatalog

# No sensible type comes near it: SAM's largest flattens to ~60 fields, a ROS message of geometry_msgs covariances
# and headers to a few hundred. 2^14 nested copies of a type are a hostile or broken spec, not a vehicle.
MAX_FLAT_FIELDS = 10_000

# name -> its children as (child type name, multiplicity), or None for an unknown type; a primitive field is
# ("", 1): it counts, and leads nowhere.
Children = Callable[[str], "list[tuple[str, int]] | None"]


@dataclass(frozen=True)
class TypeGraph:
    """What one pass over the types found (see module doc)."""

    cycles: list[list[str]]  # each strongly connected component with a cycle, its types in the order reached
    cyclic: frozenset[str]  # the types of those components
    height: dict[str, int]  # the longest chain of types from a type down (1: it holds no composite), cycles left out
    deepest: dict[str, str]  # the child on that longest chain
    size: dict[str, int]  # the flattened size (a cyclic child counts 1: it is an error of its own)
    edges: dict[str, list[tuple[str, int]]]  # the composite children of each type reached

    def chain(self, name: str, length: int) -> list[str]:
        """The first `length` types of the longest chain from `name`."""
        out = [name]
        while len(out) < length and out[-1] in self.deepest:
            out.append(self.deepest[out[-1]])
        return out

    def cycle_from(self, name: str) -> list[str]:
        """A shortest cycle from `name` back to itself (name on a cycle), by breadth-first search inside its
        component: `[name, ..., name]`."""
        component = next(set(c) for c in self.cycles if name in c)
        parent: dict[str, str] = {}
        queue = deque([name])
        while queue:
            current = queue.popleft()
            for child, _ in self.edges.get(current, []):
                if child not in component:
                    continue
                if child == name:
                    path = [current]
                    while path[-1] != name:
                        path.append(parent[path[-1]])
                    return [*reversed(path), name]
                if child not in parent:
                    parent[child] = current
                    queue.append(child)
        raise AssertionError(f"{name} is on no cycle")

    def reaches(self, bad: set[str]) -> set[str]:
        """The types that are in `bad` or hold one of them, at any depth."""
        holders: dict[str, list[str]] = {}
        for parent, children in self.edges.items():
            for child, _ in children:
                holders.setdefault(child, []).append(parent)
        found, stack = set(bad), list(bad)
        while stack:
            for parent in holders.get(stack.pop(), []):
                if parent not in found:
                    found.add(parent)
                    stack.append(parent)
        return found


def type_graph(roots: Iterable[str], children: Children) -> TypeGraph:
    """One pass over the types reachable from `roots` (see module doc)."""
    edges: dict[str, list[tuple[str, int]]] = {}
    leaves: dict[str, int] = {}  # fields that lead to no known type: primitives, unknown composites
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    order: list[list[str]] = []  # the components, children first (Tarjan's order)

    def expand(name: str) -> None:
        found = children(name) or []
        edges[name] = [(c, m) for c, m in found if c and children(c) is not None]
        leaves[name] = sum(m if not c else 1 for c, m in found if not c or children(c) is None)

    for root in roots:
        if root in index:
            continue
        expand(root)
        work: list[tuple[str, int]] = [(root, 0)]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            name, i = work[-1]
            if i < len(edges[name]):
                work[-1] = (name, i + 1)
                child = edges[name][i][0]
                if child not in index:
                    expand(child)
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, 0))
                elif child in on_stack:
                    low[name] = min(low[name], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[name])
            if low[name] == index[name]:
                component: list[str] = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == name:
                        break
                order.append(sorted(component, key=index.__getitem__))

    cycles = [c for c in order if len(c) > 1 or any(child == c[0] for child, _ in edges[c[0]])]
    cyclic = frozenset(name for c in cycles for name in c)
    height: dict[str, int] = {}
    deepest: dict[str, str] = {}
    size: dict[str, int] = {}
    for component in order:  # children first: every child's figures are known
        for name in component:
            if name in cyclic:
                height[name], size[name] = 0, 1
                continue
            best = max((c for c, _ in edges[name] if c not in cyclic), key=lambda c: height[c], default=None)
            height[name] = 1 + (height[best] if best is not None else 0)
            if best is not None:
                deepest[name] = best
            size[name] = leaves[name] + sum(m * size[c] for c, m in edges[name])
    return TypeGraph(cycles, cyclic, height, deepest, size, edges)


def check_flat_sizes(graph: TypeGraph, local: dict[str, Pos], what: str, diag: Diagnostics) -> bool:
    """An error for each of the spec's types (`local`: name -> position) that flattens to more than MAX_FLAT_FIELDS
    while none of its nested types does (a type holding such a type is too large for the same reason, and one error
    names the cause); False when there was any."""
    ok = True
    for name, pos in local.items():
        if graph.size.get(name, 0) <= MAX_FLAT_FIELDS:
            continue
        ok = False
        if all(graph.size[c] <= MAX_FLAT_FIELDS for c, _ in graph.edges[name]):
            diag.error(pos, f"{what} {name} flattens to {graph.size[name]:,} fields (its nested types and fixed "
                       f"arrays of composites expanded), more than the limit of {MAX_FLAT_FIELDS:,}",
                       "fewer copies of nested types; an array of primitives counts as one field")
    return ok


def ros_children(message: RosMessage | None) -> list[tuple[str, int]] | None:
    if message is None:
        return None
    out: list[tuple[str, int]] = []
    for f in message.fields:
        assert isinstance(f.type, RosType)
        out.append(("" if f.type.is_primitive else f.type.base,
                    f.type.capacity or 1 if f.type.array == "fixed" and not f.type.is_primitive else 1))
    return out


def dsdl_children(struct: DsdlStruct | None) -> list[tuple[str, int]] | None:
    """Children of a Cyphal or DroneCAN type (see Children)."""
    if struct is None:
        return None
    out: list[tuple[str, int]] = []
    for f in struct.fields:
        assert isinstance(f.type, DsdlType)
        composite = f.type.composite if f.type.kind == "composite" else None
        out.append((composite or "", f.type.capacity or 1 if composite and f.type.array == "fixed" else 1))
    if isinstance(struct, V0Struct) and struct.service:
        out += dsdl_children(replace(struct, fields=struct.response, service=False)) or []
    return out


def check_type_sizes(spec: Spec, ros: RosCatalog, dsdl: DsdlCatalog, v0: V0Catalog, diag: Diagnostics) -> bool:
    """The flattened size of every type the spec defines (its messages, external messages, Cyphal and DroneCAN
    types and the halves of its service types), at most MAX_FLAT_FIELDS; False after reporting any beyond it."""
    messages = {**{m.full_name: m for m in spec.external_messages.values()}, **ros.messages}
    ros_graph = type_graph(messages, lambda name: ros_children(ros.get(name)))
    ok = check_flat_sizes(ros_graph, {name: m.pos for name, m in messages.items()}, "message", diag)
    cyphal = {**spec.dsdl_types}
    for service in spec.dsdl_services.values():
        cyphal.update({service.request.name + " (request)": service.request,
                       service.response.name + " (response)": service.response})

    def cyphal_children(name: str) -> list[tuple[str, int]] | None:
        return dsdl_children(cyphal.get(name) or dsdl.get(name))

    cyphal_graph = type_graph(cyphal, cyphal_children)
    ok &= check_flat_sizes(cyphal_graph, {name: t.pos for name, t in cyphal.items()}, "DSDL type", diag)
    v0_graph = type_graph(spec.dronecan_types, lambda name: dsdl_children(v0.get(name)))
    ok &= check_flat_sizes(v0_graph, {name: t.pos for name, t in spec.dronecan_types.items()}, "DroneCAN type", diag)
    return ok
