"""Files in and out: configuration and Nav2 parameter files, YAML, JSON numbers and schema, files written atomically.

Nothing is imported here: import the module you need (``from pfm_stability.io.X import Y``),
so that importing one module does not load its siblings."""

__all__ = []
