"""Performance monitor (IV.H): :class:`~sam_runtime.nav.performance_monitor.PerformanceMonitor`
on /pressure, /altitude and
/battery_state, evaluated at EVALUATE_HZ and at once when one of its parameters changes (through the node's
~/set_parameters service: the new limits apply from that moment).

/abort (latched) carries the state: active=false at start, then a message on every change. In emergency the node
also commands zero RPM and full positive buoyancy at EVALUATE_HZ (the controller, obeying the abort, commands the
same). The emergency is latched: it stays until this node is restarted (an operator's decision), even when the
condition that triggered it has gone.
"""

from __future__ import annotations

import math
from typing import Any

from sam_nodes.performance_monitor import PerformanceMonitorBase

from sam_runtime.nav.performance_monitor import EMERGENCY, MonitorLimits, MonitorOutput
from sam_runtime.nav.performance_monitor import PerformanceMonitor as StateMachine
from sam_runtime.nodes.common import Level, StatusReporter, guarded_timer, now_s

__all__ = ["EVALUATE_HZ", "PerformanceMonitor"]

EVALUATE_HZ = 10.0


class PerformanceMonitor(PerformanceMonitorBase):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.monitor = StateMachine(self._limits())
        self.output: MonitorOutput | None = None
        self.aborts_published = 0
        self.status = StatusReporter(self)
        self.add_post_set_parameters_callback(lambda _params: self.evaluate())
        self.timer = guarded_timer(self, 1.0 / EVALUATE_HZ, "evaluate", self.evaluate)
        self._publish_abort(False, "")  # the latched state for late joiners: nominal
        self.evaluate()

    def _limits(self) -> MonitorLimits:
        return MonitorLimits(critical_depth=self.critical_depth, critical_altitude=self.critical_altitude,
                             min_battery_percent=self.min_battery_percent)

    # ---------------------------------------------------------------------------------- inputs
    def on_pressure(self, msg: Any) -> None:
        self.monitor.on_pressure(now_s(self), msg.fluid_pressure)

    def on_altitude(self, msg: Any) -> None:
        self.monitor.on_altitude(now_s(self), msg.range)

    def on_battery_state(self, msg: Any) -> None:
        percent = float(msg.percentage) * 100.0 if math.isfinite(msg.percentage) else math.nan
        self.monitor.on_battery(now_s(self), percent, int(msg.power_supply_health))

    # ---------------------------------------------------------------------------------- state machine
    def evaluate(self) -> None:
        self.monitor.limits = self._limits()
        out = self.monitor.evaluate(now_s(self))
        was = self.output
        self.output = out
        if out.changed or was is None or was.state != out.state:
            if out.abort_active:
                self.get_logger().error(f"emergency ascent: {out.abort_reason}")
            self._publish_abort(out.abort_active, out.abort_reason)
        if out.state == EMERGENCY:
            self._emergency_commands(out)
        self.report(out)

    def _publish_abort(self, active: bool, reason: str) -> None:
        from sam_msgs.msg import Abort

        msg = Abort(active=bool(active), reason=reason)
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = self.frame("base_link")
        self.publish_abort(msg)
        self.aborts_published += 1

    def _emergency_commands(self, out: MonitorOutput) -> None:
        from sam_msgs.msg import PercentStamped, ThrusterRPMs

        stamp = self.get_clock().now().to_msg()
        rpm = int(out.rpm or 0)
        rpms = ThrusterRPMs(thruster_1_rpm=rpm, thruster_2_rpm=rpm)
        buoyancy = PercentStamped(percent=float(out.buoyancy_pct if out.buoyancy_pct is not None else 100.0))
        for msg in (rpms, buoyancy):
            msg.header.stamp = stamp
            msg.header.frame_id = self.frame("base_link")
        self.publish_thruster_rpms(rpms)
        self.publish_buoyancy_piston_position(buoyancy)

    def report(self, out: MonitorOutput) -> None:
        m, lim = self.monitor, self.monitor.limits
        values = dict(state=out.state, depth=m.depth, altitude=m.altitude, battery_percent=m.battery_percent,
                      battery_health=m.battery_health, critical_depth=lim.critical_depth,
                      critical_altitude=lim.critical_altitude, min_battery_percent=lim.min_battery_percent,
                      triggers=m.triggers, aborts_published=self.aborts_published)
        if out.state == EMERGENCY:
            self.status(Level.ERROR, f"emergency: {out.abort_reason}", since_s=now_s(self) - (out.since or 0.0),
                        **values)
        else:
            self.status(Level.OK, "nominal", **values)
