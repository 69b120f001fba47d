"""Lateral force laws and fields: KB's power law, the grid's law, potential fields, velocity and fuzzy laws, 2-D scenes.

Nothing is imported here: import the module you need (``from pfm_stability.laws.X import Y``),
so that importing one module does not load its siblings."""

__all__ = []
