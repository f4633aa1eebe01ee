"""`sam-codegen run`, the main job: build when stale, start the simulated devices, the bridge(s) and the node host
as children, fly the mission and show it live (job), with its views (vehicle_view, diag_view) and the demo
actuator sweeps (demo).

Layer: top, with the entry points; imports bridge, sim and nodes only through their command lines.
"""
