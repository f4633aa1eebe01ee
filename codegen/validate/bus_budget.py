"""The CAN bus budget of every layout: frames per second and bus load of each node and of the whole bus, predicted
from the spec alone (the ports' nominal rates and the types' serialized sizes).

Invariants:

- A transfer's frames follow its protocol's rules. Cyphal/CAN: one frame while the payload and the tail byte fit the
  MTU, else ceil((payload + 2) / (MTU - 1)) frames (a tail byte per frame, the 2-byte transfer CRC after the
  payload); on CAN FD a frame's data length is rounded up to the next DLC length (0-8, 12, 16, 20, 24, 32, 48, 64).
  DroneCAN v0 (always classic CAN): one frame while the payload fits 7 bytes, else ceil((payload + 2) / 7) (the CRC
  goes first); a dynamic array of bytes-or-larger elements at the end of the message is a tail array (no length
  prefix: the tail array optimisation).
- A variable-length type counts at its largest size (the budget is a bound), except a DroneCAN broadcast command,
  which carries exactly the elements its mapping writes (`rpm[0]`, `rpm[1]`: 2 elements).
- Every node adds its 1 Hz liveness message: Cyphal's uavcan.node.Heartbeat.1.0 or DroneCAN's
  uavcan.protocol.NodeStatus (7 bytes each, one frame). pycyphal's optional uavcan.node.port.List (every 10 s) is not
  counted: the spec does not ask for it and firmware need not send it.
- Bits per frame, 29-bit identifiers (UAVCAN never uses 11-bit ones): classic CAN 67 + 8*DLC (the often quoted
  47 + 8*DLC is the 11-bit frame), intermission included; worst-case bit stuffing adds one bit per 4 of the 54 + 8*DLC
  stuffed bits. 8-byte frames: 131 bits (7,634 frames/s at 1 Mbit/s), 160 worst case (6,250 frames/s). CAN FD: 48
  bits at the nominal bit rate (arbitration, ACK, EOF, intermission) and 32 + 8*DLC (DLC <= 16) or 37 + 8*DLC at the
  data bit rate (control, stuff count, CRC 17/21 with its fixed stuff bits, CRC delimiter).
- The verdict judges the load with worst-case stuffing (the bound a bus must survive): above the warning threshold
  (default 70 %, the spec's `load_warning_percent`) a warning, above 100 % a spec error (check_bus_budgets) at the
  layout's own `bus`, else the named layout, else the spec's `bus`, else the device that loads the bus most.
- The bus: a layout's own `bus:`, else the spec's, else classic CAN at 1 Mbit/s; `bus: none` has no budget.
- Pure arithmetic on the resolved spec: no clock, no I/O; the same spec gives the same figures byte for byte.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from sam_codegen.model.diagnostics import Diagnostic, Pos, SpecError
from sam_codegen.model.protocols.registry import protocol as protocol_of
from sam_codegen.model.protocols.registry import registered
from sam_codegen.model.spec import CanBus, DsdlStruct, Spec, V0Struct
from sam_codegen.model.types import DsdlType
from sam_codegen.validate.dronecan import ResolvedLayout
from sam_codegen.validate.mapping_rules import ResolvedMapping

__all__ = [
    "DEFAULT_BITRATE",
    "DEFAULT_FD_DATA_BITRATE",
    "DEFAULT_WARNING_PERCENT",
    "Bus",
    "LayoutBudget",
    "NodeBudget",
    "Transfer",
    "bus_for",
    "check_bus_budgets",
    "classic_frame_bits",
    "cyphal_frame_lengths",
    "cyphal_max_bytes",
    "dronecan_frame_lengths",
    "dronecan_max_bytes",
    "fd_frame_bits",
    "fd_frame_length",
    "layout_budgets",
]

DEFAULT_BITRATE = 1_000_000
DEFAULT_FD_DATA_BITRATE = 4_000_000
DEFAULT_WARNING_PERCENT = 70.0
CLASSIC_MTU = 8
FD_MTU = 64
FD_LENGTHS = (0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64)
LIVENESS_BYTES = 7  # uavcan.node.Heartbeat.1.0 and uavcan.protocol.NodeStatus are both 56 bits
LIVENESS_HZ = 1.0

Lookup = Callable[[str], DsdlStruct | None]
V0Lookup = Callable[[str], V0Struct | None]


# ---- frames and bits --------------------------------------------------------------------------------------------

def classic_frame_bits(data_bytes: int, *, worst_case: bool = False) -> int:
    """Bits of a classic CAN data frame with a 29-bit id on the bus, the 3-bit intermission included.

    >>> classic_frame_bits(8), classic_frame_bits(8, worst_case=True), classic_frame_bits(0)
    (131, 160, 67)
    >>> round(1_000_000 / 131), 1_000_000 // 160  # 8-byte frames a second on a saturated 1 Mbit/s bus
    (7634, 6250)
    """
    if not 0 <= data_bytes <= CLASSIC_MTU:
        raise ValueError(f"a classic CAN frame has 0..8 data bytes, got {data_bytes}")
    stuffed = 54 + 8 * data_bytes  # SOF, 11+18-bit id, SRR, IDE, RTR, r1, r0, DLC, data, CRC 15
    return stuffed + 13 + ((stuffed - 1) // 4 if worst_case else 0)  # + CRC delimiter, ACK 2, EOF 7, IFS 3


def fd_frame_length(data_bytes: int) -> int:
    """The smallest CAN FD data length (a DLC value) that holds ``data_bytes``.

    >>> [fd_frame_length(n) for n in (0, 8, 9, 13, 33, 64)]
    [0, 8, 12, 16, 48, 64]
    """
    for length in FD_LENGTHS:
        if length >= data_bytes:
            return length
    raise ValueError(f"a CAN FD frame has 0..64 data bytes, got {data_bytes}")


def fd_frame_bits(data_bytes: int, *, worst_case: bool = False) -> tuple[int, int]:
    """(bits at the nominal bit rate, bits at the data bit rate) of a CAN FD frame with a 29-bit id and bit rate
    switching; ``data_bytes`` must be a DLC length.

    >>> fd_frame_bits(8), fd_frame_bits(64), fd_frame_bits(64, worst_case=True)
    ((48, 96), (48, 549), (56, 678))
    """
    if data_bytes not in FD_LENGTHS:
        raise ValueError(f"{data_bytes} is not a CAN FD data length {FD_LENGTHS}")
    arbitration = 36  # SOF, 11+18-bit id, SRR, IDE, RRS, FDF, res, BRS
    data = (32 if data_bytes <= 16 else 37) + 8 * data_bytes
    if worst_case:  # dynamic stuff bits up to the CRC (its own stuff bits are fixed, counted above)
        arbitration += (arbitration - 1) // 4
        data += (5 + 8 * data_bytes) // 4
    return arbitration + 12, data  # + ACK 2, EOF 7, IFS 3 at the nominal rate


def cyphal_frame_split(payload_bytes: int, mtu: int = CLASSIC_MTU) -> tuple[tuple[int, int], ...]:
    """The frames of one Cyphal/CAN transfer as (data length, how many) pairs, computed, never listed one by one:
    a capacity of millions of elements must cost no more than one of ten.

    >>> cyphal_frame_split(7), cyphal_frame_split(47), cyphal_frame_split(10 ** 9)
    (((8, 1),), ((8, 7),), ((8, 142857143), (2, 1)))
    """
    if payload_bytes < 0 or mtu not in (CLASSIC_MTU, FD_MTU):
        raise ValueError(f"payload {payload_bytes} bytes, MTU {mtu}")
    pad = (lambda n: n) if mtu == CLASSIC_MTU else fd_frame_length
    per_frame = mtu - 1
    if payload_bytes <= per_frame:
        return ((pad(payload_bytes + 1), 1),)
    full, rest = divmod(payload_bytes + 2, per_frame)
    return ((mtu, full),) + (((pad(rest + 1), 1),) if rest else ())


def dronecan_frame_split(payload_bytes: int) -> tuple[tuple[int, int], ...]:
    """The classic CAN frames of one DroneCAN transfer as (data length, how many) pairs (see cyphal_frame_split).

    >>> dronecan_frame_split(7), dronecan_frame_split(8), dronecan_frame_split(10 ** 9)
    (((8, 1),), ((8, 1), (4, 1)), ((8, 142857143), (2, 1)))
    """
    if payload_bytes < 0:
        raise ValueError(f"payload length must be >= 0, got {payload_bytes}")
    if payload_bytes <= 7:
        return ((payload_bytes + 1, 1),)
    full, rest = divmod(payload_bytes + 2, 7)
    return ((8, full),) + (((rest + 1, 1),) if rest else ())


def cyphal_frame_lengths(payload_bytes: int, mtu: int = CLASSIC_MTU) -> list[int]:
    """Data lengths (tail byte and CAN FD padding included) of the frames of one Cyphal/CAN transfer.

    >>> cyphal_frame_lengths(7), cyphal_frame_lengths(8), cyphal_frame_lengths(47)
    ([8], [8, 4], [8, 8, 8, 8, 8, 8, 8])
    >>> cyphal_frame_lengths(47, FD_MTU), cyphal_frame_lengths(63, FD_MTU), cyphal_frame_lengths(64, FD_MTU)
    ([48], [64], [64, 4])
    """
    if payload_bytes < 0 or mtu not in (CLASSIC_MTU, FD_MTU):
        raise ValueError(f"payload {payload_bytes} bytes, MTU {mtu}")
    pad = (lambda n: n) if mtu == CLASSIC_MTU else fd_frame_length
    per_frame = mtu - 1
    if payload_bytes <= per_frame:
        return [pad(payload_bytes + 1)]
    full, rest = divmod(payload_bytes + 2, per_frame)
    return [mtu] * full + ([pad(rest + 1)] if rest else [])


def dronecan_frame_lengths(payload_bytes: int) -> list[int]:
    """Data lengths (tail byte included) of the classic CAN frames of one DroneCAN (UAVCAN v0) transfer.

    >>> dronecan_frame_lengths(7), dronecan_frame_lengths(8), dronecan_frame_lengths(47)
    ([8], [8, 4], [8, 8, 8, 8, 8, 8, 8])
    """
    if payload_bytes < 0:
        raise ValueError(f"payload length must be >= 0, got {payload_bytes}")
    if payload_bytes <= 7:
        return [payload_bytes + 1]
    full, rest = divmod(payload_bytes + 2, 7)
    return [8] * full + ([rest + 1] if rest else [])


# ---- serialized sizes -------------------------------------------------------------------------------------------

def _bytes(bits: int) -> int:
    return -(-bits // 8)


def _cyphal_struct(lookup: Lookup, name: str | None) -> DsdlStruct:
    found = lookup(name or "")
    if found is None:
        raise ValueError(f"unknown DSDL type {name}")
    return found


def _cyphal_bits(t: DsdlType, lookup: Lookup) -> int:
    if t.array:
        one = _cyphal_bits(t.element, lookup)
        if t.array == "fixed":
            return one * (t.capacity or 0)
        prefix = 2 ** math.ceil(math.log2(max(8, (t.capacity or 0).bit_length())))
        return prefix + one * (t.capacity or 0)
    if t.kind != "composite":
        return t.bits
    nested = _cyphal_struct(lookup, t.composite)
    return 8 * cyphal_max_bytes(nested, lookup) if nested.sealed else 32 + 8 * (nested.extent or 0)


def cyphal_max_bytes(struct: DsdlStruct, lookup: Lookup) -> int:
    """The largest serialized size of a Cyphal v1 composite in bytes (pydsdl's rules: composites byte-aligned, a
    delimited nested one counts its 4-byte header and its extent, a union its tag and its largest field)."""
    fields = [f.type for f in struct.declared_fields]
    if struct.union:
        tag = 2 ** math.ceil(math.log2(max(8, (len(fields) - 1).bit_length())))
        return _bytes(tag + max(_cyphal_bits(t, lookup) for t in fields))  # type: ignore[arg-type]
    bits = 0
    for t in fields:
        assert isinstance(t, DsdlType)
        if t.kind == "composite" and not t.array:
            bits = 8 * _bytes(bits)
        elif t.array and t.element.kind == "composite":
            bits = 8 * _bytes(bits)
        bits += _cyphal_bits(t, lookup)
    return _bytes(bits)


def _v0_struct(lookup: V0Lookup, name: str | None) -> V0Struct:
    found = lookup(name or "")
    if found is None:
        raise ValueError(f"unknown UAVCAN v0 type {name}")
    return found


def _v0_min_bits(t: DsdlType, lookup: V0Lookup) -> int:
    """dronecan's get_min_bitlen, which decides the tail array optimisation (an element of >= 8 bits)."""
    if t.array == "fixed":
        return (t.capacity or 0) * _v0_min_bits(t.element, lookup)
    if t.array:
        return 0
    if t.kind != "composite":
        return t.bits
    s = _v0_struct(lookup, t.composite)
    lens = [_v0_min_bits(f.type, lookup) for f in s.declared_fields]  # type: ignore[arg-type]
    if not lens:
        return 0
    return min(lens) + max(len(lens) - 1, 1).bit_length() if s.union else sum(lens)


