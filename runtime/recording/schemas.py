"""What a recording stores besides the bytes: the ROS message definitions (ros2msg, concatenated as rosbag2 writes
them), the envelope of one raw UAVCAN transfer (a ROS message of its own, so that the whole file stays a ROS 2
MCAP every rosbag2 reader takes), and the DSDL / UAVCAN v0 definitions the transfers' payloads decode with.

Invariants:

- A ROS schema is named like the topic type (``sensor_msgs/msg/Imu``) with encoding ``ros2msg``; its data is the
  type's .msg text followed, for every message type it uses (depth first, each once), by a line of 80 ``=``, a line
  ``MSG: pkg/Type`` and that type's .msg text: what rosbag2's local message definition source writes.
- The envelope (:data:`TRANSFER_MSG`, :func:`encode_transfer` / :func:`decode_transfer`) is plain little-endian CDR
  of :data:`TRANSFER_TYPE`; encode and decode are exact inverses.
- Definition files are attached under ``dsdl/<root namespace>/...`` (Cyphal v1, ``*.dsdl``) and
  ``dsdl_v0/<namespace path>/<id>.<Name>.uavcan`` (DroneCAN): a folder laid out from the attachments is what
  pydsdl / nunavut and ``dronecan.load_dsdl`` read.
"""

from __future__ import annotations

import re
import struct
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "CYPHAL_TOPIC",
    "DRONECAN_TOPIC",
    "HEARTBEAT_SUBJECT",
    "HEARTBEAT_TYPE",
    "KIND_MESSAGE",
    "KIND_REQUEST",
    "KIND_RESPONSE",
    "ROS_LOST_METADATA",
    "TRANSFER_MSG",
    "TRANSFER_TYPE",
    "MessageDefinitionError",
    "Transfer",
    "cyphal_definition_files",
    "decode_transfer",
    "dronecan_definition_files",
    "encode_transfer",
    "qos_yaml",
    "ros2msg_definition",
]

TRANSFER_TYPE = "sam_recording/msg/UavcanTransfer"
CYPHAL_TOPIC = "/uavcan/cyphal/transfers"
DRONECAN_TOPIC = "/uavcan/dronecan/transfers"
HEARTBEAT_SUBJECT = 7509
HEARTBEAT_TYPE = "uavcan.node.Heartbeat.1.0"
KIND_MESSAGE, KIND_REQUEST, KIND_RESPONSE = 0, 1, 2
# The recording's metadata record of the ROS messages the recorder knows it did not get, per topic: the gaps in the
# publisher's sequence numbers of a topic with one publisher (a best-effort subscription loses messages silently on
# a loaded machine). Written when the recorder closes; replay counts that many replayed messages as the recording's
# loss, not as a difference.
ROS_LOST_METADATA = "sam_recording.ros_lost"

TRANSFER_MSG = """\
# One UAVCAN transfer as a sniffer on the bus received it (sam-codegen record).
uint8 KIND_MESSAGE=0
uint8 KIND_REQUEST=1
uint8 KIND_RESPONSE=2
int64 timestamp_ns           # system clock [ns] when the recorder received the transfer
uint64 transfer_id
uint64 data_type_signature   # DroneCAN: the data type signature (seeds the CRC); 0 on Cyphal
uint16 port_id               # Cyphal: subject or service id; DroneCAN: data type id
int16 source_node_id         # -1: anonymous
int16 destination_node_id    # -1: none (a message)
uint8 priority               # Cyphal 0 (exceptional) .. 7 (optional); DroneCAN 0 .. 31
uint8 kind                   # KIND_*
string protocol              # cyphal | dronecan
string data_type             # Cyphal: full name and version (sam.sensor.RawIMU.0.1); DroneCAN: full name; "" unknown
uint8[] payload              # the transfer's payload (DroneCAN: without tail bytes and transfer CRC)
"""

_FIXED = struct.Struct("<qQQHhhBB")
_U32 = struct.Struct("<I")
_CDR_HEADER = b"\x00\x01\x00\x00"


@dataclass(frozen=True)
class Transfer:
    """One recorded UAVCAN transfer (the envelope's fields)."""

    protocol: str
    port_id: int
    data_type: str
    source_node_id: int | None
    transfer_id: int
    priority: int
    timestamp_ns: int
    payload: bytes
    kind: int = KIND_MESSAGE
    destination_node_id: int | None = None
    data_type_signature: int = 0


