"""The report of a recorded run: `sam-codegen plot FILE.mcap` and the main job's picture at the end of a recorded run.

recording.py reads an MCAP written with rosbag2's conventions (ROS 2 CDR messages, ros2msg schemas) into time
series; plot.py draws them with matplotlib (an optional extra, imported when a picture is drawn).
"""
