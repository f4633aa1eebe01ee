"""SLAM (IV.E.2): world -> odom on /tf at PUBLISH_HZ, from GPS fixes at the surface.

Each fix goes to :class:`sam_runtime.nav.slam.SlamCorrector` with the dead reckoning's odom -> base_link at that
moment (its depth tells whether the vehicle is at the surface). Submerged there are no usable fixes and the last
correction is published on (the system runs on dead reckoning). The world origin (the first fix) is on
/diagnostics (``origin_lat``, ``origin_lon``) so that a tool can relate world to latitude and longitude.
"""

from __future__ import annotations

from typing import Any

from sam_nodes.slam import SlamBase

from sam_runtime.nav.slam import SlamConfig, SlamCorrector
from sam_runtime.nodes.common import Level, StatusReporter, guarded_timer, now_s
from sam_runtime.tf_buffer import TfError

__all__ = ["PUBLISH_HZ", "Slam"]

PUBLISH_HZ = 2.0
ODOM_MAX_AGE_S = 0.5  # a fix is paired with the dead reckoning only while that is this recent


class Slam(SlamBase):
    def __init__(self, *, config: SlamConfig | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.corrector = SlamCorrector(config)
        self.published = 0
        self.last_problem = ""
        self.status = StatusReporter(self)
        self.timer = guarded_timer(self, 1.0 / PUBLISH_HZ, "publish", self.publish)
        self.status(Level.WARN, "waiting for a GPS fix at the surface")

    def on_gps_fix(self, msg: Any) -> None:
        t = now_s(self)
        try:
            odom = self.lookup_odom_to_base_link(max_age_s=ODOM_MAX_AGE_S)
        except TfError as ex:
            self.corrector.counts["ignored.no_odometry"] += 1
            self.last_problem = f"fix ignored: {ex}"
            return
        x, y, z = odom.translation
        self.corrector.on_fix(t, int(msg.status.status), msg.latitude, msg.longitude, x, y, -z)

    def publish(self) -> None:
        tr = self.corrector.transform()
        counts = dict(self.corrector.counts)
        if tr is None:
            self.status(Level.WARN, "waiting for a GPS fix at the surface", last_problem=self.last_problem or None,
                        **counts)
            return
        translation, rotation = tr
        self.publish_world_to_odom(self.get_clock().now(), translation, rotation)
        self.published += 1
        lat, lon = self.corrector.origin or (None, None)
        age = None if self.corrector.last_fix_t is None else now_s(self) - self.corrector.last_fix_t
        mode = "correcting from GPS fixes" if age is not None and age < 2.0 else "dead reckoning only (no fix)"
        self.status(Level.OK, mode, origin_lat=f"{lat:.8f}", origin_lon=f"{lon:.8f}", correction_x=translation[0],
                    correction_y=translation[1], last_fix_age_s=age, published=self.published, **counts)
