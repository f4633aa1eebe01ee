"""A simulated Cyphal board's settings as registers (runtime/sim/cyphal.py), in this process on Cyphal/UDP 127.0.0.1
(the machine-wide UDP lock), through uavcan.register.Access as any tool (yakut) sees them:

- a setting reads its spec default, with the standard read-only "<name><", "<name>>", "<name>=" (min, max, default);
- an out-of-range write is refused: the response shows the value kept;
- a value set but not saved is lost at a reboot; saved (ExecuteCommand STORE_PERSISTENT_STATES) it survives one;
  FACTORY_RESET brings the spec's default back.
"""

from __future__ import annotations

import asyncio
from typing import Any

import pytest

pytest.importorskip("pycyphal")

from helpers.runtime_support import cyphal_udp_lock, generated_or_skip

from sam_runtime.sim.simulator import SimConfig, Simulator

DEVICE, REGISTER = "thruster_1", "motor.pole_count"

pytestmark = [pytest.mark.slow, pytest.mark.filterwarnings("ignore::DeprecationWarning:pydsdl"),
              pytest.mark.filterwarnings("ignore:Data type uavcan.node.ExecuteCommand:DeprecationWarning")]


async def _scenario(gen: Any) -> dict[str, Any]:
    import uavcan.node
    import uavcan.register

    from sam_runtime.cyphal_io.registers import register_stored, register_value
    from sam_runtime.cyphal_io.transport import aclose, make_node

    tables = gen.tables()
    nid = next(d.node_id for d in tables.DEVICES if d.name == DEVICE)
    sim = Simulator(gen, SimConfig("udp", "127.0.0.1", devices=[DEVICE]))
    client = make_node("org.test.registers", tables.BRIDGE_NODE_ID, "udp", iface="127.0.0.1")
    access = client.make_client(uavcan.register.Access_1_0, nid)
    access.response_timeout = 2.0
    execute = uavcan.node.ExecuteCommand_1_1
    cmd = client.make_client(execute, nid)
    out: dict[str, Any] = {}

    async def reg(name: str, value: int | None = None) -> Any:
        request = uavcan.register.Access_1_0.Request(name=uavcan.register.Name_1_0(name))
        if value is not None:
            request.value = register_value("integer", value)
        for _ in range(20):  # a board that is rebooting answers nothing: ask again (each waits its timeout)
            got = await access.call(request)
            if got is not None:
                return register_stored("integer", got[0].value)
        raise AssertionError(f"no answer to {name}")

    try:
        await sim.start()
        out["read"] = [await reg(REGISTER + s) for s in ("", "<", ">", "=")]
        out["out_of_range"] = await reg(REGISTER, 60)
        out["in_range"] = await reg(REGISTER, 20)
        await sim.restart(DEVICE)
        out["after_reboot_unsaved"] = await reg(REGISTER)
        await reg(REGISTER, 22)
        stored = await cmd.call(execute.Request(command=65530))  # COMMAND_STORE_PERSISTENT_STATES
        out["store"] = None if stored is None else int(stored[0].status)
        await sim.restart(DEVICE)
        out["after_reboot_saved"] = await reg(REGISTER)
        reset = await cmd.call(execute.Request(command=65532))  # COMMAND_FACTORY_RESET
        out["reset"] = None if reset is None else int(reset[0].status)
        out["after_reset"] = await reg(REGISTER)
    finally:
        await sim.close()
        await aclose(access, cmd, client)
    return out


def test_a_board_holds_refuses_saves_and_resets_its_settings() -> None:
    gen = generated_or_skip()
    if gen.tables().VEHICLE != "sam":
        pytest.skip("SAM's devices")
    gen.compile_dsdl()

    async def bounded() -> Any:
        async with asyncio.timeout(90):
            return await _scenario(gen)

    with cyphal_udp_lock():
        out = asyncio.run(bounded())
    assert out["read"] == [14, 2, 48, 14], out
    assert out["out_of_range"] == 14 and out["in_range"] == 20, out
    assert out["after_reboot_unsaved"] == 14, out
    assert out["store"] == 0 and out["after_reboot_saved"] == 22, out
    assert out["reset"] == 0 and out["after_reset"] == 14, out
