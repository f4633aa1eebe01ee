"""The `bus:` key, at the top level of a spec or in a layout: the CAN bus the build's bus budget judges.

    bus: {bitrate: 1000000, fd_data_bitrate: 4000000, load_warning_percent: 70}
    bus: none    # no CAN bus (Cyphal/UDP only): no budget

Invariants: every key is optional (classic CAN at 1 Mbit/s, warning at 70 %); a bit rate is an integer in bit/s, the
nominal one at most 1 Mbit/s (classic CAN, and CAN FD's arbitration phase), the data phase's at least that and at most
12 Mbit/s; the warning threshold is a percentage in (0, 100]. Values out of range are spec errors at their key.
"""

from __future__ import annotations

from sam_codegen.frontend.reading import Reader, kind_of
from sam_codegen.frontend.yaml_source import YNode, YScalar
from sam_codegen.model.diagnostics import Diagnostics
from sam_codegen.model.spec import CanBus

__all__ = ["BUS_KEYS", "parse_bus"]

BUS_KEYS = ("bitrate", "fd_data_bitrate", "load_warning_percent")
BITRATES = (10_000, 1_000_000)
FD_DATA_BITRATE_MAX = 12_000_000


def parse_bus(node: YNode | None, what: str, diag: Diagnostics) -> CanBus | None:
    """The bus of ``node`` (None when the key is absent or wrong; the errors are in ``diag``)."""
    if node is None:
        return None
    if isinstance(node, YScalar):
        if node.value == "none":
            return CanBus(present=False, pos=node.pos)
        diag.error(node.pos, f"{what} must be a mapping or none, found {kind_of(node)}",
                   "{bitrate: ..., fd_data_bitrate: ..., load_warning_percent: ...} or none")
        return None
    r = Reader(node, what, diag, BUS_KEYS)
    if not r.ok:
        return None
    errors = len(diag.items)
    bitrate = r.get("bitrate", int, BITRATES[1])
    data = r.get("fd_data_bitrate", int, None)
    warning = r.get("load_warning_percent", (int, float), 70.0)
    if bitrate is not None and not BITRATES[0] <= bitrate <= BITRATES[1]:
        diag.error(r.key_pos("bitrate"), f"bitrate {bitrate} of {what} is out of range",
                   f"{BITRATES[0]}..{BITRATES[1]} bit/s (classic CAN, or CAN FD's arbitration phase)")
    if data is not None and bitrate is not None and not bitrate <= data <= FD_DATA_BITRATE_MAX:
        diag.error(r.key_pos("fd_data_bitrate"), f"fd_data_bitrate {data} of {what} is out of range",
                   f"{bitrate}..{FD_DATA_BITRATE_MAX} bit/s (at least the bitrate)")
    if warning is not None and not 0 < warning <= 100:
        diag.error(r.key_pos("load_warning_percent"), f"load_warning_percent {warning} of {what} is out of range",
                   "a percentage above 0, at most 100")
    if len(diag.items) > errors or bitrate is None or warning is None:
        return None
    return CanBus(bitrate, data, float(warning), True, r.pos)
