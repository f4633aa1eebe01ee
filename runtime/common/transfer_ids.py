"""How far a source's transfer id may plausibly advance in a given time (issue 29: a transfer-id jump).

Cyphal and DroneCAN number a source's transfers of a port one by one, so a gap in the ids is transfers lost on the
way, but only as many as the source can have sent since its previous transfer. A gap beyond that is no loss: the
source restarted with another counter, or someone else sends with its node id. Counting it as ``lost`` would let one
frame add 2**40 to a loss counter, and adopting it as the expected id would refuse the real device's next transfers
for the transfer-id timeout. The bound: :data:`JUMP_SLACK` transfers plus :data:`MAX_PLAUSIBLE_RATE_HZ` times the
elapsed time (ten times the fastest nominal rate of the SAM spec, 100 Hz; far above what either bus carries per
port).

>>> plausible_gap(0.0), plausible_gap(0.01), plausible_gap(2.0)
(64, 74, 2064)
"""

from __future__ import annotations

__all__ = ["JUMP_SLACK", "MAX_PLAUSIBLE_RATE_HZ", "plausible_gap"]

MAX_PLAUSIBLE_RATE_HZ = 1000.0
# Transfers a gap may hold whatever the time: a burst of a source whose earlier transfers were read late.
JUMP_SLACK = 64


def plausible_gap(elapsed_s: float) -> int:
    """The largest plausible advance of a transfer id ``elapsed_s`` seconds after the previous one (in ids)."""
    return JUMP_SLACK + int(MAX_PLAUSIBLE_RATE_HZ * max(elapsed_s, 0.0))
