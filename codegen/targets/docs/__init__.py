"""The docs target: generated/docs/interfaces.md and dataflow.svg.
"""
