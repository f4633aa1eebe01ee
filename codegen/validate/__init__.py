"""Spec + catalogs -> Resolved: every semantic error at once, with the spec's positions.

Layer: above catalogs and frontend; below the conversion plan and the targets. Public: validate, Resolved.
"""

from sam_codegen.validate.resolve import Resolved as Resolved
from sam_codegen.validate.resolve import validate as validate
