"""Definitions from outside the spec: ROS messages from the installed share/ folders (ros), Cyphal DSDL from
CYPHAL_PATH (cyphal), the DroneCAN v0 types bundled with dronecan (dronecan).

Layer: above model and project; below validate. Catalogs are independent of each other.
"""
