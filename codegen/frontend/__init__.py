"""YAML -> model.Spec: reading the spec file with positions, structural errors all at once.

Layer: above model; below validate. Public: load_spec_file, parse_spec.
"""

from sam_codegen.frontend.loader import load_spec_file as load_spec_file
from sam_codegen.frontend.loader import parse_spec as parse_spec
