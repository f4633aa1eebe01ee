"""UAVCAN v0 (DroneCAN) types: the standard ones, read from the `dronecan` package's definitions, and the spec's own;
their data type ids and signatures.

The standard definitions are the `.uavcan` files dronecan itself loads (its `dsdl_specs/` folder: the root namespaces
uavcan, dronecan, ardupilot, com, cuav), found without importing dronecan (whose import parses every definition).
DRONECAN_DSDL_PATH, folders holding such root namespaces separated by `:`, replaces them (e.g. a DroneCAN/DSDL
checkout). Files are read on demand; the signature is computed here as dronecan's parser computes it (the tests
compare the two over every standard type).

Which standard namespaces a spec uses is its choice (`dronecan_namespaces`: root namespaces such as `ardupilot`, or
namespaces inside one such as `com.hobbywing`; `uavcan` always): the catalog knows only the definitions inside them
(`files`, `get`, `standard_ids`), so a type of another namespace is unknown and its data type id free for the spec's
own types. Without the key it knows every definition (`all_files`), as dronecan.load_dsdl() loads them.

Invariant: the catalog changes no struct. `get` gives a type as declared (its `signature` 0); `signed` gives it with
the data type signature, computed on demand: what an emitter of ids and signatures reads.
"""

from __future__ import annotations

import ast
import importlib.util
import os
import re
import struct
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

from sam_codegen.model.spec import Constant, Field, Spec, V0Struct
from sam_codegen.model.types import DsdlType, parse_v0_type, v0_normalized

# The root namespaces dronecan.load_dsdl() reads from its own definitions (its other folders it leaves alone).
DRONECAN_ROOTS = ("uavcan", "dronecan", "ardupilot", "com", "cuav")
TIMESTAMP = "uavcan.Timestamp"  # truncated uint56 usec; 0 = unknown
MESSAGE_ID_MAX = 65535
SERVICE_ID_MAX = 255
VENDOR_MESSAGE_IDS = range(20000, 21000)  # DroneCAN's vendor-specific message range
VENDOR_SERVICE_IDS = range(200, 256)  # DroneCAN's vendor-specific service range

_MASK64 = 0xFFFFFFFFFFFFFFFF
_POLY64 = 0x42F0E1EBA9EA3693


class V0CatalogError(Exception):
    """The standard definitions cannot be found or one of them cannot be read."""


# ---- signatures ------------------------------------------------------------------------------------------------


def crc64we(data: bytes, value: int | None = None) -> int:
    """CRC-64-WE (the v0 signature hash), optionally continuing from a previous `value`.

    >>> hex(crc64we(b"123456789"))
    '0x62ec59e3f1a4f00a'
    >>> crc64we(b"456789", crc64we(b"123")) == crc64we(b"123456789")
    True
    """
    crc = _MASK64 if value is None else (value & _MASK64) ^ _MASK64
    for byte in data:
        crc ^= (byte << 56) & _MASK64
        for _ in range(8):
            crc = ((crc << 1) & _MASK64) ^ _POLY64 if crc & (1 << 63) else crc << 1
    return (crc & _MASK64) ^ _MASK64


def normalized_definition(name: str, layout: list[Field], union: bool = False,
                          response: tuple[list[Field], bool] | None = None) -> str:
    """The normalized definition the DSDL signature hashes: the full name, then one line per field (void padding
    included, constants not), as `<cast> <type> <name>`.

    >>> f = [Field("usec", parse_v0_type("truncated uint56"))]
    >>> normalized_definition("uavcan.Timestamp", f)
    'uavcan.Timestamp\\ntruncated uint56 usec'
    """
    def lines(fields: list[Field]) -> str:
        return "\n".join(v0_normalized(f.type) + (f" {f.name}" if f.name else "")  # type: ignore[arg-type]
                         for f in fields) + "\n"

    text = name + "\n" + ("\n@union\n" if union else "") + lines(layout)
    if response is not None:
        text += "\n---\n" + ("\n@union\n" if response[1] else "") + lines(response[0])
    return text.strip().replace("\n\n\n", "\n").replace("\n\n", "\n")


def data_type_signature(dsdl_signature: int, nested: list[int]) -> int:
    """A type's data type signature: its DSDL signature extended, per field of a composite type (or array of one),
    with that type's data type signature and the value so far (little-endian 64-bit each)."""
    value = dsdl_signature
    for field_signature in nested:
        value = crc64we(struct.pack("<Q", field_signature) + struct.pack("<Q", value), value)
    return value


# ---- the definition files --------------------------------------------------------------------------------------


@dataclass
class _Definition:
    """One `.uavcan` file, parsed."""

    struct: V0Struct
    layout: list[Field]  # request (or message) fields, void padding included
    response: tuple[list[Field], bool] | None  # services: response fields and union
    override_signature: int | None


_LINE_COMMENT = re.compile(r"#.*")


