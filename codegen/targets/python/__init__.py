"""The Python target: generated/python/<vehicle>_bridge (tables.py, convert.py, convert_v0.py,
conversion_support.py), the object converters between the protocol libraries' messages and ROS messages.
"""
