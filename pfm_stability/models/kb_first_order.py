"""`kb_first_order`: KB's criterion, eq (19)–(20).

The delay e^(−sT) of (18) replaced by 1 − sT gives (19),
τs³ + s² + k(1 − NVT)s + kNV = 0, and Routh gives (20): NV(τ + T) < 1, so
NV* = 1/(τ + T) — independent of k *only in this approximation*. At NV* the
s¹ row of the Routh array vanishes and the auxiliary polynomial s² + kNV* gives
the boundary oscillation ω* = √(k/(τ + T)).
"""

from __future__ import annotations

import math

import numpy as np

from .base import AffineGainModel, Loop, _check_NV, checked

__all__ = ["KBFirstOrder"]


class KBFirstOrder(AffineGainModel):
    """Koren & Borenstein 1991 eq (19): delay approximated by 1 − sT."""

    name = "kb_first_order"
    equation = "tau s^3 + s^2 + k(1 - N V T) s + k N V = 0  (KB eq 19)"

    def polynomials(self, loop: Loop):
        """D = τs³ + s² + ks, E = 1 − sT (descending powers of s)."""
        return loop.plant, np.array([-loop.T, 1.0])

    @checked
    def critical_delay(self, NV: float, loop: Loop) -> float:
        """KB eq (20) solved for T: T* = 1/NV − τ (0 if negative), s."""
        return max(1.0 / _check_NV(NV) - loop.tau, 0.0)

    @checked
    def critical_gain_k(self, NV: float, loop: Loop) -> float:
        """k cancels from eq (20): ``inf`` if NV(τ + T) < 1, else 0 (1/s)."""
        return math.inf if _check_NV(NV) * (loop.tau + loop.T) < 1.0 else 0.0
