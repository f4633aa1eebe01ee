"""Cyphal v1 plumbing shaped like dronecan_io: the transport from the command line or registers (transport),
transport-level ports (ports), the compiled DSDL cache (dsdl_cache), the nunavut workaround (nunavut_fix), the
transmit thread's send windows of python-can media (can_tx_times, for the time-sync master).

Layer: above common; used by genpkg, bridge and sim.
"""
