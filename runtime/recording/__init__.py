"""Keep and replay what the vehicle did (issue 18): ``sam-codegen record`` / ``run --record`` and ``replay``.

- :mod:`.recorder`: every ROS topic of the spec (and /diagnostics) as ROS 2 CDR with its ros2msg schema, and the
  raw UAVCAN bus (one envelope message per transfer, the DSDL / v0 definitions attached), into one MCAP;
- :mod:`.writer`: the chunked MCAP file that any end of the process leaves readable up to its last chunk;
- :mod:`.reading`: reading a recording, whole or cut, and the rosbag2 folder rosbags needs;
- :mod:`.replay`: the recorded bus through a spec's bridge conversion (given as a :class:`.replay.Converter`), a
  new MCAP and the per-topic difference report;
- :mod:`.schemas` and :mod:`.target`: the definitions stored, and the recording's path checked before anything
  starts.

Layer: beside bridge, sim and nodes, independent of them (tests/test_layers.py). Replay needs the bridge's inbound
logic (source filter, select routing, counters, codecs): the bridge offers it as
``sam_runtime.bridge.offline.OfflineBridge`` and the replay command (``sam_runtime.main_job.record_replay``, a layer
above both) hands it to :func:`.replay.replay`, so neither package imports the other.

Import the submodules (they need the runtime extra: mcap, rclpy, pycyphal); this package imports nothing.
"""
