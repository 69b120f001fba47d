"""Roots, crossings and stability of the retarded quasi-polynomial a(s) + K·e^(−sT).

Koren & Borenstein 1991 (KB) eq (18) is τs³ + s² + ks + K·e^(−sT) = 0 with
K = kNV; this module handles the general form a(s) + K·e^(−sT) with any real
polynomial a(s) of degree ≥ 1 (a retarded equation: the delayed term has lower
degree than a).

Methods
-------
* **Delay crossings** (K fixed, T varies). A root s = jω exists iff
  |a(jω)| = |K| and e^(−jωT) = −a(jω)/K: the frequencies are the positive
  real roots of the polynomial F(ω²) = |a(jω)|² − K², and each gives the delay
  sequence T_m = (θ + 2πm)/ω. A root crosses towards Re s > 0 as T increases
  through T_m iff F′(ω²) > 0, whatever m is (Cooke & van den Driessche, "On
  zeroes of some transcendental equations", Funkcial. Ekvac. 29, 1986; Walton &
  Marshall, IEE Proc. D 134, 1987). Hence the number of roots with Re s > 0 at
  delay T is exactly

      Z(T) = Z(0) + 2·Σ_{T_m < T} sign F′(ω²),

  where Z(0) is the Routh count of a(s) + K. This is the *crossing count* used
  for every verdict; it never rests on a root found by Newton.
* **Gain crossings** (T fixed, K grows). s = jω is a root for a real K > 0 iff
  arg a(jω) + ωT ≡ π (mod 2π); the phase is unwrapped through the roots of a
  (continuous in ω) and every level (2m + 1)π is bracketed on a grid and refined
  by bisection; K_m = |a(jω_m)|. When a(s) has no roots with Re > 0 the
  phase is monotone and the crossings found are provably all of them.
* **Rightmost roots** by pseudospectral collocation of the infinitesimal
  generator (Breda, Maset & Vermiglio, "Pseudospectral differencing methods for
  characteristic roots of delay differential equations", SIAM J. Sci. Comput.
  27, 2005), each eigenvalue then polished by Newton's method on the
  quasi-polynomial itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .checks import check_number
from .crossings import Crossing, StabilityInterval, stable_interval
from .routh import routh_array, strip_leading_zeros
from .solve import bisect_root

__all__ = ["DelayLoop", "DelayCrossing"]

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class DelayCrossing:
    """A root on the imaginary axis at s = jω for the delay T (K fixed).

    Attributes
    ----------
    delay : float
        T_m, s.
    frequency : float
        ω > 0, rad/s.
    direction : int
        +1 if the root pair moves into Re s > 0 as T grows, −1 if it leaves.
    """

    delay: float
    frequency: float
    direction: int


def _newton_polish(p, dp, x: float, steps: int = 3) -> float:
    """A few Newton steps on a real polynomial: np.roots loses relative accuracy
    on small roots of badly scaled polynomials (e.g. τ → 0 in |a(jω)|² − K²)."""
    for _ in range(steps):
        slope = np.polyval(dp, x)
        if slope == 0:
            break
        x = x - np.polyval(p, x) / slope
    return float(x)


def _polyval_derivative(p, s):
    return np.polyval(np.polyder(p), s) if len(p) > 1 else 0.0 * s


class DelayLoop:
    """The quasi-polynomial a(s) + K·e^(−sT) for fixed a(s) and T.

    Parameters
    ----------
    a : array_like
        Real coefficients of a(s), descending powers, degree ≥ 1.
    T : float
        Delay, s, >= 0.
    """

    def __init__(self, a, T: float):
        self.a = strip_leading_zeros(a)
        if len(self.a) < 2:
            raise ValueError("a(s) must have degree >= 1 (a retarded quasi-polynomial)")
        self.T = check_number("T", T, 0.0, low_open=False, unit="s")
        self._a_roots = np.roots(self.a)

    # ------------------------------------------------------------------ values
    def value(self, s, K: float):
        """a(s) + K·e^(−sT) at complex `s`."""
        return np.polyval(self.a, s) + K * np.exp(-s * self.T)

    def _derivative(self, s, K):
        return _polyval_derivative(self.a, s) - K * self.T * np.exp(-s * self.T)

    def _delay_free(self, K):
        return np.polyadd(self.a, [K])

    # -------------------------------------------------------- delay crossings
    def _modulus_poly_in_y(self, K):
        """F(y) = |a(j√y)|² − K² as a polynomial in y = ω² (descending)."""
        n = len(self.a) - 1
        # a(jω) conj a(jω) = Σ c_m (jω)^m with c = a * a(−s) coefficients
        a_minus = self.a * (-1.0) ** np.arange(n, -1, -1)
        prod = np.polymul(self.a, a_minus)  # a(s)·a(−s): even polynomial in s
        # a(s)a(−s) at s = jω equals |a(jω)|²; only even powers survive: s^(2i) = (−y)^i
        deg = len(prod) - 1
        coeff_y = [prod[idx] * (-1.0) ** ((deg - idx) // 2) for idx in range(0, deg + 1, 2)]
        return np.polysub(np.array(coeff_y), [K * K])

    def crossing_frequencies(self, K: float):
        """Frequencies ω > 0 with |a(jω)| = |K|, and the crossing direction there.

        Returns
        -------
        list of (float, int)
            (ω in rad/s, sign F′(ω²)) sorted by ω. A zero derivative (tangent
            touch) gives direction 0.
        """
        F = self._modulus_poly_in_y(K)
        dF = np.polyder(F)
        roots = np.roots(np.trim_zeros(F, "f")) if np.any(F[:-1]) else np.empty(0)
        out = []
        for y in roots:
            if abs(y.imag) > 1e-9 * max(1.0, abs(y)) or y.real <= 0:
                continue
            y = _newton_polish(F, dF, y.real)
            w = math.sqrt(y)
            slope = np.polyval(dF, y)
            scale = max(abs(np.polyval(np.abs(dF), y)), 1e-300)
            direction = 0 if abs(slope) <= 1e-10 * scale else int(np.sign(slope))
            out.append((w, direction))
        return sorted(out)

    def _first_delay(self, w: float, K: float) -> float:
        """Smallest T >= 0 with e^(−jωT) = −a(jω)/K, s."""
        theta = (-np.angle(-np.polyval(self.a, 1j * w) / K)) % _TWO_PI
        return theta / w

    def crossing_delays(self, K: float, T_max: float) -> list[DelayCrossing]:
        """Every delay 0 < T_m <= T_max at which a root lies on the imaginary axis.

        Parameters
        ----------
        K : float
            Gain (any real, non-zero).
        T_max : float
            Largest delay of interest, s.
        """
        out = []
        for w, direction in self.crossing_frequencies(K):
            first = self._first_delay(w, K)
            count = int(math.floor((T_max - first) * w / _TWO_PI)) + 1 if T_max >= first else 0
            delays = first + _TWO_PI * np.arange(count) / w
            out.extend(DelayCrossing(float(d), w, direction) for d in delays if d > 0)
        return sorted(out, key=lambda c: c.delay)

    def unstable_root_count(self, K: float) -> int | None:
        """Number of roots with Re s > 0 (crossing count), or None on the boundary.

        Z(T) = Z(0) + 2·Σ_{T_m < T} sign F′(ω_m²) (Cooke & van den Driessche 1986).
        Returns None when a root lies on the imaginary axis at this T (within a
        relative 1e-12 in delay) or at s = 0, or a crossing is tangent.
        """
        if np.polyval(self.a, 0.0) + K == 0.0:
            return None
        base = routh_array(self._delay_free(K))
        if base.marginal:
            return None
        count = base.sign_changes
        if self.T == 0:
            return count
        for crossing in self.crossing_delays(K, self.T * (1 + 1e-12)):
            if abs(crossing.delay - self.T) <= 1e-12 * self.T or crossing.direction == 0:
                return None
            count += 2 * crossing.direction
        return count

    def is_stable(self, K: float) -> bool:
        """True when every root has Re s < 0 (by the crossing count)."""
        return self.unstable_root_count(K) == 0

    def delay_margin(self, K: float) -> float:
        """sup{T̄ : stable for every delay in [0, T̄)} for gain K, s.

        0 if a(s) + K is not Hurwitz; ``inf`` when no root can reach the axis
        (delay-independent stability). Does not depend on this loop's own T.
        """
        if not routh_array(self._delay_free(K)).stable:
            return 0.0
        firsts = [self._first_delay(w, K) for w, _ in self.crossing_frequencies(K)]
        return min(firsts) if firsts else math.inf

    # --------------------------------------------------------- gain crossings
    def _unwrapped_phase(self, omega):
        """arg a(jω), continuous in ω > 0 (each root factor on its own branch)."""
        omega = np.asarray(omega, dtype=float)
        phase = np.full(omega.shape, float(np.angle(self.a[0])))
        for r in self._a_roots:
            factor = 1j * omega - r
            if r.real > 0:
                phase += np.angle(-factor) + math.pi
            else:
                phase += np.angle(factor)
        return phase

    def _phase(self, omega):
        return self._unwrapped_phase(omega) + omega * self.T

    def _frequency_bound(self, K_max: float) -> float:
        """Largest ω with |a(jω)| <= K_max (0 if none)."""
        freqs = [w for w, _ in self.crossing_frequencies(K_max)]
        return max(freqs) if freqs else 0.0

    def gain_crossings(self, K_max: float, grid_points: int = 4096) -> list[Crossing]:
        """Every crossing of the imaginary axis with 0 < K <= K_max as K grows (T fixed).

        Parameters
        ----------
        K_max : float
            Largest gain of interest.
        grid_points : int
            Bracketing grid over (0, ω_max]; exact for a(s) without roots in
            Re s > 0 (monotone phase), otherwise a pair of crossings closer than
            the grid step could be missed.

        Returns
        -------
        list of Crossing
            (gain K_m = |a(jω_m)|, frequency ω_m in rad/s), sorted by gain.
        """
        w_max = self._frequency_bound(K_max) * (1 + 1e-9)
        if w_max <= 0:
            return []
        scale = w_max
        grid = np.unique(np.concatenate([np.linspace(0, w_max, grid_points)[1:], np.geomspace(scale * 1e-9, w_max, grid_points)]))
        psi = self._phase(grid)
        levels = np.floor((psi - math.pi) / _TWO_PI)
        out = []
        for i in np.flatnonzero(levels[1:] != levels[:-1]):
            lo, hi = sorted((levels[i], levels[i + 1]))
            for level in np.arange(lo + 1, hi + 1):
                target = math.pi + _TWO_PI * level
                w = bisect_root(lambda x: float(self._phase(x)) - target, grid[i], grid[i + 1], rtol=1e-15)
                gain = abs(np.polyval(self.a, 1j * w))
                if 0 < gain <= K_max * (1 + 1e-12):
                    out.append(Crossing(float(gain), float(w)))
        return sorted(out, key=lambda c: c.gain)

    def critical_gain(self) -> StabilityInterval:
        """K*: stable for 0 < K < K* (T fixed), and the boundary frequency ω*.

        The gain crossings are searched up to a bound that doubles until the
        stable interval ends inside it (or 60 doublings: then K* = inf).
        """
        if self.T == 0:
            from .crossings import first_stable_interval

            return first_stable_interval(self.a, [1.0], "s")
        K_max = self._first_level_gain()
        for _ in range(60):
            interval = stable_interval(self.gain_crossings(K_max), self.is_stable)
            if interval.gain <= K_max:
                return interval
            K_max *= 2
        return StabilityInterval(math.inf, None, interval.crossings)

    def _first_level_gain(self) -> float:
        """Gain of the lowest-frequency phase crossing, a first search bound."""
        w = 1.0 / self.T
        while self._phase(w) < math.pi and w < 1e12 / self.T:
            w *= 2
        return max(abs(np.polyval(self.a, 1j * w)), 1e-12)

    # ---------------------------------------------------------- rightmost roots
    def rightmost_roots(self, K: float, count: int = 6, nodes: int = 40) -> np.ndarray:
        """The `count` roots with largest real part, sorted by decreasing real part.

        Pseudospectral collocation (Breda, Maset & Vermiglio 2005) on `nodes`
        Chebyshev nodes in [−T, 0], then Newton's method on a(s) + K·e^(−sT)
        from each eigenvalue (to |Δs| < 1e-13·max(1, |s|)). Conjugate pairs are
        both returned. T = 0 returns the polynomial roots of a(s) + K.
        """
        if self.T == 0:
            roots = np.roots(self._delay_free(K))
            return roots[np.argsort(-roots.real)][:count]
        eig = np.linalg.eigvals(self._generator(K, nodes))
        eig = eig[np.argsort(-eig.real)][: max(4 * count, 12)]
        polished = []
        for s in eig:
            s = self._newton(s, K)
            if s is not None and not any(abs(s - p) <= 1e-8 * max(1.0, abs(s)) for p in polished):
                polished.append(s)
        polished = np.array(polished)
        return polished[np.argsort(-polished.real)][:count]

    def spectral_abscissa(self, K: float) -> float:
        """max Re s over all roots, 1/s."""
        return float(self.rightmost_roots(K, count=1)[0].real)

    def _generator(self, K, nodes):
        n = len(self.a) - 1
        lead = self.a[0]
        A0 = np.zeros((n, n))
        A0[:-1, 1:] = np.eye(n - 1)
        A0[-1, :] = -self.a[:0:-1] / lead
        A1 = np.zeros((n, n))
        A1[-1, 0] = -K / lead
        x = np.cos(math.pi * np.arange(nodes + 1) / nodes)
        c = np.ones(nodes + 1)
        c[0] = c[-1] = 2.0
        c *= (-1.0) ** np.arange(nodes + 1)
        X = np.subtract.outer(x, x)
        D = np.outer(c, 1.0 / c) / (X + np.eye(nodes + 1))
        D -= np.diag(D.sum(axis=1))
        D *= 2.0 / self.T  # θ = T(x − 1)/2 ∈ [−T, 0]
        G = np.kron(D, np.eye(n))
        G[:n, :] = 0.0
        G[:n, :n] = A0
        G[:n, -n:] = A1
        return G

    def _newton(self, s, K, iterations=50):
        for _ in range(iterations):
            f = self.value(s, K)
            df = self._derivative(s, K)
            if df == 0:
                return None
            step = f / df
            s = s - step
            if abs(step) <= 1e-13 * max(1.0, abs(s)):
                return complex(s)
        return complex(s) if abs(self.value(s, K)) <= 1e-9 * max(1.0, abs(np.polyval(self.a, s))) else None
