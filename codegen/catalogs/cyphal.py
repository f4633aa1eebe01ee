"""Standard DSDL types (uavcan.*, reg.*) read with pydsdl from CYPHAL_PATH into the spec's model."""

from __future__ import annotations

from pathlib import Path

import pydsdl

from sam_codegen.model.spec import Constant, DsdlStruct, Field, Spec
from sam_codegen.model.types import ArrayKind, DsdlType, split_composite_name
from sam_codegen.project.cyphal_path import dsdl_lookup_roots


def dsdl_file_for(name: str, roots: list[Path]) -> Path | None:
    """The .dsdl file that defines `ns.Name.MAJ.MIN` under one of the root namespace dirs."""
    full, major, minor = split_composite_name(name)
    parts = full.split(".")
    for root in roots:
        if root.name != parts[0]:
            continue
        folder = root.joinpath(*parts[1:-1])
        for candidate in (folder.glob(f"*{parts[-1]}.{major}.{minor}.dsdl") if folder.is_dir() else []):
            # File names are [PORT_ID.]Name.MAJOR.MINOR.dsdl.
            if candidate.name.split(".")[-4] == parts[-1]:
                return candidate
    return None


def from_pydsdl(data_type: pydsdl.Any) -> DsdlType:
    """Translate a pydsdl field type into the spec's DsdlType."""
    if isinstance(data_type, pydsdl.ArrayType):
        element = from_pydsdl(data_type.element_type)
        kind: ArrayKind = "fixed" if isinstance(data_type, pydsdl.FixedLengthArrayType) else "bounded"
        return DsdlType(element.kind, element.bits, element.composite, kind, data_type.capacity, element.truncated)
    if isinstance(data_type, pydsdl.CompositeType):
        version = data_type.version
        return DsdlType("composite", composite=f"{data_type.full_name}.{version.major}.{version.minor}")
    truncated = getattr(data_type, "cast_mode", None) == pydsdl.PrimitiveType.CastMode.TRUNCATED
    if isinstance(data_type, pydsdl.BooleanType):
        return DsdlType("bool", 1)
    if isinstance(data_type, pydsdl.ByteType):
        return DsdlType("byte", 8)
    if isinstance(data_type, pydsdl.UTF8Type):
        return DsdlType("utf8", 8)
    if isinstance(data_type, pydsdl.VoidType):
        return DsdlType("void", data_type.bit_length)
    if isinstance(data_type, pydsdl.UnsignedIntegerType):
        return DsdlType("uint", data_type.bit_length, truncated=truncated)
    if isinstance(data_type, pydsdl.SignedIntegerType):
        return DsdlType("int", data_type.bit_length)
    if isinstance(data_type, pydsdl.FloatType):
        return DsdlType("float", data_type.bit_length, truncated=truncated)
    raise ValueError(f"unsupported DSDL type {data_type}")


def _to_struct(composite: pydsdl.CompositeType) -> DsdlStruct:
    name = f"{composite.full_name}.{composite.version.major}.{composite.version.minor}"
    layout = [Field(f.name, from_pydsdl(f.data_type), f.doc or "") for f in composite.fields]
    fields = [f for f in layout if f.name]  # void padding has no name
    constants = [Constant(c.name, from_pydsdl(c.data_type), c.value.native_value, c.doc or "")
                 for c in composite.constants]
    sealed = not isinstance(composite, pydsdl.DelimitedType)
    return DsdlStruct(name, fields, constants, composite.doc or "", sealed, None if sealed else composite.extent // 8,
                      standard=True, union=isinstance(composite.inner_type, pydsdl.UnionType),
                      layout=layout if len(fields) < len(layout) else [])


def read_service(name: str, roots: list[Path]) -> tuple[DsdlStruct, DsdlStruct, int | None] | None:
    """A standard Cyphal service type's request and response (named `<name>.Request`/`.Response`) and its fixed
    port id; None when `name` is no service type under `roots`."""
    try:
        path = dsdl_file_for(name, roots)
    except ValueError:
        return None
    if path is None:
        return None
    root = roots[[r.name for r in roots].index(name.split(".")[0])]
    direct, _ = pydsdl.read_files([path], [root], roots)
    service = next((t for t in direct if isinstance(t, pydsdl.ServiceType)), None)
    if service is None:
        return None
    return _to_struct(service.request_type), _to_struct(service.response_type), service.fixed_port_id


class DsdlCatalog:
    """Looks DSDL composite types up by versioned full name: the spec's own first, then CYPHAL_PATH."""

    def __init__(self, spec: Spec, roots: list[Path] | None = None) -> None:
        self._spec = spec
        self._roots = roots
        self._cache: dict[str, DsdlStruct | None] = {}

    @property
    def roots(self) -> list[Path]:
        if self._roots is None:
            self._roots = dsdl_lookup_roots()
        return self._roots

    def get(self, name: str) -> DsdlStruct | None:
        if name in self._spec.dsdl_types:
            return self._spec.dsdl_types[name]
        if name not in self._cache:
            self._load(name)
        return self._cache.get(name)

    def service(self, name: str) -> tuple[DsdlStruct, DsdlStruct, int | None] | None:
        """A Cyphal service type's request, response and fixed port id: the spec's own (no fixed port id) or a
        standard one."""
        own = self._spec.dsdl_services.get(name)
        if own is not None:
            return own.request, own.response, None
        return read_service(name, self.roots)

    def _load(self, name: str) -> None:
        self._cache[name] = None
        try:
            path = dsdl_file_for(name, self.roots)
        except ValueError:
            return
        if path is None:
            return
        root = self.roots[[r.name for r in self.roots].index(name.split(".")[0])]
        direct, transitive = pydsdl.read_files([path], [root], self.roots)
        for composite in [*direct, *transitive]:
            struct = _to_struct(composite)
            if self._cache.get(struct.name) is None:
                self._cache[struct.name] = struct
