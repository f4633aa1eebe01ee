"""Utilities every part of the runtime shares; imports nothing else of sam_runtime."""
