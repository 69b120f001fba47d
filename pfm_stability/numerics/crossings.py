"""Where the roots of D + K·E cross the stability boundary as the gain K grows.

Every polynomial loop model of this package (``continuous``, ``kb_first_order``,
``pade`` in s; ``sampled`` in z) has a characteristic polynomial that is affine in
the loop gain K = kNV (Koren & Borenstein 1991, eq 17–19):

    P(x; K) = D(x) + K·E(x).

A root lies on the boundary (x = jω in s, x = e^{jφ} in z) exactly when
K = −D(x)/E(x) is real there, i.e. where Im(D(x)·conj E(x)) = 0. On the imaginary
axis that imaginary part is a real polynomial in ω; on the unit circle it is
sin φ times a polynomial in cos φ (Chebyshev polynomials of the second kind), so
both cases reduce to real roots of a polynomial — every crossing is found, with
no search grid and no initial guess. The critical gain K* is the end of the stable
interval that starts at K = 0+, checked by Routh (s) or Schur–Cohn (z) between
consecutive crossing gains.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .routh import routh_array, schur_cohn_stable, strip_leading_zeros

__all__ = [
    "Crossing",
    "StabilityInterval",
    "walk_stable_set",
    "affine_crossings",
    "first_stable_interval",
    "stable_interval",
    "stable_set",
    "verdict_at",
]

_REAL_ROOT_TOL = 1e-7


@dataclass(frozen=True)
class Crossing:
    """A root of D + K·E on the stability boundary.

    Attributes
    ----------
    gain : float
        K at which the crossing happens.
    frequency : float
        ω ≥ 0 (domain ``"s"``, rad/s) or φ ∈ [0, π] (domain ``"z"``, rad/sample).
    """

    gain: float
    frequency: float


@dataclass(frozen=True)
class StabilityInterval:
    """The stable gains adjacent to K = 0+.

    Attributes
    ----------
    gain : float
        K*: the loop is stable for 0 < K < K* (``inf`` if stable for all K > 0;
        0 if unstable for every small K > 0).
    frequency : float or None
        Boundary frequency at K* (ω in rad/s for ``"s"``, φ in rad/sample for
        ``"z"``); None when K* is 0 or infinite.
    crossings : tuple of Crossing
        Every crossing with K > 0, sorted by gain.
    intervals : tuple of (float, float)
        Every stable gain interval (lo, hi), ascending; the first starts at 0
        when K* > 0. Stability in K need not be one interval: a sampled
        steering loop with kT near 2 is unstable for small K and stable
        further up.
    """

    gain: float
    frequency: float | None
    crossings: tuple
    intervals: tuple = ()


def _align(d, e):
    n = max(len(d), len(e))
    return np.pad(d, (n - len(d), 0)), np.pad(e, (n - len(e), 0))


def _imaginary_axis_parts(p: np.ndarray):
    """Real and imaginary parts of p(jω) as real polynomials in ω (descending)."""
    n = len(p) - 1
    re = np.zeros(n + 1)
    im = np.zeros(n + 1)
    for idx, coeff in enumerate(p):
        power = n - idx
        unit = (1, 1j, -1, -1j)[power % 4]
        if unit.real:
            re[idx] = coeff * unit.real
        else:
            im[idx] = coeff * unit.imag
    return re, im


def _real_roots(poly: np.ndarray, low: float, high: float) -> np.ndarray:
    poly = np.trim_zeros(np.asarray(poly, dtype=float), "f")
    if poly.size <= 1:
        return np.empty(0)
    roots = np.roots(poly)
    scale = np.maximum(np.abs(roots), 1.0)
    real = roots[np.abs(roots.imag) <= _REAL_ROOT_TOL * scale].real
    real = real[(real >= low - _REAL_ROOT_TOL) & (real <= high + _REAL_ROOT_TOL)]
    return np.unique(np.clip(real, low, high))


def _s_crossings(d, e):
    d_re, d_im = _imaginary_axis_parts(d)
    e_re, e_im = _imaginary_axis_parts(e)
    # Im(D conj E) = Im D · Re E − Re D · Im E, a real polynomial in ω
    im_part = np.polysub(np.polymul(d_im, e_re), np.polymul(d_re, e_im))
    omegas = _real_roots(im_part, 0.0, np.inf)
    if not np.any(np.trim_zeros(im_part, "f")):
        raise ValueError("D·conj(E) is real on the whole imaginary axis; crossings are not isolated")
    out = []
    for w in np.append(omegas, 0.0):
        dv = np.polyval(d, 1j * w)
        ev = np.polyval(e, 1j * w)
        if abs(ev) == 0.0:
            continue
        out.append((float(np.real(-dv / ev)), float(w)))
    return out


def _chebyshev_u_to_power(b: np.ndarray) -> np.ndarray:
    """Σ_{m≥1} b[m] U_{m−1}(x) as descending power coefficients in x."""
    poly = np.zeros(1)
    u_prev, u_curr = np.zeros(1), np.ones(1)  # U_{-1} = 0, U_0 = 1
    for m in range(1, len(b)):
        poly = np.polyadd(poly, b[m] * u_curr)
        u_prev, u_curr = u_curr, np.polysub(np.polymul([2.0, 0.0], u_curr), u_prev)
    return poly


def _z_crossings(d, e):
    d_asc, e_asc = d[::-1], e[::-1]
    # cross[m] = Σ_i d_i e_(i−m): D(z)·conj E(z) on |z| = 1 equals Σ_m cross[m] e^{jmφ}
    full = np.correlate(d_asc, e_asc, mode="full")
    zero_lag = len(e_asc) - 1
    lags = np.arange(len(full)) - zero_lag
    top = int(lags.max(initial=0))
    b = np.zeros(max(top, 0) + 1)
    for lag, value in zip(lags, full):
        if lag > 0:
            b[lag] += value
        elif lag < 0:
            b[-lag] -= value
    poly = _chebyshev_u_to_power(b)
    cosines = _real_roots(poly, -1.0, 1.0) if np.any(poly) else np.empty(0)
    phis = np.concatenate([np.arccos(cosines), [0.0, math.pi]])
    out = []
    for phi in np.unique(phis):
        z = np.exp(1j * phi)
        ev = np.polyval(e, z)
        if abs(ev) == 0.0:
            continue
        out.append((float(np.real(-np.polyval(d, z) / ev)), float(phi)))
    return out


def affine_crossings(d, e, domain: str = "s") -> list[Crossing]:
    """All crossings of the stability boundary by roots of D + K·E with K > 0.

    Parameters
    ----------
    d, e : array_like
        Descending coefficients of D and E (real).
    domain : {"s", "z"}
        ``"s"``: the boundary is the imaginary axis; ``"z"``: the unit circle.

    Returns
    -------
    list of Crossing
        Sorted by gain; conjugate crossings appear once (ω ≥ 0, φ ∈ [0, π]).
    """
    d = np.asarray(d, dtype=float)
    e = np.asarray(e, dtype=float)
    d, e = _align(d, e)
    raw = _s_crossings(d, e) if domain == "s" else _z_crossings(d, e)
    # K = −D/E at a root of D on the boundary is 0 up to round-off: not a positive crossing
    zero = 1e3 * np.finfo(float).eps * np.max(np.abs(d)) / np.max(np.abs(e))
    crossings = sorted({(g, w) for g, w in raw if g > zero and math.isfinite(g)})
    return [Crossing(g, w) for g, w in crossings]


def verdict_at(d, e, gain: float, domain: str = "s") -> bool:
    """True when D + gain·E is Hurwitz (``"s"``, Routh) or Schur (``"z"``, Schur–Cohn).

    Parameters
    ----------
    d, e : array_like
        Real coefficients of D and E, descending powers (aligned on the constant term).
    gain : float
        The gain K in D + K·E.
    domain : {"s", "z"}
        ``"s"``: continuous time (Hurwitz); ``"z"``: discrete time (Schur).
    """
    d, e = _align(np.asarray(d, dtype=float), np.asarray(e, dtype=float))
    p = strip_leading_zeros(d + gain * e)
    return routh_array(p).stable if domain == "s" else schur_cohn_stable(p)


def stable_set(crossings, is_stable) -> tuple:
    """Every interval of gains K > 0 on which the loop is stable.

    Stability can change only at a crossing gain, so one verdict between
    consecutive crossing gains (and beyond the last) decides each stretch;
    adjacent stable stretches (a crossing that merely touches the boundary)
    are merged.

    Parameters
    ----------
    crossings : sequence of Crossing
        Every boundary crossing with K > 0, sorted by gain.
    is_stable : callable
        ``is_stable(K) -> bool`` by an independent test.

    Returns
    -------
    tuple of (float, float)
        Ascending (lo, hi) pairs; hi may be ``inf``.
    """
    gains = sorted({c.gain for c in crossings})
    edges = [0.0] + gains + [math.inf]
    out = []
    for lo, hi in zip(edges, edges[1:]):
        probe = (lo + hi) / 2 if math.isfinite(hi) else (2 * lo if lo > 0 else 1.0)
        if is_stable(probe):
            if out and out[-1][1] == lo:
                out[-1] = (out[-1][0], hi)
            else:
                out.append((lo, hi))
    return tuple(out)


def stable_interval(crossings, is_stable) -> StabilityInterval:
    """K*: the end of the interval (0, K*) of stabilizing gains.

    Parameters
    ----------
    crossings : sequence of Crossing
        Every boundary crossing with K > 0 (of any loop, polynomial or not),
        sorted by gain.
    is_stable : callable
        ``is_stable(K) -> bool`` by an independent test (Routh, Schur–Cohn, a
        crossing count). It is asked once between consecutive crossing gains
        (and beyond the last one), so a crossing that merely touches the
        boundary does not end the interval.

    Returns
    -------
    StabilityInterval
        K* = 0 when the loop is unstable for every small K > 0.
    """
    crossings = tuple(crossings)
    intervals = stable_set(crossings, is_stable)
    if not intervals or intervals[0][0] > 0:
        return StabilityInterval(0.0, None, crossings, intervals)
    end = intervals[0][1]
    if math.isinf(end):
        return StabilityInterval(math.inf, None, crossings, intervals)
    frequency = next(c.frequency for c in crossings if c.gain == end)
    return StabilityInterval(end, frequency, crossings, intervals)


def first_stable_interval(d, e, domain: str = "s") -> StabilityInterval:
    """K* of D + K·E: `stable_interval` with Routh (``"s"``) or Schur–Cohn (``"z"``).

    Parameters
    ----------
    d, e : array_like
        Descending coefficients (real).
    domain : {"s", "z"}

    Returns
    -------
    StabilityInterval
    """
    return stable_interval(affine_crossings(d, e, domain), lambda gain: verdict_at(d, e, gain, domain))


def walk_stable_set(base: int, crossings, tail=None) -> StabilityInterval:
    """The stable gains from the count of unstable roots at K → 0+ and the direction of every crossing above it.

    The count changes only at a crossing, by its `change` (+2 when a root pair moves into the unstable region as K
    grows, −2 when it leaves, ±1 for a real root through s = 0 or z = −1, 0 when it touches and returns), so the
    stretches where it is 0 are the stable set; no verdict is asked between crossings.

    Parameters
    ----------
    base : int
        Unstable roots for small K > 0.
    crossings : sequence of (float, float, int)
        (gain K > 0, frequency, change), every crossing that can bound the stable set (any order).
    tail : callable, optional
        ``tail(gain) -> (gain, frequency) or None``: the next crossing above the last one, for a crossing set that is
        complete only up to its last gain and beyond which every crossing destabilises; without it a stretch stable
        past the last crossing is stable for every larger K.

    Returns
    -------
    StabilityInterval
        K* = 0 when the loop is unstable for every small K > 0.
    """
    crossings = sorted(crossings)
    count, edges, intervals, start = base, [], [], 0.0 if base == 0 else None
    for gain, frequency, change in crossings:
        count += change
        edges.append(Crossing(gain, frequency))
        if start is not None and count > 0:
            intervals.append((start, gain))
            start = None
        elif start is None and count == 0:
            start = gain
    if start is not None:
        above = tail(crossings[-1][0] if crossings else 0.0) if tail is not None else None
        intervals.append((start, math.inf if above is None else above[0]))
        if above is not None:
            edges.append(Crossing(*above))
    intervals = [(lo, hi) for lo, hi in intervals if lo < hi]
    if not intervals or intervals[0][0] > 0:
        return StabilityInterval(0.0, None, tuple(edges), tuple(intervals))
    end = intervals[0][1]
    frequency = None if math.isinf(end) else next(c.frequency for c in edges if c.gain == end)
    return StabilityInterval(end, frequency, tuple(edges), tuple(intervals))
