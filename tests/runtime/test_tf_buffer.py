"""sam_runtime.tf_buffer on its own: chained lookups in any direction, time stamps, staleness, interpolation,
re-parenting, and clear errors for what cannot be stored or looked up."""

from __future__ import annotations

import math
import random
import threading

import pytest

from sam_runtime.tf_buffer import (
    IDENTITY,
    TfBuffer,
    TfError,
    TfExtrapolation,
    TfMissingEdge,
    TfStale,
    Transform,
    quat_from_rpy,
    quat_to_rpy,
)

S = 1_000_000_000  # ns per second
YAW90 = quat_from_rpy(0.0, 0.0, math.pi / 2)


def approx(values: tuple[float, ...]) -> object:
    return pytest.approx(values, abs=1e-9)


@pytest.fixture
def tree() -> TfBuffer:
    """world -> odom -> base_link (dynamic), base_link -> imu_link and base_link -> gps_link (static)."""
    b = TfBuffer()
    b.set_transform("world", "odom", 10 * S, (10.0, 0.0, 0.0), YAW90)
    b.set_transform("odom", "base_link", 11 * S, (1.0, 2.0, -3.0), IDENTITY)
    b.set_transform("base_link", "imu_link", 0, (0.1, 0.0, 0.0), IDENTITY, static=True)
    b.set_transform("base_link", "gps_link", 0, (-0.2, 0.0, 0.1), quat_from_rpy(0.0, 0.0, math.pi), static=True)
    return b


def test_lookup_down_the_tree(tree: TfBuffer) -> None:
    t = tree.lookup("world", "base_link")
    assert (t.parent, t.child) == ("world", "base_link")
    # odom is turned 90 degrees in world: odom's (1, 2, -3) is world's (10 - 2, 1, -3).
    assert t.translation == approx((8.0, 1.0, -3.0))
    assert t.yaw() == pytest.approx(math.pi / 2)
    assert t.stamp_ns == 10 * S  # the older of the two dynamic edges


def test_lookup_up_and_across(tree: TfBuffer) -> None:
    up = tree.lookup("base_link", "world")
    assert up.compose(tree.lookup("world", "base_link")).translation == approx((0.0, 0.0, 0.0))
    across = tree.lookup("imu_link", "gps_link")  # siblings: up to base_link, down again
    assert across.translation == approx((-0.3, 0.0, 0.1))
    assert abs(across.yaw()) == pytest.approx(math.pi)
    assert across.stamp_ns == 0  # static edges only


def test_points_map_through_the_chain(tree: TfBuffer) -> None:
    """A point 1 m ahead of the GPS antenna (which faces aft), in world coordinates."""
    t = tree.lookup("world", "gps_link")
    # gps_link x is base_link -x: the point is at base_link (-1.2, 0, 0.1), odom (-0.2, 2, -2.9),
    # world (10 - 2, -0.2, -2.9).
    assert t.apply((1.0, 0.0, 0.0)) == approx((8.0, -0.2, -2.9))


def test_identity_lookup(tree: TfBuffer) -> None:
    t = tree.lookup("odom", "odom")
    assert t.translation == (0.0, 0.0, 0.0) and t.rotation == IDENTITY


def test_missing_edge_names_the_pair(tree: TfBuffer) -> None:
    b = TfBuffer()
    b.set_transform("odom", "base_link", S, (0.0, 0.0, 0.0), IDENTITY)
    with pytest.raises(TfMissingEdge) as info:
        b.lookup("world", "base_link")
    assert info.value.missing == ("world", "odom")
    assert "'world' (unknown: no transform names it)" in str(info.value)
    assert "'odom' (the root of 'base_link''s tree)" in str(info.value)
    b.set_transform("map", "other", S, (0.0, 0.0, 0.0), IDENTITY)
    with pytest.raises(TfMissingEdge) as info:
        b.lookup("other", "base_link")
    assert info.value.missing == ("map", "odom")
    assert not b.can_transform("other", "base_link") and b.can_transform("base_link", "odom")


