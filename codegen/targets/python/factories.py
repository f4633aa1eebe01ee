"""The fast constructors of convert.py: one per ROS message class and pycyphal class the converters build, writing
the slots their setters would write (the converters have checked ranges and lengths already).

Invariant: a Factory says what its code needs (numpy, copy): convert.py's imports come from these flags, never from
searching the generated text.
"""

from __future__ import annotations

from dataclasses import dataclass

from sam_codegen.model.spec import DsdlStruct
from sam_codegen.model.types import ROS_FLOAT_BITS, ROS_INT_RANGES, DsdlType, RosType
from sam_codegen.render.pysource import LINE_LIMIT, typed_literal
from sam_codegen.targets.python.module import PycyphalObjects
from sam_codegen.targets.python.names import dsdl_factory_name, py_attr, ros_factory_name

# rosidl_generator_py keeps fixed-size arrays of these in numpy arrays (`char` is uint8 in ROS 2 IDL).
_NUMPY_BASES = frozenset(base for base in [*ROS_INT_RANGES, *ROS_FLOAT_BITS] if base != "byte")
_PY_TYPES = {"bool": "bool", "byte": "bytes", "string": "str", "wstring": "str"}


@dataclass(frozen=True)
class FactoryField:
    """How a constructor sets one slot: one `line`, or if/elif/else `branches` ((condition or None, statement))."""

    line: str | None = None
    branches: tuple[tuple[str | None, str], ...] = ()


@dataclass(frozen=True)
class Factory:
    """One fast constructor of convert.py, as templates/python/convert.py.j2 writes it."""

    name: str
    cls: str  # the class it stands in for
    ros: bool
    params: tuple[str, ...]
    fields: tuple[FactoryField, ...]
    prototype: str | None  # a default instance whose arrays the defaults copy
    uses_numpy: bool = False
    uses_copy: bool = False


def _factory_field(slot: str, param: str, default: str, given: list[tuple[str | None, str]] | None = None
                   ) -> FactoryField:
    """One field of a generated constructor: `default` when the argument is None, else `given` (if/elif/else
    branches: (condition or None, statement)); by default the argument goes into the slot as it is."""
    if given is None:
        line = f"_m.{slot} = {default} if {param} is None else {param}"
        if len(line) + 4 <= LINE_LIMIT - 30:
            return FactoryField(line=line)
        given = [(None, f"_m.{slot} = {param}")]
    return FactoryField(branches=((f"{param} is None", f"_m.{slot} = {default}"), *given))


def ros_factory(module: PycyphalObjects, full: str) -> Factory:
    """What templates/python/convert.py.j2 needs to write the fast constructor of one ROS message class.

    Scalars, strings and nested messages go straight into their slots, as rosidl_generator_py's setters put them
    when field checks are off; arrays go through the setters (which convert to numpy / array.array), and their
    defaults are copies of a default instance's.
    """
    message = module.ros_message(full)
    alias = module.ros_aliases[full]
    prototype = f"_DEFAULT_{alias}"
    params: list[str] = []
    fields: list[FactoryField] = []
    uses_prototype = uses_copy = False
    for f in message.fields:
        t = f.type
        assert isinstance(t, RosType)
        if t.array:
            params.append(f"{f.name}: Any = None")
            if not t.is_primitive:
                nested = ros_factory_name(module.ros_aliases[t.base])
                default = f"[{nested}() for _ in range({t.capacity})]" if t.array == "fixed" else "[]"
            elif t.array == "fixed" and t.base in _NUMPY_BASES:
                default, uses_prototype = f"{prototype}._{f.name}.copy()", True
            else:
                default, uses_prototype, uses_copy = f"_copy({prototype}._{f.name})", True, True
            # the setter converts a given sequence to the class's array type
            fields.append(_factory_field(f"_{f.name}", f.name, default, [(None, f"_m.{f.name} = {f.name}")]))
        elif not t.is_primitive:
            params.append(f"{f.name}: {module.ros_aliases[t.base]} | None = None")
            fields.append(_factory_field(f"_{f.name}", f.name, f"{ros_factory_name(module.ros_aliases[t.base])}()"))
        else:
            py_type = _PY_TYPES.get(t.base, "float" if t.base in ROS_FLOAT_BITS else "int")
            default = typed_literal(f.default if f.default is not None else 0, t.base)
            if t.base in ("string", "wstring") and f.default is None:
                default = "''"
            params.append(f"{f.name}: {py_type} = {default}")
            fields.append(FactoryField(line=f"_m._{f.name} = {f.name}"))
    return Factory(ros_factory_name(alias), alias, True, tuple(params), tuple(fields),
                   prototype if uses_prototype else None, uses_copy=uses_copy)


def _numpy_dtype(t: DsdlType) -> str:
    """The numpy element type pycyphal (nunavut 2.3) keeps a primitive array in.

    >>> [_numpy_dtype(DsdlType(k, b)) for k, b in (("float", 16), ("int", 18), ("uint", 7), ("bool", 1), ("utf8", 8))]
    ['_np.float16', '_np.int32', '_np.uint8', '_np.bool_', '_np.uint8']
    """
    if t.kind == "float":
        return f"_np.float{t.bits}"
    if t.kind == "bool":
        return "_np.bool_"
    if t.kind in ("byte", "utf8"):
        return "_np.uint8"
    bits = next(b for b in (8, 16, 32, 64) if b >= t.bits)
    return f"_np.{t.kind}{bits}"


def dsdl_factory(module: PycyphalObjects, struct: DsdlStruct) -> Factory:
    """What templates/python/convert.py.j2 needs to write the fast constructor of one pycyphal class.

    Values go straight into the attributes pycyphal's properties keep them in (`_<name>`), converted as its
    setters convert them; the converters have already checked ranges and lengths, which the setters check again.
    """
    params: list[str] = []
    fields: list[FactoryField] = []
    uses_numpy = False
    for f in struct.fields:
        t = f.type
        assert isinstance(t, DsdlType)
        if t.kind == "void":
            continue
        name = py_attr(f.name)
        if t.kind == "composite":
            nested = module.struct(t.composite)  # type: ignore[arg-type]
            params.append(f"{name}: Any = None")
            fields.append(_factory_field(f"_{name}", name, f"{module.dsdl_new(nested)}()"))
        elif t.array or t.kind == "utf8":
            dtype, uses_numpy = _numpy_dtype(t), True
            default = f"_np.zeros({t.capacity}, {dtype})" if t.array == "fixed" else f"_np.array([], {dtype})"
            given: list[tuple[str | None, str]] = [(None, f"_m._{name} = _np.array({name}, {dtype})")]
            if dtype == "_np.uint8":  # pycyphal takes bytes for these too (utf8 text, byte strings)
                given.insert(0, (f"{name}.__class__ is bytes", f"_m._{name} = _np.frombuffer({name}, _np.uint8)"))
            params.append(f"{name}: Any = None")
            fields.append(_factory_field(f"_{name}", name, default, given))
        elif t.kind == "float":
            params.append(f"{name}: float = 0.0")
            fields.append(FactoryField(line=f"_m._{name} = float({name})"))
        else:
            params.append(f"{name}: {'bool' if t.kind == 'bool' else 'int'} = {'False' if t.kind == 'bool' else '0'}")
            fields.append(FactoryField(line=f"_m._{name} = {name}"))
    return Factory(dsdl_factory_name(struct), module.dsdl_ref(struct), False, tuple(params), tuple(fields), None,
                   uses_numpy=uses_numpy)
