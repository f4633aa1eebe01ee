"""The docs target: generated/docs/interfaces.md (the interface reference) and generated/docs/dataflow.svg (the
dataflow picture), from one resolved spec.

`emit(resolved)` returns {path under generated/: text}:

- docs/interfaces.md: the `type / topic / contents` tables of the document, generated from the spec: topics,
  messages, parameters, frames, devices, DSDL types, the bridge's mappings with their conversions, and the DroneCAN
  part (markdown.py, dronecan.py);
- docs/dataflow.svg: a picture like the document's Fig. 1, devices -> bridge -> topics -> nodes, laid out here
  (columns, barycentric rows) so that it needs no graphviz and comes out byte for byte the same (svg.py).

The modules import one way: this package (emit) -> markdown | svg | dronecan -> wording -> graph. Only this module
imports markdown, svg, dronecan and services (the service types and mappings); none of them imports this package.
The target imports targets.nodes only for the names of generated files. Everything that comes from the spec reaches
the output through md_cell / md_code / xml_text in the templates (templates/docs/); the modules compute structure,
numbers and the conversion wording.
"""

from __future__ import annotations

from sam_codegen.render.templating import render
from sam_codegen.targets.docs.budget import budget_context
from sam_codegen.targets.docs.dronecan import dronecan_context
from sam_codegen.targets.docs.graph import SVG_NAME, build_graph
from sam_codegen.targets.docs.markdown import markdown_context
from sam_codegen.targets.docs.services import services_context
from sam_codegen.targets.docs.svg import svg_context
from sam_codegen.validate.interface_version import hex_hash, interface_versions
from sam_codegen.validate.resolve import Resolved

MD_PATH = "docs/interfaces.md"
SVG_PATH = f"docs/{SVG_NAME}"


def emit(resolved: Resolved) -> dict[str, str]:
    """The documentation files, by path under generated/."""
    graph = build_graph(resolved)
    return {
        MD_PATH: render("docs/interfaces.md.j2", **markdown_context(resolved, graph),
                        **dronecan_context(resolved), **budget_context(resolved),
                        **services_context(resolved),
                        interface_version=_interface_version_context(resolved)).rstrip("\n") + "\n",
        SVG_PATH: render("docs/dataflow.svg.j2", **svg_context(resolved, graph)),
    }


def _interface_version_context(resolved: Resolved) -> dict[str, object]:
    """The interface version section: the whole spec's hash and each board's (validate.interface_version)."""
    versions = interface_versions(resolved)
    devices = resolved.spec.devices
    return {"whole": hex_hash(versions.whole),
            "boards": [{"name": name, "node_id": devices[name].node_id, "protocols": devices[name].protocols,
                        "hash": hex_hash(value)} for name, value in versions.boards]}


__all__ = ["MD_PATH", "SVG_PATH", "emit"]