def _cdr_string(out: bytearray, text: str) -> None:
    raw = text.encode() + b"\x00"
    out += b"\x00" * (-(len(out) - 4) % 4)  # CDR aligns to the field's size from after the encapsulation header
    out += _U32.pack(len(raw)) + raw


def encode_transfer(t: Transfer) -> bytes:
    """The envelope as CDR (encapsulation header included).

    >>> t = Transfer("cyphal", 1100, "sam.sensor.RawIMU.0.1", 11, 7, 4, 123, b"\\x01\\x02")
    >>> decode_transfer(encode_transfer(t)) == t
    True
    """
    out = bytearray(_CDR_HEADER)
    out += _FIXED.pack(t.timestamp_ns, t.transfer_id, t.data_type_signature, t.port_id,
                       -1 if t.source_node_id is None else t.source_node_id,
                       -1 if t.destination_node_id is None else t.destination_node_id, t.priority, t.kind)
    _cdr_string(out, t.protocol)
    _cdr_string(out, t.data_type)
    out += b"\x00" * (-(len(out) - 4) % 4)
    out += _U32.pack(len(t.payload)) + t.payload
    return bytes(out)


def decode_transfer(data: bytes | memoryview) -> Transfer:
    """The envelope from its CDR (ValueError when it is not one)."""
    data = bytes(data)
    if data[:2] != b"\x00\x01":
        raise ValueError("not little-endian plain CDR")
    try:
        ts, tid, sig, port, src, dst, prio, kind = _FIXED.unpack_from(data, 4)
        pos = 4 + _FIXED.size
        texts = []
        for _ in range(2):
            pos += -(pos - 4) % 4
            (n,) = _U32.unpack_from(data, pos)
            texts.append(data[pos + 4:pos + 4 + n - 1].decode())
            pos += 4 + n
        pos += -(pos - 4) % 4
        (n,) = _U32.unpack_from(data, pos)
        payload = data[pos + 4:pos + 4 + n]
    except (struct.error, UnicodeDecodeError) as ex:
        raise ValueError(f"not a {TRANSFER_TYPE}: {ex}") from None
    if len(payload) != n:
        raise ValueError(f"not a {TRANSFER_TYPE}: the payload is cut")
    return Transfer(texts[0], port, texts[1], None if src < 0 else src, tid, prio, ts, payload, kind,
                    None if dst < 0 else dst, sig)


# ============================================================================================ ROS definitions
class MessageDefinitionError(LookupError):
    """A .msg file of a recorded type (or of one it uses) is not installed."""


_BUILTINS = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
             "int64", "uint64", "string", "wstring"}
_FIELD = re.compile(r"^\s*([A-Za-z_][\w/]*)")


def _msg_path(share_dirs: Sequence[Path], package: str, name: str) -> Path:
    for share in share_dirs:
        path = share / package / "msg" / f"{name}.msg"
        if path.is_file():
            return path
    raise MessageDefinitionError(f"no {package}/msg/{name}.msg under {', '.join(map(str, share_dirs))}")


def _dependencies(text: str, package: str) -> list[str]:
    """The message types a .msg text uses, as pkg/Type, in order of appearance."""
    out: list[str] = []
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        m = _FIELD.match(line)
        if m is None:
            continue
        base = re.split(r"[\[<]", m.group(1))[0]
        if base in _BUILTINS:  # constants are of builtin types too
            continue
        full = base if "/" in base else f"{package}/{base}"
        if full.count("/") == 2:  # pkg/msg/Type
            p, _, t = full.split("/")
            full = f"{p}/{t}"
        if full not in out:
            out.append(full)
    return out


