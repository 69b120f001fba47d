"""`exact_delay`: KB eq (18), τs³ + s² + ks + kNV·e^(−sT) = 0, solved exactly.

The quasi-polynomial has infinitely many roots; module `pfm_stability.delay`
finds the crossings of the imaginary axis (Cooke & van den Driessche 1986;
Walton & Marshall 1987), counts the roots in Re s > 0 exactly, and finds the
rightmost roots by pseudospectral collocation (Breda, Maset & Vermiglio 2005)
polished by Newton. For a(s) = τs³ + s² + ks the phase arg a(jω) + ωT is
strictly increasing (arg a(jω) = π − atan((k − τω²)/ω)), so each level
(2m + 1)π gives one gain crossing K_m = |a(jω_m)|. |a(jω)| itself is monotone
only for kτ <= 2 + √3; above that the steering loop τs² + s + k resonates,
|a(jω)|² = τ²ω⁶ + (1 − 2kτ)ω⁴ + k²ω² dips, and a later crossing can have the
smallest gain. K* is therefore the end of the stable interval found by
checking the crossing count between consecutive crossing gains, and
NV* = K*/k — which depends on k, unlike KB's eq (20).
T = 0 reduces to `continuous` (eq 17).
"""

from __future__ import annotations

from ..delay import DelayLoop
from .base import Boundary, Loop, LoopModel, _check_NV

__all__ = ["ExactDelay"]


class ExactDelay(LoopModel):
    """Koren & Borenstein 1991 eq (18) with the exact delay e^(−sT)."""

    name = "exact_delay"
    equation = "tau s^3 + s^2 + k s + k N V exp(-s T) = 0  (KB eq 18)"

    @staticmethod
    def quasi_polynomial(loop: Loop) -> DelayLoop:
        """The quasi-polynomial a(s) + K e^(−sT) with a(s) = τs³ + s² + ks."""
        return DelayLoop(loop.plant, loop.T)

    def compute_boundary(self, loop: Loop) -> Boundary:
        interval = self.quasi_polynomial(loop).critical_gain()
        return Boundary(self.name, interval.gain / loop.k, interval.frequency, interval.gain)

    def is_stable(self, NV: float, loop: Loop) -> bool:
        """Crossing count Z(T) = 0 (no root in Re s >= 0)."""
        return self.quasi_polynomial(loop).is_stable(loop.k * _check_NV(NV))

    def unstable_root_count(self, NV: float, loop: Loop) -> int | None:
        """Roots with Re s > 0 (None when a root is on the imaginary axis)."""
        return self.quasi_polynomial(loop).unstable_root_count(loop.k * _check_NV(NV))

    def rightmost_root(self, NV: float, loop: Loop) -> complex:
        roots = self.quasi_polynomial(loop).rightmost_roots(loop.k * _check_NV(NV), count=2)
        top = roots[roots.real >= roots[0].real - 1e-9 * max(1.0, abs(roots[0]))]
        return complex(top[top.imag.argmax()])

    def critical_delay(self, NV: float, loop: Loop) -> float:
        """Delay margin: largest T keeping NV stable (τ, k fixed), s."""
        return self.quasi_polynomial(loop).delay_margin(loop.k * _check_NV(NV))
