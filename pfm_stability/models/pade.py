"""`pade`: KB eq (18) with the delay replaced by its Padé(m, m) approximant.

e^(−sT) ≈ P_m(s)/Q_m(s) turns (18) into the polynomial
(τs³ + s² + ks)·Q_m(s) + kNV·P_m(s) = 0, decided by Routh; K* is the first
crossing of the imaginary axis (module `crossings`). K* converges to the
`exact_delay` value as m grows. With a heading gain c (`Loop.c`) the delayed
term is k(cs + NV)·P_m(s): D = (τs³ + s² + ks)·Q_m + kc·s·P_m, E = P_m. The
holonomic loop (`models.holonomic`) is s²·Q_m + (c_h s + κ)·P_m = 0.

How `pade` with m = 1 differs from `kb_first_order`: KB's 1 − sT is the
first-order *Taylor* polynomial of e^(−sT) — its gain grows without bound with
frequency and its phase lag saturates at 90°. Padé(1,1),
(1 − sT/2)/(1 + sT/2), is all-pass (|·| = 1, like the true delay) and its phase
lag goes to 180°, and it raises the order of (18) from 3 to 4. The two agree to
O(s²T²) only, so their critical gains differ; Padé(1,1) is closer to the exact
delay for the CARMEL ratio T/τ (tests check both orderings against
`exact_delay`).

The coefficients are the closed form of Golub & Van Loan, *Matrix
Computations*, 3rd ed., §11.3 (the same as python-control's ``pade``, against
which the tests check them for m = 1…12); they are computed here so that a
report does not pay python-control's import time.
"""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_integer, check_number
from .base import AffineGainModel
from .family import Characteristic

__all__ = ["Pade", "pade_coefficients", "MAX_PADE_ORDER"]

MAX_PADE_ORDER = 12


def pade_coefficients(T: float, m: int):
    """Padé(m, m) approximant of e^(−sT).

    Parameters
    ----------
    T : float
        Delay, s, >= 0.
    m : int
        Order, 1 … 12.

    Returns
    -------
    num, den : ndarray
        Descending coefficients, normalized so that the leading coefficient of
        `den` is 1 (python-control's convention). T = 0 gives ([1], [1]).
    """
    T = check_number("T", T, 0.0, low_open=False, unit="s")
    m = check_integer("pade_order", m, 1, MAX_PADE_ORDER)
    if T == 0:
        return np.array([1.0]), np.array([1.0])
    # c_j = (2m − j)! m! / ((2m)! j! (m − j)!) ; Q(s) = Σ c_j (sT)^j, P(s) = Q(−s)
    c = np.array([_pade_term(m, j) for j in range(m + 1)])
    powers = T ** np.arange(m + 1)
    den = (c * powers)[::-1]
    num = (c * powers * (-1.0) ** np.arange(m + 1))[::-1]
    return num / den[0], den / den[0]


def _pade_term(m: int, j: int) -> float:
    """c_j = (2m − j)! m! / ((2m)! j! (m − j)!) (Golub & Van Loan §11.3)."""
    return math.factorial(2 * m - j) * math.factorial(m) / (math.factorial(2 * m) * math.factorial(j) * math.factorial(m - j))


