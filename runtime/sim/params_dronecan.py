"""A simulated DroneCAN board's settings on the bus, as AP_Periph-style firmware serves them:
uavcan.protocol.param.GetSet by index (spec order) or by name, with the value, default, min and max in the
response; a write the board refuses (a bad type, out of range) leaves the value as it was, which the response shows;
ExecuteOpcode SAVE stores the values (a reboot loads them), ERASE forgets them (a reboot loads the defaults)."""

from __future__ import annotations

import logging
from typing import Any

from sam_runtime.common.board_settings import BoardSettings
from sam_runtime.dronecan_io.params import OPCODE_ERASE, OPCODE_SAVE, fill_value, read_value

__all__ = ["PARAM_GETSET", "PARAM_OPCODE", "param_getset_handler", "param_opcode_handler"]

PARAM_GETSET = "uavcan.protocol.param.GetSet"
PARAM_OPCODE = "uavcan.protocol.param.ExecuteOpcode"

_log = logging.getLogger("sam_runtime.sim.simulator")


def param_getset_handler(device: str, board: BoardSettings) -> Any:
    import dronecan

    getset = dronecan.TYPENAMES[PARAM_GETSET]
    names = list(board.params)

    def on_getset(event: Any) -> Any:
        req = event.request
        name = bytes(req.name).decode("utf-8", "replace")
        if not name:
            index = int(req.index)
            name = names[index] if index < len(names) else ""
        p = board.params.get(name)
        if p is None:  # no such parameter: an empty response (empty name)
            return getset.Response()
        new = read_value(req.value, p.type)
        if new is not None:
            problem = board.write(name, new)
            if problem is not None:
                _log.info("%s: param %s: write refused: %s", device, name, problem)
        elif dronecan.get_active_union_field(req.value) not in (None, "empty"):
            board.refused += 1
            _log.info("%s: param %s: write refused: not a %s", device, name, p.type)
        resp = getset.Response()
        resp.name = name
        fill_value(resp.value, p.type, board.values[name])
        fill_value(resp.default_value, p.type, board.defaults[name])
        if p.type in ("integer", "real"):
            fill_value(resp.min_value, p.type, p.minimum)
            fill_value(resp.max_value, p.type, p.maximum)
        return resp

    return on_getset


def param_opcode_handler(device: str, board: BoardSettings) -> Any:
    import dronecan

    opcode = dronecan.TYPENAMES[PARAM_OPCODE]

    def on_opcode(event: Any) -> Any:
        op = int(event.request.opcode)
        if op == OPCODE_SAVE:
            board.save()
        elif op == OPCODE_ERASE:
            board.erase()
        _log.info("%s: ExecuteOpcode %d from node %s", device, op, event.transfer.source_node_id)
        return opcode.Response(ok=op in (OPCODE_SAVE, OPCODE_ERASE))

    return on_opcode
