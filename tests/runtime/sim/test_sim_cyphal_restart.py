"""A simulated Cyphal device's reboot (runtime/sim/cyphal.py, ExecuteCommand.1.1 COMMAND_RESTART), in this process on
Cyphal/UDP 127.0.0.1 (the machine-wide UDP lock), as a client that polls GetInfo all along sees it:

- an unknown command is refused (STATUS_BAD_COMMAND), RESTART answered with success, then the device reboots: silent
  for at least ``SimConfig.reboot_s``, a new node whose heartbeat uptime starts again, one power cycle counted;
- closing the node while GetInfo responses are being sent logs nothing at ERROR and no traceback (its servers stop
  before its sockets close; a request met while it is off goes unanswered, as on a device that is off); the race
  is also made certain: a response whose send resumes only once the node is closing (as when the send's task was
  scheduled just before the close), the failure pycyphal logged as a "task failure" traceback (EBADF);
- a power cycle (``power_off``/``power_on``) reboots it the same way.
"""

from __future__ import annotations

import asyncio
import logging
import time
from typing import Any

import pytest

pytest.importorskip("pycyphal")

from helpers.runtime_support import cyphal_udp_lock, generated_or_skip

from sam_runtime.sim.simulator import SimConfig, Simulator

DEVICE = "gps"

pytestmark = [pytest.mark.filterwarnings("ignore::DeprecationWarning:pydsdl"),
              pytest.mark.filterwarnings("ignore:Data type uavcan.node.ExecuteCommand:DeprecationWarning")]


def _run(coro: Any, timeout: float = 60.0) -> Any:
    async def bounded() -> Any:
        async with asyncio.timeout(timeout):
            return await coro

    return asyncio.run(bounded())


