"""Vectorized `exact_delay` verdicts: millions of parameter points per second.

For KB eq (18), a(s) + K e^(−sT) with a(s) = τs³ + s² + ks and K = kNV, the
crossing count of `pfm_stability.delay` (Cooke & van den Driessche 1986) needs
no iteration at all:

1. crossing frequencies: the positive roots y = ω² of
   F(y) = |a(jω)|² − K² = τ²y³ + (1 − 2kτ)y² + k²y − K² (closed-form cubic,
   polished by two Newton steps); there are three when kτ > 2 + √3 (the
   steering loop resonates), else one;
2. direction of each crossing as T grows: sign F′(y);
3. first crossing delay: T₀ = (ψ mod 2π)/ω with ψ = atan((k − τω²)/ω);
   the crossings repeat every 2π/ω;
4. roots in Re s > 0: Z = Z₀ + 2·Σ direction·#{m : T₀ + 2πm/ω < T}, with
   Z₀ = 2 if τK > k (Routh on a(s) + K), else 0.

Stable ⇔ Z = 0. The delay margin (largest T that keeps the point stable, s) is
the smallest T₀ when Z₀ = 0, and 0 otherwise. Every parameter may vary per
point; N comes from KB's power law for a wall (eq 11, 23) or a corridor (eq 25).
Chunks of the arrays are processed on all cores (numpy releases the GIL).
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .parameters import RANGES, check_parameter

__all__ = ["VectorVerdicts", "exact_delay_verdicts", "loop_gain_arrays", "delay_verdicts_from_gain"]

_CHUNK = 32768
_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class VectorVerdicts:
    """Per-point `exact_delay` answers.

    Attributes
    ----------
    stable : ndarray of bool
        No root in Re s >= 0.
    unstable_roots : ndarray of int
        Number of roots with Re s > 0 (crossing count).
    delay_margin : ndarray of float
        Largest T keeping the point stable (τ, k, NV fixed), s; ``inf`` if
        none limits it; 0 if unstable at T = 0.
    NV : ndarray of float
        Loop NV, 1/s.
    T : ndarray of float
        The sampling period / delay of each point, s.
    """

    stable: np.ndarray
    unstable_roots: np.ndarray
    delay_margin: np.ndarray
    NV: np.ndarray
    T: np.ndarray

    @property
    def relative_delay_margin(self) -> np.ndarray:
        """T*/T − 1: distance from the boundary in T (inf where T = 0 and stable, −1 where unstable at T = 0)."""
        positive = self.T > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = self.delay_margin / np.where(positive, self.T, 1.0) - 1.0
        return np.where(positive, ratio, np.where(self.stable, np.inf, -1.0))


def _check(name, x):
    """x as a float array, every value in ``RANGES[name]``; else the library's message and the point index."""
    x = np.asarray(x, dtype=float)
    r = RANGES[name]
    bad = ~np.isfinite(x)
    bad |= (x <= r.low) if r.low_open else (x < r.low)
    bad |= (x >= r.high) if r.high_open else (x > r.high)
    if bad.any():
        index = int(np.flatnonzero(bad.ravel())[0])
        try:
            check_parameter(name, float(x.ravel()[index]))
        except ValueError as exc:
            raise ValueError(f"{exc} (point {index})") from None
    return x


def loop_gain_arrays(V, tau, T, k, f, n, W, *, alpha=None, L=None):
    """Validated, broadcast arrays (tau, T, k, NV) for a wall (α, rad) or a corridor (L, m).

    N per KB's power law: wall N = (n/W) f^(−1/n) cos^((n+1)/n)α / sin α
    (eq 11 at the equilibrium of eq 23); corridor N = 2nfWⁿ/L^(n+1) (eq 25).

    Raises
    ------
    ValueError
        Naming the first offending parameter, its range and the point index.
    """
    if (alpha is None) == (L is None):
        raise ValueError("exactly one of alpha (wall, rad) or L (corridor, m) must be given")
    V, tau, T, k, f, n, W = (_check(name, x) for name, x in zip(("V", "tau", "T", "k", "f", "n", "W"), (V, tau, T, k, f, n, W)))
    if alpha is not None:
        alpha = _check("alpha", alpha)
        N = (n / W) * f ** (-1.0 / n) * np.cos(alpha) ** ((n + 1.0) / n) / np.sin(alpha)
    else:
        L = _check("L", L)
        L_all, W_all = (a.ravel() for a in np.broadcast_arrays(L, W))
        narrow = np.flatnonzero(L_all <= W_all / 2)
        if narrow.size:
            i = int(narrow[0])
            high = RANGES["L"].high
            raise ValueError(f"L must be a finite number in (W/2, {high:g}] m = ({W_all[i] / 2:g}, {high:g}] m; got {float(L_all[i])!r} (point {i})")
        N = 2.0 * n * f * W**n / L ** (n + 1.0)
    tau, T, k, NV = np.broadcast_arrays(tau, T, k, N * V)
    return tau, T, k, NV


