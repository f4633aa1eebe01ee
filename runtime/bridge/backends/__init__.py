"""The only protocol-specific part of the bridge: Cyphal v1 (cyphal, its wire path cyphal_wire) and DroneCAN
(dronecan, its node duties dronecan_duties). Only the composition root imports these.
"""
