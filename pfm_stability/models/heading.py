"""Gain crossings of KB's delay loop with a heading gain: τs³ + s² + ks + (kcs + K)·e^(−sT).

The heading gain c (`Loop.c`, docs/models.md "The heading gain") adds kc·s to
the delayed term of KB eq (18). The crossing count and the rightmost roots of
`pfm_stability.numerics.delay` take it directly; the stable set in K = kNV needs more,
because the gain crossings are no longer all destabilizing (for c = 0 they are,
and `delay.kb_critical_gain` finds K* among three levels). This module finds
every crossing that can bound the stable set, from polynomial roots and a
monotone level equation, and decides each stretch between them by the crossing
count (`kb_heading_interval`). `exact_delay` uses it for c ≠ 0 only.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.crossings import Crossing, StabilityInterval, first_stable_interval, stable_interval
from ..numerics.delay import delay_verdicts_from_gain
from ..numerics.solve import newton_increasing

__all__ = ["kb_heading_crossings", "kb_heading_interval", "heading_level_offset"]

_TWO_PI = 2.0 * math.pi


def heading_level_offset(w, tau, T, k, c):
    """G(ω) and G′(ω): G = ωT − atan(k/ω − τω) − asin(kc/R), R² = (k − τω²)² + ω².

    A root of τs³ + s² + ks + (kcs + K)·e^(−sT) sits at s = jω for a gain
    K > 0 exactly when G(ω) = 2πm (m = 0, 1, …), and then K = ω·√(R² − k²c²);
    it moves into Re s > 0 as K grows iff G′(ω) > 0 (Re ds/dK has the sign of
    G′). c = 0 gives KB's level function `_kb_level_offset`. G is defined
    where R >= k|c| (elsewhere no gain puts a root on the axis).

    Parameters
    ----------
    w : float or ndarray
        Frequency ω, rad/s.
    tau, T, k : float
        τ (s), T (s, > 0) and k (1/s).
    c : float
        Heading gain (dimensionless).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        y = w * w
        g = (k - tau * y) ** 2 + y
        kc = k * c
        G = w * T - np.arctan(k / w - tau * w) - np.arcsin(np.clip(kc / np.sqrt(g), -1.0, 1.0))
        g_y = 2 * tau * tau * y + 1 - 2 * k * tau
        slope = T + (k + tau * y) / g + kc * w * g_y / (g * np.sqrt(g - kc * kc))
    return G, np.where(np.isfinite(slope), slope, np.nan)


def _positive_roots(poly) -> list[float]:
    """Positive real roots of a real polynomial, generously (a near-real pair counts: an extra split is harmless)."""
    poly = np.trim_zeros(np.asarray(poly, dtype=float), "f")
    if poly.size <= 1:
        return []
    roots = np.roots(poly)
    keep = (np.abs(roots.imag) <= 1e-6 * np.abs(roots)) & (roots.real > 0)
    return [float(r) for r in roots.real[keep]]


