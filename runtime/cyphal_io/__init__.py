"""Cyphal v1 plumbing shaped like dronecan_io: the transport from the command line or registers (transport),
transport-level ports (ports), the compiled DSDL cache (dsdl_cache), the nunavut workaround (nunavut_fix).

Layer: above common; used by genpkg, bridge and sim.
"""