def _v0_bits(t: DsdlType, lookup: V0Lookup, tail: bool, length: int | None = None) -> int:
    if t.array:
        count = (t.capacity or 0) if length is None else length
        one = _v0_bits(t.element, lookup, False)
        if t.array == "fixed":
            return one * (t.capacity or 0)
        if tail and _v0_min_bits(t.element, lookup) >= 8:
            return one * count  # the tail array optimisation: no length prefix
        return math.ceil(math.log2((t.capacity or 0) + 1)) + one * count
    if t.kind != "composite":
        return t.bits
    return _v0_struct_bits(_v0_struct(lookup, t.composite), lookup, tail, {})


def _v0_struct_bits(s: V0Struct, lookup: V0Lookup, tail: bool, lengths: dict[str, int]) -> int:
    fields = s.declared_fields
    if s.union:
        tag = math.ceil(math.log2(len(fields))) if len(fields) > 1 else 0
        return tag + max(_v0_bits(f.type, lookup, tail) for f in fields)  # type: ignore[arg-type]
    total = 0
    for i, f in enumerate(fields):
        assert isinstance(f.type, DsdlType)
        total += _v0_bits(f.type, lookup, tail and i == len(fields) - 1, lengths.get(f.name))
    return total


def dronecan_max_bytes(struct: V0Struct, lookup: V0Lookup, lengths: dict[str, int] | None = None) -> int:
    """The largest payload of a DroneCAN message on classic CAN in bytes (tail array optimisation on); ``lengths``
    fixes the element count of top-level dynamic arrays (a broadcast command's written elements)."""
    return _bytes(_v0_struct_bits(struct, lookup, True, lengths or {}))


