"""The wire target: codec.py and codec_v0.py, straight-line code per mapping between UAVCAN payload bytes and
ROS CDR. Modules are ``<format>_<role>`` with role in {layout, read, write}; codec and codec_v0 emit.
"""
