"""Jinja2 filters shared by the templates: small, pure, and safe for hostile text.

Every text that comes from the spec (descriptions, comments) passes one of these before it reaches an
output file, so that a quote, a newline or a template marker stays inert in that file's language.
"""

from __future__ import annotations

import re


def comment_lines(text: str, prefix: str = "# ") -> str:
    """Turn free text into comment lines; empty text gives nothing.

    >>> comment_lines("one\\ntwo")
    '# one\\n# two'
    >>> comment_lines("") == ""
    True
    """
    lines = [line.rstrip() for line in one_paragraph_safe(text).split("\n")]
    return "\n".join((prefix + line).rstrip() for line in lines) if text.strip() else ""


def one_paragraph_safe(text: str) -> str:
    """Normalise line ends and drop control characters other than newline and tab.

    >>> one_paragraph_safe("a\\r\\nb\\x00c")
    'a\\nbc'
    """
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    return "".join(ch for ch in text if ch in "\n\t" or ch.isprintable())


def one_line(text: str) -> str:
    """Collapse text onto one line (for trailing comments and table cells).

    >>> one_line("a\\n  b")
    'a b'
    """
    return " ".join(one_paragraph_safe(text).split())


def md_cell(text: object) -> str:
    """Text for a Markdown table cell: one line, pipes and markup escaped.

    >>> md_cell("a|b <x> `c`")
    'a\\\\|b &lt;x&gt; \\\\`c\\\\`'
    """
    value = one_line(str(text))
    value = value.replace("\\", "\\\\").replace("|", "\\|").replace("`", "\\`")
    value = value.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return re.sub(r"([*_\[\]])", r"\\\1", value)


def md_code(text: object) -> str:
    """Inline Markdown code for identifiers (which are validated, so never contain backticks).

    >>> md_code("/imu")
    '`/imu`'
    """
    return f"`{text}`"


def py_str(text: object) -> str:
    """A Python string literal for any text (repr is exact and inert).

    >>> py_str("it's")
    '"it\\'s"'
    """
    return repr(str(text))


def xml_text(text: object) -> str:
    """Escape text for XML/SVG element content and attribute values.

    >>> xml_text('<a & "b">')
    '&lt;a &amp; &quot;b&quot;&gt;'
    """
    value = one_paragraph_safe(str(text))
    return (value.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;").replace("'", "&apos;"))


def py_number(value: float | int) -> str:
    """A Python literal for a number, exact for floats and with nan/inf spelled as expressions.

    >>> py_number(1e-08), py_number(float("nan")), py_number(3)
    ('1e-08', "float('nan')", '3')
    """
    if isinstance(value, bool):
        return repr(value)
    if isinstance(value, float) and value != value:
        return "float('nan')"
    if isinstance(value, float) and value in (float("inf"), float("-inf")):
        return "float('inf')" if value > 0 else "-float('inf')"
    return repr(value)


FILTERS = {
    "comment_lines": comment_lines,
    "one_line": one_line,
    "md_cell": md_cell,
    "md_code": md_code,
    "py_str": py_str,
    "py_number": py_number,
    "xml_text": xml_text,
}


def natural_key(text: str) -> list[int | str]:
    """Case-insensitive, with digit runs compared as numbers (ruff's isort order): Int8 before Int16.

    >>> sorted(["UInt16", "Int16", "Int8MultiArray", "uint8"], key=natural_key)
    ['Int8MultiArray', 'Int16', 'uint8', 'UInt16']
    """
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", text.lower())]
