"""Type expressions of both sides: ROS 2 .msg field types and Cyphal DSDL field types.

Pure data and parsing; the rules that relate the two live in validate.mapping_rules.

Invariants (checked on construction, as pydsdl's types check theirs): a RosType's base is a primitive or
`pkg/Name`; an array kind has a capacity exactly when it is bounded or fixed, at least 1; only a string has a bound.
A DsdlType of kind `composite` names its type and has no bit length, a primitive has its kind's bit length (bool 1,
byte and utf8 8, float 16/32/64, int 2..64, uint and void 1..64); a cast mode only on a numeric or bool; DSDL has no
unbounded arrays. The parse functions report a bad type text with their own messages before constructing anything,
so these checks fire only on a type built wrongly in code.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal, TypeGuard

ArrayKind = Literal["", "fixed", "bounded", "dynamic"]
_ARRAY_KINDS = ("", "fixed", "bounded", "dynamic")

ROS_INT_RANGES: dict[str, tuple[int, int]] = {
    "byte": (0, 255),
    "char": (0, 255),
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}
ROS_FLOAT_BITS = {"float32": 32, "float64": 64}
ROS_PRIMITIVES = frozenset({"bool", "string", "wstring", *ROS_INT_RANGES, *ROS_FLOAT_BITS})
# The ROS integer widths in increasing order, per signedness: the targets of the widening rule.
ROS_SIGNED_INTS = ("int8", "int16", "int32", "int64")
ROS_UNSIGNED_INTS = ("uint8", "uint16", "uint32", "uint64")

ROS_FIELD_NAME = re.compile(r"^[a-z](?:[a-z0-9]|_(?!_))*(?<!_)$")
ROS_MESSAGE_NAME = re.compile(r"^[A-Z][A-Za-z0-9]*$")
ROS_CONSTANT_NAME = re.compile(r"^[A-Z](?:[A-Z0-9]|_(?!_))*(?<!_)$")
ROS_PACKAGE_NAME = re.compile(r"^[a-z](?:[a-z0-9]|_(?!_))*(?<!_)$")
ROS_TOPIC_NAME = re.compile(r"^(/[A-Za-z_][A-Za-z0-9_]*)+$")

_ROS_MESSAGE_TYPE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*/[A-Za-z][A-Za-z0-9_]*$")
_ROS_TYPE = re.compile(
    r"^(?P<base>[A-Za-z][A-Za-z0-9_]*(?:/(?:msg/)?[A-Za-z][A-Za-z0-9_]*)?)"
    r"(?:<=(?P<strbound>[0-9]+))?"
    r"(?:\[(?P<array>(?:<=)?[0-9]*)\])?$"
)


@dataclass(frozen=True)
class RosType:
    """A ROS 2 field type: a primitive or `pkg/Name`, optionally an array."""

    base: str
    array: ArrayKind = ""
    capacity: int | None = None
    string_bound: int | None = None

    def __post_init__(self) -> None:
        """
        >>> RosType("x", "fixed", None)
        Traceback (most recent call last):
        ...
        ValueError: RosType('x', 'fixed', None, None): the base is not a primitive nor pkg/Name
        >>> RosType("float32", "fixed", None)
        Traceback (most recent call last):
        ...
        ValueError: RosType('float32', 'fixed', None, None): a fixed array needs a capacity of at least 1
        """
        problem = None
        if not (self.base in ROS_PRIMITIVES or (isinstance(self.base, str) and _ROS_MESSAGE_TYPE.fullmatch(self.base))):
            problem = "the base is not a primitive nor pkg/Name"
        elif self.array not in _ARRAY_KINDS:
            problem = f"unknown array kind {self.array!r}"
        elif self.array in ("fixed", "bounded") and not (_is_int(self.capacity) and self.capacity >= 1):
            problem = f"a {self.array} array needs a capacity of at least 1"
        elif self.array in ("", "dynamic") and self.capacity is not None:
            problem = "only a fixed or bounded array has a capacity"
        elif self.string_bound is not None and (not _is_int(self.string_bound) or self.string_bound < 0
                                                or self.base not in ("string", "wstring")):
            problem = "only a string has a bound, a count of characters"
        if problem is not None:
            raise ValueError(f"RosType({self.base!r}, {self.array!r}, {self.capacity!r}, {self.string_bound!r}): "
                             f"{problem}")

    @property
    def is_primitive(self) -> bool:
        return self.base in ROS_PRIMITIVES

    @property
    def package(self) -> str | None:
        return self.base.split("/")[0] if "/" in self.base else None

    @property
    def element(self) -> RosType:
        return RosType(self.base, string_bound=self.string_bound)

    def __str__(self) -> str:
        text = self.base
        if self.string_bound is not None:
            text += f"<={self.string_bound}"
        if self.array == "fixed":
            text += f"[{self.capacity}]"
        elif self.array == "bounded":
            text += f"[<={self.capacity}]"
        elif self.array == "dynamic":
            text += "[]"
        return text


def _is_int(value: object) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool)


def parse_ros_type(text: str, package: str | None = None) -> RosType:
    """Parse a .msg field type; a bare message name refers to `package`.

    >>> str(parse_ros_type("float32[<=36]"))
    'float32[<=36]'
    >>> parse_ros_type("sensor_msgs/msg/Imu").base
    'sensor_msgs/Imu'
    >>> parse_ros_type("Header", "std_msgs").base
    'std_msgs/Header'
    """
    match = _ROS_TYPE.fullmatch(text.strip())
    if not match:
        raise ValueError(f"{text!r} is not a ROS field type")
    base = match["base"].replace("/msg/", "/")
    if "/" not in base and base not in ROS_PRIMITIVES:
        if not ROS_MESSAGE_NAME.fullmatch(base):
            raise ValueError(f"unknown ROS type {base!r}")
        if package is None:
            raise ValueError(f"message type {base!r} needs its package, as pkg/{base}")
        base = f"{package}/{base}"
    if "/" in base:
        pkg, name = base.split("/")
        if not ROS_PACKAGE_NAME.fullmatch(pkg) or not ROS_MESSAGE_NAME.fullmatch(name):
            raise ValueError(f"{base!r} is not a valid ROS message type name")
    string_bound = int(match["strbound"]) if match["strbound"] else None
    if string_bound is not None and base not in ("string", "wstring"):
        raise ValueError(f"only strings take a bound (<=N), not {base}")
    array_text = match["array"]
    if array_text is None:
        return RosType(base, string_bound=string_bound)
    if array_text == "":
        return RosType(base, "dynamic", None, string_bound)
    if array_text.startswith("<="):
        capacity, kind = int(array_text[2:]), "bounded"
    else:
        capacity, kind = int(array_text), "fixed"
    if capacity < 1:
        raise ValueError(f"array size of {text!r} must be at least 1")
    return RosType(base, kind, capacity, string_bound)  # type: ignore[arg-type]


DsdlKind = Literal["bool", "int", "uint", "float", "byte", "utf8", "void", "composite"]

DSDL_IDENTIFIER = re.compile(r"^[a-zA-Z_][a-zA-Z0-9_]*$")
DSDL_SHORT_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
DSDL_NAMESPACE_COMPONENT = re.compile(r"^[a-z_][a-z0-9_]*$")
# Words pydsdl reserves (keywords, type names and the patterns of primitive names).
_DSDL_RESERVED = re.compile(
    r"^(truncated|saturated|true|false|bool|byte|utf8|optional|aligned|const|struct|super|template|"
    r"enum|self|and|or|not|auto|type|con|prn|aux|nul|(com|lpt)[1-9]|"
    r"(u?int|u?q|float|void)\d*|(u?int|float|void)\d+x\d+)$",
    re.IGNORECASE,
)
_DSDL_TYPE = re.compile(
    r"^(?:(?P<cast>saturated|truncated)\s+)?"
    r"(?P<base>bool|byte|utf8|u?int[0-9]+|float(?:16|32|64)|void[0-9]+|"
    r"(?:[a-z_][a-z0-9_]*\.)+[A-Za-z_][A-Za-z0-9_]*\.[0-9]+\.[0-9]+)"
    r"(?:\[(?P<array>(?:<=)?[0-9]+)\])?$"
)
_COMPOSITE_NAME = re.compile(
    r"^(?P<full>(?:[a-z_][a-z0-9_]*\.)+[A-Za-z_][A-Za-z0-9_]*)\.(?P<maj>[0-9]+)\.(?P<min>[0-9]+)$"
)


def is_dsdl_identifier(name: str) -> bool:
    """A DSDL attribute name: an identifier that is not reserved.

    >>> is_dsdl_identifier("rpm"), is_dsdl_identifier("uint8"), is_dsdl_identifier("2x")
    (True, False, False)
    """
    return bool(DSDL_IDENTIFIER.fullmatch(name)) and not _DSDL_RESERVED.fullmatch(name) and not name.startswith("_")


@dataclass(frozen=True)
class DsdlType:
    """A DSDL field type: primitive (with bit length) or composite (full name with version)."""

    kind: DsdlKind
    bits: int = 0
    composite: str | None = None
    array: ArrayKind = ""
    capacity: int | None = None
    truncated: bool = False

    def __post_init__(self) -> None:
        """
        >>> DsdlType("float", 8)
        Traceback (most recent call last):
        ...
        ValueError: DsdlType('float', 8, None, '', None): a float has 16, 32 or 64 bits
        >>> DsdlType("composite", composite="uavcan.Timestamp", array="dynamic")
        Traceback (most recent call last):
        ...
        ValueError: DsdlType('composite', 0, 'uavcan.Timestamp', 'dynamic', None): DSDL arrays are fixed or bounded
        """
        problem = None
        bits = _DSDL_BITS.get(self.kind)
        if self.kind == "composite":
            if not isinstance(self.composite, str) or not self.composite or self.bits != 0:
                problem = "a composite names its type and has no bit length"
        elif bits is None:
            problem = f"unknown kind {self.kind!r}"
        elif self.composite is not None:
            problem = "only a composite names a type"
        elif not _is_int(self.bits) or self.bits not in bits:
            problem = _DSDL_BITS_TEXT[self.kind]
        if problem is None and self.array not in ("", "fixed", "bounded"):
            problem = "DSDL arrays are fixed or bounded"
        elif problem is None and self.array and not (_is_int(self.capacity) and self.capacity >= 1):
            problem = f"a {self.array} array needs a capacity of at least 1"
        elif problem is None and not self.array and self.capacity is not None:
            problem = "only an array has a capacity"
        elif problem is None and self.truncated and self.kind not in ("bool", "int", "uint", "float"):
            problem = "only a number or bool has a cast mode"
        if problem is not None:
            raise ValueError(f"DsdlType({self.kind!r}, {self.bits!r}, {self.composite!r}, {self.array!r}, "
                             f"{self.capacity!r}): {problem}")

    @property
    def element(self) -> DsdlType:
        return DsdlType(self.kind, self.bits, self.composite, truncated=self.truncated)

    @property
    def range(self) -> tuple[int, int]:
        """The value range of an integer type."""
        if self.kind == "uint" or self.kind == "byte":
            return 0, 2**self.bits - 1
        if self.kind == "int":
            return -(2 ** (self.bits - 1)), 2 ** (self.bits - 1) - 1
        raise ValueError(f"{self} is not an integer type")

    @property
    def base_name(self) -> str:
        if self.kind == "composite":
            assert self.composite
            return self.composite
        if self.kind in ("bool", "byte", "utf8"):
            return self.kind
        return f"{self.kind}{self.bits}"

    def __str__(self) -> str:
        text = ("truncated " if self.truncated else "") + self.base_name
        if self.array == "fixed":
            text += f"[{self.capacity}]"
        elif self.array == "bounded":
            text += f"[<={self.capacity}]"
        return text


# The bit lengths a primitive kind may have (pydsdl's and dronecan's limits together).
_DSDL_BITS: dict[str, range | tuple[int, ...]] = {
    "bool": (1,), "byte": (8,), "utf8": (8,), "float": (16, 32, 64), "int": range(2, 65), "uint": range(1, 65),
    "void": range(1, 65),
}
_DSDL_BITS_TEXT = {
    "bool": "a bool has 1 bit", "byte": "a byte has 8 bits", "utf8": "a utf8 has 8 bits",
    "float": "a float has 16, 32 or 64 bits", "int": "an int has 2..64 bits", "uint": "a uint has 1..64 bits",
    "void": "a void has 1..64 bits",
}


def split_composite_name(name: str) -> tuple[str, int, int]:
    """`uavcan.time.SynchronizedTimestamp.1.0` -> (`uavcan.time.SynchronizedTimestamp`, 1, 0)."""
    match = _COMPOSITE_NAME.fullmatch(name)
    if not match:
        raise ValueError(f"{name!r} is not a versioned DSDL type name (namespace.Name.MAJOR.MINOR)")
    return match["full"], int(match["maj"]), int(match["min"])


# The most elements a Cyphal or DroneCAN array of the spec may hold. A transfer carries at most the largest extent
# the tool accepts (65,535 bytes, `extent`), so no array of whole-byte elements can be longer on the bus; DroneCAN
# has no extent, but a transfer of 65,535 bytes is already ~9,400 classic CAN frames. Checked when the type is read,
# so that no later stage (the bus budget, the codecs, pydsdl) ever sees a capacity of 10^9.
MAX_ARRAY_CAPACITY = 65535


def _check_capacity(text: str, capacity: int) -> None:
    if capacity < 1:
        raise ValueError(f"array capacity of {text!r} must be at least 1")
    if capacity > MAX_ARRAY_CAPACITY:
        raise ValueError(f"array capacity {capacity:,} of {text!r} is more than a transfer can carry "
                         f"(at most {MAX_ARRAY_CAPACITY:,} elements)")


def parse_dsdl_type(text: str) -> DsdlType:
    """Parse a DSDL field type.

    >>> str(parse_dsdl_type("float16[<=36]")), parse_dsdl_type("int18").range
    ('float16[<=36]', (-131072, 131071))
    >>> parse_dsdl_type("uavcan.time.SynchronizedTimestamp.1.0").composite
    'uavcan.time.SynchronizedTimestamp.1.0'
    """
    match = _DSDL_TYPE.fullmatch(" ".join(text.split()))
    if not match:
        raise ValueError(f"{text!r} is not a DSDL field type")
    base, cast = match["base"], match["cast"]
    kind: DsdlKind
    bits = 0
    composite = None
    if base in ("bool", "byte", "utf8"):
        kind, bits = base, (1 if base == "bool" else 8)  # type: ignore[assignment]
    elif base.startswith("float"):
        kind, bits = "float", int(base[5:])
    elif base.startswith("uint"):
        kind, bits = "uint", int(base[4:])
    elif base.startswith("int"):
        kind, bits = "int", int(base[3:])
    elif base.startswith("void"):
        kind, bits = "void", int(base[4:])
    else:
        kind, composite = "composite", base
        split_composite_name(base)
    if (kind == "uint" and not 1 <= bits <= 64) or (kind == "int" and not 2 <= bits <= 64):
        raise ValueError(f"{base}: integer bit length must be 1..64 (unsigned) or 2..64 (signed)")
    if kind == "void" and not 1 <= bits <= 64:
        raise ValueError(f"{base}: void bit length must be 1..64")
    if cast and kind not in ("uint", "float", "bool"):
        raise ValueError(f"cast mode {cast!r} applies only to unsigned integers, floats and bool, not {base}")
    if kind in ("byte", "utf8") and match["array"] is None:
        raise ValueError(f"{base} is allowed only as an array element")
    array_text = match["array"]
    if array_text is None:
        return DsdlType(kind, bits, composite, truncated=cast == "truncated")
    if kind == "void":
        raise ValueError("void cannot be an array element")
    bounded = array_text.startswith("<=")
    capacity = int(array_text[2:] if bounded else array_text)
    _check_capacity(text, capacity)
    return DsdlType(kind, bits, composite, "bounded" if bounded else "fixed", capacity, cast == "truncated")


# ---- UAVCAN v0 (DroneCAN) ------------------------------------------------------------------------------------
# v0 DSDL has no versions in type names, no byte/utf8 (text is uint8[<=N]), integers of 2..64 bits (bool, not
# uint1), floats of 16/32/64 bits, and a cast mode on any primitive. `[<N]` is `[<=N-1]`.
V0_NAMESPACE_COMPONENT = re.compile(r"^[a-z][a-z0-9_]*$")
V0_SHORT_NAME = re.compile(r"^[A-Z][A-Za-z0-9_]*$")
V0_MAX_FULL_NAME = 80  # dronecan's parser refuses longer type and namespace names
_V0_TYPE = re.compile(
    r"^(?:(?P<cast>saturated|truncated)\s+)?"
    r"(?P<base>bool|u?int[0-9]+|float[0-9]+|void[0-9]+|(?:[a-z][a-z0-9_]*\.)+[A-Z][A-Za-z0-9_]*)"
    r"(?:\[(?P<array><=?[0-9]+|[0-9]+)\])?$"
)


def parse_v0_type(text: str) -> DsdlType:
    """Parse a UAVCAN v0 (DroneCAN) field type; a composite is named by its full name, without version.

    >>> str(parse_v0_type("float16[<=36]")), str(parse_v0_type("uint8[<32]")), parse_v0_type("int18").range
    ('float16[<=36]', 'uint8[<=31]', (-131072, 131071))
    >>> t = parse_v0_type("uavcan.Timestamp"); (t.kind, t.composite)
    ('composite', 'uavcan.Timestamp')
    >>> parse_v0_type("uint1")
    Traceback (most recent call last):
    ...
    ValueError: uint1: a v0 integer has 2..64 bits (a single bit is a bool)
    """
    match = _V0_TYPE.fullmatch(" ".join(text.split()))
    if not match:
        raise ValueError(f"{text!r} is not a UAVCAN v0 field type")
    base, cast = match["base"], match["cast"]
    kind: DsdlKind
    bits, composite = 0, None
    if base == "bool":
        kind, bits = "bool", 1
    elif base.startswith("float"):
        kind, bits = "float", int(base[5:])
        if bits not in (16, 32, 64):
            raise ValueError(f"{base}: a v0 float has 16, 32 or 64 bits")
    elif base.startswith("void"):
        kind, bits = "void", int(base[4:])
        if not 1 <= bits <= 64:
            raise ValueError(f"{base}: void bit length must be 1..64")
    elif base.startswith(("uint", "int")):
        kind = "uint" if base.startswith("uint") else "int"
        bits = int(base[len(kind):])
        if not 2 <= bits <= 64:
            raise ValueError(f"{base}: a v0 integer has 2..64 bits (a single bit is a bool)")
    else:
        kind, composite = "composite", base
        if len(base) > V0_MAX_FULL_NAME:
            raise ValueError(f"{base}: a v0 type name has at most {V0_MAX_FULL_NAME} characters")
    if cast and kind in ("void", "composite"):
        raise ValueError(f"cast mode {cast!r} applies only to primitive types, not {base}")
    array = match["array"]
    if array is None:
        return DsdlType(kind, bits, composite, truncated=cast == "truncated")
    if kind == "void":
        raise ValueError("void cannot be an array element")
    if array.startswith("<="):
        capacity, mode = int(array[2:]), "bounded"
    elif array.startswith("<"):
        capacity, mode = int(array[1:]) - 1, "bounded"
    else:
        capacity, mode = int(array), "fixed"
    _check_capacity(text, capacity)
    return DsdlType(kind, bits, composite, mode, capacity, cast == "truncated")  # type: ignore[arg-type]


def v0_normalized(t: DsdlType) -> str:
    """The type as the v0 signature sees it (the normalized definition): the cast mode spelled out.

    >>> v0_normalized(parse_v0_type("float16[<=36]")), v0_normalized(parse_v0_type("truncated uint56"))
    ('saturated float16[<=36]', 'truncated uint56')
    >>> v0_normalized(parse_v0_type("uavcan.equipment.actuator.Command[<=15]")), v0_normalized(DsdlType("void", 3))
    ('uavcan.equipment.actuator.Command[<=15]', 'void3')
    """
    if t.kind == "composite":
        text = t.composite or ""
    elif t.kind == "void":
        text = f"void{t.bits}"
    else:
        text = ("truncated " if t.truncated else "saturated ") + t.base_name
    if t.array == "fixed":
        text += f"[{t.capacity}]"
    elif t.array == "bounded":
        text += f"[<={t.capacity}]"
    return text