class Pade(AffineGainModel):
    """The delay replaced by Padé(m, m): a(s)·Q_m(s) + (δs + K)·P_m(s) = 0 (KB eq 18 for the steering loop).

    Parameters
    ----------
    order : int
        Padé order m, 1 … 12.
    """

    name = "pade"

    def __init__(self, order: int = 3):
        self.order = check_integer("pade_order", order, 1, MAX_PADE_ORDER)

    def polynomials(self, loop: Characteristic):
        """D = a(s)·Q_m + δ·s·P_m, E = P_m (descending powers of s; Q_m(0) = P_m(0) = 1); the general steering loop's
        with each of its delays replaced (`general_polynomials`).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if not getattr(loop, "kb_form", True):
            return self.general_polynomials(loop)
        D, E = self.batch_polynomials([loop])
        return np.trim_zeros(D[0], "f"), np.trim_zeros(E[0], "f")

    def general_polynomials(self, loop):
        """(D, E) of the general steering loop p0 + Σ_j p_j·e^(−s·h_j) + K·e^(−s·h_K) (`models.loop.Loop.quasi_terms`)
        with every e^(−s·h) replaced by P_m(s·h)/Q_m(s·h), one approximant per distinct delay, cleared of denominators:

            D = p0·Π_g Q_g + Σ_j p_j·P_(g(j))·Π_(g ≠ g(j)) Q_g,   E = P_(h_K)·Π_(g ≠ h_K) Q_g

        (a delay of 0 is exactly 1). Descending; Q_m(0) = P_m(0) = 1.

        Parameters
        ----------
        loop : models.loop.Loop
            A steering loop that is not KB's form (a dead time, a second lag or a sampled heading).
        """
        quasi = loop.quasi_terms()
        delays = sorted({t.delay for t in quasi.terms if t.delay > 0} | ({quasi.gain_delay} if quasi.gain_delay > 0 else set()))
        approximants = {h: self._approximant(h) for h in delays}

        def others(skip):
            out = np.array([1.0])
            for h in delays:
                if h != skip:
                    out = np.polymul(out, approximants[h][1])
            return out

        D = np.polymul(quasi.p0, others(None))
        for t in quasi.terms:
            numerator = approximants[t.delay][0] if t.delay > 0 else np.array([1.0])
            D = np.polyadd(D, np.polymul(np.polymul(t.poly, numerator), others(t.delay)))
        numerator = approximants[quasi.gain_delay][0] if quasi.gain_delay > 0 else np.array([1.0])
        return np.trim_zeros(D, "f"), np.trim_zeros(np.polymul(numerator, others(quasi.gain_delay)), "f")

    def _approximant(self, h: float) -> tuple:
        """(P_m(s·h), Q_m(s·h)), descending, constant terms 1."""
        c = np.array([_pade_term(self.order, j) for j in range(self.order + 1)])
        powers = h ** np.arange(self.order + 1)
        return (c * powers * (-1.0) ** np.arange(self.order + 1))[::-1], (c * powers)[::-1]

    def parts(self, loop: Characteristic):
        """(a(s)·Q_m, s·P_m, P_m), one length.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        aQ, sP, P = self._rows([loop])
        return aQ[0], sP[0], P[0]

    def _rows(self, loops):
        """Rows of a(s)·Q_m, s·P_m and P_m for each loop, one width (the plants padded to the largest degree)."""
        T = np.array([loop.delay for loop in loops])  # T + D (docs/models.md, "Plant gain and dead time")
        m = self.order
        c = np.array([_pade_term(m, j) for j in range(m + 1)])
        powers = T[:, None] ** np.arange(m + 1)
        den = (c * powers)[:, ::-1]  # descending; constant term 1 (no division by a vanishing T^m)
        num = (c * powers * (-1.0) ** np.arange(m + 1))[:, ::-1]
        width = max(4, max(len(loop.plant) for loop in loops))  # KB's plant τs³ + s² + ks + 0: four columns
        plant = np.array([np.pad(loop.plant, (width - len(loop.plant), 0)) for loop in loops])
        aQ = np.zeros((len(loops), m + width))
        for i in range(width):
            aQ[:, i:i + m + 1] += plant[:, i, None] * den
        sP = np.zeros_like(aQ)
        sP[:, width - 2:m + width - 1] = num
        P = np.zeros_like(aQ)
        P[:, width - 1:] = num
        return aQ, sP, P

    def batch_polynomials(self, loops):
        """`polynomials` of many loops at once: rows of D = a(s)·Q_m + δ·s·P_m and E = P_m (general loops one by one).

        Parameters
        ----------
        loops : sequence of Characteristic
            The loops, one row each.
        """
        loops = list(loops)
        if not all(getattr(loop, "kb_form", True) for loop in loops):
            return AffineGainModel.batch_polynomials(self, loops)
        D, sP, E = self._rows(loops)
        damping = np.array([loop.damping for loop in loops])
        rows = np.flatnonzero(damping)
        if rows.size:  # δ·s·P_m, only where δ ≠ 0 (c = 0 keeps KB's rows untouched)
            D[rows] += damping[rows, None] * sP[rows]
        return D, E

    def options(self) -> dict:
        """``{"order": m}``."""
        return {"order": self.order}

    def __repr__(self) -> str:
        return f"Pade(order={self.order})"