def _literal(text: str) -> bool | int | float | None:
    try:
        value = ast.literal_eval(text.replace("true", "True").replace("false", "False"))
    except (ValueError, SyntaxError):
        return None  # an expression dronecan evaluates; constants are not needed for mapping
    if isinstance(value, str) and len(value) == 1:
        return ord(value)
    return value if isinstance(value, (bool, int, float)) else None


def parse_definition(text: str, full_name: str, data_type_id: int | None, source: str = "") -> _Definition:
    """Parse the text of a v0 definition file of type `full_name`; relative type names are resolved in its
    namespace. Raises ValueError with the line number on a line it cannot read."""
    namespace = full_name.rsplit(".", 1)[0]
    parts: list[tuple[list[Field], list[Constant], bool]] = [([], [], False)]
    override = None
    for number, raw in enumerate(text.splitlines(), 1):
        tokens = _LINE_COMMENT.sub("", raw).split()
        if not tokens:
            continue
        if tokens == ["---"]:
            if len(parts) > 1:
                raise ValueError(f"line {number}: a second '---'")
            parts.append(([], [], False))
            continue
        if tokens == ["@union"]:
            fields, constants, _ = parts[-1]
            parts[-1] = (fields, constants, True)
            continue
        if len(tokens) == 2 and tokens[0] == "OVERRIDE_SIGNATURE":
            override = int(tokens[1], 16)
            continue
        cast = ""
        if tokens[0] in ("saturated", "truncated"):
            cast, tokens = tokens[0] + " ", tokens[1:]
        if not tokens:
            raise ValueError(f"line {number}: a cast mode without a type")
        type_text = tokens[0]
        element = type_text.split("[", 1)[0]
        if "." not in element and element[:1].isupper():  # relative: in this type's namespace
            type_text = f"{namespace}.{type_text}"
        try:
            t = parse_v0_type(cast + type_text)
        except ValueError as exc:
            raise ValueError(f"line {number}: {exc}") from None
        if t.kind == "void":
            parts[-1][0].append(Field("", t))
        elif len(tokens) >= 4 and tokens[2] == "=":
            value = _literal("".join(tokens[3:]))
            if value is not None:
                parts[-1][1].append(Constant(tokens[1], t, value))
        elif len(tokens) == 2:
            parts[-1][0].append(Field(tokens[1], t))
        else:
            raise ValueError(f"line {number}: expected `<type> <name>` or `<type> <NAME> = <value>`")
    layout, constants, union = parts[0]
    struct_ = V0Struct(
        full_name, [f for f in layout if f.name], constants, standard=True, union=union,
        layout=layout if any(not f.name for f in layout) else [], data_type_id=data_type_id,
        service=len(parts) > 1, source=source,
        response=[f for f in parts[1][0] if f.name] if len(parts) > 1 else [],
        response_layout=parts[1][0] if len(parts) > 1 and any(not f.name for f in parts[1][0]) else [],
    )
    response = (parts[1][0], parts[1][2]) if len(parts) > 1 else None
    return _Definition(struct_, layout, response, override)


def standard_roots() -> list[Path]:
    """The root namespace folders of the standard definitions: DRONECAN_DSDL_PATH's, else the dronecan package's."""
    configured = os.environ.get("DRONECAN_DSDL_PATH", "")
    if configured:
        return [Path(folder) / root for folder in configured.split(os.pathsep) if folder
                for root in DRONECAN_ROOTS if (Path(folder) / root).is_dir()]
    return list(_package_roots())


@cache
def _package_roots() -> tuple[Path, ...]:
    try:
        spec = importlib.util.find_spec("dronecan")
    except (ImportError, ValueError):
        spec = None
    locations = list(spec.submodule_search_locations or []) if spec is not None else []
    for location in locations:
        specs = Path(location) / "dsdl_specs"
        if specs.is_dir():
            return tuple(specs / root for root in DRONECAN_ROOTS if (specs / root).is_dir())
    return ()


def _file_name_parts(name: str) -> tuple[int | None, str] | None:
    """`1003.RawIMU.uavcan` -> (1003, "RawIMU"); `Timestamp.uavcan` -> (None, "Timestamp"); None: not a type file.

    >>> _file_name_parts("1003.RawIMU.uavcan"), _file_name_parts("Timestamp.uavcan"), _file_name_parts("x.txt")
    ((1003, 'RawIMU'), (None, 'Timestamp'), None)
    """
    items = name.split(".")
    if items[-1] != "uavcan" or len(items) not in (2, 3, 4, 5):
        return None
    if len(items) in (3, 5):
        try:
            return int(items[0]), items[1]
        except ValueError:
            return None
    return None, items[0]


def in_namespaces(name: str, namespaces: tuple[str, ...]) -> bool:
    """Whether the full name `name` lies in one of `namespaces` (a namespace holds what its name prefixes).

    >>> in_namespaces("com.hobbywing.esc.RawCommand", ("uavcan", "com.hobbywing"))
    True
    >>> in_namespaces("com.hobbywingx.Thing", ("com.hobbywing",)), in_namespaces("uavcan.Timestamp", ("uavcan",))
    (False, True)
    """
    return any(name.startswith(ns + ".") for ns in namespaces)


