"""Geometry shared by the vehicle model and the navigation logic: angles, quaternions, REP-103 frames, the local
metric frame around a GPS datum, and depth from pressure.

Conventions (REP-103/105): world and odom are ENU (x east, y north, z up); base_link is FLU (x forward, y left,
z up). Attitude is roll, pitch, yaw applied as R = Rz(yaw) Ry(pitch) Rx(roll) (body to world): yaw is counter-
clockwise from east seen from above; pitch is about the body's left axis, so a positive pitch puts the nose DOWN;
a positive roll lowers the starboard (right) side. Quaternions are (x, y, z, w) as in geometry_msgs.
"""

from __future__ import annotations

import math

from sam_codegen.model.frames import quat_from_rpy

__all__ = [
    "EARTH_RADIUS_M",
    "P_ATM",
    "RHO_SEAWATER",
    "G",
    "Vec3",
    "depth_from_pressure",
    "euler_from_quaternion",
    "latlon_from_local",
    "local_from_latlon",
    "pressure_at_depth",
    "quaternion_from_euler",
    "rotate_body_to_world",
    "rotate_world_to_body",
    "wrap_angle",
]

Vec3 = tuple[float, float, float]

G = 9.80665  # standard gravity [m/s^2]
RHO_SEAWATER = 1025.0  # [kg/m^3]
P_ATM = 101325.0  # [Pa]
EARTH_RADIUS_M = 6_371_000.0  # mean radius: the equirectangular frame is good to ~1e-3 over kilometres


def wrap_angle(a: float) -> float:
    """An angle in [-pi, pi).

    >>> round(wrap_angle(3 * math.pi / 2), 6), round(wrap_angle(-3 * math.pi / 2), 6)
    (-1.570796, 1.570796)
    """
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def depth_from_pressure(pressure_pa: float, p_atm: float = P_ATM, rho: float = RHO_SEAWATER, g: float = G) -> float:
    """Depth [m] below the surface from the absolute pressure: d = (p - p_atm) / (rho g) (may be slightly negative
    at the surface through noise; callers clamp if they need to).

    >>> round(depth_from_pressure(101325 + 1025 * 9.80665 * 10), 9)
    10.0
    """
    return (pressure_pa - p_atm) / (rho * g)


def pressure_at_depth(depth_m: float, p_atm: float = P_ATM, rho: float = RHO_SEAWATER, g: float = G) -> float:
    """Absolute pressure [Pa] at a depth [m]: the inverse of :func:`depth_from_pressure`."""
    return p_atm + rho * g * depth_m


# R = Rz(yaw) Ry(pitch) Rx(roll), (x, y, z, w): the same rotation as a spec frame's rpy, so one definition.
quaternion_from_euler = quat_from_rpy


def euler_from_quaternion(q: tuple[float, float, float, float]) -> tuple[float, float, float]:
    """(roll, pitch, yaw) of a quaternion (x, y, z, w); it need not be normalised.

    >>> [round(v, 6) for v in euler_from_quaternion(quaternion_from_euler(0.1, -0.2, 3.0))]
    [0.1, -0.2, 3.0]
    """
    x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n == 0.0 or not math.isfinite(n):
        raise ValueError(f"not a rotation quaternion: {q}")
    x, y, z, w = x / n, y / n, z / n, w / n
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def _rotation(roll: float, pitch: float, yaw: float) -> tuple[Vec3, Vec3, Vec3]:
    """Rows of R = Rz(yaw) Ry(pitch) Rx(roll) (body -> world)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def rotate_body_to_world(v: Vec3, roll: float, pitch: float, yaw: float) -> Vec3:
    """A body (FLU) vector in world (ENU) axes.

    >>> [round(c, 6) for c in rotate_body_to_world((1.0, 0.0, 0.0), 0.0, 0.3, 0.0)]  # nose down: forward dips
    [0.955336, 0.0, -0.29552]
    """
    r = _rotation(roll, pitch, yaw)
    return (r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
            r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
            r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2])


def rotate_world_to_body(v: Vec3, roll: float, pitch: float, yaw: float) -> Vec3:
    """A world (ENU) vector in body (FLU) axes (the transpose of :func:`rotate_body_to_world`).

    >>> [round(c, 6) for c in rotate_world_to_body((0.0, 0.0, 9.81), 0.0, 0.0, 1.0)]  # at rest: +g on body z
    [0.0, 0.0, 9.81]
    """
    r = _rotation(roll, pitch, yaw)
    return (r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
            r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
            r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2])


def local_from_latlon(lat_deg: float, lon_deg: float, lat0_deg: float, lon0_deg: float) -> tuple[float, float]:
    """(east, north) metres of a position relative to the datum (lat0, lon0), equirectangular.

    >>> [round(c, 3) for c in local_from_latlon(59.35 + 1e-4, 18.07, 59.35, 18.07)]
    [0.0, 11.119]
    """
    k = math.pi / 180.0 * EARTH_RADIUS_M
    return (lon_deg - lon0_deg) * k * math.cos(math.radians(lat0_deg)), (lat_deg - lat0_deg) * k


def latlon_from_local(east_m: float, north_m: float, lat0_deg: float, lon0_deg: float) -> tuple[float, float]:
    """(lat, lon) degrees of a local (east, north) position: the inverse of :func:`local_from_latlon`.

    >>> lat, lon = latlon_from_local(100.0, -50.0, 59.35, 18.07)
    >>> [round(c, 9) for c in local_from_latlon(lat, lon, 59.35, 18.07)]
    [100.0, -50.0]
    """
    k = math.pi / 180.0 * EARTH_RADIUS_M
    return lat0_deg + north_m / k, lon0_deg + east_m / (k * math.cos(math.radians(lat0_deg)))
