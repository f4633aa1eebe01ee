"""Where a run acts: the user's project (workspace), the Cyphal standard types (cyphal_path), building the
generated ROS packages into an environment (ros_install). Also used by sam_runtime.

Layer: bottom, beside model; imports nothing else of sam_codegen.
"""
