"""The simulated devices of a spec (simulator, its options: config), their Cyphal and DroneCAN adapters (cyphal,
dronecan) and what those share with the simulator (ports: SimDevice, PubPort, SubPort, DeviceAdapter, DeviceHost),
the device models (devices, devices_dronecan) and the in-process closed loop of the nav logic on the vehicle
(closed_loop).

Layer: beside bridge and nodes (independent of both); above genpkg, nav, physics, cyphal_io, dronecan_io.
"""