async def _until(cond: Any, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > deadline:
            raise AssertionError(f"not within {timeout} s: {what}")
        await asyncio.sleep(0.02)


async def _scenario(gen: Any) -> dict[str, Any]:
    import uavcan.node

    from sam_runtime.cyphal_io.transport import aclose, make_node

    tables = gen.tables()
    nid = next(d.node_id for d in tables.DEVICES if d.name == DEVICE)
    sim = Simulator(gen, SimConfig("udp", "127.0.0.1", devices=[DEVICE]))
    client = make_node("org.test.restarter", tables.BRIDGE_NODE_ID, "udp", iface="127.0.0.1")
    beats: list[tuple[float, int]] = []  # (received, uptime) of the device's heartbeats
    out: dict[str, Any] = {"info": {"answered": 0, "unanswered": 0}}
    stop = asyncio.Event()
    hb = client.make_subscriber(uavcan.node.Heartbeat_1_0)
    execute = uavcan.node.ExecuteCommand_1_1
    cmd = client.make_client(execute, nid)
    info = client.make_client(uavcan.node.GetInfo_1_0, nid)
    info.response_timeout = 0.3
    poller = None
    try:
        await sim.start()
        hb.receive_in_background(lambda msg, tr: beats.append((time.monotonic(), int(msg.uptime)))
                                 if tr.source_node_id == nid else None)

        async def poll_info() -> None:  # GetInfo all along: responses in flight when the node closes
            while not stop.is_set():
                got = await info.call(uavcan.node.GetInfo_1_0.Request())
                out["info"]["answered" if got is not None else "unanswered"] += 1
                await asyncio.sleep(0.005)

        poller = asyncio.create_task(poll_info())
        await _until(lambda: beats and beats[-1][1] >= 2, 15, "the device up 2 s")
        bad = await cmd.call(execute.Request(command=execute.Request.COMMAND_POWER_OFF))
        out["bad_command"] = None if bad is None else int(bad[0].status)
        ok = await cmd.call(execute.Request(command=execute.Request.COMMAND_RESTART))
        out["restart"] = None if ok is None else int(ok[0].status)
        t_restart, before = time.monotonic(), beats[-1][1]
        # the client's pycyphal too drops the new node's first heartbeats within its transfer-id timeout (2 s)
        await _until(lambda: any(t > t_restart and up < before for t, up in beats), 15, "a heartbeat with uptime down")
        last_old = max(t for t, up in beats if t <= t_restart or up >= before)
        out["silent_s"] = min(t for t, up in beats if t > last_old) - last_old
        out["power_cycles"] = sim.report()["devices"][DEVICE]["power_cycles"]
        answered = out["info"]["answered"]
        await _until(lambda: out["info"]["answered"] > answered, 10, "GetInfo answered after the reboot")

        # a power cycle: the same reboot (the heartbeat lost for longer than the offline timeout)
        await sim.power_off(DEVICE)
        n_beats = len(beats)
        await asyncio.sleep(3.5)  # the fault's duration (a device off), no verdict on timing
        out["beats_while_off"] = len(beats) - n_beats
        await sim.power_on(DEVICE)
        t_on = time.monotonic()
        await _until(lambda: any(t > t_on for t, _ in beats), 10, "a heartbeat after the power cycle")
        out["uptime_after_power_on"] = next(up for t, up in beats if t > t_on)
        out["power_cycles_after"] = sim.report()["devices"][DEVICE]["power_cycles"]
    finally:
        stop.set()
        if poller is not None:
            await asyncio.gather(poller, return_exceptions=True)
        await sim.close()
        await aclose(hb, cmd, info, client)
    return out


@pytest.mark.slow
def test_a_restart_reboots_the_device_quietly(caplog: pytest.LogCaptureFixture) -> None:
    gen = generated_or_skip()
    if gen.tables().VEHICLE != "sam":
        pytest.skip("SAM's devices")
    caplog.set_level(logging.INFO)
    gen.compile_dsdl()  # the types on the path before _scenario imports them (CI ran this test first in its worker)
    with cyphal_udp_lock():
        out = _run(_scenario(gen))
    execute_status = {"success": 0, "bad_command": 3}
    assert out["bad_command"] == execute_status["bad_command"] and out["restart"] == execute_status["success"], out
    assert out["silent_s"] >= SimConfig().reboot_s, out  # a lower bound: a loaded machine only adds to it
    assert out["power_cycles"] == 1 and out["power_cycles_after"] == 2, out
    assert out["beats_while_off"] == 0 and out["uptime_after_power_on"] <= 1, out
    assert out["info"]["answered"] >= 10, out
    problems = [r for r in caplog.records if r.levelno >= logging.ERROR or r.exc_info]
    assert problems == [], [f"{r.name}: {r.getMessage()}" for r in problems]
    assert any("restart requested by node" in r.getMessage() for r in caplog.records)


async def _close_during_a_response(gen: Any) -> dict[str, Any]:
    """A GetInfo response whose send resumes just as the node closes (released as its ``close()`` begins)."""
    import uavcan.node

    from sam_runtime.cyphal_io.transport import aclose, make_node

    tables = gen.tables()
    nid = next(d.node_id for d in tables.DEVICES if d.name == DEVICE)
    loop = asyncio.get_running_loop()
    original = loop.sock_sendall
    entered, closing = asyncio.Event(), asyncio.Event()

    async def sendall(sock: Any, data: bytes) -> None:
        if not closing.is_set() and f"sim.{DEVICE}".encode() in data:  # the device's GetInfo response
            entered.set()
            await closing.wait()
        return await original(sock, data)

    sim = Simulator(gen, SimConfig("udp", "127.0.0.1", devices=[DEVICE]))
    client = make_node("org.test.restarter", tables.BRIDGE_NODE_ID, "udp", iface="127.0.0.1")
    info = client.make_client(uavcan.node.GetInfo_1_0, nid)
    info.response_timeout = 1.0
    out: dict[str, Any] = {}
    try:
        await sim.start()
        node = sim.device(DEVICE).node
        close = node.close

        def closing_then_close() -> None:  # the held send is ready to run before the close cancels anything
            closing.set()
            close()

        node.close = closing_then_close
        loop.sock_sendall = sendall  # type: ignore[method-assign]
        call = asyncio.create_task(info.call(uavcan.node.GetInfo_1_0.Request()))
        await asyncio.wait_for(entered.wait(), 10)
        await sim.power_off(DEVICE)  # the response is being sent
        out["closing_seen"] = closing.is_set()
        out["response"] = await call
        await sim.power_on(DEVICE)
        got = await info.call(uavcan.node.GetInfo_1_0.Request())
        out["after_power_on"] = None if got is None else bytes(got[0].name.tobytes()).decode()
    finally:
        loop.sock_sendall = original  # type: ignore[method-assign]
        await sim.close()
        await aclose(info, client)
    return out


def test_closing_while_a_response_is_sent_logs_no_traceback(caplog: pytest.LogCaptureFixture) -> None:
    gen = generated_or_skip()
    if gen.tables().VEHICLE != "sam":
        pytest.skip("SAM's devices")
    caplog.set_level(logging.INFO)
    gen.compile_dsdl()  # as above: each test puts the types on the path itself
    with cyphal_udp_lock():
        out = _run(_close_during_a_response(gen))
    assert out["closing_seen"] and out["response"] is None, out  # unanswered: the device went off
    assert out["after_power_on"] == f"org.{gen.tables().VEHICLE}.sim.{DEVICE}", out
    problems = [r for r in caplog.records if r.levelno >= logging.ERROR or r.exc_info]
    assert problems == [], [f"{r.name}: {r.getMessage()}" for r in problems]
