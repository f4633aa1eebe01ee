"""The plan's vocabulary: the typed operations a link's value goes through (frozen dataclasses, in the order they
apply), and the plans made of them: LinkPlan (one link, one direction), FieldSet (a field set without reading the
source), MappingPlan (a whole mapping, both directions) and ElementMapping (an array of composites, element by
element, with a plan of its own)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Literal

from sam_codegen.conversion_plan.value_ranges import width_change
from sam_codegen.model.expr import ENode
from sam_codegen.model.spec import Scalar
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.validate.mapping_rules import Key, PathSeg, Step

TO_ROS: Final = "to_ros"
TO_UAVCAN: Final = "to_uavcan"
PlanDirection = Literal["to_ros", "to_uavcan"]


@dataclass(frozen=True)
class Convert:
    """The value changes representation (type names of the source and target element); `change` says how."""

    src: str
    dst: str

    @property
    def change(self) -> str:
        return width_change(self.src, self.dst)


@dataclass(frozen=True)
class Scale:
    """value * factor (UAVCAN -> ROS), value / factor (`inverse`, ROS -> UAVCAN); `factor` as the spec wrote it."""

    factor: float
    inverse: bool = False


@dataclass(frozen=True)
class Offset:
    """value + amount (UAVCAN -> ROS), value - amount (`inverse`, ROS -> UAVCAN); `amount` as the spec wrote it."""

    amount: float
    inverse: bool = False


@dataclass(frozen=True)
class RejectNaN:
    """A NaN drops the message (counted as rejected), whatever the policy."""


@dataclass(frozen=True)
class Limits:
    """The spec's `limits` (in ROS units): beyond them the value saturates or the message is rejected.

    `low` and `high` are compared (ints for an integer value, where whole); `declared` as the spec wrote them."""

    low: float
    high: float
    declared: tuple[Scalar, Scalar]
    reject: bool


ClampMode = Literal["integer", "round", "float16", "float32"]


@dataclass(frozen=True)
class Clamp:
    """Into the target's range; beyond it the value saturates to the bound or the message is rejected.

    - integer: checks `high` then `low`, each only where the value can pass it (None: cannot);
    - round: a float into an integer: rounded half to even, what rounds beyond [low, high] saturates;
    - float16: beyond +-65504, infinities included; NaN passes;
    - float32: finite values beyond +-FLOAT32_MAX; infinities and NaN are float32 values and pass.
    """

    mode: ClampMode
    low: float | None
    high: float | None
    reject: bool


@dataclass(frozen=True)
class Wrap:
    """An integer into an integer target of `bits` bits, stored modulo 2**bits as C stores it (`on_out_of_range:
    wrap` on the line, issue 27): two's complement for a signed target; nothing is counted (the spec asked for it)."""

    bits: int
    signed: bool


@dataclass(frozen=True)
class Round:
    """A float into an integer known to be in range: rounded half to even, nothing to check."""


@dataclass(frozen=True)
class Table:
    """A lookup in the link's table; `inverse` (ROS -> UAVCAN) looks up the first key per value. A miss rejects
    the message, unless there is a `default` (UAVCAN -> ROS only)."""

    pairs: tuple[tuple[int, int], ...]  # (UAVCAN value, ROS value) as declared
    default: int | None
    inverse: bool

    def lookup(self) -> list[tuple[int, int]]:
        """(input, output) pairs in this direction.

        >>> Table(((0, 5), (1, 5), (2, 6)), None, True).lookup()
        [(5, 0), (6, 2)]
        """
        if not self.inverse:
            return list(self.pairs)
        inverse: dict[int, int] = {}
        for key, value in self.pairs:
            inverse.setdefault(value, key)  # first key per value
        return sorted(inverse.items())


@dataclass(frozen=True)
class TimestampToRos:
    """Microseconds (0 = unknown: the receive time) into builtin_interfaces/Time; beyond what Time holds
    (`high`, `low`: None where the source cannot reach) saturates to its limits or rejects."""

    high: int | None
    low: int | None
    reject: bool


@dataclass(frozen=True)
class TimestampFromRos:
    """builtin_interfaces/Time into microseconds; beyond the target integer's `high` / `low` (None: cannot happen)
    saturates or rejects."""

    high: int | None
    low: int | None
    reject: bool


@dataclass(frozen=True)
class DecodeUtf8:
    """UTF-8 bytes into a ROS string; invalid bytes are replaced."""


@dataclass(frozen=True)
class EncodeUtf8:
    """A ROS string into UTF-8 bytes (lone surrogates replaced)."""


@dataclass(frozen=True)
class Utf8Length:
    """Longer than `capacity` bytes: cut at a character boundary (saturate) or rejected."""

    capacity: int
    reject: bool


