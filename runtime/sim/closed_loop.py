"""The five nodes' logic on the simulated vehicle in one process, in simulated time (no ROS, no wall clock).

It wires them as the ROS graph does, at the nominal rates: the sensors at the devices' rates (IMU 100 Hz,
magnetometer 50, pressure 20, altimeter and thruster feedback 10, GPS 5, battery 1; IMU and magnetometer values
rounded to float16 as on the bus) feed the dead reckoning; the SLAM corrector takes each GPS fix with the dead
reckoning's position; world -> base_link = world -> odom (published at 1 Hz) composed with odom -> base_link
(20 Hz); the planner replans every ``replan_period`` (and at once on a new goal); the controller runs at 10 Hz on
the latest plan; the monitor at 10 Hz sends its abort to the controller and its emergency commands to the
actuators. Used by the tests (closed-loop figures, gain tuning) and as the reference the ROS scenarios mirror.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from sam_runtime.nav.controller import Commands, Controller, ControllerConfig, ControllerPose
from sam_runtime.nav.dead_reckoning import DeadReckoning, DeadReckoningConfig, DrPose
from sam_runtime.nav.motion_planner import GoalDecision, Plan, Planner, PlannerConfig
from sam_runtime.nav.performance_monitor import MonitorLimits, MonitorOutput, PerformanceMonitor
from sam_runtime.nav.slam import SlamConfig, SlamCorrector
from sam_runtime.physics.geo import Vec3, local_from_latlon
from sam_runtime.physics.vehicle import SimulatedVehicle, VehicleOptions

__all__ = ["ClosedLoop", "LoopOptions"]

TICK_HZ = 100  # the vehicle's step; every rate below divides it


def _f16(v: float) -> float:
    return struct.unpack("<e", struct.pack("<e", v))[0]


def _f16_3(v: Sequence[float]) -> Vec3:
    """A vector as float16 fields carry it."""
    return _f16(v[0]), _f16(v[1]), _f16(v[2])


@dataclass(frozen=True, kw_only=True)
class LoopOptions(VehicleOptions):
    """The simulated vehicle's options (its start in the truth frame) and the navigation stack's."""

    safe_depth: float = 50.0
    safe_altitude: float = 5.0
    limits: MonitorLimits = field(default_factory=MonitorLimits)
    planner: PlannerConfig = field(default_factory=PlannerConfig)
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    dead_reckoning: DeadReckoningConfig = field(default_factory=DeadReckoningConfig)
    slam: SlamConfig = field(default_factory=SlamConfig)
    replan_period: float = 2.0  # [s]
    record_period: float = 0.5  # [s] of the history samples


# Periods in ticks of TICK_HZ.
_PERIODS = {"imu": 1, "mag": 2, "pressure": 5, "altitude": 10, "feedback": 10, "gps": 20, "battery": 100,
            "dr_out": 5, "slam_out": 100, "control": 10, "monitor": 10}


class ClosedLoop:
    def __init__(self, options: LoopOptions | None = None) -> None:
        o = self.options = options or LoopOptions()
        self.sim = SimulatedVehicle(o)
        self.vehicle, self.sensors = self.sim.vehicle, self.sim.sensors
        self.dr = DeadReckoning(o.dead_reckoning)
        self.slam = SlamCorrector(o.slam)
        self.planner = Planner(o.planner, safe_depth=o.safe_depth, safe_altitude=o.safe_altitude)
        self.controller = Controller(o.controller)
        self.monitor = PerformanceMonitor(o.limits)
        self.tick = 0
        self.altitude = math.nan  # the latest altimeter reading
        self.odom_pose: DrPose | None = None  # the latest published odom -> base_link
        self.world_odom: tuple[float, float] | None = None  # the latest published world -> odom
        self.plan: Plan | None = None
        self.plan_reason = ""
        self.commands: Commands | None = None
        self.monitor_output: MonitorOutput | None = None
        self.history: list[dict[str, Any]] = []
        self.events: list[tuple[float, str]] = []  # (t, what): goals, plans refused, monitor transitions
        self._next_replan = 0.0
        self.replanning = True  # False: the planner has died (no new plans; the controller's plan goes stale)

    @property
    def t(self) -> float:
        return self.tick / TICK_HZ

    # ---------------------------------------------------------------------------------- goals
    def goal_pose(self, x: float, y: float, z: float, frame_id: str = "world") -> GoalDecision:
        d = self.planner.set_pose_goal(self.t, frame_id, x, y, z)
        self.events.append((self.t, f"goal pose ({x}, {y}, {z}) in {frame_id!r}: "
                                    f"{'accepted' if d.accepted else 'refused: ' + d.reason}"))
        if d.accepted:
            self._next_replan = self.t
        return d

    def goal_heading(self, heading: float, z: float, frame_id: str = "world") -> GoalDecision:
        d = self.planner.set_heading_goal(self.t, frame_id, heading, z)
        self.events.append((self.t, f"goal heading {heading} z {z}: "
                                    f"{'accepted' if d.accepted else 'refused: ' + d.reason}"))
        if d.accepted:
            self._next_replan = self.t
        return d

    # ---------------------------------------------------------------------------------- frames
    def world_pose(self) -> ControllerPose | None:
        """world -> base_link from the latest published transforms (what a TF lookup gives the nodes)."""
        if self.odom_pose is None or self.world_odom is None:
            return None
        p, (cx, cy) = self.odom_pose, self.world_odom
        return ControllerPose(p.x + cx, p.y + cy, p.z, p.roll, p.pitch, p.yaw)

    def world_to_truth(self, x: float, y: float) -> tuple[float, float]:
        """A world position in the simulator's frame (ENU around its GPS origin); world's origin is SLAM's."""
        if self.slam.origin is None:
            raise RuntimeError("world has no origin yet (no GPS fix)")
        ox, oy = local_from_latlon(*self.slam.origin, *self.options.gps_origin)
        return x + ox, y + oy

    def truth_to_world(self, x: float, y: float) -> tuple[float, float]:
        ox, oy = self.world_to_truth(0.0, 0.0)
        return x - ox, y - oy

    # ---------------------------------------------------------------------------------- run
    def _due(self, name: str) -> bool:
        return self.tick % _PERIODS[name] == 0

    def run(self, seconds: float, until: Any = None) -> bool:
        """Advance ``seconds`` of simulated time, or until ``until(self)`` is true (checked at 10 Hz); returns
        whether ``until`` ended it."""
        end = self.tick + round(seconds * TICK_HZ)
        while self.tick < end:
            self._tick()
            if until is not None and self.tick % 10 == 0 and until(self):
                return True
        return False

    def _tick(self) -> None:
        t, s, dr = self.t, self.sensors, self.dr
        veh = self.vehicle
        if self._due("imu"):
            m = s.imu()
            dr.on_imu(t, _f16_3(m.gyro), _f16_3(m.accel))
        if self._due("mag"):
            dr.on_magnetometer(t, _f16_3(s.magnetometer()))
        if self._due("pressure"):
            p = s.pressure()
            dr.on_pressure(t, p)
            self.monitor.on_pressure(t, p)
        if self._due("feedback"):
            dr.on_thruster_rpm(t, 0, round(veh.actuators.rpm_1))
            dr.on_thruster_rpm(t, 1, round(veh.actuators.rpm_2))
        if self._due("altitude"):
            self.altitude = s.altitude()
            self.monitor.on_altitude(t, self.altitude)
        if self._due("battery"):
            b = s.battery()
            self.monitor.on_battery(t, round(b.soc * 100.0), 0)  # BatteryInfo carries whole percent
        if self._due("gps"):
            g = s.gps()
            pose = dr.pose(t)
            if pose is not None:
                self.slam.on_fix(t, 0 if g.status >= 2 else -1, g.lat, g.lon, pose.x, pose.y, -pose.z)
        if self._due("dr_out"):
            self.odom_pose = dr.pose(t)
        if self._due("slam_out"):
            tr = self.slam.transform()
            if tr is not None:
                self.world_odom = (tr[0][0], tr[0][1])
        world = self.world_pose()
        if self.replanning and t >= self._next_replan and self.planner.goal is not None:
            self._next_replan = t + self.options.replan_period
            self.planner.safe_depth, self.planner.safe_altitude = self.options.safe_depth, self.options.safe_altitude
            if world is None:
                self.plan_reason = "no world -> base_link yet"
            else:
                res = self.planner.plan(t, world.x, world.y, -world.z, self.altitude, world.yaw)
                self.plan_reason = res.reason
                if res.plan is not None:
                    self.plan = res.plan
                    self.controller.set_plan(t, res.plan.poses)
        if self._due("monitor"):
            out = self.monitor.evaluate(t)
            if out.changed:
                self.events.append((t, f"monitor {out.state}: {out.abort_reason}"))
                self.controller.set_abort(out.abort_active, out.abort_reason)
            self.monitor_output = out
        if self._due("control"):
            c = self.controller.step(t, world)
            self.commands = c
            veh.command(rpm_1=c.rpm_1, rpm_2=c.rpm_2, vertical_rad=c.vertical_rad, horizontal_rad=c.horizontal_rad,
                        ballast_1_rad=c.ballast_1_rad, ballast_2_rad=c.ballast_2_rad,
                        longitudinal_weight_pct=c.longitudinal_weight_pct, buoyancy_pct=c.buoyancy_pct)
            emergency = self.monitor_output
            if emergency is not None and emergency.abort_active:  # the monitor's own commands (same topics)
                rpm, buoyancy = emergency.rpm, emergency.buoyancy_pct
                assert rpm is not None and buoyancy is not None, "an active abort carries its commands"
                veh.command(rpm_1=rpm, rpm_2=rpm, buoyancy_pct=buoyancy)
        if self.tick % round(self.options.record_period * TICK_HZ) == 0:
            self._record(world)
        self.tick += 1
        veh.advance_to(self.t)

    def _record(self, world: ControllerPose | None) -> None:
        truth = self.vehicle.truth()
        est = None
        if world is not None and self.slam.origin is not None:
            ex, ey = self.world_to_truth(world.x, world.y)
            est = {"x": ex, "y": ey, "depth": -world.z, "yaw": world.yaw}
        c = self.commands
        self.history.append({"t": self.t, "truth": truth, "estimate": est,
                             "mode": None if c is None else c.mode,
                             "monitor": None if self.monitor_output is None else self.monitor_output.state})

    # ---------------------------------------------------------------------------------- figures
    def dr_error(self) -> float | None:
        """Horizontal distance [m] between the estimate world -> base_link and the truth, now."""
        w = self.world_pose()
        if w is None or self.slam.origin is None:
            return None
        ex, ey = self.world_to_truth(w.x, w.y)
        s = self.vehicle.state
        return math.hypot(ex - s.x, ey - s.y)
