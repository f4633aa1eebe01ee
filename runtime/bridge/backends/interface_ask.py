"""Each protocol's request for a board's interface version (sam_runtime.bridge.interface_check's ``Ask``), on the
loop's thread: Cyphal ``uavcan.node.GetInfo.1.0`` (``software_vcs_revision_id``), DroneCAN
``uavcan.protocol.GetNodeInfo`` (``software_version.image_crc`` when ``optional_field_flags`` has
OPTIONAL_FIELD_FLAG_IMAGE_CRC; else 0, "reports none"). One request per first contact or restart: no per-message
cost."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any

from sam_runtime.bridge.interface_check import Ask

__all__ = ["ASK_TIMEOUT_S", "cyphal_ask", "dronecan_ask"]

ASK_TIMEOUT_S = 1.0  # the GetInfo / GetNodeInfo timeout (a board answers within milliseconds)

Done = Callable[[int | None, str], None]


def cyphal_ask(backend: Any, timeout_s: float = ASK_TIMEOUT_S) -> Ask:
    tasks: set[asyncio.Task[None]] = set()

    def ask(nid: int, done: Done) -> None:
        node = backend.node
        if node is None:
            done(None, "the Cyphal link is down")
            return
        import uavcan.node

        client = node.presentation.make_client_with_fixed_service_id(uavcan.node.GetInfo_1_0, nid)
        client.response_timeout = timeout_s

        async def call() -> None:
            try:
                result = await client.call(uavcan.node.GetInfo_1_0.Request())
            except Exception as ex:  # the transport closed under it
                done(None, f"the request was not sent: {type(ex).__name__}: {ex}")
                return
            finally:
                client.close()
            if result is None:
                done(None, f"no answer within {timeout_s:g} s")
            else:
                done(int(result[0].software_vcs_revision_id), "")

        task = asyncio.get_running_loop().create_task(call())
        tasks.add(task)
        task.add_done_callback(tasks.discard)

    return ask


def dronecan_ask(backend: Any, timeout_s: float = ASK_TIMEOUT_S) -> Ask:
    def ask(nid: int, done: Done) -> None:
        import dronecan

        node = backend.node
        if node is None:
            done(None, "the DroneCAN link is down")
            return

        def on_response(event: Any) -> None:
            if event is None:
                done(None, f"no answer within {timeout_s:g} s")
                return
            version = event.response.software_version
            has_crc = version.optional_field_flags & version.OPTIONAL_FIELD_FLAG_IMAGE_CRC
            done(int(version.image_crc) if has_crc else 0, "")

        node.request(dronecan.uavcan.protocol.GetNodeInfo.Request(), nid, on_response, timeout=timeout_s)
        node_loop = getattr(backend, "node_loop", None)
        if node_loop is not None:  # the timeout is on dronecan's scheduler: the NodeLoop re-arms its timer
            node_loop.wake()

    return ask