def test_stale_edge_names_the_edge_and_its_age(tree: TfBuffer) -> None:
    assert tree.lookup("world", "base_link", now_ns=11 * S, max_age_s=1.5).stamp_ns == 10 * S
    with pytest.raises(TfStale) as info:
        tree.lookup("world", "base_link", now_ns=13 * S, max_age_s=2.5)
    assert info.value.edge == ("world", "odom") and info.value.age_s == pytest.approx(3.0)
    assert "world->odom is stale: 3.000 s old (at most 2.5 s)" in str(info.value)
    # Static edges never age.
    assert tree.lookup("base_link", "imu_link", now_ns=10**6 * S, max_age_s=0.1).translation == approx((0.1, 0, 0))
    with pytest.raises(ValueError, match="now_ns"):
        tree.lookup("world", "base_link", max_age_s=1.0)


def test_newest_sample_wins_and_older_ones_are_history(tree: TfBuffer) -> None:
    tree.set_transform("odom", "base_link", 12 * S, (2.0, 2.0, -3.0), IDENTITY)
    tree.set_transform("odom", "base_link", 11 * S + S // 2, (1.5, 2.0, -3.0), IDENTITY)  # late: history
    assert tree.lookup("odom", "base_link").translation == approx((2.0, 2.0, -3.0))
    assert tree.lookup("odom", "base_link", time_ns=11 * S + S // 2).translation == approx((1.5, 2.0, -3.0))


def test_interpolation_in_time() -> None:
    b = TfBuffer()
    b.set_transform("odom", "base_link", 10 * S, (0.0, 0.0, 0.0), IDENTITY)
    b.set_transform("odom", "base_link", 12 * S, (2.0, 4.0, 0.0), YAW90)
    mid = b.lookup("odom", "base_link", time_ns=11 * S)
    assert mid.translation == approx((1.0, 2.0, 0.0)) and mid.yaw() == pytest.approx(math.pi / 4)
    assert mid.stamp_ns == 11 * S
    with pytest.raises(TfExtrapolation, match=r"not known at 13\.000 s"):
        b.lookup("odom", "base_link", time_ns=13 * S)


def test_cache_time_drops_old_samples() -> None:
    b = TfBuffer(cache_time_s=2.0)
    for second in range(10):
        assert b.set_transform("odom", "base_link", second * S, (float(second), 0.0, 0.0), IDENTITY)
    with pytest.raises(TfExtrapolation):
        b.lookup("odom", "base_link", time_ns=6 * S + S // 2)
    assert b.lookup("odom", "base_link", time_ns=7 * S + S // 2).translation == approx((7.5, 0.0, 0.0))
    assert not b.set_transform("odom", "base_link", 3 * S, (3.0, 0.0, 0.0), IDENTITY)  # beyond the cache
    assert b.ignored_old == 1
    with pytest.raises(ValueError):
        TfBuffer(cache_time_s=0.0)


def test_reparenting_and_loops() -> None:
    b = TfBuffer()
    b.set_transform("odom", "base_link", S, (1.0, 0.0, 0.0), IDENTITY)
    b.set_transform("map", "base_link", 2 * S, (5.0, 0.0, 0.0), IDENTITY)  # tf2 allows a new parent
    assert b.parent_of("base_link") == "map" and b.reparented == 1
    assert b.lookup("map", "base_link").translation == approx((5.0, 0.0, 0.0))
    b.set_transform("base_link", "arm", S, (0.0, 0.0, 1.0), IDENTITY)
    with pytest.raises(TfError, match="would close a loop"):
        b.set_transform("arm", "map", S, (0.0, 0.0, 0.0), IDENTITY)
    assert b.frames() == ["arm", "base_link", "map"]  # odom is in no edge any more


@pytest.mark.parametrize("parent,child,translation,rotation,match", [
    ("odom", "odom", (0, 0, 0), IDENTITY, "relates a frame to itself"),
    ("", "base_link", (0, 0, 0), IDENTITY, "non-empty string"),
    ("odom", "base_link", (math.nan, 0, 0), IDENTITY, "non-finite"),
    ("odom", "base_link", (0, 0, 0), (0.0, 0.0, 0.0, 0.0), "not a unit quaternion"),
    ("odom", "base_link", (0, 0, 0), (0.0, 0.0, 0.0, 2.0), "not a unit quaternion"),
    ("odom", "base_link", (0, 0), IDENTITY, "malformed"),
])
def test_bad_transforms_are_refused(parent: str, child: str, translation: tuple, rotation: tuple, match: str) -> None:
    b = TfBuffer()
    with pytest.raises(TfError, match=match):
        b.set_transform(parent, child, S, translation, rotation)
    assert b.frames() == []


def test_frame_ids_and_quaternions_are_normalised() -> None:
    b = TfBuffer()
    b.set_transform("/odom", "/base_link", S, (0, 0, 0), (0.0, 0.0, 0.0, 1.0004))  # ROS 1 slashes: stripped
    assert b.frames() == ["base_link", "odom"]
    assert math.fsum(c * c for c in b.lookup("odom", "base_link").rotation) == pytest.approx(1.0)
    with pytest.raises(TfError, match="leading slash"):
        b.lookup("/odom", "base_link")


def test_transform_algebra_against_random_chains() -> None:
    """compose/inverse/apply agree with applying each step to a point, for random rotations and translations."""
    rng = random.Random(9)
    for _ in range(200):
        steps = [Transform(f"f{i}", f"f{i + 1}", i + 1, tuple(rng.uniform(-5, 5) for _ in range(3)),
                           quat_from_rpy(rng.uniform(-3, 3), rng.uniform(-1.5, 1.5), rng.uniform(-3, 3)))
                 for i in range(4)]
        point = tuple(rng.uniform(-5, 5) for _ in range(3))
        expected = point
        for t in reversed(steps):
            expected = t.apply(expected)
        chained = steps[0]
        for t in steps[1:]:
            chained = chained.compose(t)
        assert chained.apply(point) == pytest.approx(expected, abs=1e-9)
        assert chained.inverse().apply(chained.apply(point)) == pytest.approx(point, abs=1e-9)
        assert chained.stamp_ns == 1
        b = TfBuffer()
        for t in steps:
            b.set_transform(t.parent, t.child, t.stamp_ns, t.translation, t.rotation)
        assert b.lookup("f0", "f4").apply(point) == pytest.approx(expected, abs=1e-9)
        assert b.lookup("f4", "f0").apply(expected) == pytest.approx(point, abs=1e-9)
        middle = b.lookup("f3", "f1")  # f1 is above f3: the chain runs up from f3, then is inverted
        assert middle.apply(steps[1].apply(steps[2].apply(point))) == pytest.approx(point, abs=1e-9)


def test_rpy_round_trip() -> None:
    rng = random.Random(3)
    for _ in range(100):
        rpy = (rng.uniform(-3.1, 3.1), rng.uniform(-1.5, 1.5), rng.uniform(-3.1, 3.1))
        assert quat_to_rpy(quat_from_rpy(*rpy)) == pytest.approx(rpy, abs=1e-9)


def test_compose_refuses_unrelated_frames() -> None:
    with pytest.raises(ValueError, match="cannot compose"):
        Transform("a", "b", 0, (0, 0, 0), IDENTITY).compose(Transform("c", "d", 0, (0, 0, 0), IDENTITY))


def test_concurrent_writers_and_readers() -> None:
    """Feeding from an executor thread while another thread looks up: no torn state, no exception."""
    b = TfBuffer()
    b.set_transform("world", "odom", 1, (0.0, 0.0, 0.0), IDENTITY)
    errors: list[BaseException] = []
    stop = threading.Event()

    def writer() -> None:
        for i in range(1, 3000):
            b.set_transform("odom", "base_link", i, (float(i), 0.0, 0.0), IDENTITY)
        stop.set()

    def reader() -> None:
        try:
            while not stop.is_set():
                if b.can_transform("world", "base_link"):
                    t = b.lookup("world", "base_link")
                    assert t.translation[1:] == (0.0, 0.0)
        except BaseException as ex:  # reported below
            errors.append(ex)

    threads = [threading.Thread(target=writer), threading.Thread(target=reader)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=30)
    assert not errors and b.lookup("world", "base_link").translation[0] == 2999.0
