"""Text into a byte-bounded UAVCAN array: the one rule for topics and services (issue 27).

A ROS string longer than the UAVCAN array's bound is cut at a UTF-8 character boundary, never inside a character
(a lone lead byte 0xC3 would make the device's text invalid UTF-8). The generated converters and codecs inline
:func:`cut_utf8_expr` (generated code imports nothing of this package); the bridge's service mappings call
:func:`cut_utf8`; tests/codegen/test_text_cut.py proves the two agree.

Invariants: the input is valid UTF-8 (a ROS string encoded with lone surrogates replaced: :func:`encode_text`), so
decoding the cut bytes with ``ignore`` drops only the partial character at the end; the result is at most ``cap``
bytes and a prefix of the input.
"""

from __future__ import annotations

__all__ = ["cut_utf8", "cut_utf8_expr", "encode_text"]


def encode_text(text: str) -> bytes:
    """A ROS string's UTF-8 bytes (a lone surrogate, which rclpy can hand over, becomes ``?``)."""
    return text.encode(errors="replace")


def cut_utf8_expr(var: str, cap: int) -> str:
    """The Python expression of :func:`cut_utf8` on variable `var`, as generated code writes it.

    >>> cut_utf8_expr("text", 7)
    "text[:7].decode(errors='ignore').encode()"
    """
    return f"{var}[:{cap}].decode(errors='ignore').encode()"


def cut_utf8(data: bytes, cap: int) -> bytes:
    """`data` (valid UTF-8) cut to at most `cap` bytes at a character boundary.

    >>> cut_utf8("éééé".encode(), 7), cut_utf8(b"abc", 7)
    (b'\\xc3\\xa9\\xc3\\xa9\\xc3\\xa9', b'abc')
    """
    return data[:cap].decode(errors="ignore").encode()
