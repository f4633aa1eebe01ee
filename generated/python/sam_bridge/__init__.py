# Generated from interfaces.yaml by sam-codegen; do not edit.
"""The sam UAVCAN <-> ROS 2 bridge: generated tables and converters.

- ``sam_bridge.tables``: the interface as data (standard library only);
- ``sam_bridge.convert``: the converters (imports the ROS message packages and the compiled DSDL).

Nothing is imported here, so reading the tables never pulls in ROS or pycyphal.
"""
