"""Spec + catalogs -> Resolved: every semantic error at once, with the spec's positions.

Layer: above catalogs and frontend; below the conversion plan and the targets. Public: validate, Resolved and what it
holds (ResolvedMapping, ResolvedLayout, Step). Validation changes nothing in the spec: what it derives is in Resolved,
which is frozen.
"""

from sam_codegen.validate.dronecan import ResolvedLayout as ResolvedLayout
from sam_codegen.validate.mapping_rules import ResolvedMapping as ResolvedMapping
from sam_codegen.validate.mapping_rules import Step as Step
from sam_codegen.validate.resolve import Resolved as Resolved
from sam_codegen.validate.resolve import validate as validate