def _cubic_positive_roots(tau, k, K):
    """Positive roots y of F(y) = τ²y³ + (1 − 2kτ)y² + k²y − K² (up to three; NaN where absent).

    No discriminant (it cancels catastrophically when τ is small): the
    critical points of F (a stable quadratic formula) split (0, ∞) into
    intervals where F is monotone and of one convexity, so each root is reached
    by Newton's method from a start that satisfies Fourier's condition
    F·F″ > 0 — convergence is monotone and needs no safeguard. τ = 0 leaves
    the quadratic y² + k²y − K² (one positive root, closed form).
    """
    roots = np.full(tau.shape + (3,), np.nan)
    quadratic = tau == 0
    if quadratic.any():
        kk, KK = k[quadratic] ** 2, K[quadratic] ** 2
        roots[quadratic, 0] = 2 * KK / (kk + np.sqrt(kk * kk + 4 * KK))
    cubic = ~quadratic
    if cubic.any():
        roots[cubic] = _newton_cubic_roots(tau[cubic] ** 2, 1 - 2 * k[cubic] * tau[cubic], k[cubic] ** 2, K[cubic] ** 2)
    return roots


def _newton_cubic_roots(a, beta, c, D):
    """Up to three positive roots of a·y³ + β·y² + c·y − D (a, c, D > 0)."""

    def F(y):
        return ((a * y + beta) * y + c) * y - D

    inflection = -beta / (3 * a)
    disc = beta * beta - 3 * a * c
    critical = (beta < 0) & (disc > 0)
    c2 = np.where(critical, (-beta + np.sqrt(np.maximum(disc, 0))) / (3 * a), np.inf)
    c1 = np.where(critical, c / (3 * a * np.where(critical, c2, 1.0)), np.inf)
    F1 = np.where(critical, F(np.where(critical, c1, 0.0)), np.inf)
    F2 = np.where(critical, F(np.where(critical, c2, 0.0)), -np.inf)
    # a point right of every root: with β >= 0 each term alone bounds the root
    # (within a factor 3 of it); otherwise Fujiwara's bound
    with np.errstate(divide="ignore"):
        positive_bound = np.minimum.reduce([D / c, np.sqrt(D / np.where(beta > 0, beta, 0.0)), np.cbrt(D / a)])
    right = np.where(beta >= 0, positive_bound, 2 * np.maximum.reduce([np.abs(beta) / a, np.sqrt(c / a), np.cbrt(D / (2 * a))]))
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
    y = out
    return y


def delay_verdicts_from_gain(tau, T, k, K):
    """Crossing-count verdicts for arrays (τ, T, k, K = kNV); returns (stable, Z, delay margin)."""
    y = _cubic_positive_roots(tau, k, K)
    present = np.isfinite(y)
    y0 = np.where(present, y, 1.0)
    w = np.sqrt(y0)
    t3, k3 = tau[:, None], k[:, None]
    slope = 3 * t3**2 * y0**2 + 2 * (1 - 2 * k3 * t3) * y0 + k3**2
    direction = np.where(present, np.sign(slope), 0.0)
    psi = np.arctan((k3 - t3 * y0) / w)
    first = np.where(psi >= 0, psi, psi + _TWO_PI) / w
    passed = np.where(present & (T[:, None] > first), np.floor((T[:, None] - first) * w / _TWO_PI) + 1, 0.0)
    base = np.where(tau * K > k, 2, 0)
    Z = base + 2 * np.sum(direction * passed, axis=1).astype(np.int64)
    margin = np.where(base == 0, np.min(np.where(present, first, np.inf), axis=1), 0.0)
    return Z == 0, Z, margin


def _run_chunks(func, arrays):
    size = arrays[0].size
    flat = [a.ravel() for a in arrays]
    bounds = [(i, min(i + _CHUNK, size)) for i in range(0, size, _CHUNK)]
    workers = min(os.cpu_count() or 1, len(bounds)) or 1
    outputs = [None] * len(bounds)

    def work(j):
        lo, hi = bounds[j]
        outputs[j] = func(*(a[lo:hi] for a in flat))

    if workers > 1:
        with ThreadPoolExecutor(workers) as pool:
            list(pool.map(work, range(len(bounds))))
    else:
        for j in range(len(bounds)):
            work(j)
    if not outputs:
        return [np.empty(0, dtype=bool), np.empty(0, dtype=np.int64), np.empty(0)]
    return [np.concatenate([o[i] for o in outputs]) for i in range(len(outputs[0]))]


def exact_delay_verdicts(V, tau, T, k, f, n, W, *, alpha=None, L=None) -> VectorVerdicts:
    """`exact_delay` verdicts and delay margins for arrays of parameters.

    Parameters
    ----------
    V, tau, T, k, f, n, W : array_like
        Speed (m/s), steering time constant (s), sampling period (s), steering
        gain (1/s), force ratio, exponent, width (m); broadcast together.
    alpha : array_like, optional
        Wall target angle, rad, in (0, π/2) (KB eq 9).
    L : array_like, optional
        Corridor half-width, m, > W/2 (KB eq 25).

    Returns
    -------
    VectorVerdicts
        Arrays shaped like the broadcast inputs.

    Raises
    ------
    ValueError
        For the first out-of-range value (parameter, range, point index).
    """
    tau, T, k, NV = loop_gain_arrays(V, tau, T, k, f, n, W, alpha=alpha, L=L)
    shape = NV.shape
    K = k * NV
    stable, Z, margin = _run_chunks(delay_verdicts_from_gain, [tau, T, k, K])
    return VectorVerdicts(stable.reshape(shape), Z.reshape(shape), margin.reshape(shape), NV, T)
