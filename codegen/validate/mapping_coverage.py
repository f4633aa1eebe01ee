"""Coverage of a resolved mapping: every UAVCAN field is mapped, ignored or given a value, a DroneCAN array's
elements are named one way, and in a UAVCAN -> ROS mapping every ROS field is written or listed in `ros_defaults`."""

from __future__ import annotations

from sam_codegen.model.expr import fields_of
from sam_codegen.model.spec import ROS_TO_UAVCAN, UAVCAN_TO_ROS, DsdlStruct, Mapping, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.validate.mapping_paths import MappingPaths, Reported
from sam_codegen.validate.mapping_rules import TIME, PathSeg, ResolvedMapping, RuleError, format_path, parse_path

__all__ = ["MappingCoverage"]


class MappingCoverage(MappingPaths):
    """The coverage checks of a resolved mapping; part of MappingValidator (validate.mappings)."""

    def uncovered(self, struct: DsdlStruct, prefix: str, pool: set[str], skip: str | None = None
                  ) -> list[tuple[str, DsdlType]]:
        """The fields of `struct` (paths under `prefix`) that `pool` leaves without a value, each as large as
        possible: a field or array element under which the pool has no path is one entry, whole."""
        result: list[tuple[str, DsdlType]] = []
        for f in struct.fields:
            assert isinstance(f.type, DsdlType)
            if (struct.name, f.name) not in self.bad_dsdl_fields and f.name != skip:  # reported with its declaration
                result.extend(self.uncovered_at(prefix + f.name, f.type, pool))
        return result

    def uncovered_at(self, path: str, t: DsdlType, pool: set[str]) -> list[tuple[str, DsdlType]]:
        if path in pool:
            return []
        uses = self.element_uses.get(path)
        if uses is not None:  # a DroneCAN array of which the mapping names elements
            if self.direction == UAVCAN_TO_ROS:
                return []  # it reads its elements; the others are other mappings' (or nobody's)
            if uses["index"]:  # the message is built with exactly the elements up to the last one named
                return [u for i in range(max(uses["index"]) + 1)
                        for u in self.uncovered_at(f"{path}[{i}]", t.element, pool)]
            item = self.types.get(t.composite) if t.composite else None
            return [u for key in uses["key"] for u in self.uncovered(item, f"{path}[{key}].", pool, key.field)
                    ] if item is not None else []
        if not any(p.startswith((path + ".", path + "[")) for p in pool):
            return [(path, t)]
        if t.array == "fixed":  # some elements (or their fields) are covered: look at each
            return [u for i in range(t.capacity or 0) for u in self.uncovered_at(f"{path}[{i}]", t.element, pool)]
        nested = self.types.get(t.composite) if t.kind == "composite" and not t.array and t.composite else None
        if nested is not None:
            return self.uncovered(nested, path + ".", pool)
        return [(path, t)]

    def check_elements(self, mapping: Mapping, what: str) -> tuple[dict[tuple[PathSeg, ...], list], bool]:
        """A DroneCAN array's elements are named by position or by one key field, not both. Returns the arrays
        named one way (path -> positions or items, in order) and whether every array is."""
        ok = True
        elements: dict[tuple[PathSeg, ...], list] = {}
        for path, uses in self.elements.items():
            text = format_path(list(path))
            fields = {key.field for key in uses["key"]}
            if uses["index"] and uses["key"]:
                self.error(mapping.pos, f"{what} names elements of {text} both by position and by key",
                           "one way for one array")
                ok = False
            elif len(fields) > 1:
                self.error(mapping.pos, f"{what} chooses items of {text} by more than one key field ("
                           + ", ".join(sorted(fields)) + ")", "one key field per array")
                ok = False
            else:
                elements[path] = list(uses["index"] or uses["key"])
        self.element_uses = {format_path(list(path)): uses for path, uses in self.elements.items()}
        return elements, ok

    def check_coverage(self, resolved: ResolvedMapping, what: str) -> None:
        mapping = resolved.mapping
        self.direction = mapping.direction
        linked = {s.uavcan for s in resolved.steps if s.uavcan_path} | self.failed_paths
        linked |= {f.text for s in resolved.steps if s.expr is not None and not s.uavcan_path
                   for f in fields_of(s.expr)}  # what UAVCAN -> ROS expressions read
        valued = {format_path(list(p)) for p, _, _ in resolved.uavcan_values}
        selected = {format_path(list(p)) for p, _, _ in resolved.select}
        # UAVCAN->ROS may also publish a select field (esc_index routed on and reported); ROS->UAVCAN sets it once
        for path in sorted(selected & (linked | valued) if mapping.direction == ROS_TO_UAVCAN else selected & valued):
            self.error(mapping.pos, f"UAVCAN field {path!r} is set by `select` in {what}; it cannot also be mapped",
                       "the field in select only")
        linked |= selected
        struct = resolved.dsdl_struct
        if mapping.direction == UAVCAN_TO_ROS:
            if not mapping.name.endswith("[]"):  # an element mapping's (`<mapping>.<array>[]`): element_mappings
                self.check_ros_written(resolved, what)  # checks its fields, with advice that fits `fields`
            for path, t in self.uncovered(struct, "", linked | self.ignored):
                self.error(mapping.pos, f"required field left unmapped: UAVCAN field {path!r} ({t}) of "
                           f"{struct.name} is neither mapped nor ignored in {what}",
                           f"a `ros_field: {path}` line or `{path}` in ignore")
        else:
            if mapping.ros_defaults:
                self.error(mapping.pos, f"{what} goes ROS->UAVCAN: ros_defaults name ROS fields a UAVCAN->ROS "
                           "mapping leaves unwritten")
            for path, t in self.uncovered(struct, "", linked | valued):
                self.error(mapping.pos, f"required field left unmapped: UAVCAN field {path!r} ({t}) of "
                           f"{struct.name} gets no value in {what}",
                           f"a `ros_field: {path}` line or an entry in uavcan_values")
            for path in sorted(linked & valued):
                self.error(mapping.pos, f"UAVCAN field {path!r} is both mapped and in uavcan_values in {what}")

    def check_ros_written(self, resolved: ResolvedMapping, what: str) -> None:
        """UAVCAN -> ROS: every ROS field gets a value (a link, a `value`, an `expr`; header.stamp and frame_id
        from the bridge) or is listed in ros_defaults: a field nothing writes would always read 0 / false."""
        m = resolved.mapping
        message = resolved.ros_message
        written = {s.ros for s in resolved.steps if s.ros_path} | self.failed_ros
        if "" in written:
            return  # a link names a ROS field that does not resolve: reported already, coverage would only guess
        if resolved.has_header:
            written.add("header")  # stamp: the source's or the receive time; frame_id: the mapping's
        defaults: set[str] = set()
        for text in m.ros_defaults:
            try:
                segments = parse_path(text)
                self.ros_leaf(message, segments)
            except Reported:
                continue
            except RuleError as exc:
                self.error(m.pos, f"ros_defaults of {what}: {exc}")
                continue
            name = format_path(segments)
            if name in written:
                self.error(m.pos, f"ROS field {name!r} is in ros_defaults of {what} but the mapping writes it",
                           "ros_defaults lists only fields nothing writes")
            defaults.add(name)
        for path, t, elements in self.ros_unwritten(message, "", written, defaults):
            self.error(m.pos, f"ROS field {path!r} ({t}) of {message.full_name} is written by nothing in {what}"
                       + (f" (elements {elements})" if elements else "") + ": it would always keep its default",
                       f"a `{path}: <uavcan field>` line, `{path}: {{value: ...}}`, `{path}: {{expr: ...}}` or "
                       f"`{path}` in ros_defaults")

    def ros_unwritten(self, message: RosMessage, prefix: str, written: set[str], defaults: set[str]
                      ) -> list[tuple[str, RosType, str]]:
        """The fields of `message` (paths under `prefix`) that nothing writes and no default names, each as large
        as possible; a fixed array written in part is one entry with the elements left (a default naming a
        field covers everything under it that nothing writes)."""
        out: list[tuple[str, RosType, str]] = []
        for f in message.fields:
            assert isinstance(f.type, RosType)
            path, t = prefix + f.name, f.type
            if path in written or path in defaults:
                continue
            if not t.is_primitive and self.ros.get(t.base) is None and t.base != TIME:
                continue  # an unknown type: reported with its declaration
            if not any(p.startswith((path + ".", path + "[")) for p in written):
                out.append((path, t, ""))
            elif t.array == "fixed":
                element = t.element
                nested = self.ros.get(element.base) if not element.is_primitive else None
                left = []
                for i in range(t.capacity or 0):
                    item = f"{path}[{i}]"
                    if item in written or item in defaults:
                        continue
                    if nested is not None and any(p.startswith(item + ".") for p in written):
                        out += self.ros_unwritten(nested, item + ".", written, defaults)
                    else:
                        left.append(str(i))
                if left:
                    out.append((path, t, ", ".join(left)))
            elif not t.array and not t.is_primitive and self.ros.get(t.base) is not None:
                out += self.ros_unwritten(self.ros.get(t.base), path + ".", written, defaults)  # type: ignore[arg-type]
            else:
                out.append((path, t, ""))
        return out
