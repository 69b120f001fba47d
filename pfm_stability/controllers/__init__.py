"""Nav2's path-tracking controllers: the registry of their names, plugins and parameters (`controllers.registry`).

Nothing is imported here: import the module you need (``from pfm_stability.controllers.registry import …``), so that
the command line can read the registry without loading numpy (docs/path_tracking.md)."""

__all__ = []
