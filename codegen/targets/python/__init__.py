"""The Python target: generated/python/<vehicle>_bridge (tables.py, convert.py, convert_v0.py,
conversion_support.py), the object converters between the protocol libraries' messages and ROS messages.

Imports run one way, top to bottom:

- convert.py (emit: the package, convert.py) -> tables.py (the whole tables.py context) -> convert_v0.py (emit:
  convert_v0.py; used_types) -> mapping_v0.py (DroneCAN objects, their reads, MATCHES)
- mapping.py (MappingEmitter and its strategies: UavcanReader, RosReader, Signatures) -> module.py (ConvertModule,
  its Construction, the result trees) and statements.py (the typed statement IR) -> names.py
- factories.py (convert.py's fast constructors) -> module.py; the generated tables' classes (copied verbatim into
  tables.py) and a Protocol of the generated module are sam_codegen.contracts' (the runtime shares them).

The wire codecs (targets/wire) compose the same MappingEmitter with their own readers and Constructions.
"""
