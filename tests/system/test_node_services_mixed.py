"""The device duties in a mixed layout (`bridge.node_services`, issue 19): two bridges (one per protocol) share one
namespace, so each serves the duties under its protocol's suffix; the DroneCAN half of SAM's `mixed` layout, in
process, on a private loopback bus, with an rclpy probe:

- its duties are /uavcan_get_node_info_dronecan etc. and none goes by the bare name (the Cyphal half's would be
  _cyphal, the same rule);
- a node id of a device the layout puts on Cyphal is no device of this bridge: success false, the reason, at once.
"""

from __future__ import annotations

import asyncio
from typing import Any

import pytest

pytest.importorskip("dronecan")
pytest.importorskip("rclpy")

from helpers.dronecan_support import private_iface, until
from helpers.ros_probe import ThreadedProbe
from helpers.runtime_support import domain_id, generated_or_skip

pytestmark = [pytest.mark.ros, pytest.mark.slow]


@pytest.fixture(scope="module")
def run() -> dict[str, Any]:
    gen = generated_or_skip()
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ROS_DOMAIN_ID", domain_id(75))
        return asyncio.run(_scenario(gen, private_iface()))


async def _scenario(gen: Any, iface: str) -> dict[str, Any]:
    from sam_runtime.bridge import Bridge

    bridge = Bridge(gen, layout="mixed", protocol="dronecan", dronecan_iface=iface, diagnostics_period=0.5)
    await bridge.start()
    probe = None
    out: dict[str, Any] = {"name": bridge.name, "devices": dict(bridge.selection.devices)}
    try:
        probe = ThreadedProbe(gen, [], [])

        def duty_services() -> list[str]:
            return sorted(n for n, types in probe.node.get_service_names_and_types()
                          if any("/srv/Uavcan" in t for t in types))

        await until(lambda: len(duty_services()) >= 3, 20, "the duties' services")
        out["services"] = duty_services()
        cyphal_device = min(d.node_id for d in gen.tables().DEVICES if d.node_id not in bridge.selection.devices)
        out["cyphal_device"] = cyphal_device
        out["refused"] = await asyncio.to_thread(probe.call_duty, "/uavcan_get_node_info_dronecan",
                                                  "UavcanGetNodeInfo", cyphal_device, 20.0)
        out["stats"] = bridge.stats()["services"]
    finally:
        if probe is not None:
            probe.close()
        await bridge.close()
    return out


def test_each_half_serves_its_duties_under_its_protocol(run: dict[str, Any]) -> None:
    assert run["name"] == "uavcan_ros_bridge_dronecan"
    assert run["services"] == ["/uavcan_get_node_info_dronecan", "/uavcan_get_transport_stats_dronecan",
                               "/uavcan_restart_node_dronecan"]
    assert run["stats"]["node_services.get_node_info"]["service"] == "uavcan_get_node_info_dronecan"


def test_a_device_of_the_other_protocol_is_refused(run: dict[str, Any]) -> None:
    refused = run["refused"]
    assert refused.success is False and refused.name == ""
    assert refused.message.startswith(f"node {run['cyphal_device']} is no DroneCAN device of this bridge (its "
                                      "devices: "), refused.message
    assert run["cyphal_device"] not in run["devices"]
    assert run["stats"]["node_services.get_node_info"]["failed.bad_node_id"] == 1
