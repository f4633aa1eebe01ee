"""sam_runtime.dronecan_io.types at run time: what dronecan decodes a data type id as is the spec's choice
(`dronecan_namespaces`, its own types). In a child process (``dronecan.DATATYPES`` is the process's):

- tests/specs/trawler_v0.yaml ([uavcan, ardupilot]; trawler.io.Switch at 20100): 20100 decodes as the Switch, an
  ardupilot type still decodes, a type of com.xacti or dronecan.remoteid is an unknown data type (what the NodeLoop
  counts as ``unknown_data_type``);
- then SAM's package (no dronecan_namespaces: every namespace) in the same process: dronecan's own types are back,
  20100 is com.hobbywing.esc.RawCommand again, the trawler's Switch still known by name.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytest.importorskip("dronecan")

from helpers.runtime_support import REPO
from helpers.spec_build import generated_spec

CHILD = r'''
import json, sys
import dronecan
from dronecan import transport
from sam_runtime.dronecan_io.types import ensure_types
from sam_runtime.genpkg import GeneratedPackage

def decodes(dtid):
    t = dronecan.DATATYPES.get((dtid, 1))
    return None if t is None else t.full_name

def transfer_error(msg):
    frames = transport.Transfer(payload=msg, source_node_id=30, transfer_id=0).to_frames()
    try:
        transport.Transfer().from_frames(frames)
    except transport.TransferError as ex:
        return str(ex)
    return None

out = {"before": decodes(20100)}
ensure_types(GeneratedPackage(sys.argv[1]))
xacti = dronecan.TYPENAMES["com.xacti.GnssStatus"]()
out["trawler"] = {"20100": decodes(20100), "20000": decodes(20000), "20030": decodes(20030),
                  "20305": decodes(20305), "1003": decodes(1003), "xacti_error": transfer_error(xacti)}
switch = dronecan.TYPENAMES["trawler.io.Switch"](switch_id=1, level=513, flags=3)
got = transport.Transfer()
got.from_frames(transport.Transfer(payload=switch, source_node_id=30, transfer_id=0).to_frames())
out["decoded"] = [dronecan.get_dronecan_data_type(got.payload).full_name, int(got.payload.level)]
ensure_types(GeneratedPackage(sys.argv[2]))
out["sam"] = {"20100": decodes(20100), "20305": decodes(20305), "20102": decodes(20102),
              "switch_known": "trawler.io.Switch" in dronecan.TYPENAMES}
print(json.dumps(out))
'''


@pytest.mark.system  # starts a process: not in the unit tier
def test_data_type_ids_decode_as_the_spec_chooses() -> None:
    trawler = generated_spec("trawler_v0")
    proc = subprocess.run([sys.executable, "-c", CHILD, str(trawler), str(REPO / "generated")],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.splitlines()[-1])
    assert out["before"] == "com.hobbywing.esc.RawCommand"  # dronecan's import loads every namespace
    assert out["trawler"] == {"20100": "trawler.io.Switch", "20000": "ardupilot.indication.SafetyState",
                              "20030": None, "20305": None, "1003": "uavcan.equipment.ahrs.RawIMU",
                              "xacti_error": "Unrecognised message type ID 20305"}
    assert out["decoded"] == ["trawler.io.Switch", 513]
    assert out["sam"] == {"20100": "com.hobbywing.esc.RawCommand", "20305": "com.xacti.GnssStatus",
                          "20102": "sam.actuator.PositionFeedback", "switch_known": True}

