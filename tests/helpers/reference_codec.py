"""Wire codecs built from the object path: the protocol library's deserializer, the generated object converter and
rclpy's serializer, composed behind the generated codecs' API (``CODECS``, ``WIRE_MATCHES``).

They are slow and obviously right, so they test the bridge's wire path (raw ports, raw ROS endpoints, counters)
apart from the generated codecs, and give a reference to compare those with.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any


class ReferenceWireError(ValueError):
    """The protocol library refused the payload."""


def _header(msg: Any, frame_id: str | None, receive_ns: int) -> int:
    hdr = getattr(msg, "header", None)
    if hdr is None:
        return -1
    if not hdr.frame_id and frame_id:
        hdr.frame_id = frame_id
    if hdr.stamp.sec == 0 and hdr.stamp.nanosec == 0:
        hdr.stamp.sec, hdr.stamp.nanosec = divmod(receive_ns, 1_000_000_000)
    return hdr.stamp.sec * 1_000_000_000 + hdr.stamp.nanosec


def reference_codec(gen: Any, protocol: str = "cyphal") -> Any:
    """A module-like object with ``CODECS`` (and ``WIRE_MATCHES``) for the mappings of ``protocol``."""
    from rclpy.serialization import deserialize_message, serialize_message

    tables = gen.tables()
    dronecan = protocol == "dronecan"
    convert = gen.convert_v0() if dronecan else gen.convert()
    codecs: dict[str, tuple[Any, Any]] = {}
    wire_matches: dict[str, Any] = {}
    for m in tables.MAPPINGS:
        if hasattr(m, "data_type") != dronecan:
            continue
        ros_cls = gen.ros_class(m.topic)
        to_ros, to_uavcan = convert.CONVERTERS[m.name]
        decode, encode = _v0_coders(m.data_type.name) if dronecan else _cyphal_coders(gen.dsdl_class(m.port))

        def wire_to_ros(payload: Any, receive_ns: int, stats: Any, decode=decode, to_ros=to_ros, m=m) -> Any:
            msg = to_ros(decode(payload), receive_ns, stats)
            if msg is None:
                return None
            stamp = _header(msg, m.frame_id, receive_ns)
            return serialize_message(msg), stamp

        def ros_to_wire(cdr: Any, stats: Any, encode=encode, to_uavcan=to_uavcan, ros_cls=ros_cls) -> Any:
            obj = to_uavcan(deserialize_message(bytes(cdr), ros_cls), stats)
            return None if obj is None else encode(obj)

        codecs[m.name] = (wire_to_ros, ros_to_wire)
        match = getattr(convert, "MATCHES", {}).get(m.name)
        if match is not None and match.__name__ != "_always":
            wire_matches[m.name] = lambda payload, match=match, decode=decode: match(decode(payload))
    return SimpleNamespace(CODECS=codecs, WIRE_MATCHES=wire_matches, WireError=ReferenceWireError)


def _cyphal_coders(cls: type) -> tuple[Any, Any]:
    import pycyphal.dsdl

    def decode(payload: Any) -> Any:
        obj = pycyphal.dsdl.deserialize(cls, [memoryview(payload)])
        if obj is None:
            raise ReferenceWireError(f"{cls.__name__}: pycyphal refuses the payload")
        return obj

    def encode(obj: Any) -> bytes:
        return b"".join(pycyphal.dsdl.serialize(obj))

    return decode, encode


def _v0_coders(type_name: str) -> tuple[Any, Any]:
    import dronecan
    from dronecan import transport

    def decode(payload: Any) -> Any:
        msg = dronecan.TYPENAMES[type_name]()
        try:
            msg._unpack(transport.bits_from_bytes(bytearray(payload)), True)
        except Exception as ex:
            raise ReferenceWireError(f"{type_name}: dronecan refuses the payload: {ex}") from None
        return msg

    def encode(obj: Any) -> bytes:
        return bytes(transport.Transfer(payload=obj).payload)

    return decode, encode
