"""Vectorized `exact_delay` verdicts: millions of parameter points per second.

For KB eq (18), a(s) + K e^(−sT) with a(s) = τs³ + s² + ks and K = kNV, the
crossing count of `pfm_stability.numerics.delay` (Cooke & van den Driessche 1986) needs
no search over T:

1. crossing frequencies: the positive roots y = ω² of
   F(y) = |a(jω)|² − K² = τ²y³ + (1 − 2kτ)y² + k²y − K² (Newton's method
   from starts that satisfy Fourier's condition, `delay._cubic_positive_roots`;
   the verdict-only path of `loop_verdicts` takes the one root of the
   non-resonant case in closed form, `delay_verdicts`); there are three when
   kτ > 2 + √3 (the steering loop resonates) and K² lies in the dip, else one;
2. direction of each crossing as T grows: sign F′(y);
3. first crossing delay: T₀ = (ψ mod 2π)/ω with ψ = atan((k − τω²)/ω);
   the crossings repeat every 2π/ω;
4. roots in Re s > 0: Z = Z₀ + 2·Σ direction·#{m : T₀ + 2πm/ω < T}, with
   Z₀ = 2 if τK > k (Routh on a(s) + K), else 0.

Stable ⇔ Z = 0. The delay margin (largest T that keeps the point stable, s) is
the smallest T₀ when Z₀ = 0, and 0 otherwise. Every parameter may vary per
point; N comes from KB's power law for a wall (eq 11, 23) or a corridor (eq 25).
Chunks of the arrays are processed on all cores (numpy releases the GIL).

A heading gain c (``c=`` array, default 0; docs/models.md, "The heading
gain") makes the delayed term kcs + K: F(y) gains −k²c²y, the first delay
gains arg(kcjω + K), and Z₀ is the Routh count of τs³ + s² + k(1 + c)s + K.
Without ``c`` (or with c = 0 everywhere) the code and the floats are KB's.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from ..numerics.delay import delay_verdicts_from_gain
from ..laws.force_law import power_law_corridor_gain, power_law_wall_gain
from ..models.loop import HEADING_GAIN_RANGE, check_heading_gain
from ..parameters import RANGES, T_RESOLUTION, TAU_RESOLUTION, check_parameter

__all__ = ["VectorVerdicts", "exact_delay_verdicts", "heading_gain_array", "loop_gain_arrays", "delay_verdicts_from_gain", "resolved_lag_and_delay"]

_CHUNK = 32768


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
    try:
        x = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number or an array of real numbers; got {x!r}") from None
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

    Parameters
    ----------
    V : array_like
        Speed, m/s.
    tau, T, k : array_like
        τ (s), T (s) and k (1/s).
    f, n : array_like
        KB's power law: strength and exponent (dimensionless).
    W : array_like
        Robot width, m.
    alpha : array_like, optional
        Target angle to the wall, rad (a wall; give `alpha` or `L`).
    L : array_like, optional
        Corridor half-width, m (a corridor).

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
        N = power_law_wall_gain(f, n, W, alpha)
    else:
        L = _check("L", L)
        L_all, W_all = (a.ravel() for a in np.broadcast_arrays(L, W))
        narrow = np.flatnonzero(L_all <= W_all / 2)
        if narrow.size:
            i = int(narrow[0])
            high = RANGES["L"].high
            raise ValueError(f"L must be a finite number in (W/2, {high:g}] m = ({W_all[i] / 2:g}, {high:g}] m; got {float(L_all[i])!r} (point {i})")
        N = power_law_corridor_gain(f, n, W, L)
    tau, T, k, NV = np.broadcast_arrays(tau, T, k, N * V)
    tau, T = resolved_lag_and_delay(tau, T, k)
    return tau, T, k, NV


def resolved_lag_and_delay(tau, T, k):
    """(τ, T) as the loop models take them, for arrays: the one array twin of `models.Loop`'s rule.

    τ with τk below `parameters.TAU_RESOLUTION` is 0 (an ideal steering motor) and
    T below `parameters.T_RESOLUTION` is 0 (a continuous controller).

    Parameters
    ----------
    tau, T, k : ndarray
        s, s, 1/s; broadcast together.

    Returns
    -------
    tau, T : ndarray
        New arrays, s.
    """
    return np.where(tau * k < TAU_RESOLUTION, 0.0, tau), np.where(T < T_RESOLUTION, 0.0, T)


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


def heading_gain_array(c) -> np.ndarray:
    """c as a float array, every value finite and in `HEADING_GAIN_RANGE`; else `Loop`'s message and the point index.

    Parameters
    ----------
    c : array_like
        Heading gains (dimensionless).
    """
    try:
        c = np.asarray(c, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"c must be a real number or an array of real numbers; got {c!r}") from None
    low, high = HEADING_GAIN_RANGE
    bad = ~np.isfinite(c) | (c < low) | (c > high)
    if bad.any():
        index = int(np.flatnonzero(bad.ravel())[0])
        try:
            check_heading_gain(float(c.ravel()[index]))
        except ValueError as exc:
            raise ValueError(f"{exc} (point {index})") from None
    return c


def exact_delay_verdicts(V, tau, T, k, f, n, W, *, alpha=None, L=None, c=None) -> VectorVerdicts:
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
    c : array_like, optional
        Heading gain, dimensionless, in [−0.99, 100] (`models.Loop.c`);
        default 0 everywhere (KB's loop, KB's code path).

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
    heading = [] if c is None else [heading_gain_array(c)]
    if heading and not heading[0].any():
        heading = []  # c = 0 everywhere: KB's code path
    if heading:
        tau, T, k, NV, heading[0] = np.broadcast_arrays(tau, T, k, NV, heading[0])
    shape = NV.shape
    K = k * NV
    stable, Z, margin = _run_chunks(delay_verdicts_from_gain, [tau, T, k, K] + heading)
    return VectorVerdicts(stable.reshape(shape), Z.reshape(shape), margin.reshape(shape), NV, T)
