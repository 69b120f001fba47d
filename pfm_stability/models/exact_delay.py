"""`exact_delay`: KB eq (18), τs³ + s² + ks + kNV·e^(−sT) = 0, solved exactly.

The quasi-polynomial has infinitely many roots. Module `pfm_stability.numerics.delay`
answers every question without a search bound, by the same array code that
`pfm_stability.vectorized` runs on millions of points:

* **K*** (`kb_critical_gain`): the phase arg a(jω) + ωT of a(s) = τs³ + s² + ks
  increases strictly (arg a(jω) = π − atan((k − τω²)/ω)), so each level
  (2m + 1)π gives one gain crossing K_m = |a(jω_m)|, every one of them
  destabilizing; the loop is stable exactly for 0 < K < K* = min_m K_m.
  |a(jω)| is monotone only for kτ <= 2 + √3; above that the steering loop
  τs² + s + k resonates, |a(jω)|² = τ²ω⁶ + (1 − 2kτ)ω⁴ + k²ω² dips, and a
  later level can give the smallest gain — NV* = K*/k then depends on k,
  unlike KB's eq (20).
* **Verdict and delay margin** (`delay_verdicts_from_gain`): the crossing count
  of Cooke & van den Driessche (1986), Z(T) = Z(0) + 2·Σ_{T_m < T} sign F′(ω²).
* **Rightmost roots**: pseudospectral collocation polished by Newton
  (`DelayLoop.rightmost_roots`).

T = 0 reduces to `continuous` (eq 17).

NV = 0 (N = 0, `models.base.neutral_reason`): the quasi-polynomial is
s·(τs² + s + k + kc·e^(−sT)); every query judges the heading loop
τs² + s + k + kc·e^(−sT) (`heading_quasi_polynomial`). The crossing count at
K = 0 is that loop's (`delay.delay_verdicts_from_gain`: the crossing
frequencies and delays of s·h(s) are those of h), so verdict and delay
margin come from the same call; with c = 0 it is τs² + s + k, stable at every
T and k.

With a heading gain c (`Loop.c`, docs/models.md) the equation is
τs³ + s² + ks + k(cs + NV)·e^(−sT) = 0, the quasi-polynomial
a(s) + (kcs + K)·e^(−sT). The crossing count and the rightmost roots take the
delayed kc·s as they take K (`delay_verdicts_from_gain(…, c)`,
`DelayLoop(…, delayed=[kc, 0])`); the gain crossings no longer all
destabilize, and `models.heading.kb_heading_interval` finds every one that can bound the
stable set, from polynomial roots, each stretch decided by the crossing count.
c = 0 runs exactly KB's code above.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.delay import DelayLoop, delay_verdicts_from_gain, kb_critical_gain
from .base import Boundary, Loop, LoopModel, _check_NV, checked, gain_range
from .pade import Pade

__all__ = ["ExactDelay"]


def _one(x) -> np.ndarray:
    return np.array([float(x)])


class ExactDelay(LoopModel):
    """Koren & Borenstein 1991 eq (18) with the exact delay e^(−sT)."""

    name = "exact_delay"
    equation = "tau s^3 + s^2 + k s + k N V exp(-s T) = 0  (KB eq 18)"

    @staticmethod
    def quasi_polynomial(loop: Loop) -> DelayLoop:
        """The quasi-polynomial a(s) + (kcs + K)·e^(−sT) with a(s) = τs³ + s² + ks (c = 0: a(s) + K e^(−sT)).

        Parameters
        ----------
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        if loop.c == 0.0:
            return DelayLoop(loop.plant, loop.T)
        return DelayLoop(loop.plant, loop.T, delayed=[loop.heading, 0.0])

    @staticmethod
    def heading_quasi_polynomial(loop: Loop) -> DelayLoop:
        """N = 0: the quasi-polynomial divided by s, τs² + s + k + kc·e^(−sT) (its gain K is kc).

        Parameters
        ----------
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        return DelayLoop(loop.plant[:-1], loop.T)

    def _quasi(self, NV: float, loop: Loop):
        """(quasi-polynomial, gain) of the roots the verdict judges: the loop's at kNV, the heading loop's at NV = 0."""
        return (self.heading_quasi_polynomial(loop), loop.heading) if NV == 0 else (self.quasi_polynomial(loop), loop.k * NV)

    def compute_boundary(self, loop: Loop) -> Boundary:
        if loop.c != 0.0:
            from .heading import kb_heading_interval  # only with a heading gain: KB's reports never compile it

            return Boundary.from_interval(self.name, kb_heading_interval(loop.tau, loop.T, loop.k, loop.c), loop.k)
        K, w = (float(x[0]) for x in kb_critical_gain(_one(loop.tau), _one(loop.T), _one(loop.k)))
        omega = w if math.isfinite(K) else None
        return Boundary(self.name, K / loop.k, omega, K, ((0.0, K / loop.k),))

    def _count(self, NV: float, loop: Loop):
        K = loop.k * _check_NV(NV)
        heading = () if loop.c == 0.0 else (_one(loop.c),)
        stable, Z, margin = delay_verdicts_from_gain(_one(loop.tau), _one(loop.T), _one(loop.k), _one(K), *heading)
        return bool(stable[0]), int(Z[0]), float(margin[0])

    @checked
    def is_stable(self, NV: float, loop: Loop) -> bool:
        """Crossing count Z(T) = 0 (no root in Re s >= 0).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        return self._count(NV, loop)[0]

    @checked
    def unstable_root_count(self, NV: float, loop: Loop) -> int | None:
        """Roots with Re s > 0 (None when a root is on the imaginary axis; NV = 0: the heading loop's).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        q, K = self._quasi(NV, loop)
        return q.unstable_root_count(K)

    @checked
    def rightmost_root(self, NV: float, loop: Loop) -> complex | None:
        """Dominant root σ + jω (1/s, rad/s); None where the pseudospectral method cannot resolve
        it (|s|·T in the thousands: `DelayLoop.rightmost_roots`). The verdict does not need it.
        NV = 0: the heading loop's (`heading_quasi_polynomial`).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        q, K = self._quasi(NV, loop)
        for nodes in (40, 160):
            roots = q.rightmost_roots(K, count=2, nodes=nodes)
            if roots.size:
                top = roots[roots.real >= roots[0].real - 1e-9 * max(1.0, abs(roots[0]))]
                return complex(top[top.imag.argmax()])
        return None

    @checked
    def critical_delay(self, NV: float, loop: Loop) -> float:
        """Delay margin: the smallest T at which NV loses stability (τ, k fixed), s.

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        return self._count(NV, loop)[2]

    @checked
    def critical_gain_k(self, NV: float, loop: Loop) -> float:
        """Smallest steering gain k at which NV loses stability (τ, T fixed), 1/s.

        Stability is NV < NV*(k); NV*(k) → 1/(τ + T) as k → 0 (the roots
        shrink and e^(−sT) ≈ 1 − sT becomes exact: KB's eq 20), so k* = 0
        when NV(τ + T) >= 1. Otherwise the first k with NV*(k) <= NV.

        With c ≠ 0 the k → 0 limit is NV(τ + T) < 1 + c (the loop tends to
        `kb_first_order`'s), and beyond it `solve.first_crossing` over k on a
        measure whose sign is the crossing count's (exact, one array call) and
        whose size is the growth rate of Padé(6) (batched eigenvalues: a
        stand-in that peaks where a root nears the axis, so the search refines
        near-misses between grid points). NV < 0: 0. NV = 0: the heading
        loop's k* (c = 0: τs² + s + k, ``inf``).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        from ..numerics.solve import first_crossing

        NV = _check_NV(NV)
        if NV < 0:
            return 0.0
        if NV == 0 and loop.c == 0.0:
            return math.inf
        if loop.T == 0:
            return super().critical_gain_k(NV, loop)
        if NV * (loop.tau + loop.T) >= 1.0 + loop.c:
            return 0.0
        if loop.c != 0.0:
            return self._heading_gain_k(NV, loop)

        def measure(ks):
            K_star = kb_critical_gain(loop.tau, loop.T, ks)[0]
            return math.log(NV) + np.log(ks) - np.log(K_star)  # a sum of logs: NV·k underflows for subnormal NV

        lo, hi = gain_range(loop)
        return first_crossing(measure, lo, hi, start=lo)

    def _heading_gain_k(self, NV: float, loop: Loop) -> float:
        """k* for c ≠ 0 (`critical_gain_k`): first sign change of the signed measure over k."""
        from ..numerics.solve import first_crossing

        def measure(ks):
            loops = [Loop(loop.tau, loop.T, float(k), c=loop.c) for k in ks]
            arrays = (np.array([getattr(x, name) for x in loops]) for name in ("tau", "T", "k"))
            tau, T, k = arrays
            stable = delay_verdicts_from_gain(tau, T, k, k * NV, np.full(k.shape, loop.c))[0]
            size = np.abs(Pade(6).growth_rates(NV, loops)) + 1e-300
            return np.where(stable, -size, size)

        lo, hi = gain_range(loop)
        if measure(np.array([lo]))[0] >= 0:
            return 0.0
        return first_crossing(measure, lo, hi, start=lo)