def ros2msg_definition(ros_type: str, share_dirs: Sequence[Path]) -> str:
    """The concatenated definition of ``ros_type`` (``pkg/msg/Type``) as rosbag2 stores it in an MCAP schema."""
    package, _, name = ros_type.split("/")
    top = _msg_path(share_dirs, package, name).read_text()
    parts = [top]
    seen: set[str] = set()

    def visit(text: str, pkg: str) -> None:
        for dep in _dependencies(text, pkg):
            if dep in seen:
                continue
            seen.add(dep)
            dep_pkg, dep_name = dep.split("/")
            dep_text = _msg_path(share_dirs, dep_pkg, dep_name).read_text()
            parts.append("=" * 80 + f"\nMSG: {dep}\n" + dep_text)
            visit(dep_text, dep_pkg)

    visit(top, package)
    return "\n".join(p.rstrip("\n") for p in parts) + "\n"


def qos_yaml(reliability: str, durability: str, depth: int) -> str:
    """rosbag2's ``offered_qos_profiles`` channel metadata (its metadata version 9) for one publisher's QoS."""
    infinite = "\n    sec: 9223372036\n    nsec: 854775807\n"
    return (f"- history: keep_last\n  depth: {depth}\n  reliability: {reliability}\n  durability: {durability}\n"
            f"  deadline:{infinite}  lifespan:{infinite}  liveliness: automatic\n"
            f"  liveliness_lease_duration:{infinite}  avoid_ros_namespace_conventions: false\n")


# ============================================================================================ UAVCAN definitions
def cyphal_definition_files(namespace_dirs: Sequence[Path], lookup_dirs: Sequence[Path],
                            extra_types: Iterable[str] = (HEARTBEAT_TYPE,)) -> dict[str, bytes]:
    """Attachment name -> content: every .dsdl file of ``namespace_dirs`` and every definition they or
    ``extra_types`` (full names with version) use from ``lookup_dirs`` (the standard ``uavcan`` namespace)."""
    import pydsdl

    files: dict[str, bytes] = {}
    roots = [Path(d) for d in namespace_dirs]
    lookups = [Path(d) for d in lookup_dirs]
    types: list[Any] = []
    for root in roots:
        types += pydsdl.read_namespace(str(root), [str(d) for d in lookups if d.name != root.name])
    for full in extra_types:
        *ns, short, major, minor = full.split(".")
        lookup = next((d for d in lookups if d.name == ns[0]), None)
        if lookup is None:
            continue
        folder = lookup.joinpath(*ns[1:])
        # a type with a fixed port id is named <id>.<Name>.<major>.<minor>.dsdl
        leaf = f"{short}.{major}.{minor}.dsdl"
        found = sorted(folder.glob(leaf)) + sorted(folder.glob(f"*.{leaf}"))
        for path in found[:1]:
            got, deps = pydsdl.read_files([str(path)], [str(lookup)], [str(d) for d in lookups])
            types += [*got, *deps]
    queue = list(types)
    seen: set[str] = set()
    while queue:
        t = queue.pop()
        source = getattr(t, "source_file_path", None)
        if source is None or str(source) in seen:
            continue
        seen.add(str(source))
        home = next((r for r in [*roots, *lookups] if Path(source).is_relative_to(r)), None)
        if home is not None:
            files[f"dsdl/{home.name}/{Path(source).relative_to(home).as_posix()}"] = Path(source).read_bytes()
        for f in getattr(t, "fields_except_padding", ()):
            inner = f.data_type
            while hasattr(inner, "element_type"):
                inner = inner.element_type
            if hasattr(inner, "source_file_path"):
                queue.append(inner)
    return dict(sorted(files.items()))


def dronecan_definition_files(dtypes: Iterable[Any]) -> dict[str, bytes]:
    """Attachment name -> content: the .uavcan files of these dronecan types and of every type they nest."""
    files: dict[str, bytes] = {}
    queue = list(dtypes)
    seen: set[str] = set()
    while queue:
        t = queue.pop()
        source = getattr(t, "source_file", None)
        if not source or source in seen:
            continue
        seen.add(source)
        ns = t.full_name.split(".")[:-1]
        files["dsdl_v0/" + "/".join([*ns, Path(source).name])] = Path(source).read_bytes()
        for group in (getattr(t, "fields", None) or [], getattr(t, "request_fields", None) or [],
                      getattr(t, "response_fields", None) or []):
            for f in group:
                inner = f.type
                while getattr(inner, "value_type", None) is not None:
                    inner = inner.value_type
                if getattr(inner, "source_file", None):
                    queue.append(inner)
    return dict(sorted(files.items()))
