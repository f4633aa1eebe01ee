"""One board setting read or written over the bus, per protocol: Cyphal's uavcan.register.Access (the response
carries the value the board holds after the write) and DroneCAN's uavcan.protocol.param.GetSet (likewise). Both
run in the bridge's asyncio loop thread (which owns the protocol's node) and raise :class:`ParamIOError` with the
reason a ROS parameter set reports: the link down, no answer within the timeout, no such setting on the board.

A store (``store``) asks the board to save its current values, which its next reboot loads: Cyphal's
uavcan.node.ExecuteCommand.1.1 COMMAND_STORE_PERSISTENT_STATES (status SUCCESS, anything else is a refusal named by
its status), DroneCAN's uavcan.protocol.param.ExecuteOpcode OPCODE_SAVE (``ok``)."""

from __future__ import annotations

import asyncio
from typing import Any, Protocol

from sam_runtime.common.board_settings import Stored
from sam_runtime.cyphal_io.registers import register_stored, register_value
from sam_runtime.dronecan_io.params import OPCODE_SAVE, fill_value, read_value

__all__ = ["COMMAND_STORE_PERSISTENT_STATES", "CyphalParamAccess", "DroneCanParamAccess", "ParamAccess", "ParamIOError"]

COMMAND_STORE_PERSISTENT_STATES = 65530  # uavcan.node.ExecuteCommand.1.1's standard command
# ExecuteCommand.1.1's statuses by value, to name a refusal
_CYPHAL_STATUS = {1: "FAILURE", 2: "NOT_AUTHORIZED", 3: "BAD_COMMAND", 4: "BAD_PARAMETER", 5: "BAD_STATE",
                  6: "INTERNAL_ERROR"}


class ParamIOError(Exception):
    """A read or write that did not complete: the reason, for the caller."""


class ParamAccess(Protocol):
    async def __call__(self, nid: int, name: str, kind: str, value: Stored | None, timeout: float) -> Stored:
        """The board's value of setting `name` (its name on the protocol) after writing `value` (None: a read)."""

    async def store(self, nid: int, timeout: float) -> None:
        """Ask board `nid` to save its current values; returns on its OK, raises ParamIOError otherwise."""


class CyphalParamAccess:
    def __init__(self, backend: Any) -> None:
        self.backend = backend

    async def __call__(self, nid: int, name: str, kind: str, value: Stored | None, timeout: float) -> Stored:
        import uavcan.register

        node = self.backend.node
        if node is None:
            raise ParamIOError("the Cyphal link is down")
        request = uavcan.register.Access_1_0.Request(name=uavcan.register.Name_1_0(name))
        if value is not None:
            request.value = register_value(kind, value)
        client = node.presentation.make_client_with_fixed_service_id(uavcan.register.Access_1_0, nid)
        try:
            client.response_timeout = timeout
            result = await client.call(request)
        finally:
            client.close()
        if result is None:
            raise ParamIOError(f"node {nid} did not answer within {timeout:g} s")
        response, _meta = result
        stored = register_stored(kind, response.value)
        if stored is None:
            raise ParamIOError(f"node {nid} has no {kind} register {name!r}")
        return stored

    async def store(self, nid: int, timeout: float) -> None:
        import uavcan.node

        node = self.backend.node
        if node is None:
            raise ParamIOError("the Cyphal link is down")
        execute = uavcan.node.ExecuteCommand_1_1
        client = node.presentation.make_client_with_fixed_service_id(execute, nid)
        try:
            client.response_timeout = timeout
            result = await client.call(execute.Request(command=COMMAND_STORE_PERSISTENT_STATES))
        finally:
            client.close()
        if result is None:
            raise ParamIOError(f"node {nid} did not answer within {timeout:g} s")
        status = int(result[0].status)
        if status != execute.Response.STATUS_SUCCESS:
            raise ParamIOError(f"node {nid} refused to store its settings: status {status} "
                               f"({_CYPHAL_STATUS.get(status, 'unknown')})")


class DroneCanParamAccess:
    def __init__(self, backend: Any) -> None:
        self.backend = backend

    async def __call__(self, nid: int, name: str, kind: str, value: Stored | None, timeout: float) -> Stored:
        import dronecan

        node = self.backend.node
        if node is None:
            raise ParamIOError("the DroneCAN link is down")
        done: asyncio.Future[Any] = asyncio.get_running_loop().create_future()
        request = dronecan.TYPENAMES["uavcan.protocol.param.GetSet"].Request(name=name)
        fill_value(request.value, kind, value)
        node.request(request, nid, lambda event: None if done.done() else done.set_result(event), timeout=timeout)
        node_loop = getattr(self.backend, "node_loop", None)
        if node_loop is not None:  # the timeout is on dronecan's scheduler: the NodeLoop re-arms its timer
            node_loop.wake()
        event = await done
        if event is None:
            raise ParamIOError(f"node {nid} did not answer within {timeout:g} s")
        response = event.response
        if bytes(response.name).decode("utf-8", "replace") != name:
            raise ParamIOError(f"node {nid} has no parameter {name!r}")
        stored = read_value(response.value, kind)
        if stored is None:
            raise ParamIOError(f"node {nid} holds {name!r} as another type than {kind}")
        return stored

    async def store(self, nid: int, timeout: float) -> None:
        import dronecan

        node = self.backend.node
        if node is None:
            raise ParamIOError("the DroneCAN link is down")
        done: asyncio.Future[Any] = asyncio.get_running_loop().create_future()
        request = dronecan.TYPENAMES["uavcan.protocol.param.ExecuteOpcode"].Request(opcode=OPCODE_SAVE)
        node.request(request, nid, lambda event: None if done.done() else done.set_result(event), timeout=timeout)
        node_loop = getattr(self.backend, "node_loop", None)
        if node_loop is not None:  # (as above: the NodeLoop re-arms its timer for the timeout)
            node_loop.wake()
        event = await done
        if event is None:
            raise ParamIOError(f"node {nid} did not answer within {timeout:g} s")
        if not event.response.ok:
            raise ParamIOError(f"node {nid} refused to store its settings (ExecuteOpcode SAVE answered ok=false)")
