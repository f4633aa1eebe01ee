"""Reference (b) of the converter benchmark: a generic, reflection-based field copier.

One interpreter for every mapping: the spec's resolved field links (``ros.path: uavcan.path`` with scale,
offset, table, constant value) are walked at run time for every message - paths followed with
getattr/index, the destination's type found by looking at the field it replaces (float, int, bool, list,
numpy array), the value coerced to it and written with setattr. This is what a bridge without generated code
does (e.g. a dict- or introspection-driven copier). Same semantics as the generated converters for in-range
values; no saturation counting.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

PathSeg = tuple[str, int | None]


def _get(obj: Any, path: tuple[PathSeg, ...]) -> Any:
    for name, index in path:
        obj = getattr(obj, name)
        if index is not None:
            obj = obj[index]
    return obj


def _name(path: tuple[PathSeg, ...]) -> str:
    """``a.b[2]``: the counter key of a path (as convert.py's).

    >>> _name((("a", None), ("b", 2)))
    'a.b[2]'
    """
    return ".".join(name if index is None else f"{name}[{index}]" for name, index in path)


def _set(obj: Any, path: tuple[PathSeg, ...], value: Any) -> None:
    for name, index in path[:-1]:
        obj = getattr(obj, name)
        if index is not None:
            obj = obj[index]
    name, index = path[-1]
    if index is None:
        current = getattr(obj, name)
        setattr(obj, name, _coerce(value, current))
    else:
        seq = getattr(obj, name)
        seq[index] = _coerce(value, seq[index])


def _coerce(value: Any, like: Any) -> Any:
    """Reflection: make value the kind of thing the destination holds now."""
    if hasattr(value, "tolist"):  # numpy scalar or array
        value = value.tolist()
    if isinstance(like, bool):
        return bool(value)
    if isinstance(like, float) or type(like).__name__.startswith("float"):
        return float(value)
    if isinstance(like, int) or type(like).__name__.startswith(("int", "uint")):
        return round(value) if isinstance(value, float) else int(value)
    if isinstance(value, list | tuple) and (isinstance(like, list | tuple) or hasattr(like, "__len__")):
        kind = _element_kind(like)
        out = [_coerce(v, kind) for v in value]
        size = _fixed_size(like)
        if size is not None and len(out) < size:
            out += [kind] * (size - len(out))  # zero = unknown
        return out
    return value


def _element_kind(seq: Any) -> Any:
    dtype = getattr(seq, "dtype", None)
    if dtype is not None:
        return 0.0 if dtype.kind == "f" else 0
    typecode = getattr(seq, "typecode", None)
    if typecode is not None:
        return 0.0 if typecode in "fd" else 0
    return seq[0] if len(seq) else 0.0


def _fixed_size(seq: Any) -> int | None:
    # ROS fixed arrays are numpy arrays of their full size; bounded/unbounded ones are array.array or list.
    return len(seq) if hasattr(seq, "dtype") and len(seq) > 0 else None


class GenericMapping:
    """Converters of one mapping that interpret its resolved steps at run time."""

    def __init__(self, resolved: Any, ros_cls: type, dsdl_cls: type, frame_id: str | None) -> None:
        self.name = resolved.mapping.name
        self.ros_cls, self.dsdl_cls = ros_cls, dsdl_cls
        self.frame_id = frame_id
        self.has_header = resolved.has_header
        self.steps = list(resolved.steps)
        self.uavcan_values = list(resolved.uavcan_values)

    # UAVCAN -> ROS
    def to_ros(self, src: Any, receive_ns: int, stats: Any) -> Any:
        msg = self.ros_cls()
        stamped = False
        for step in self.steps:
            kind = step.kind
            if kind == "value":
                _set(msg, step.ros_path, step.value)
                continue
            value = _get(src, step.uavcan_path)
            if kind == "time":
                us = int(value)
                ns = receive_ns if us == 0 else us * 1000
                stamp = _get(msg, step.ros_path)
                stamp.sec, stamp.nanosec = divmod(ns, 1_000_000_000)
                stamped = stamped or step.ros_path == (("header", None), ("stamp", None))
                continue
            if kind == "table":
                value = dict(step.table).get(int(value), step.table_default)
                if value is None:  # a key the table does not list, and no default: rejected
                    stats.reject(f"{self.name}.{_name(step.uavcan_path)}")
                    return None
            elif step.scale is not None or step.offset is not None:
                scale, offset = step.scale or 1.0, step.offset or 0.0
                if hasattr(value, "tolist"):
                    value = value.tolist()
                value = [v * scale + offset for v in value] if isinstance(value, list) else value * scale + offset
            _set(msg, step.ros_path, value)
        if self.has_header:
            if self.frame_id:
                msg.header.frame_id = self.frame_id
            if not stamped:
                msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(receive_ns, 1_000_000_000)
        return msg

    # ROS -> UAVCAN
    def to_uavcan(self, src: Any, stats: Any) -> Any:
        obj = self.dsdl_cls()
        for step in self.steps:
            kind = step.kind
            if kind == "value":
                continue
            value = _get(src, step.ros_path)
            if kind == "time":
                _set(obj, step.uavcan_path, value.sec * 1_000_000 + value.nanosec // 1000)
                continue
            if kind == "table":
                inverse: dict[int, int] = {}
                for k, v in step.table:
                    inverse.setdefault(v, k)
                value = inverse.get(int(value))
                if value is None:  # no key has this value: rejected
                    stats.reject(f"{self.name}.{_name(step.uavcan_path)}")
                    return None
            else:
                if step.scale is not None or step.offset is not None:
                    scale, offset = step.scale or 1.0, step.offset or 0.0
                    if hasattr(value, "tolist"):
                        value = value.tolist()
                    if isinstance(value, list):
                        value = [(v - offset) / scale for v in value]
                    else:
                        value = (value - offset) / scale
                if step.limits is not None:
                    lo, hi = step.limits
                    value = min(max(value, lo), hi)
            if hasattr(value, "tolist"):
                value = value.tolist()
            if isinstance(value, list):
                _set_array(obj, step.uavcan_path, value)
            else:
                _set(obj, step.uavcan_path, value)
        for path, _leaf, value in self.uavcan_values:
            _set(obj, path, value)
        return obj


def _set_array(obj: Any, path: tuple[PathSeg, ...], values: list[Any]) -> None:
    parent = _get(obj, path[:-1]) if len(path) > 1 else obj
    name, _ = path[-1]
    current = getattr(parent, name)
    kind = _element_kind(current)
    setattr(parent, name, [_coerce(v, kind) for v in values])


def build(gen: Any, spec_path: Path) -> dict[str, GenericMapping]:
    """A GenericMapping per mapping of the spec (resolved by sam_codegen, as the generator sees it)."""
    from sam_codegen.frontend.loader import load_spec_file
    from sam_codegen.validate.resolve import validate

    resolved = validate(load_spec_file(Path(spec_path)))
    by_name = {m.name: m for m in gen.tables().MAPPINGS}
    out: dict[str, GenericMapping] = {}
    for rm in resolved.mappings:
        info = by_name[rm.mapping.name]
        out[info.name] = GenericMapping(rm, gen.ros_class(info.topic), gen.dsdl_class(info.port), info.frame_id)
    return out


__all__ = ["GenericMapping", "build"]
