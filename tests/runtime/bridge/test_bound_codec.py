"""The wire codecs of a namespaced run (issue 26), without ROS: ``GeneratedPackage.codec(protocol, frame_prefix)``
gives a copy of the generated codec module bound to the prefix (sam_runtime.genpkg.bound_codec), one per prefix,
the module without a prefix untouched; the bound codec's CDR has the prefixed frame id as a CDR string; a codec
module from before ``bind`` gives no bound copy (the bridge then runs its object path, saying why).

The codecs against rclpy and the object converters with prefixes of every length: tests/codegen/test_codec.py,
test_codec_v0.py, test_element_mappings.py; a namespaced bridge end to end: tests/system/test_bridge_namespaced.py.
"""

from __future__ import annotations

import struct
from types import ModuleType
from typing import Any

import pytest
from helpers.runtime_support import generated_or_skip

from sam_runtime.genpkg import bound_codec


class _Stats:
    def saturate(self, key: str) -> None:
        pass

    def reject(self, key: str) -> None:
        pass

    def reject_nan(self, key: str) -> None:
        pass


def _converts(module: Any, to_ros: Any, payload: bytes) -> bool:
    try:
        return to_ros(payload, 5_000_000_000, _Stats()) is not None
    except module.WireError:  # too short for the type: a longer one
        return False


def _frame_id(cdr: bytes) -> str:
    """The frame id of a CDR message that starts with a Header (a CDR string after the stamp)."""
    (length,) = struct.unpack_from("<I", cdr, 12)  # encapsulation 4, stamp 8: the frame id's length with its NUL
    assert cdr[16 + length - 1] == 0
    return cdr[16:16 + length - 1].decode()


@pytest.mark.parametrize("protocol", ["cyphal", "dronecan"])
def test_a_bound_copy_per_prefix_and_the_prefixed_frame_ids(protocol: str) -> None:
    gen = generated_or_skip()
    plain = gen.codec(protocol)
    if plain is None or not hasattr(plain, "bind"):
        pytest.skip("a generated package without wire codecs that take a frame prefix")
    sam1, sam22 = gen.codec(protocol, "sam1/"), gen.codec(protocol, "sam22/")
    assert isinstance(sam1, ModuleType) and isinstance(sam22, ModuleType)
    assert gen.codec(protocol, "sam1/") is sam1 and gen.codec(protocol, "") is plain  # bound once per run
    assert len({id(plain), id(sam1), id(sam22)}) == 3
    assert (plain.FRAME_PREFIX, sam1.FRAME_PREFIX, sam22.FRAME_PREFIX) == ("", "sam1/", "sam22/")
    checked = 0
    for name, (to_ros, _) in plain.CODECS.items():
        size = next((n for n in range(600) if _converts(plain, to_ros, bytes(n))), None)  # zeros, long enough
        if size is None:
            continue  # a mapping that selects by value (no zero payload is its)
        payload = bytes(size)
        out: Any = to_ros(payload, 5_000_000_000, _Stats())
        if len(out[0]) < 20 or out[0][4:12] != struct.pack("<iI", 5, 0):
            continue  # no header first (its stamp: the receive time, as the payload's timestamp is zero)
        for prefix, module in (("sam1/", sam1), ("sam22/", sam22)):
            cdr, stamp = module.CODECS[name][0](payload, 5_000_000_000, _Stats())
            assert stamp == out[1] and _frame_id(cdr) == prefix + _frame_id(out[0])
            # the rest as before, aligned for the longer string: at most 7 bytes of padding more or less
            assert abs(len(cdr) - len(out[0]) - len(prefix)) <= 7, (name, prefix)
        checked += 1
    assert checked >= 5, checked


def test_a_codec_module_without_bind_has_no_bound_copy() -> None:
    old = ModuleType("old_codec")
    old.CODECS = {}  # type: ignore[attr-defined]
    assert bound_codec(old, "") is old
    assert bound_codec(old, "sam1/") is None
