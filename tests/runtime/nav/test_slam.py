"""The SLAM corrector (runtime/nav/slam.py): world around the first fix, world -> odom from fixes at the surface,
kept when submerged, unusable fixes ignored and counted."""

from __future__ import annotations

import math

import pytest

from sam_runtime.nav.slam import SlamConfig, SlamCorrector
from sam_runtime.physics.geo import latlon_from_local

ORIGIN = (59.35, 18.07)


def _fix(east: float, north: float) -> tuple[float, float]:
    return latlon_from_local(east, north, *ORIGIN)


def test_the_first_fix_is_the_world_origin_and_gives_the_first_correction() -> None:
    s = SlamCorrector()
    assert s.transform() is None
    assert s.on_fix(0.0, 0, *ORIGIN, dr_x=0.0, dr_y=0.0)
    assert s.origin == ORIGIN and s.transform() == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    # Dead reckoning says (10, 0) in odom; GPS says (12, 1) in world: odom sits at (2, 1) in world.
    s2 = SlamCorrector(SlamConfig(gain=1.0))
    s2.on_fix(0.0, 0, *ORIGIN, 0.0, 0.0)
    s2.on_fix(1.0, 0, *_fix(12.0, 1.0), 10.0, 0.0)
    assert s2.correction == pytest.approx((2.0, 1.0), abs=1e-6)
    assert s2.world_position(*_fix(12.0, 1.0)) == pytest.approx((12.0, 1.0, 0.0), abs=1e-6)


def test_the_correction_is_low_pass_filtered_and_kept_when_submerged() -> None:
    s = SlamCorrector(SlamConfig(gain=0.25))
    s.on_fix(0.0, 0, *ORIGIN, 0.0, 0.0)
    for k in range(1, 40):
        s.on_fix(k * 0.2, 0, *_fix(4.0, -2.0), 0.0, 0.0)  # a 4, -2 offset appears (resurfaced after a drift)
    assert s.correction == pytest.approx((4.0, -2.0), abs=0.01)
    s2 = SlamCorrector(SlamConfig(gain=0.25))
    s2.on_fix(0.0, 0, *ORIGIN, 0.0, 0.0)
    s2.on_fix(0.2, 0, *_fix(4.0, -2.0), 0.0, 0.0)
    assert s2.correction == pytest.approx((1.0, -0.5), abs=1e-6)  # one step of the filter, no jump
    before = s.correction
    assert not s.on_fix(9.0, -1, *_fix(50.0, 50.0), 0.0, 0.0)  # submerged: no fix
    assert not s.on_fix(9.2, 0, *_fix(50.0, 50.0), 0.0, 0.0, depth=3.0)  # a stray fix under water
    assert s.correction == before and s.counts["ignored.no_fix"] == 1 and s.counts["ignored.submerged"] == 1


@pytest.mark.parametrize(("args", "kind"), [
    ((0, math.nan, 18.0, 0.0, 0.0), "ignored.invalid_position"),
    ((0, 59.0, math.inf, 0.0, 0.0), "ignored.invalid_position"),
    ((0, 91.0, 18.0, 0.0, 0.0), "ignored.invalid_position"),
    ((0, 59.0, 18.0, math.nan, 0.0), "ignored.invalid_odometry"),
    ((-1, 59.0, 18.0, 0.0, 0.0), "ignored.no_fix"),
])
def test_unusable_fixes_are_ignored_and_counted(args: tuple, kind: str) -> None:
    s = SlamCorrector()
    assert not s.on_fix(0.0, *args)
    assert s.origin is None and s.transform() is None and s.counts == {kind: 1}
    with pytest.raises(RuntimeError, match="no world origin yet"):
        s.world_position(59.0, 18.0)


def test_origin_from_a_datum_or_the_mean_of_the_first_fixes() -> None:
    s = SlamCorrector(SlamConfig(datum=ORIGIN, gain=1.0))
    s.on_fix(0.0, 0, *_fix(3.0, 4.0), 0.0, 0.0)
    assert s.origin == ORIGIN and s.correction == pytest.approx((3.0, 4.0), abs=1e-6)
    m = SlamCorrector(SlamConfig(origin_fixes=2, gain=1.0))
    assert m.on_fix(0.0, 0, *_fix(1.0, 0.0), 0.0, 0.0) and m.transform() is None
    m.on_fix(0.2, 0, *_fix(3.0, 2.0), 0.0, 0.0)
    assert m.origin == pytest.approx(_fix(2.0, 1.0)) and m.correction == pytest.approx((1.0, 1.0), abs=1e-6)
    with pytest.raises(ValueError, match="gain must be within"):
        SlamConfig(gain=0.0)
    with pytest.raises(ValueError, match="datum must be a valid"):
        SlamCorrector(SlamConfig(datum=(math.nan, 0.0)))
