"""`kb_first_order`: KB's criterion, eq (19)–(20).

The delay e^(−sT) of (18) replaced by 1 − sT gives (19),
τs³ + s² + k(1 − NVT)s + kNV = 0, and Routh gives (20): NV(τ + T) < 1, so
NV* = 1/(τ + T) — independent of k *only in this approximation*. At NV* the
s¹ row of the Routh array vanishes and the auxiliary polynomial s² + kNV* gives
the boundary oscillation ω* = √(k/(τ + T)).

With a heading gain c (`Loop.c`, docs/models.md) the delayed term is
k(cs + NV)(1 − sT), and (19) becomes

    τs³ + (1 − kcT)s² + k(1 + c − NVT)s + kNV = 0.

Routh: stable ⇔ 1 − kcT > 0, NV > 0 and (1 − kcT)(1 + c − NVT) > τNV
(which implies 1 + c − NVT > 0), i.e.

    NV* = (1 − kcT)(1 + c) / (τ + T(1 − kcT)),   ω*² = k(1 + c)/(τ + T(1 − kcT)),

and unstable at every NV when kcT >= 1 (τ > 0: the s² coefficient is not
positive). k no longer cancels (unless c = 0): a heading term makes the
first-order approximation itself depend on the steering gain. The boundary is
computed by the generic crossing route (`AffineGainModel`), the closed forms
above are the tests' reference (derived there with sympy).

The holonomic loop (`models.holonomic`) is s² + (c_h s + κ)(1 − sT) = 0,
(1 − c_hT)s² + (c_h − κT)s + κ: Routh gives stable ⇔ κ > 0, c_h > κT and c_hT < 1,
so κ* = c_h/T and T* = min(1/c_h, c_h/κ) — half the sampled loop's (the tests'
closed form; the model searches T* as for any loop, `LoopModel.critical_delay`).
"""

from __future__ import annotations

import math

import numpy as np

from ..parameters import RANGES
from .base import AffineGainModel, LoopModel, _aligned, _check_NV, _steering, checked
from .family import Characteristic

__all__ = ["KBFirstOrder", "first_order_polynomials"]


def first_order_polynomials(loop):
    """(D, E) of the general steering loop with every e^(−s·h) replaced by 1 − s·h (KB's step from eq 18 to 19, taken
    for each delay): D = p0 + Σ_j p_j·(1 − s·h_j), E = 1 − s·h_K, descending (`models.loop.Loop.quasi_terms`).

    For τ_a = 0 with the heading delayed by h₁ (D, or T + D when sampled) and the field by h_K = T + D:
    τs³ + (1 − gk(h₁ + c·h_K))s² + gk(1 + c − NV·h_K)s + gkNV (docs/models.md, "Plant gain and dead time").

    Parameters
    ----------
    loop : models.loop.Loop
        A steering loop that is not KB's form.
    """
    quasi = loop.quasi_terms()
    D = quasi.p0
    for t in quasi.terms:
        D = np.polyadd(D, np.polymul(t.poly, [-t.delay, 1.0]))
    return np.trim_zeros(D, "f"), np.array([-quasi.gain_delay, 1.0])


