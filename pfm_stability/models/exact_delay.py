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

The model reads its loop through `family.Characteristic`, so it decides any
family's a(s) + (δ·s + K)·e^(−sT): rightmost roots and root counts by the same
`delay.DelayLoop` for every family; the boundary, the verdict and T* from the
family's crossing structure (`Characteristic.delay_interval`, `delay_stable`,
`delay_margin`): KB's array route above for the steering loop, the closed forms
of `models.holonomic` (and `DelayLoop`'s crossing count) for the holonomic one.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.delay import DelayLoop, delay_verdicts_from_gain, kb_critical_gain
from .base import LoopModel, _check_NV, _steering, checked
from .loop import Loop, gain_range
from .family import Characteristic
from .pade import Pade

__all__ = ["ExactDelay"]


class ExactDelay(LoopModel):
    """The delay taken exactly: a(s) + (δs + K)·e^(−sT) = 0 (Koren & Borenstein 1991 eq 18 for the steering loop)."""

    name = "exact_delay"

    @staticmethod
    def quasi_polynomial(loop: Characteristic) -> DelayLoop:
        """The quasi-polynomial a(s) + (δs + K)·e^(−sT) (δ = 0: a(s) + K e^(−sT)).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return loop.quasi_polynomial()

    @staticmethod
    def heading_quasi_polynomial(loop: Characteristic) -> DelayLoop:
        """Gain 0 (N = 0): the quasi-polynomial divided by s, a(s)/s + δ·e^(−sT) (its gain is δ).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return DelayLoop(loop.plant[:-1], loop.delay)

    def _quasi(self, gain: float, loop: Characteristic):
        """(quasi-polynomial, K) of the roots the verdict judges: the loop's at its K, the heading loop's at gain 0
        (the general steering loop's: `numerics.quasi.QuasiPolynomial.heading` at K = 0)."""
        if not getattr(loop, "kb_form", True):
            quasi = loop.quasi_terms()
            return (quasi.heading(), 0.0) if gain == 0 else (quasi, loop.loop_gain(gain))
        return (self.heading_quasi_polynomial(loop), loop.damping) if gain == 0 else (self.quasi_polynomial(loop), loop.loop_gain(gain))

    def compute_boundary(self, loop: Characteristic):
        """The family's crossing structure (`Characteristic.delay_interval`) in its gain.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return loop.boundary_from(self.name, loop.delay_interval())

    def _stable(self, gain: float, loop: Characteristic) -> bool:
        """Crossing count Z(T) = 0 (no root in Re s >= 0)."""
        return loop.delay_stable(loop.loop_gain(_check_NV(gain)))

    @checked
    def unstable_root_count(self, gain: float, loop: Characteristic) -> int | None:
        """Roots with Re s > 0 (None when a root is on the imaginary axis; NV = 0: the heading loop's).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        q, K = self._quasi(gain, loop)
        return q.unstable_root_count(K)

    @checked
    def rightmost_root(self, gain: float, loop: Characteristic) -> complex | None:
        """Dominant root σ + jω (1/s, rad/s, ω >= 0); None where the pseudospectral method cannot resolve
        it (|s|·T in the thousands: `DelayLoop.rightmost_roots`). The verdict does not need it.
        NV = 0: the heading loop's (`heading_quasi_polynomial`).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        q, K = self._quasi(gain, loop)
        for nodes in (40, 160):
            roots = q.rightmost_roots(K, count=2, nodes=nodes)
            if roots.size:
                return _dominant_of_sorted(roots)
        return None

    @checked
    def critical_delay(self, gain: float, loop: Characteristic) -> float:
        """Delay margin: the smallest T at which the gain loses stability (the rest fixed), s.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged; its own T, s, is replaced by the searched ones.
        """
        return loop.delay_margin(loop.loop_gain(gain))

    @checked
    def critical_dead_time(self, gain: float, loop: Characteristic) -> float:
        """D*: the first dead time at which a root reaches the imaginary axis, T fixed (`Loop.shift_margin`), s; exact, as T*.

        Parameters
        ----------
        gain : float
            Loop gain NV, 1/s.
        loop : Loop
            τ, T, k, c and g.
        """
        loop = _steering(loop, "critical_dead_time")
        if gain < 0:
            return 0.0
        return loop.shift_margin(loop.loop_gain(gain), "D")  # D delays the whole command: exact, from D = 0

    @checked
    def damping_range(self, gain: float, loop: Characteristic) -> tuple:
        """Every interval of the damping δ (the holonomic c_h, 1/s) that makes the gain stable at the loop's T
        (`HolonomicLoop.delay_damping_range`: the closed form of docs/models.md); ``()`` for a negative gain.

        Parameters
        ----------
        gain : float
            The family's loop gain (κ, 1/s², of a holonomic loop).
        loop : Characteristic
            The loop judged; its T, s, is kept and its own damping ignored.
        """
        loop.with_damping(0.0)  # a family whose damping is a parameter of its own
        if gain < 0:
            return ()
        return loop.delay_damping_range(loop.loop_gain(gain))

    @checked
    def critical_gain_k(self, NV: float, loop) -> float:
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

        loop = _steering(loop, "critical_gain_k")
        NV = _check_NV(NV)
        if NV < 0:
            return 0.0
        if not loop.kb_form:  # the general loop: the signed measure's first sign change over k (`_signed_gain_k`)
            if NV * (loop.tau + loop.actuator_lag + loop.slip_lag + loop.delay) >= 1.0 + loop.c:  # the k → 0 limit: kb_first_order's
                return 0.0
            return self._signed_gain_k(NV, loop, lambda loops: np.array([x.delay_stable(x.loop_gain(NV)) for x in loops]))
        if NV == 0 and loop.c == 0.0:
            return math.inf
        if loop.delay == 0:
            return super().critical_gain_k(NV, loop)
        if NV * (loop.tau + loop.delay) >= 1.0 + loop.c:
            return 0.0
        if loop.c != 0.0:
            return self._heading_gain_k(NV, loop)
        g = loop.plant_gain

        def measure(ks):  # the loop's steering gain is g·k (`Loop.steering_gain`); k* is the controller's k
            K_star = kb_critical_gain(loop.tau, loop.delay, g * ks)[0]
            return math.log(NV) + np.log(g * ks) - np.log(K_star)  # a sum of logs: NV·k underflows for subnormal NV

        lo, hi = gain_range(loop)
        return first_crossing(measure, lo, hi, start=lo)

    def _heading_gain_k(self, NV: float, loop: Loop) -> float:
        """k* for c ≠ 0 (`critical_gain_k`): first sign change of the signed measure over k, the sign the vectorized
        crossing count's."""
        def stable(loops):
            tau, T, k = (np.array([getattr(x, name) for x in loops]) for name in ("tau", "delay", "steering_gain"))
            return delay_verdicts_from_gain(tau, T, k, k * NV, np.full(k.shape, loop.c))[0]

        return self._signed_gain_k(NV, loop, stable)

    def _signed_gain_k(self, NV: float, loop: Loop, stable) -> float:
        """k*: the first sign change over k of a measure whose sign is the exact verdict's (``stable(loops)``, arrays)
        and whose size is Padé(6)'s growth rate (batched eigenvalues: a stand-in that peaks where a root nears the axis,
        so the search refines near-misses between grid points)."""
        from ..numerics.solve import first_crossing

        pade = Pade(6)  # one model for every probe

        def measure(ks):
            loops = [loop._with_steering_gain(k) for k in ks]
            size = np.abs(pade._growth_rates(NV, loops)) + 1e-300
            return np.where(stable(loops), -size, size)

        lo, hi = gain_range(loop)
        if measure(np.array([lo]))[0] >= 0:
            return 0.0
        return first_crossing(measure, lo, hi, start=lo)


def _dominant_of_sorted(roots) -> complex:
    """`base._dominant` of rightmost roots sorted by real part, the first the rightmost (its tolerance 1e-9)."""
    top = roots[roots.real >= roots[0].real - 1e-9 * max(1.0, abs(roots[0]))]
    return complex(top[top.imag.argmax()])
