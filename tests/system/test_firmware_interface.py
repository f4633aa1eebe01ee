"""One interface version from spec to firmware (issue 28 part 4), end to end: SAM's devices simulated with the imu
running stale firmware (`--stale-firmware imu`: it reports another interface hash) and the bridge in one process, on
Cyphal/UDP and on DroneCAN (a private loopback bus), with `bridge.interface_check.on_mismatch: stop`. The bridge
asks every board on first contact (GetInfo / GetNodeInfo): the imu is a mismatch, reported on its /diagnostics
status (ERROR, "firmware interface <got> != spec <want>") and in the stats, counted, and its mapping's messages are
dropped as `interface_mismatch` (none published after the verdict); every other board matches. Every wait polls with
a deadline.
"""

from __future__ import annotations

import asyncio
from typing import Any

import pytest

pytest.importorskip("rclpy")

from helpers.dronecan_support import until
from helpers.runtime_support import domain_id, generated_or_skip

pytestmark = [pytest.mark.ros, pytest.mark.slow]

TIMEOUT_S = 30.0  # every board's verdict, and the imu's drops (100 Hz), on a loaded machine
DROPS = 20  # the imu's messages dropped after the verdict: its traffic is stopped, not just once


@pytest.fixture(scope="module", params=["cyphal", "dronecan"])
def run(request: pytest.FixtureRequest) -> dict[str, Any]:
    protocol = request.param
    if protocol == "dronecan":
        pytest.importorskip("dronecan")
    else:
        pytest.importorskip("pycyphal")
    gen = generated_or_skip()
    with pytest.MonkeyPatch.context() as mp:  # a private ROS domain
        mp.setenv("ROS_DOMAIN_ID", domain_id(151 if protocol == "cyphal" else 152))
        tables = gen.tables()
        mp.setattr(tables, "INTERFACE_ON_MISMATCH", "stop")  # the spec's bridge.interface_check.on_mismatch
        return asyncio.run(_scenario(gen, protocol))


async def _scenario(gen: Any, protocol: str) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge
    from sam_runtime.bridge.diagnostics import statuses
    from sam_runtime.sim.simulator import SimConfig, Simulator

    tables = gen.tables()
    if protocol == "dronecan":
        from helpers.dronecan_support import private_iface

        iface = private_iface()
        bridge = Bridge(gen, layout="dronecan", dronecan_iface=iface, diagnostics_period=0.5)
        sim = Simulator(gen, SimConfig(layout="dronecan", dronecan_iface=iface, stale_firmware=("imu",)))
        infos = tables.DRONECAN_DEVICES
    else:
        bridge = Bridge(gen, diagnostics_period=0.5)
        sim = Simulator(gen, SimConfig(stale_firmware=("imu",)))
        infos = tables.DEVICES
    await bridge.start()
    try:
        await sim.start(publish_now=True)
        check = bridge.interface_check
        assert check is not None
        await until(lambda: all(b.verdict in ("match", "mismatch") for b in check.boards.values()), TIMEOUT_S,
                    "every board's verdict")
        imu_mappings = [name for name, sw in bridge.switches.items() if not sw.enabled]
        published = {name: bridge.stats()["mappings"][name]["published"] for name in imu_mappings}

        def dropped() -> int:
            return min(bridge.stats()["mappings"][n]["dropped"].get("interface_mismatch", 0)
                       for n in imu_mappings if bridge.stats()["mappings"][n]["direction"] == "uavcan_to_ros")

        await until(lambda: dropped() >= DROPS, TIMEOUT_S, f"{DROPS} imu messages dropped")
        snap = bridge.stats()
        return {
            "protocol": protocol, "boards": check.snapshot()["boards"], "want": {d.name: d.interface_hash
                                                                                for d in infos},
            "held": imu_mappings, "published_at_verdict": published,
            "published_now": {n: snap["mappings"][n]["published"] for n in imu_mappings},
            "dropped": {n: snap["mappings"][n]["dropped"] for n in imu_mappings},
            "device_imu": snap["devices"]["imu"],
            "statuses": {name: (level, msg) for level, name, msg, *_ in statuses(snap, bridge.reporter.naming)},
        }
    finally:
        await sim.close()
        await bridge.close()


def test_the_stale_board_is_a_mismatch_and_the_others_match(run: dict[str, Any]) -> None:
    boards = run["boards"]
    assert boards["imu"]["verdict"] == "mismatch" and boards["imu"]["mismatches"] == 1
    assert boards["imu"]["got"] == f"{run['want']['imu'] ^ 0xFFFF_FFFF_FFFF_FFFF:016x}"
    others = {name: b["verdict"] for name, b in boards.items() if name != "imu"}
    assert len(others) >= 5 and set(others.values()) == {"match"}
    assert all(b["verdict_after_s"] is not None and b["verdict_after_s"] < 5.0 for b in boards.values())


def test_the_mismatch_is_reported_on_diagnostics(run: dict[str, Any]) -> None:
    (level, msg), = [v for k, v in run["statuses"].items() if k.endswith("/device/imu")]
    want = f"{run['want']['imu']:016x}"
    assert level == 2 and f"!= spec {want}: its mappings are stopped" in msg
    assert run["device_imu"]["interface"] == "mismatch" and run["device_imu"]["interface_mismatches"] == 1


def test_with_stop_the_boards_traffic_is_not_bridged(run: dict[str, Any]) -> None:
    assert run["held"], "the imu's mapping is held off"
    assert run["published_now"] == run["published_at_verdict"]
    assert all(d.get("interface_mismatch", 0) >= DROPS for d in run["dropped"].values() if d)
