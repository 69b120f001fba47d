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
from .base import STEERING, AffineGainModel, LoopModel, _aligned, _check_NV, _steering, checked
from .family import Characteristic

__all__ = ["KBFirstOrder"]


class KBFirstOrder(AffineGainModel):
    """KB's approximation of the delay, e^(−sT) ≈ 1 − sT: a(s) + (δs + K)(1 − sT) = 0 (Koren & Borenstein 1991 eq 19)."""

    name = "kb_first_order"

    def polynomials(self, loop: Characteristic):
        """D = a(s) + δs(1 − sT), E = 1 − sT (descending powers of s): τs³ + (1 − kcT)s² + k(1 + c)s (c = 0: KB eq 19)."""
        T = loop.delay  # T + D (docs/models.md, "Plant gain and dead time")
        if loop.damping == 0.0:
            return loop.plant, np.array([-T, 1.0])
        D = loop.closed_plant.copy()
        D[-3] -= loop.damping * T  # the s² coefficient: 1 − δT
        return D, np.array([-T, 1.0])

    def parts(self, loop: Characteristic):
        """(a(s), s(1 − sT), 1 − sT)."""
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
        """
        if loop.family is not STEERING:
            return LoopModel.critical_delay(self, NV, loop)
        NV = _check_NV(NV)
        if NV < 0:
            return 0.0
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
        NV = _check_NV(NV)
        if NV < 0:
            return 0.0
        T = loop.delay  # T + D
        if loop.c == 0.0:
            return math.inf if NV * (loop.tau + T) < 1.0 else 0.0
        slack = 1.0 + loop.c - NV * (loop.tau + T)
        if slack <= 0:
            return 0.0
        if loop.c < 0 or T == 0:
            return math.inf
        k_star = slack / (loop.c * T * (1.0 + loop.c - NV * T)) / loop.plant_gain  # the closed form gives g·k*
        return k_star if k_star <= RANGES["k"].high else math.inf