class KBFirstOrder(AffineGainModel):
    """KB's approximation of the delay, e^(−sT) ≈ 1 − sT: a(s) + (δs + K)(1 − sT) = 0 (Koren & Borenstein 1991 eq 19)."""

    name = "kb_first_order"

    def polynomials(self, loop: Characteristic):
        """D = a(s) + δs(1 − sT), E = 1 − sT (descending powers of s): τs³ + (1 − kcT)s² + k(1 + c)s (c = 0: KB eq 19).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if not getattr(loop, "kb_form", True):
            return first_order_polynomials(loop)
        T = loop.delay
        if loop.damping == 0.0:
            return loop.plant, np.array([-T, 1.0])
        D = loop.closed_plant.copy()
        D[-3] -= loop.damping * T  # the s² coefficient: 1 − δT
        return D, np.array([-T, 1.0])

    def parts(self, loop: Characteristic):
        """(a(s), s(1 − sT), 1 − sT).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return _aligned(loop.plant, [-loop.delay, 1.0, 0.0], [-loop.delay, 1.0])

    @checked
    def critical_delay(self, NV: float, loop: Characteristic) -> float:
        """KB eq (20) solved for T: T* = 1/NV − τ (0 if negative), s.

        With c ≠ 0: the smallest T > 0 where (1 − kcT)(1 + c − NVT) = τNV,
        the root 2C/(B + √(B² − 4AC)) of kcNV·T² − (kc(1 + c) + NV)T + (1 + c − τNV)
        (0 when τNV >= 1 + c: unstable already at T = 0). NV < 0: 0. NV = 0
        (the heading loop τs² + (1 − kcT)s + k(1 + c), `neutral_reason`): the
        same root, 1/(kc) for c > 0, ``inf`` for c <= 0. Another family's loop: searched
        (`LoopModel.critical_delay`). With a dead time D these are the margins of
        the delay T + D, and T* is that less D (`Characteristic.period_margin`);
        k is the loop's g·k (`Loop.steering_gain`).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Characteristic
            The loop judged; its own T, s, is replaced by T*.
        """
        if loop.family.name != "steering" or _beyond_first_order(loop):
            return LoopModel.critical_delay(self, NV, loop)
        NV = _check_NV(NV)
        if NV < 0:
            return 0.0
        if not loop.kb_form:
            return _routh_margin(loop, NV, "T")
        if loop.c == 0.0:
            return loop.period_margin(max(1.0 / NV - loop.tau, 0.0) if NV > 0 else math.inf)
        A = loop.heading * NV
        B = loop.heading * (1.0 + loop.c) + NV
        C = 1.0 + loop.c - loop.tau * NV
        if C <= 0:
            return 0.0
        denominator = B + math.sqrt(B * B - 4.0 * A * C)
        return loop.period_margin(2.0 * C / denominator if denominator > 0 else math.inf)  # 0 only at NV = 0 with c < 0

    @checked
    def critical_gain_k(self, NV: float, loop) -> float:
        """k cancels from eq (20): ``inf`` if NV(τ + T) < 1, else 0 (1/s).

        With c ≠ 0: as k → 0 the condition is NV(τ + T) < 1 + c (else 0);
        for c < 0 or T = 0 a larger k never hurts (``inf``); for c > 0 the
        loop loses stability where (1 − kcT)(1 + c − NVT) = τNV,
        k* = (1 + c − NV(τ + T))/(cT(1 + c − NVT)) (``inf`` beyond the largest
        allowed k, 10⁴ 1/s). NV < 0: 0. NV = 0: the same rules, the heading
        loop's (k* = 1/(cT) for c > 0).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        loop = _steering(loop, "critical_gain_k")
        if _beyond_first_order(loop):
            return LoopModel.critical_gain_k(self, NV, loop)
        NV = _check_NV(NV)
        if NV < 0:
            return 0.0
        if not loop.kb_form:
            return _routh_gain(loop, NV)
        T = loop.delay
        if loop.c == 0.0:
            return math.inf if NV * (loop.tau + T) < 1.0 else 0.0
        slack = 1.0 + loop.c - NV * (loop.tau + T)
        if slack <= 0:
            return 0.0
        if loop.c < 0 or T == 0:
            return math.inf
        k_star = slack / (loop.c * T * (1.0 + loop.c - NV * T)) / loop.plant_gain  # the closed form gives g·k*
        return k_star if k_star <= RANGES["k"].high else math.inf


    @checked
    def critical_dead_time(self, NV: float, loop) -> float:
        """D*, s: Routh's conditions of the first-order loop as D grows with T fixed (`_routh_margin`, exact); with a
        second lag the search of `LoopModel.critical_dead_time`.

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            τ, T, k, c and g (its own D is replaced).
        """
        loop = _steering(loop, "critical_dead_time")
        if _beyond_first_order(loop):
            return LoopModel.critical_dead_time(self, NV, loop)
        return 0.0 if NV < 0 else _routh_margin(loop, _check_NV(NV), "D")


def _beyond_first_order(loop) -> bool:
    """True for a steering loop whose first-order form is not τs³ + αs² + gk·b·s + gkNV (a second lag, or a course that
    lags the heading): its critical values are `LoopModel`'s searches, not the closed forms below."""
    return getattr(loop, "actuator_lag", 0.0) > 0 or getattr(loop, "slip_lag", 0.0) > 0


