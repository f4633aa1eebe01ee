"""Mapping expressions (model.expr) resolved against a mapping's types: `ros_field: {expr: ...}` lines of a
UAVCAN -> ROS mapping and `uavcan_exprs` of a ROS -> UAVCAN one, type-checked by validate.expressions."""

from __future__ import annotations

from collections.abc import Callable

from sam_codegen.model.expr import ExprSource
from sam_codegen.model.spec import ROS_TO_UAVCAN, UAVCAN_TO_ROS, DsdlStruct, FieldLink, Mapping, RosMessage
from sam_codegen.model.types import DsdlType, RosType
from sam_codegen.validate.expressions import ExprError, check_expr, check_target
from sam_codegen.validate.mapping_paths import MappingPaths, Reported
from sam_codegen.validate.mapping_rules import RuleError, Step, format_path, parse_path, wrap_problem

__all__ = ["MappingExpressions"]


class MappingExpressions(MappingPaths):
    """The expression lines of a mapping; part of MappingValidator (validate.mappings)."""

    def check_expression(self, source: ExprSource, resolve: Callable[[list], DsdlType | RosType],
                         target: DsdlType | RosType, target_name: str, what: str) -> Step | None:
        """The typed tree of an expression whose names `resolve` finds, checked against its target; None when
        reported (at the column of the offending node)."""
        def field_type(path_text: str) -> DsdlType | RosType:
            try:
                return resolve(parse_path(path_text))
            except Reported:
                raise
            except RuleError as exc:
                raise ValueError(f"unknown field: {exc}") from None

        try:
            tree = check_expr(source.tree, field_type)
            check_target(tree, target, target_name)
        except Reported:
            return None
        except ExprError as exc:
            self.error(source.at(exc.col), f"{what}: {exc.message}")
            return None
        return Step("expr", (), RosType("float64"), pos=source.pos, exact=False, expr=tree)

    def resolve_expr_link(self, link: FieldLink, source: ExprSource, ros_path: list, ros_type: RosType,
                          struct: DsdlStruct, mapping: Mapping, what: str) -> Step | None:
        """`ros_field: {expr: "..."}` in a UAVCAN -> ROS mapping: the ROS field computed from UAVCAN fields."""
        if mapping.direction == ROS_TO_UAVCAN:
            raise RuleError("an `expr` line computes a ROS field from UAVCAN fields; a ROS->UAVCAN mapping "
                            "computes UAVCAN fields from ROS fields in uavcan_exprs")
        step = self.check_expression(source, lambda path: self.dsdl_leaf(struct, path), ros_type, link.ros_path,
                                     f"{what}, field {link.ros_path!r}")
        if step is None:
            return None
        return Step("expr", tuple(ros_path), ros_type, pos=link.pos, exact=False, expr=step.expr, wrap=link.wrap)

    def resolve_uavcan_exprs(self, mapping: Mapping, ros_message: RosMessage, struct: DsdlStruct, what: str,
                             linked: list[Step]) -> list[Step]:
        """`uavcan_exprs: {uavcan_field: "..."}` of a ROS -> UAVCAN mapping: UAVCAN fields computed from ROS
        fields."""
        steps: list[Step] = []
        if mapping.uavcan_exprs and mapping.direction == UAVCAN_TO_ROS:
            self.error(mapping.uavcan_exprs[0].pos, f"{what} goes UAVCAN->ROS: uavcan_exprs compute UAVCAN fields "
                       "of a ROS->UAVCAN mapping", "`ros_field: {expr: ...}` lines in fields")
            return steps
        for entry in mapping.uavcan_exprs:
            try:
                path = parse_path(entry.uavcan_path)
                target = self.dsdl_leaf(struct, path)
            except Reported:
                self.failed_paths.add(entry.uavcan_path.split("[")[0].split(".")[0])
                continue
            except RuleError as exc:
                self.error(entry.pos, f"uavcan_exprs of {what}: {exc}")
                continue
            step = self.check_expression(entry.expr, lambda p: self.ros_leaf(ros_message, p), target,
                                         entry.uavcan_path, f"{what}, UAVCAN field {entry.uavcan_path!r}")
            if step is None:
                self.failed_paths.add(entry.uavcan_path.split("[")[0].split(".")[0])
            else:
                if any(s.uavcan == format_path(path) for s in [*linked, *steps]):
                    self.error(entry.pos, f"UAVCAN field {entry.uavcan_path!r} is both mapped and in uavcan_exprs "
                               f"in {what}", "one of them")
                    continue
                resolved = Step("expr", (), RosType("float64"), tuple(path), target, pos=entry.pos, exact=False,
                                expr=step.expr, wrap=entry.wrap)
                problem = wrap_problem(resolved, to_ros=False)
                if problem is not None:
                    self.error(entry.pos, f"{what}, UAVCAN field {entry.uavcan_path!r}: {problem}")
                    continue
                steps.append(resolved)
        return steps
