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

The holonomic loop (`models.holonomic`) is s² + c_h s + κ = 0: stable exactly when
c_h > 0 and κ > 0.
"""

from __future__ import annotations

import math

import numpy as np

from .base import AffineGainModel, _aligned, _steering, checked
from .family import Characteristic

__all__ = ["Continuous"]


class Continuous(AffineGainModel):
    """No delay: a(s) + δs + K = 0; Koren & Borenstein 1991 eq (17) for the steering loop."""

    name = "continuous"

    def polynomials(self, loop: Characteristic):
        """D = a(s) + δs, E = 1 (descending powers of s): τs³ + s² + k(1 + c)s (c = 0: KB eq 17); s² + c_h s.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return loop.closed_plant, np.array([1.0])

    def parts(self, loop: Characteristic):
        """(a(s), s, 1).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return _aligned(loop.plant, [1.0, 0.0], [1.0])

    @checked
    def critical_delay(self, gain: float, loop: Characteristic) -> float:
        """T does not enter: ``inf`` if the loop is stable (`is_stable`; steering: τNV < 1 + c, NV >= 0), else 0 (s).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (its T is not used).
        """
        return math.inf if self._stable(gain, loop) else 0.0

    @checked
    def critical_gain_k(self, NV: float, loop) -> float:
        """k cancels from Routh's condition 0 <= τNV < 1 + c (`is_stable`): ``inf`` if it holds, else 0 (1/s).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            The steering loop judged (τ, T, k, c).
        """
        return math.inf if self._stable(NV, _steering(loop, "critical_gain_k")) else 0.0
