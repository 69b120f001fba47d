"""Numerical building blocks: searches, Routh/Schur-Cohn, crossings, quasi-polynomials, the matrix exponential, seeded samples.

Nothing is imported here: import the module you need (``from pfm_stability.numerics.X import Y``),
so that importing one module does not load its siblings."""

__all__ = []
