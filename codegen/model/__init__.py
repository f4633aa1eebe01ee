"""The data every stage shares: the spec model (spec), the type system (types) and the error model (diagnostics).

The bottom layer of sam_codegen: it imports nothing else of the package.
"""
