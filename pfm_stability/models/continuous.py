"""`continuous`: no delay, KB eq (17): τs³ + s² + ks + kNV = 0.

Routh on (17) gives stable ⇔ τNV < 1, so NV* = 1/τ (∞ for τ = 0, where the
loop s² + ks + kNV is stable for every gain); the boundary oscillation is at
ω* = √(k/τ). Both closed forms are checked against the derivation and against
the generic crossing computation in the tests.

With a heading gain c (`Loop.c`, docs/models.md) the equation is
τs³ + s² + k(1 + c)s + kNV = 0: Routh gives τNV < 1 + c, so NV* = (1 + c)/τ
and ω* = √(k(1 + c)/τ); k still cancels. NV < 0 leaves a sign change in the
coefficients: unstable. NV = 0 leaves s·(τs² + s + k(1 + c)): the heading loop
is stable (docs/models.md, "N = 0"), so T* = k* = ``inf``.
"""

from __future__ import annotations

import math

import numpy as np

from .base import AffineGainModel, Loop, checked

__all__ = ["Continuous"]


class Continuous(AffineGainModel):
    """Koren & Borenstein 1991 eq (17): the delay-free robot–environment loop."""

    name = "continuous"
    equation = "tau s^3 + s^2 + k s + k N V = 0  (KB eq 17)"

    def polynomials(self, loop: Loop):
        """D = τs³ + s² + k(1 + c)s, E = 1 (descending powers of s; c = 0: KB eq 17).

        Parameters
        ----------
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        return loop.closed_plant, np.array([1.0])

    @checked
    def critical_delay(self, NV: float, loop: Loop) -> float:
        """T does not enter (17): ``inf`` if τNV < 1 + c (and NV >= 0: `is_stable`), else 0 (s).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        return math.inf if self.is_stable(NV, loop) else 0.0

    @checked
    def critical_gain_k(self, NV: float, loop: Loop) -> float:
        """k cancels from Routh's condition 0 <= τNV < 1 + c (`is_stable`): ``inf`` if it holds, else 0 (1/s).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        return math.inf if self.is_stable(NV, loop) else 0.0
