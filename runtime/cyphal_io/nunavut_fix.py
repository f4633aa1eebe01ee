"""A fix for nunavut 2.3's Python serializer under numpy 2, applied to each compiled DSDL cache entry.

pycyphal keeps an array of a signed integer type in the smallest numpy integer that holds it (int5[<=8] in an
int8 array), and the serializer nunavut 2.3 emits (``nunavut_support.py``) writes each element of an array that
is not byte-sized with ``add_aligned_signed`` / ``add_unaligned_signed``: ``2**bit_length + value`` for a
negative value, then ``value & 0xFF`` per byte. With the element still a numpy integer, numpy 2 (NEP 50) keeps
the arithmetic in the element's type and raises OverflowError where it does not fit: for int2..int7 arrays on
every element (0xFF does not fit int8), for int15, int31 and int63 arrays on every negative element. pycyphal
1.27 requires numpy 2, so the stack cannot be pinned around it. The fix turns the element into a Python int
first, which is what the serializer's arithmetic assumes; the bytes are those of the DSDL layout either way.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["FIX_VERSION", "fix_support"]

# Part of the DSDL cache key: a change here must recompile (runtime.dsdl includes it in its cache format).
FIX_VERSION = 1

_SIGNED = "        self.add_{kind}_unsigned((2**bit_length + value) if value < 0 else value, bit_length)\n"
_FIXED = "        value = int(value)  # sam-codegen: a numpy integer overflows here under numpy 2\n"


def fix_support(path: Path) -> bool:
    """Patch a compiled ``nunavut_support.py`` in place; returns whether it changed.

    Only the exact lines of nunavut 2.3 are patched; a support module without them (fixed already, or another
    nunavut) is left as it is: tests/test_generator_defects.py serializes every narrow signed array width
    through the runtime's compile, so a nunavut that is still broken is noticed there.
    """
    text = path.read_text(encoding="utf-8")
    lines = [_SIGNED.format(kind=kind) for kind in ("aligned", "unaligned")]
    if _FIXED in text or any(text.count(line) != 1 for line in lines):
        return False
    for line in lines:
        text = text.replace(line, _FIXED + line)
    path.write_text(text, encoding="utf-8")
    return True