def kb_heading_crossings(tau: float, T: float, k: float, c: float) -> list[Crossing]:
    """The gain crossings (K > 0, ω) that decide the stable set of τs³ + s² + ks + (kcs + K)e^(−sT), T > 0.

    A root is on the axis at s = jω for K > 0 iff G(ω) = 2πm
    (`heading_level_offset`), with K = ω√(R² − k²c²); its direction is
    sign G′. With c ≠ 0, G need not increase, so a crossing can be
    stabilizing and the stable set need not be one interval. Everything
    reduces to polynomials in y = ω²:

    * G′ = 0 ⇔ (Tg + k + τy)²(g − k²c²) = k²c²·y·g_y² (after squaring; a
      degree-6 polynomial, g = (k − τy)² + y, g_y = dg/dy), so the critical
      points of G are roots of a polynomial; so are the ends of G's domain
      (g = k²c²) and the critical points of K² = y(g − k²c²). Between
      consecutive split points G and K are both monotone, and each level
      2πm in G's range there gives exactly one crossing.
    * On a stretch where G decreases, G = ωT − atan(·) − asin(·) falls by less
      than 2π: at most one (stabilizing) crossing each. Let S be their number.
    * Every other crossing is destabilizing, so once S + 1 of them lie below
      K, Z(K) >= 2 for good. From each stretch where G increases only its
      S + 1 lowest-gain levels can therefore matter (the first levels where
      K increases with ω, the last where it decreases; the unbounded last
      stretch has increasing K), and the list returned holds every crossing
      below the (S + 1)-th lowest destabilizing gain: `stable_interval` with
      the crossing count is then exact.

    Parameters
    ----------
    tau, T, k : float
        τ (s), T (s, > 0) and k (1/s).
    c : float
        Heading gain (dimensionless).

    Returns
    -------
    list of Crossing
        Sorted by gain (ω in rad/s).
    """
    kc = k * c
    g = np.array([tau * tau, 1 - 2 * k * tau, k * k])
    q = np.array([tau * tau, 1 - 2 * k * tau, k * k - kc * kc])  # g − k²c²; K² = y·q(y)
    g_y = np.array([2 * tau * tau, 1 - 2 * k * tau])
    P = np.polyadd(T * g, [tau, k])
    critical = np.polysub(np.polymul(np.polymul(P, P), q), kc * kc * np.polymul([1.0, 0.0], np.polymul(g_y, g_y)))
    K_slope = np.array([3 * tau * tau, 2 * (1 - 2 * k * tau), k * k - kc * kc])
    splits = sorted({0.0, *_positive_roots(q), *_positive_roots(critical), *_positive_roots(K_slope)})

    def level(w):
        return float(heading_level_offset(np.array([w]), tau, T, k, c)[0][0])

    stretches = []  # (w_a, w_b, G_a, G_b, increasing, K increasing)
    for y_a, y_b in zip(splits, splits[1:] + [math.inf]):
        mid = 0.5 * (y_a + y_b) if math.isfinite(y_b) else 2.0 * y_a + 1.0
        if np.polyval(q, mid) <= 0:
            continue
        w_a, w_b = math.sqrt(y_a), math.sqrt(y_b)
        G_a = level(w_a) if w_a > 0 else -0.5 * math.pi - math.asin(max(-1.0, min(1.0, c)))
        G_b = level(w_b) if math.isfinite(w_b) else math.inf
        stretches.append((w_a, w_b, G_a, G_b, G_b > G_a, np.polyval(K_slope, mid) > 0))
    falling = [(s, m) for s in stretches if not s[4] for m in range(math.ceil(s[3] / _TWO_PI), math.floor(s[2] / _TWO_PI) + 1)]
    extra = len(falling)
    rising = []
    for s in stretches:
        if not s[4]:
            continue
        first = math.ceil(s[2] / _TWO_PI)
        last = math.floor(s[3] / _TWO_PI) if math.isfinite(s[3]) else first + extra
        levels = range(first, min(first + extra, last) + 1) if s[5] or not math.isfinite(s[3]) else range(max(last - extra, first), last + 1)
        rising.extend((s, m) for m in levels)
    pairs = falling + rising
    if not pairs:
        return []
    sign = np.array([1.0 if s[4] else -1.0 for s, _ in pairs])
    target = np.array([_TWO_PI * m for _, m in pairs])
    lo = np.array([s[0] for s, _ in pairs])
    hi = np.array([s[1] if math.isfinite(s[1]) else max((2 * m + 1) * math.pi / T, 2 * s[0] + 1) for s, m in pairs])

    def func(w):
        G, slope = heading_level_offset(w, tau, T, k, c)
        return sign * (G - target), sign * slope

    w = newton_increasing(func, lo, hi)
    with np.errstate(invalid="ignore"):
        K = w * np.sqrt(np.maximum(np.polyval(q, w * w), 0.0))
    return sorted((Crossing(float(g), float(x)) for g, x in zip(K, w) if g > 0), key=lambda cr: (cr.gain, cr.frequency))


def kb_heading_interval(tau: float, T: float, k: float, c: float) -> StabilityInterval:
    """Stable gains K = kNV of τs³ + s² + ks + (kcs + K)e^(−sT): every interval, K* and ω*.

    T = 0: the polynomial τs³ + s² + k(1 + c)s + K (Routh: K* = k(1 + c)/τ).
    T > 0: the crossings of `kb_heading_crossings`, each stretch between them
    decided by the crossing count (`delay_verdicts_from_gain`).

    Parameters
    ----------
    tau, T, k : float
        τ (s), T (s, >= 0) and k (1/s).
    c : float
        Heading gain (dimensionless).
    """
    if T == 0:
        plant = [tau, 1.0, k * (1.0 + c), 0.0] if tau > 0 else [1.0, k * (1.0 + c), 0.0]
        return first_stable_interval(plant, [1.0], "s")

    def stable(K):
        return bool(delay_verdicts_from_gain(*(np.array([x], dtype=float) for x in (tau, T, k, K, c)))[0][0])

    return stable_interval(kb_heading_crossings(tau, T, k, c), stable)
