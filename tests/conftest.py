"""Test-wide setup. Discovery must stay on loopback before anything can start rclpy (see the ROS notes)."""

from __future__ import annotations

import os

from hypothesis import settings

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] or "LOCALHOST"

# The suite must give the same verdict on every run: property tests draw the same examples each time (derandomize).
# SAM_HYPOTHESIS_PROFILE=explore draws new ones, to hunt for counterexamples while developing.
settings.register_profile("repeatable", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("SAM_HYPOTHESIS_PROFILE", "repeatable"))
