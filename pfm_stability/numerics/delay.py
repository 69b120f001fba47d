"""Roots, crossings and stability of the retarded quasi-polynomial a(s) + (d(s) + K)·e^(−sT).

Koren & Borenstein 1991 (KB) eq (18) is τs³ + s² + ks + K·e^(−sT) = 0 with
K = kNV; a heading gain c adds d(s) = kc·s to the delayed term (docs/models.md).
This module handles a(s) + (d(s) + K)·e^(−sT) with any real polynomials,
deg d < deg a (a retarded equation); d = 0, a(s) + K·e^(−sT), runs the code it
always ran. Below, b(s) = d(s) + K.

Methods
-------
* **Delay crossings** (K fixed, T varies). A root s = jω exists iff
  |a(jω)| = |b(jω)| and e^(−jωT) = −a(jω)/b(jω): the frequencies are the
  positive real roots of the polynomial F(ω²) = |a(jω)|² − |b(jω)|², and each
  gives the delay sequence T_m = (θ + 2πm)/ω. A root crosses towards Re s > 0
  as T increases through T_m iff F′(ω²) > 0, whatever m is (Cooke & van den
  Driessche, "On zeroes of some transcendental equations", Funkcial. Ekvac. 29,
  1986; Walton & Marshall, IEE Proc. D 134, 1987). Hence the number of roots
  with Re s > 0 at delay T is exactly

      Z(T) = Z(0) + 2·Σ_{T_m < T} sign F′(ω²),

  where Z(0) is the Routh count of a(s) + b(s). This is the *crossing count*
  used for every verdict; it never rests on a root found by Newton.
* **Gain crossings** (T fixed, K grows). s = jω is a root for a real K > 0 iff
  arg a(jω) + ωT ≡ π (mod 2π); the phase is unwrapped through the roots of a
  (continuous in ω) and every level (2m + 1)π is bracketed on a grid and refined
  by bisection; K_m = |a(jω_m)|. When a(s) has no roots with Re > 0 the
  phase is monotone and the crossings found are provably all of them (d = 0;
  KB's loop with a heading gain has its own route, `models.heading`).
* **Rightmost roots** by pseudospectral collocation of the infinitesimal
  generator (Breda, Maset & Vermiglio, "Pseudospectral differencing methods for
  characteristic roots of delay differential equations", SIAM J. Sci. Comput.
  27, 2005), each eigenvalue then polished by Newton's method on the
  quasi-polynomial itself.
"""

from __future__ import annotations

import contextlib
import math
import os
from dataclasses import dataclass

import numpy as np

from ..checks import check_number
from .crossings import Crossing, StabilityInterval
from .routh import real_coefficients, routh_array, strip_leading_zeros
from .solve import bisect_root, newton_increasing

__all__ = ["DelayLoop", "DelayCrossing", "delay_verdicts_from_gain", "kb_critical_gain"]

_TWO_PI = 2.0 * math.pi


def single_blas_thread():
    """A context that keeps BLAS to one thread around a medium-sized eigenvalue problem.

    On a busy machine BLAS threads spin on such problems (the pseudospectral
    matrix is ~120 × 120) and make them several times slower. The command
    line pins the thread count in the environment before numpy loads (then
    this is a no-op); library callers get `threadpoolctl`'s limit.
    """
    if os.environ.get("OPENBLAS_NUM_THREADS") == "1" or os.environ.get("OMP_NUM_THREADS") == "1":
        return contextlib.nullcontext()
    from threadpoolctl import threadpool_limits

    return threadpool_limits(1, user_api="blas")

_K_MAX = 1e100
"""Largest |K| of `DelayLoop`: the crossing polynomial |a(jω)|² − K² must stay inside floating point."""


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