# ---- the budget -------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Bus:
    """A CAN bus: classic at ``bitrate``, or CAN FD (Cyphal at MTU 64) with its data phase at ``data_bitrate``."""

    bitrate: int = DEFAULT_BITRATE
    data_bitrate: int | None = None  # None: classic CAN
    warning_percent: float = DEFAULT_WARNING_PERCENT
    pos: Pos | None = None  # where the spec sets it

    @property
    def fd(self) -> bool:
        return self.data_bitrate is not None

    def describe(self) -> str:
        """
        >>> Bus().describe(), Bus(500_000, 2_000_000).describe()
        ('classic CAN 1 Mbit/s', 'CAN FD 500 kbit/s, data 2 Mbit/s')
        """
        def rate(bps: int) -> str:
            return f"{bps / 1e6:g} Mbit/s" if bps >= 1_000_000 else f"{bps / 1e3:g} kbit/s"
        return f"CAN FD {rate(self.bitrate)}, data {rate(self.data_bitrate)}" if self.data_bitrate \
            else f"classic CAN {rate(self.bitrate)}"


@dataclass(frozen=True)
class Transfer:
    """One periodic message a node sends: its type, nominal rate, payload size and protocol."""

    type: str
    rate_hz: float
    payload_bytes: int
    protocol: str  # cyphal | dronecan
    what: str = ""  # why it is sent: a port, a mapping's command, liveness

    def frame_lengths(self, bus: Bus) -> list[int]:
        """Every frame's data length, one by one (for tests and small payloads; the budget uses frame_split)."""
        return [n for n, count in self.frame_split(bus) for _ in range(count)]

    def frame_split(self, bus: Bus) -> tuple[tuple[int, int], ...]:
        if protocol_of(self.protocol).v0:
            return dronecan_frame_split(self.payload_bytes)
        return cyphal_frame_split(self.payload_bytes, FD_MTU if bus.fd else CLASSIC_MTU)

    def frame_count(self, bus: Bus) -> int:
        return sum(count for _, count in self.frame_split(bus))

    def frames_per_s(self, bus: Bus) -> float:
        return self.rate_hz * self.frame_count(bus)

    def bus_seconds_per_s(self, bus: Bus, *, worst_case: bool = False) -> float:
        """The share of the bus's time this message takes (1.0 = the whole bus)."""
        total = 0.0
        for n, count in self.frame_split(bus):
            if bus.data_bitrate is not None and protocol_of(self.protocol).can_fd:
                nominal, data = fd_frame_bits(n, worst_case=worst_case)
                total += count * (nominal / bus.bitrate + data / bus.data_bitrate)
            else:  # a classic frame (DroneCAN is classic on an FD bus too)
                total += count * classic_frame_bits(n, worst_case=worst_case) / bus.bitrate
        return self.rate_hz * total


