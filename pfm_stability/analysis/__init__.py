"""Analyses on top of the loop models: wall, corridor and door criteria, critical values, curves, regions, comparisons, traps, the derivation.

Nothing is imported here: import the module you need (``from pfm_stability.analysis.X import Y``),
so that importing one module does not load its siblings."""

__all__ = []