class V0Catalog:
    """Looks v0 types up by full name: the spec's own `dronecan_types` first, then the standard definitions of the
    namespaces the spec uses."""

    def __init__(self, spec: Spec, roots: list[Path] | None = None) -> None:
        self._spec = spec
        self._roots = roots
        self._all_files: dict[str, tuple[Path, int | None]] | None = None
        self._files: dict[str, tuple[Path, int | None]] | None = None
        self._definitions: dict[str, _Definition | None] = {}
        self._signatures: dict[str, int] = {}
        self._signed: dict[str, V0Struct] = {}
        self.errors: list[str] = []  # standard files that could not be read (reported once by the validator)

    @property
    def roots(self) -> list[Path]:
        if self._roots is None:
            self._roots = standard_roots()
        return self._roots

    def all_files(self) -> dict[str, tuple[Path, int | None]]:
        """Every standard type, whatever the spec uses: full name -> (file, data type id)."""
        if self._all_files is None:
            self._all_files = {}
            for root in self.roots:
                for path in sorted(root.rglob("*.uavcan")):
                    parts = _file_name_parts(path.name)
                    if parts is None:
                        continue
                    namespace = ".".join([root.name, *path.relative_to(root).parent.parts])
                    self._all_files.setdefault(f"{namespace}.{parts[1]}", (path, parts[0]))
        return self._all_files

    @property
    def namespaces(self) -> tuple[str, ...]:
        """The namespaces of the standard definitions the spec uses: `uavcan` and its `dronecan_namespaces`, or
        every root namespace when it has none (the default)."""
        chosen = self._spec.dronecan_namespaces
        if chosen is None:
            return tuple(dict.fromkeys(["uavcan", *(r.name for r in self.roots)]))
        return tuple(dict.fromkeys(["uavcan", *chosen]))

    def known_namespaces(self) -> set[str]:
        """Every namespace of the standard definitions, the root ones and those inside them."""
        result: set[str] = set()
        for name in self.all_files():
            parts = name.split(".")[:-1]
            result.update(".".join(parts[:k]) for k in range(1, len(parts) + 1))
        return result

    def files(self) -> dict[str, tuple[Path, int | None]]:
        """Every standard type of the namespaces the spec uses: full name -> (file, data type id)."""
        if self._files is None:
            namespaces = self.namespaces
            self._files = {name: entry for name, entry in self.all_files().items() if in_namespaces(name, namespaces)}
        return self._files

    def standard_ids(self) -> dict[tuple[bool, int], str]:
        """(service?, data type id) -> full name of every standard type with an id."""
        result: dict[tuple[bool, int], str] = {}
        for name, (path, dtid) in self.files().items():
            if dtid is not None:
                result.setdefault((_is_service_file(path), dtid), name)
        return result

    def get(self, name: str) -> V0Struct | None:
        if name in self._spec.dronecan_types:
            return self._spec.dronecan_types[name]
        definition = self._definition(name)
        return definition.struct if definition is not None else None

    def signed(self, name: str) -> V0Struct | None:
        """The type `name` with its data type signature (0 when a type it nests is unknown or nests itself)."""
        if name not in self._signed:
            struct = self.get(name)
            if struct is None:
                return None
            self._signed[name] = replace(struct, signature=self.signature(name))
        return self._signed[name]

    def is_standard(self, name: str) -> bool:
        return name in self.files()

    def _definition(self, name: str) -> _Definition | None:
        if name not in self._definitions:
            self._definitions[name] = None
            entry = self.files().get(name)
            if entry is not None:
                path, dtid = entry
                try:
                    self._definitions[name] = parse_definition(path.read_text(encoding="utf-8"), name, dtid, str(path))
                except (OSError, UnicodeDecodeError, ValueError) as exc:
                    self.errors.append(f"{path}: {exc}")
        return self._definitions[name]

    def signature(self, name: str, _stack: tuple[str, ...] = ()) -> int:
        """The data type signature of a type (0 when it or a type it nests is unknown or nests itself)."""
        if name in self._signatures:
            return self._signatures[name]
        if name in _stack:
            return 0
        declared = self._spec.dronecan_types.get(name)
        if declared is not None:
            layout, response, override, union = declared.declared_fields, None, None, declared.union
            if declared.service:
                response = (declared.declared_response, False)
        else:
            definition = self._definition(name)
            if definition is None:
                return 0
            layout, response, override = definition.layout, definition.response, definition.override_signature
            union = definition.struct.union
        fields = layout + (response[0] if response else [])
        nested = []
        for f in fields:
            t = f.type
            if isinstance(t, DsdlType) and t.kind == "composite" and t.composite:
                inner = self.signature(t.composite, (*_stack, name))
                if inner == 0:
                    return 0
                nested.append(inner)
        dsdl = override if override is not None else crc64we(
            normalized_definition(name, layout, union, response).encode())
        value = data_type_signature(dsdl, nested)
        self._signatures[name] = value
        return value


def _is_service_file(path: Path) -> bool:
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return False
    return any(_LINE_COMMENT.sub("", line).strip() == "---" for line in lines)