@dataclass(frozen=True)
class NodeBudget:
    name: str
    node_id: int
    protocol: str
    transfers: tuple[Transfer, ...]

    def frames_per_s(self, bus: Bus) -> float:
        return sum(t.frames_per_s(bus) for t in self.transfers)

    def load(self, bus: Bus, *, worst_case: bool = False) -> float:
        return sum(t.bus_seconds_per_s(bus, worst_case=worst_case) for t in self.transfers)


@dataclass(frozen=True)
class LayoutBudget:
    layout: str
    bus: Bus
    nodes: tuple[NodeBudget, ...]
    pos: Pos

    @property
    def frames_per_s(self) -> float:
        return sum(n.frames_per_s(self.bus) for n in self.nodes)

    @property
    def load(self) -> float:
        return sum(n.load(self.bus) for n in self.nodes)

    @property
    def load_worst_case(self) -> float:
        return sum(n.load(self.bus, worst_case=True) for n in self.nodes)

    @property
    def verdict(self) -> str:
        percent = 100 * self.load_worst_case
        if percent > 100:
            return "over capacity"
        return f"above {self.bus.warning_percent:g} %" if percent > self.bus.warning_percent else "ok"

    def summary(self) -> str:
        """One line for `sam-codegen build`."""
        return (f"layout {self.layout}: {self.frames_per_s:,.0f} frames/s on {self.bus.describe()}, load "
                f"{100 * self.load:.1f} % ({100 * self.load_worst_case:.1f} % with worst-case stuffing): "
                f"{self.verdict}")

    def diagnostic(self) -> Diagnostic | None:
        """A spec error when the bus cannot carry the layout (over 100 % with worst-case stuffing)."""
        if self.load_worst_case <= 1.0:
            return None
        top = max(self.nodes, key=lambda n: n.load(self.bus, worst_case=True))
        return Diagnostic(self.pos, f"layout {self.layout!r} needs {100 * self.load_worst_case:.0f} % of its bus "
                          f"({self.bus.describe()}, worst-case bit stuffing; {self.frames_per_s:,.0f} frames/s; "
                          f"most from {top.name}: {100 * top.load(self.bus, worst_case=True):.0f} %)",
                          "a load of at most 100 %: lower rates, smaller types, CAN FD or a faster bus")

    def warning(self) -> str | None:
        if self.load_worst_case <= 1.0 and 100 * self.load_worst_case > self.bus.warning_percent:
            return (f"{self.pos}: warning: layout {self.layout!r} uses {100 * self.load_worst_case:.0f} % of its bus "
                    f"with worst-case stuffing, above the {self.bus.warning_percent:g} % threshold")
        return None


