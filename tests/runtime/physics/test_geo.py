"""Frames, angles and the local metric frame shared by the vehicle model and the navigation logic
(runtime/physics/geo.py). The doctests of the navigation modules run where pytest collects runtime/."""

from __future__ import annotations

import math
import random

import pytest

from sam_runtime.physics.geo import (
    depth_from_pressure,
    euler_from_quaternion,
    latlon_from_local,
    local_from_latlon,
    pressure_at_depth,
    quaternion_from_euler,
    rotate_body_to_world,
    rotate_world_to_body,
    wrap_angle,
)


def test_rep103_signs() -> None:
    # Yaw counter-clockwise from east: facing north, forward is +y.
    assert rotate_body_to_world((1.0, 0.0, 0.0), 0.0, 0.0, math.pi / 2) == pytest.approx((0.0, 1.0, 0.0), abs=1e-12)
    # Pitch about the body's left axis: positive puts the nose down.
    assert rotate_body_to_world((1.0, 0.0, 0.0), 0.0, 0.2, 0.0)[2] < 0.0
    # Roll about forward: positive lowers the right (starboard, -y) side.
    assert rotate_body_to_world((0.0, -1.0, 0.0), 0.2, 0.0, 0.0)[2] < 0.0
    # Gravity's reaction at rest is +z in the body (REP-145 accelerometers).
    assert rotate_world_to_body((0.0, 0.0, 9.8), 0.0, 0.0, 2.0) == pytest.approx((0.0, 0.0, 9.8), abs=1e-12)


def test_rotations_and_quaternions_round_trip() -> None:
    rng = random.Random(4)
    for _ in range(200):
        r, p, y = rng.uniform(-3, 3), rng.uniform(-1.5, 1.5), rng.uniform(-3.1, 3.1)
        assert euler_from_quaternion(quaternion_from_euler(r, p, y)) == pytest.approx((r, p, y), abs=1e-9)
        v = (rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5))
        assert rotate_world_to_body(rotate_body_to_world(v, r, p, y), r, p, y) == pytest.approx(v, abs=1e-9)
        q = quaternion_from_euler(r, p, y)
        assert math.fsum(c * c for c in q) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="not a rotation quaternion"):
        euler_from_quaternion((0.0, 0.0, 0.0, 0.0))


def test_wrap_angle_range() -> None:
    for a in (-10.0, -math.pi, 0.0, math.pi, 7.0):
        w = wrap_angle(a)
        assert -math.pi <= w < math.pi and math.isclose(math.sin(w), math.sin(a), abs_tol=1e-12)


def test_local_frame_and_depth_from_pressure() -> None:
    east, north = local_from_latlon(59.36, 18.09, 59.35, 18.07)
    assert north == pytest.approx(1112.0, rel=1e-3) and east == pytest.approx(1135.0, rel=1e-2)
    assert latlon_from_local(east, north, 59.35, 18.07) == pytest.approx((59.36, 18.09), abs=1e-12)
    assert depth_from_pressure(pressure_at_depth(37.5)) == pytest.approx(37.5)
    assert depth_from_pressure(101325.0 + 1025.0 * 9.80665) == pytest.approx(1.0)  # sea water, not fresh