@dataclass(frozen=True)
class Pad:
    """A bounded UAVCAN array into a fixed ROS array: zeros (unknown) after the elements received."""

    size: int


@dataclass(frozen=True)
class FixedLength:
    """Into a fixed UAVCAN array: other lengths are padded with zeros or cut (saturate) or rejected."""

    size: int
    reject: bool


@dataclass(frozen=True)
class MaxLength:
    """Into a bounded UAVCAN array: elements beyond `capacity` are cut (saturate) or the message is rejected;
    `padded`: the source is a longer fixed ROS array whose zero padding beyond the bound is dropped silently."""

    capacity: int
    padded: bool
    reject: bool


@dataclass(frozen=True)
class SetConstant:
    """A field set to a value from the spec (`value` links; uavcan_values; DroneCAN's `select`)."""

    value: Scalar
    select: bool = False


@dataclass(frozen=True)
class StaticFrameId:
    """header.frame_id: the mapping's frame_id."""

    value: str


@dataclass(frozen=True)
class ReceiveTime:
    """header.stamp: the bridge's receive time (the UAVCAN type has no timestamp)."""


@dataclass(frozen=True)
class RequireItem:
    """DroneCAN: the item of the array with `key` must be present, else the message is not this mapping's
    (rejected under the item's path)."""

    array: tuple[PathSeg, ...]
    key: Key


@dataclass(frozen=True)
class RequireLength:
    """DroneCAN: the array must hold at least `length` elements (the mapping reads element length - 1)."""

    array: tuple[PathSeg, ...]
    length: int


@dataclass(frozen=True)
class Evaluate:
    """The value is an expression of source fields (model.expr's typed tree; its trunc()/round() check their own
    range with the link's policy); `as_float`: an int result stored into a float field. The checks after it
    (RejectNaN for a float result, Clamp into the target) follow as for any value."""

    tree: ENode
    as_float: bool


@dataclass(frozen=True)
class ElementMapping:
    """An array of composites converted element by element: `plan` is the element mapping's own plan (its links
    relative to one element, in the same direction); the array's length ops (MaxLength, FixedLength) follow it.
    An element whose conversion rejects drops the whole message; an element's ROS header is the message's."""

    plan: MappingPlan
    ros_element: str  # the ROS element message (pkg/Name)
    uavcan_element: str  # the UAVCAN element type's full name


Op = (Convert | Scale | Offset | RejectNaN | Limits | Clamp | Wrap | Round | Table | TimestampToRos | TimestampFromRos
      | DecodeUtf8 | EncodeUtf8 | Utf8Length | Pad | FixedLength | MaxLength | SetConstant | Evaluate | ElementMapping)
EXPRESSION_OPS = (Convert, Scale, Offset)  # pure arithmetic on the value; everything else may drop or fix it
CHECK_OPS = (RejectNaN, Limits, Clamp, Wrap, Round)


@dataclass(frozen=True)
class LinkPlan:
    """One link in one direction: its operations in the order they apply."""

    step: Step
    direction: PlanDirection
    key: str  # the stats key: "<mapping>.<ROS field>" to ROS, "<mapping>.<UAVCAN field>" to UAVCAN
    ops: tuple[Op, ...]
    reject: bool  # the mapping's on_out_of_range is "reject"

    @property
    def to_ros(self) -> bool:
        return self.direction == TO_ROS

    def has(self, *kinds: type) -> bool:
        return any(isinstance(op, kinds) for op in self.ops)

    def first(self, kind: type) -> Op | None:
        return next((op for op in self.ops if isinstance(op, kind)), None)


@dataclass(frozen=True)
class FieldSet:
    """A field a converter sets without reading the source (a constant, the frame id, the receive time)."""

    path: tuple[PathSeg, ...]
    type: DsdlType | RosType | None
    op: SetConstant | StaticFrameId | ReceiveTime


@dataclass(frozen=True)
class MappingPlan:
    name: str
    direction: str  # the mapping's: uavcan_to_ros | ros_to_uavcan
    reject: bool
    ros_fields: tuple[FieldSet, ...]  # UAVCAN -> ROS: the receive-time stamp, then header.frame_id
    to_ros: tuple[LinkPlan, ...]  # every link, `value` links included
    to_uavcan: tuple[LinkPlan, ...]  # the links with a UAVCAN field
    uavcan_fields: tuple[FieldSet, ...]  # ROS -> UAVCAN: uavcan_values, then DroneCAN's select
    required: tuple[RequireItem | RequireLength, ...]  # DroneCAN: elements a received message must have

    def links(self, direction: PlanDirection) -> tuple[LinkPlan, ...]:
        return self.to_ros if direction == TO_ROS else self.to_uavcan