def bus_for(spec: Spec, layout: str) -> Bus | None:
    """The bus a layout runs on: its own `bus:`, else the spec's, else classic CAN at 1 Mbit/s; None for `bus: none`
    (no CAN bus, no budget)."""
    named = spec.layouts.get(layout)
    declared: CanBus | None = (named.bus if named is not None else None) or spec.bus
    if declared is None:
        return Bus()
    if not declared.present:
        return None
    return Bus(declared.bitrate, declared.fd_data_bitrate, declared.load_warning_percent, declared.pos)


def _liveness(protocol: str) -> Transfer:
    kind = protocol_of(protocol).liveness_type
    return Transfer(kind, LIVENESS_HZ, LIVENESS_BYTES, protocol, "liveness")


def _command_lengths(rm: ResolvedMapping) -> dict[str, int]:
    """A DroneCAN broadcast command's top-level arrays sized by what the mapping writes (positions 0..max, or one
    item per key)."""
    lengths = {}
    for path, uses in rm.elements.items():
        if len(path) == 1:
            positions = [u for u in uses if isinstance(u, int)]
            lengths[path[0][0]] = max(positions) + 1 if len(positions) == len(uses) else len(uses)
    return lengths


def layout_budgets(spec: Spec, layouts: list[ResolvedLayout], mappings: dict[str, list[ResolvedMapping]],
                   cyphal: Lookup, dronecan: V0Lookup, *, fd: bool | None = None) -> list[LayoutBudget]:
    """The budget of every layout on its bus (``fd``: force CAN FD at the bus's data bit rate or the default, or
    classic CAN; None: the bus the spec declares). ``mappings`` holds the resolved mappings by protocol."""
    result = []
    for layout in layouts:
        found = bus_for(spec, layout.name)
        if found is None:
            continue  # `bus: none`
        bus = found
        if fd is True and not bus.fd:
            bus = Bus(bus.bitrate, DEFAULT_FD_DATA_BITRATE, bus.warning_percent, bus.pos)
        elif fd is False and bus.fd:
            bus = Bus(bus.bitrate, None, bus.warning_percent, bus.pos)
        nodes: list[NodeBudget] = []
        for device in spec.devices.values():
            protocol = layout.protocols[device.name]
            if not protocol_of(protocol).v0:
                sent = [Transfer(p.type, p.rate_hz, cyphal_max_bytes(_cyphal_struct(cyphal, p.type), cyphal),
                                 "cyphal", f"subject {p.subject_id}") for p in device.publishes]
            else:
                sent = [Transfer(p.type, p.rate_hz, dronecan_max_bytes(_v0_struct(dronecan, p.type), dronecan),
                                 "dronecan") for p in device.dronecan_publishes]
            nodes.append(NodeBudget(device.name, device.node_id, protocol, (*sent, _liveness(protocol))))
        if spec.bridge is not None:
            for protocol, active in ((p.name, layout.mappings_of(p)) for p in registered()):
                commands = []
                for rm in mappings.get(protocol, []):
                    m = rm.mapping
                    if m.name not in active or m.direction != "ros_to_uavcan":
                        continue
                    if not protocol_of(protocol).v0:
                        commands.append(Transfer(rm.dsdl_struct.name, rm.rate_hz,
                                                 cyphal_max_bytes(rm.dsdl_struct, cyphal), protocol,
                                                 f"mapping {m.name}, subject {m.subject_id}"))
                    else:
                        assert isinstance(rm.dsdl_struct, V0Struct)
                        commands.append(Transfer(m.data_type, rm.rate_hz, dronecan_max_bytes(
                            rm.dsdl_struct, dronecan, _command_lengths(rm)), protocol, f"mapping {m.name}"))
                if layout.devices(protocol):  # a bridge node per protocol its devices speak
                    nodes.append(NodeBudget(spec.bridge.name, spec.bridge.node_id, protocol,
                                            (*commands, _liveness(protocol))))
        # Where an overload is reported: the layout's own `bus`, else the named layout, else the spec's `bus`, else
        # (the implicit default layout has no place in the file) the device that loads the bus most.
        named = spec.layouts.get(layout.name)
        heaviest = max((n for n in nodes if n.name in spec.devices), key=lambda n: n.load(bus), default=None)
        if named is not None:
            pos = named.bus.pos if named.bus is not None else named.pos
        elif spec.bus is not None:
            pos = spec.bus.pos
        else:
            pos = spec.devices[heaviest.name].pos if heaviest is not None else Pos(spec.file)
        result.append(LayoutBudget(layout.name, bus, tuple(nodes), pos))
    return result


def check_bus_budgets(spec: Spec, layouts: list[ResolvedLayout], mappings: dict[str, list[ResolvedMapping]],
                      cyphal: Lookup, dronecan: V0Lookup) -> None:
    """Raise SpecError when a layout's bus cannot carry it (over 100 % with worst-case stuffing)."""
    errors = [d for d in (b.diagnostic() for b in layout_budgets(spec, layouts, mappings, cyphal, dronecan))
              if d is not None]
    if errors:
        raise SpecError(errors)
