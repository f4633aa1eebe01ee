"""The contract between the generator and the runtime: the types of a generated tables.py (table_types.py, copied
verbatim into it) and the module's members as a Protocol (tables_api.py). Standard library only; the lowest layer of
sam_codegen, so the targets that write the tables and the runtime that reads them both import it."""
