"""Geometry (geo) and the simulated rigid-body vehicle with its sensors (vehicle). Pure: no I/O, no ROS, no
protocol; time is passed in.

Layer: bottom of the runtime beside common; used by nav, sim and nodes.
"""
