"""One module or package per output; each exposes ``emit(resolved) -> {relative path: text}``.

Layer: above the conversion plan, validate and render; below build. Sibling edges run one way only:
wire -> python -> {nodes, ros, dsdl_v0}, dsdl_v0 -> dsdl, docs -> nodes.
"""