def _routh_coefficients(loop, NV: float, which: str) -> tuple:
    """(α0, α1, b0, b1): the first-order loop's s² coefficient α = α0 − α1·x and b = 1 + c − NV·h_K = b0 − b1·x as the
    delay x grows from 0 (``which="T"``: x = T with D fixed, the heading's delay growing with T when it is sampled;
    ``"D"``: x = D with T fixed)."""
    gk, c, T, D = loop.steering_gain, loop.c, loop.T, loop.dead_time
    beta = 1.0 if loop.heading_sampled else 0.0
    if which == "T":  # h1 = D + βT, h_K = T + D
        return 1.0 - gk * D * (1.0 + c), gk * (beta + c), 1.0 + c - NV * D, NV
    return 1.0 - gk * T * (beta + c), gk * (1.0 + c), 1.0 + c - NV * T, NV  # h1 = D + βT, h_K = T + D with D = x


def _routh_margin(loop, NV: float, which: str) -> float:
    """T* or D*, s, of the first-order general loop (τ_a = 0): the smallest x > 0 at which Routh's conditions of
    τs³ + αs² + gk·b·s + gkNV fail — α = 0, or α·b = τNV (b = 0 follows them for τNV >= 0) — 0 when they fail at x = 0
    (docs/models.md, "Plant gain and dead time"). NV = 0: the heading loop τs² + αs + gk(1 + c), α = 0 only."""
    a0, a1, b0, b1 = _routh_coefficients(loop, NV, which)
    tau_NV = loop.tau * NV
    if a0 <= 0 or (NV > 0 and a0 * b0 <= tau_NV) or (NV > 0 and loop.tau == 0 and b0 <= 0):
        return 0.0
    candidates = [a0 / a1] if a1 > 0 else []
    if NV > 0:  # (a0 − a1x)(b0 − b1x) − τNV = a1b1·x² − (a0b1 + a1b0)x + a0b0 − τNV
        A, B, C = a1 * b1, -(a0 * b1 + a1 * b0), a0 * b0 - tau_NV
        if A == 0:
            candidates += [C / -B] if B < 0 else []
        else:
            disc = B * B - 4 * A * C
            if disc >= 0:
                q = -0.5 * (B + math.copysign(math.sqrt(disc), B))
                candidates += [r for r in (q / A, C / q if q != 0 else math.inf) if r > 0]
    return min(candidates, default=math.inf)


def _routh_gain(loop, NV: float) -> float:
    """k*, 1/s, of the first-order general loop (τ_a = 0): α = 1 − gk(h₁ + c·h_K) falls with k, and the loop is stable while
    α·b > τNV, b = 1 + c − NV·h_K: k* = (1 − τNV/b)/(g(h₁ + c·h_K)); 0 when b <= τNV already as k → 0; ``inf`` when
    h₁ + c·h_K <= 0 (α does not fall) or beyond the largest allowed k."""
    b = 1.0 + loop.c - NV * loop.delay
    if b <= loop.tau * NV or b <= 0:
        return 0.0
    slope = loop.heading_delay + loop.c * loop.delay
    if slope <= 0:
        return math.inf
    k_star = (1.0 - loop.tau * NV / b) / (loop.plant_gain * slope)
    return k_star if k_star <= RANGES["k"].high else math.inf