def _modulus_in_y(p):
    """|p(j√y)|² as a polynomial in y = ω² (descending), for real p (descending)."""
    n = len(p) - 1
    # p(jω) conj p(jω) = Σ c_m (jω)^m with c = p * p(−s) coefficients
    p_minus = p * (-1.0) ** np.arange(n, -1, -1)
    prod = np.polymul(p, p_minus)  # p(s)·p(−s): even polynomial in s
    # p(s)p(−s) at s = jω equals |p(jω)|²; only even powers survive: s^(2i) = (−y)^i
    deg = len(prod) - 1
    return np.array([prod[idx] * (-1.0) ** ((deg - idx) // 2) for idx in range(0, deg + 1, 2)])


class DelayLoop:
    """The quasi-polynomial a(s) + (d(s) + K)·e^(−sT) for fixed a(s), d(s) and T.

    Parameters
    ----------
    a : array_like
        Real coefficients of a(s), descending powers, degree ≥ 1.
    T : float
        Delay, s, >= 0.
    delayed : array_like, optional
        Real coefficients of d(s), descending, degree < deg a (KB's loop with
        a heading gain c: d(s) = kc·s, ``[k*c, 0]``). Default: d = 0, the
        quasi-polynomial a(s) + K·e^(−sT).
    """

    def __init__(self, a, T: float, delayed=None):
        self.a = strip_leading_zeros(real_coefficients(a, "a"))
        if len(self.a) < 2:
            raise ValueError("a(s) must have degree >= 1 (a retarded quasi-polynomial)")
        self.T = check_number("T", T, 0.0, low_open=False, unit="s")
        self.d = None
        d = None if delayed is None else real_coefficients(delayed, "delayed")
        if d is not None and np.any(d):
            self.d = strip_leading_zeros(d)
            if len(self.d) >= len(self.a):
                raise ValueError(f"delayed d(s) must have a lower degree than a(s) (a retarded quasi-polynomial); got degree {len(self.d) - 1}")
        self._a_roots = np.roots(self.a)

    def _b(self, K):
        """b(s) = d(s) + K, descending."""
        return np.array([K]) if self.d is None else np.polyadd(self.d, [K])

    # ------------------------------------------------------------------ values
    def value(self, s, K: float):
        """a(s) + (d(s) + K)·e^(−sT) at complex `s`.

        Parameters
        ----------
        s : complex or array_like of complex
            Where to evaluate, 1/s.
        K : float
            The gain K.
        """
        b = K if self.d is None else np.polyval(self._b(K), s)
        return np.polyval(self.a, s) + b * np.exp(-s * self.T)

    def _derivative(self, s, K):
        if self.d is None:
            return _polyval_derivative(self.a, s) - K * self.T * np.exp(-s * self.T)
        b = self._b(K)
        return _polyval_derivative(self.a, s) + (_polyval_derivative(b, s) - self.T * np.polyval(b, s)) * np.exp(-s * self.T)

    def _delay_free(self, K):
        return np.polyadd(self.a, self._b(K))

    # -------------------------------------------------------- delay crossings
    def _modulus_poly_in_y(self, K):
        """F(y) = |a(j√y)|² − |b(j√y)|² as a polynomial in y = ω² (descending)."""
        if self.d is None:
            return np.polysub(_modulus_in_y(self.a), [K * K])
        return np.polysub(_modulus_in_y(self.a), _modulus_in_y(self._b(K)))

    def crossing_frequencies(self, K: float):
        """Frequencies ω > 0 with |a(jω)| = |b(jω)|, and the crossing direction there.

        Parameters
        ----------
        K : float
            The gain K, finite.

        Returns
        -------
        list of (float, int)
            (ω in rad/s, sign F′(ω²)) sorted by ω. A zero derivative (tangent
            touch) gives direction 0.
        """
        K = check_number("K", K, -_K_MAX, _K_MAX, low_open=False, high_open=False)
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
        """Smallest T >= 0 with e^(−jωT) = −a(jω)/b(jω), s."""
        b = K if self.d is None else np.polyval(self._b(K), 1j * w)
        theta = (-np.angle(-np.polyval(self.a, 1j * w) / b)) % _TWO_PI
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
        K = check_number("K", K, -_K_MAX, _K_MAX, low_open=False, high_open=False)
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

        Parameters
        ----------
        K : float
            The gain K, finite.
        """
        K = check_number("K", K, -_K_MAX, _K_MAX, low_open=False, high_open=False)
        if np.polyval(self.a, 0.0) + np.polyval(self._b(K), 0.0) == 0.0:
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
        """True when every root has Re s < 0 (by the crossing count).

        Parameters
        ----------
        K : float
            The gain K, finite.
        """
        K = check_number("K", K, -_K_MAX, _K_MAX, low_open=False, high_open=False)
        return self.unstable_root_count(K) == 0

    def delay_margin(self, K: float) -> float:
        """sup{T̄ : stable for every delay in [0, T̄)} for gain K, s.

        0 if a(s) + K is not Hurwitz; ``inf`` when no root can reach the axis
        (delay-independent stability). Does not depend on this loop's own T.

        Parameters
        ----------
        K : float
            The gain K, finite.
        """
        K = check_number("K", K, -_K_MAX, _K_MAX, low_open=False, high_open=False)
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
            phase += np.angle(1j * omega - r)
        return phase

    def _phase(self, omega):
        return self._unwrapped_phase(omega) + omega * self.T

    def critical_gain(self) -> StabilityInterval:
        """K*: stable for 0 < K < K* (T fixed), and the boundary frequency ω*.

        When a(s) has no root in Re s > 0 its phase arg a(jω) + ωT increases
        strictly, so a root is on the axis at gain K exactly when the phase is
        (2m + 1)π for some m = 0, 1, … (one frequency ω_m each) and
        K = K_m = |a(jω_m)|; each such crossing moves a root pair to the right
        as K grows (Re(ds/dK) has the sign of the phase slope). Hence
        K* = min_m K_m, and only one level per stretch on which |a(jω)| is
        monotone can be the minimum: the first level of an increasing stretch,
        the last of a decreasing one (stretches split at the critical points
        of |a(jω)|², a polynomial in ω²). A root of a(s) with Re s > 0 makes
        the loop unstable for small K: K* = 0.

        Raises
        ------
        ValueError
            If a(s) has a non-zero root on the imaginary axis (the phase jumps),
            or d ≠ 0 (the phase argument needs a delayed term without s; KB's
            loop with a heading gain: `models.heading.kb_heading_interval`).
        """
        if self.d is not None:
            raise ValueError("critical_gain needs d = 0 (delayed term K alone); for KB's loop with a heading gain use models.heading.kb_heading_interval")
        if self.T == 0:
            from .crossings import first_stable_interval

            return first_stable_interval(self.a, [1.0], "s")
        scale = max(1.0, float(np.max(np.abs(self._a_roots)))) if self._a_roots.size else 1.0
        if np.any(self._a_roots.real > 1e-12 * scale):
            return StabilityInterval(0.0, None, (), ())
        if np.any((np.abs(self._a_roots.real) <= 1e-12 * scale) & (np.abs(self._a_roots) > 1e-12 * scale)):
            raise ValueError("a(s) must not have non-zero roots on the imaginary axis")
        levels = set()
        for w in [0.0] + self._modulus_critical_points():
            level = self._level_at(w)
            levels.update({max(level, 0), max(level + 1, 0)} if w > 0 else {0})
        crossings = sorted((Crossing(float(abs(np.polyval(self.a, 1j * w))), w) for w in (self._level_frequency(m) for m in sorted(levels))), key=lambda c: c.gain)
        best = crossings[0]
        return StabilityInterval(best.gain, best.frequency, tuple(crossings), ((0.0, best.gain),))

    def _modulus_critical_points(self) -> list[float]:
        """ω > 0 where |a(jω)|² has a critical point (roots of its derivative in y = ω²)."""
        dF = np.polyder(self._modulus_poly_in_y(0.0))
        roots = np.roots(np.trim_zeros(dF, "f")) if np.any(dF[:-1]) else np.empty(0)
        return sorted(math.sqrt(y.real) for y in roots if abs(y.imag) <= 1e-9 * max(1.0, abs(y)) and y.real > 0)

    def _level_at(self, w: float) -> int:
        """Largest m with phase(ω_m) <= phase(w), i.e. floor((phase − π)/2π)."""
        return int(math.floor((float(self._phase(w)) - math.pi) / _TWO_PI))

    def _level_frequency(self, m: int) -> float:
        """ω > 0 where the phase equals (2m + 1)π (it increases strictly)."""
        target = math.pi + _TWO_PI * m
        hi = 1.0 / self.T
        while float(self._phase(hi)) < target:
            hi *= 2.0
        return bisect_root(lambda x: float(self._phase(x)) - target, 0.0, hi, rtol=1e-15)

    # ---------------------------------------------------------- rightmost roots
    def rightmost_roots(self, K: float, count: int = 6, nodes: int = 40) -> np.ndarray:
        """The `count` roots with largest real part, sorted by decreasing real part.

        Pseudospectral collocation (Breda, Maset & Vermiglio 2005) on `nodes`
        Chebyshev nodes in [−T, 0], then Newton's method on
        a(s) + (d(s) + K)·e^(−sT) from each eigenvalue (to
        |Δs| < 1e-13·max(1, |s|)). Conjugate pairs are both returned. T = 0
        returns the polynomial roots of a(s) + d(s) + K.

        The discretization resolves roots up to |s|·T of the order of `nodes`;
        where no eigenvalue polishes to a root (a loop with |s|·T in the
        thousands, e.g. an enormous gain), the array is empty: the rightmost
        root is then undefined, while verdicts (the crossing count) stay exact.

        Parameters
        ----------
        K : float
            The gain K, finite.
        count : int
            How many roots to return (at most).
        nodes : int
            Chebyshev nodes of the collocation on [−T, 0].
        """
        K = check_number("K", K, -_K_MAX, _K_MAX, low_open=False, high_open=False)
        if self.T == 0:
            roots = np.roots(self._delay_free(K))
            return roots[np.argsort(-roots.real)][:count]
        with single_blas_thread():
            eig = np.linalg.eigvals(self._generator(K, nodes))
        eig = eig[np.isfinite(eig)]
        eig = eig[np.argsort(-eig.real)][: max(4 * count, 12)]
        polished = []
        for s in eig:
            s = self._newton(s, K)
            if s is not None and not any(abs(s - p) <= 1e-8 * max(1.0, abs(s)) for p in polished):
                polished.append(s)
        polished = np.array(polished)
        return polished[np.argsort(-polished.real)][:count]

    def _generator(self, K, nodes):
        n = len(self.a) - 1
        lead = self.a[0]
        A0 = np.zeros((n, n))
        A0[:-1, 1:] = np.eye(n - 1)
        A0[-1, :] = -self.a[:0:-1] / lead
        A1 = np.zeros((n, n))
        A1[-1, 0] = -K / lead
        if self.d is not None:  # d(s)·x(t − T): derivatives of the delayed state, ascending powers
            b = self._b(K)[::-1]
            A1[-1, : len(b)] = -b / lead
        D = chebyshev_collocation(nodes)[2] * (2.0 / self.T)  # θ = T(x − 1)/2 ∈ [−T, 0]
        G = np.kron(D, np.eye(n))
        G[:n, :] = 0.0
        G[:n, :n] = A0
        G[:n, -n:] = A1
        return G

    def _newton(self, s, K, iterations=50):
        """Newton's method from s; None if it fails (a zero slope or leaving floating point)."""
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for _ in range(iterations):
                f = self.value(s, K)
                df = self._derivative(s, K)
                if df == 0 or not (np.isfinite(f) and np.isfinite(df)):
                    return None
                step = f / df
                s = s - step
                if abs(step) <= 1e-13 * max(1.0, abs(s)):
                    return complex(s)
            residual = abs(self.value(s, K))
        return complex(s) if residual <= 1e-9 * max(1.0, abs(np.polyval(self.a, s))) else None


def chebyshev_collocation(nodes: int) -> tuple:
    """(x, c, D): the Chebyshev points x_l = cos(πl/N) (l = 0 … N, x_0 = 1), their barycentric weights c and the
    differentiation matrix D on [−1, 1] (Trefethen, *Spectral Methods in MATLAB*, 2000, `cheb`): the collocation of the
    pseudospectral roots (`DelayLoop.rightmost_roots`, `quasi.QuasiPolynomial.rightmost_roots`).

    Parameters
    ----------
    nodes : int
        N, >= 1.
    """
    x = np.cos(math.pi * np.arange(nodes + 1) / nodes)
    c = np.ones(nodes + 1)
    c[0] = c[-1] = 2.0
    c *= (-1.0) ** np.arange(nodes + 1)
    D = np.outer(c, 1.0 / c) / (np.subtract.outer(x, x) + np.eye(nodes + 1))
    D -= np.diag(D.sum(axis=1))
    return x, c, D


# ----------------------------------------------------------------------------
# KB's quasi-polynomial τs³ + s² + ks + K·e^(−sT), vectorized over points
# ----------------------------------------------------------------------------
_RESONANCE = 2.0 + math.sqrt(3.0)
"""kτ above which |a(jω)| of a(s) = τs³ + s² + ks dips (the steering loop resonates)."""


def _kb_level_offset(w, tau, T, k):
    """g(ω) = ωT − atan(k/ω − τω) and g′(ω): the phase of a(jω)e^(jωT) minus π, increasing."""
    u = k / w - tau * w
    return w * T - np.arctan(u), T + (k / (w * w) + tau) / (1.0 + u * u)


def _kb_level_frequency(tau, T, k, m):
    """ω_m > 0 with g(ω_m) = 2πm (arrays; T > 0): a root on the axis at gain |a(jω_m)|.

    g ranges over (ωT − π/2, ωT + π/2), which brackets ω_m in a band of width
    π/T; for m = 0 also ω_0 < √(k/τ) (g > 0 needs k − τω² > 0).
    """
    target = 2.0 * math.pi * m
    lo = np.maximum((target - math.pi / 2) / T, 0.0)
    hi = (target + math.pi / 2) / T
    with np.errstate(divide="ignore"):
        hi = np.where((m == 0) & (tau > 0), np.minimum(hi, np.sqrt(k / np.where(tau > 0, tau, 1.0))), hi)

    def func(w):
        with np.errstate(divide="ignore", invalid="ignore"):
            g, slope = _kb_level_offset(w, tau, T, k)
        return np.where(w > 0, g - target, -1.0), slope

    return newton_increasing(func, lo, hi)


def kb_critical_gain(tau, T, k):
    """K* and ω* of KB eq (18), τs³ + s² + ks + K·e^(−sT), for arrays (τ, T, k).

    The loop is stable exactly for 0 < K < K* (`DelayLoop.critical_gain`: the
    phase of a(jω) = jω(k − τω² + jω) increases strictly, every gain crossing
    is destabilizing). K* = min_m |a(jω_m)| over the levels g(ω_m) = 2πm, and
    only three levels can attain it: m = 0 (|a(jω)| increases up to the first
    critical point of |a(jω)|²) and, when kτ > 2 + √3, the last level below
    and the first above the dip's bottom ω_c, where
    ω_c² = [(2kτ − 1) + √((2kτ − 1)² − 3k²τ²)]/(3τ²). Each level frequency
    is found by safeguarded Newton on g. No iteration over levels, no search
    bound: the number of levels below ω_c (up to ~10⁵ for T = 100 s) does
    not matter.

    T = 0: K* = k/τ, ω* = √(k/τ) (KB eq 17; ``inf`` and NaN for τ = 0).

    Parameters
    ----------
    tau, T, k : array_like
        s, s, 1/s; broadcast together; τ >= 0, T >= 0, k > 0.

    Returns
    -------
    K_star, omega_star : ndarray
        1/s² and rad/s.
    """
    tau, T, k = (np.asarray(x, dtype=float) for x in np.broadcast_arrays(tau, T, k))
    shape = tau.shape
    tau, T, k = tau.ravel(), T.ravel(), k.ravel()
    K_star = np.full(tau.shape, np.inf)
    omega_star = np.full(tau.shape, np.nan)
    still = (T == 0) & (tau > 0)
    K_star[still] = k[still] / tau[still]
    omega_star[still] = np.sqrt(k[still] / tau[still])
    delayed = T > 0
    # overflow (π/T, √(k/T) beyond the floats at a tiny T) gives K* = inf, the undelayed answer
    with np.errstate(over="ignore"):
        t, d, g = tau[delayed], T[delayed], k[delayed]
        kt = g * t
        resonant = kt > _RESONANCE
        safe_t = np.where(resonant, t, 1.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            y_c = ((2 * kt - 1) + np.sqrt(np.maximum((2 * kt - 1) ** 2 - 3 * kt * kt, 0.0))) / (3 * safe_t * safe_t)
            g_c = _kb_level_offset(np.sqrt(y_c), safe_t, d, g)[0]
        m_c = np.where(resonant & (g_c >= 0), np.floor(g_c / (2 * math.pi)), 0.0)
        best_K = np.full(t.shape, np.inf)
        best_w = np.full(t.shape, np.nan)
        for m in (np.zeros_like(m_c), m_c, m_c + resonant):
            w = _kb_level_frequency(t, d, g, m)
            K = w * np.sqrt((g - t * w * w) ** 2 + w * w)
            better = K < best_K
            best_K = np.where(better, K, best_K)
            best_w = np.where(better, w, best_w)
        K_star[delayed], omega_star[delayed] = best_K, best_w
    return K_star.reshape(shape), omega_star.reshape(shape)


def _cubic_positive_roots(tau, k, K, linear=None):
    """Positive roots y of F(y) = τ²y³ + (1 − 2kτ)y² + ℓy − K² (up to three; NaN where absent).

    ℓ = `linear` (k² by default; k²(1 − c²) with a heading gain c). No
    discriminant (it cancels catastrophically when τ is small): the
    critical points of F (a stable quadratic formula) split (0, ∞) into
    intervals where F is monotone and of one convexity, so each root is reached
    by Newton's method from a start that satisfies Fourier's condition
    F·F″ > 0 — convergence is monotone and needs no safeguard. τ = 0 leaves
    the quadratic y² + ℓy − K² (one positive root, closed form); K = 0 (N = 0: the heading loop's crossings)
    leaves y·(τ²y² + (1 − 2kτ)y + ℓ), the quadratic's positive roots (closed form).
    """
    roots = np.full(tau.shape + (3,), np.nan)
    lin = k**2 if linear is None else linear
    quadratic, neutral, cubic = tau == 0, (tau > 0) & (K == 0), (tau > 0) & (K != 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(lin[quadratic] ** 2 + 4 * K[quadratic] ** 2)
        roots[quadratic, 0] = np.where(lin[quadratic] >= 0, 2 * K[quadratic] ** 2 / (lin[quadratic] + root), (root - lin[quadratic]) / 2)
        a, b, c = tau[neutral] ** 2, 1 - 2 * k[neutral] * tau[neutral], lin[neutral]
        q = -0.5 * (b + np.copysign(np.sqrt(b * b - 4 * a * c), b))  # the stable quadratic formula: roots c/q, q/a
        pair = np.stack([c / q, q / a], axis=-1)
        roots[neutral, :2] = np.where(pair > 0, pair, np.nan)
    if cubic.any():
        roots[cubic] = _newton_cubic_roots(tau[cubic] ** 2, 1 - 2 * k[cubic] * tau[cubic], lin[cubic], K[cubic] ** 2)
    return roots


def _newton_cubic_roots(a, beta, c, D):
    """Up to three positive roots of a·y³ + β·y² + c·y − D (a, D > 0; c <= 0 for a heading gain |c| >= 1:
    F falls from −D, then rises, so one root, in the convex stretch: Newton from the right)."""

    def F(y):
        return ((a * y + beta) * y + c) * y - D

    inflection = -beta / (3 * a)
    disc = beta * beta - 3 * a * c
    critical = (beta < 0) & (disc > 0) & (c > 0)
    c2 = np.where(critical, (-beta + np.sqrt(np.maximum(disc, 0))) / (3 * a), np.inf)
    c1 = np.where(critical, c / (3 * a * np.where(critical, c2, 1.0)), np.inf)
    F1 = np.where(critical, F(np.where(critical, c1, 0.0)), np.inf)
    F2 = np.where(critical, F(np.where(critical, c2, 0.0)), -np.inf)
    # a point right of every root: with β >= 0 and c > 0 each term alone bounds
    # the root (within a factor 3 of it); otherwise Fujiwara's bound
    with np.errstate(divide="ignore", invalid="ignore"):
        positive_bound = np.minimum.reduce([D / c, np.sqrt(D / np.where(beta > 0, beta, 0.0)), np.cbrt(D / a)])
    right = np.where((beta >= 0) & (c > 0), positive_bound, 2 * np.maximum.reduce([np.abs(beta) / a, np.sqrt(np.abs(c) / a), np.cbrt(D / (2 * a))]))
    F_inflection = np.where(inflection > 0, F(np.maximum(inflection, 0.0)), -np.inf)
    # smallest root: in the concave stretch left of the inflection (start at 0) or in the convex one (start right)
    left_concave = np.where(critical, F1 > 0, F_inflection >= 0)
    starts = np.stack(
        [
            np.where(left_concave, 0.0, right),
            np.where(critical & (F1 > 0) & (F2 < 0), inflection, np.nan),
            np.where(critical & (F1 > 0) & (F2 < 0), right, np.nan),
        ],
        axis=-1,
    )
    used = np.isfinite(starts)
    point = np.nonzero(used)[0]
    y = starts[used]
    A, B, C, Dd = a[point], beta[point], c[point], D[point]
    for _ in range(60):
        value = ((A * y + B) * y + C) * y - Dd
        slope = (3 * A * y + 2 * B) * y + C
        with np.errstate(invalid="ignore", divide="ignore"):
            step = value / slope
        step[~np.isfinite(step)] = 0.0
        y -= step
        # converged when every step is at round-off level (1e-13 relative: near
        # double roots the iterates jitter by a few ulps and never settle)
        if not np.any(np.abs(step) > 1e-13 * np.abs(y)):
            break
    out = np.full(starts.shape, np.nan)
    out[used] = y
    return out


def delay_verdicts_from_gain(tau, T, k, K, c=None):
    """Crossing-count verdicts for arrays (τ, T, k, K = kNV[, c]); returns (stable, Z, delay margin).

    τs³ + s² + ks + (kcs + K)·e^(−sT) (c None: KB eq 18): F(y) = τ²y³ + (1 − 2kτ)y² + k²(1 − c²)y − K²,
    first delays from arg(a(jω)/b(jω)), b = kcjω + K; Z(0), the Routh count of τs³ + s² + k(1 + c)s + K,
    is 1 for K < 0 (a real root s > 0: N < 0, always unstable); K = 0 (N = 0) counts the heading loop (s = 0 left out).

    Parameters
    ----------
    tau, T, k, K : ndarray
        τ (s), T (s), k (1/s) and K = kNV (1/s²), one loop per element (1-D, equal length).
    c : ndarray or None
        Heading gain c per loop (dimensionless); None: KB's loop (c = 0).
    """
    linear = None if c is None else k**2 * (1 - c * c)
    y = _cubic_positive_roots(tau, k, K, linear)
    present = np.isfinite(y) & (y > 0)  # y = 0: K² underflowed to 0, no crossing at ω > 0
    y0 = np.where(present, y, 1.0)
    w = np.sqrt(y0)
    t3, k3 = tau[:, None], k[:, None]
    slope = 3 * t3**2 * y0**2 + 2 * (1 - 2 * k3 * t3) * y0 + (k3**2 if c is None else linear[:, None])
    direction = np.where(present, np.sign(slope), 0.0)
    psi = np.arctan((k3 - t3 * y0) / w)
    # arg b(jω): 0 for c = 0 and K > 0 (psi untouched), π for K < 0
    b_phase = np.where(K[:, None] < 0, math.pi, 0.0) if c is None else np.arctan2(k3 * c[:, None] * w, K[:, None])
    psi = np.where(b_phase == 0, psi, psi + b_phase)
    first = np.where(psi >= 0, psi, psi + _TWO_PI) / w
    passed = np.where(present & (T[:, None] > first), np.floor((T[:, None] - first) * w / _TWO_PI) + 1, 0.0)
    base = np.where(K < 0, 1, np.where(tau * K > (k if c is None else k * (1 + c)), 2, 0))
    Z = base + 2 * np.sum(direction * passed, axis=1).astype(np.int64)
    margin = np.where(base == 0, np.min(np.where(present, first, np.inf), axis=1), 0.0)
    return Z == 0, Z, margin
