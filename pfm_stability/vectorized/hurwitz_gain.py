"""Stable gain sets of Q(μ; K) = D(μ) + K·E(μ), degree <= 4, from the Hurwitz conditions in K.

A faster route to `polynomial.affine_stable_sets` for coefficient columns of
degree n <= 4 (the sampled loops' bilinear polynomials, Padé(1, 1)).
Stability changes with K only where a root of Q crosses the imaginary axis
or passes through infinity, i.e. where

* the leading coefficient q₀(K) vanishes (a root through ∞; the bilinear
  map's degree drop, z = −1),
* the constant coefficient q_n(K) vanishes (a real root through μ = 0), or
* the last Hurwitz determinant Δ_{n−1}(K) vanishes: by Orlando's formula
  Δ_{n−1} = ±q₀^{n−1}·Π_{i<j}(μᵢ + μⱼ) (Gantmacher 1959, ch. XV), which for
  roots in the closed left half-plane vanishes only for a pair ±jΩ.

Every qᵢ is affine in K, so Δ_{n−1}(K) is a polynomial of degree <= n − 1
<= 3 (Δ₁ = q₁, Δ₂ = q₁q₂ − q₀q₃, Δ₃ = q₁q₂q₃ − q₀q₃² − q₁²q₄, expanded
in K by products of the affine columns): its real roots come in closed form
(Cardano / Viète, then Newton-polished). These candidate gains, sorted,
split K > 0 into stretches on each of which the verdict is constant; the
closed-form Liénard–Chipart test (`polynomial.hurwitz_columns`) at one gain
per stretch gives the whole stable set — so K*, and whether the set is
(0, K*) (`regular`), as `polynomial._stable_sets` reads them. At a pair
crossing Q = (μ² + Ω²)·R(μ) gives Ω² = q₃/q₁ (n = 3, 4) or q₂/q₀ (n = 2).

Rows this route cannot settle are flagged `unsure` (the caller sends them
to `affine_stable_sets`): non-finite or degenerate coefficients (Δ ≡ 0),
a near-double root of Δ (a tangency: the cubic's complex pair within 10⁻⁶ of
the real axis), two candidate gains within 10⁻⁹ of each other (a tie: which
crossing sets ω* is ambiguous), a root that does not polish to a small
residual, a candidate gain in (0, ε-level] (`affine_stable_sets` drops
those), or a pair edge at K* without a positive Ω².
"""

from __future__ import annotations

import math

import numpy as np

from .polynomial import GainSets, _quadratic, hurwitz_columns

__all__ = ["hurwitz_determinant_in_gain", "hurwitz_gain_sets"]

_TIE_RTOL = 1e-9
"""Candidate gains closer than this (relative) make a row `unsure`."""

_NEAR_REAL = 1e-6
"""A complex pair of Δ's roots with |Im| <= this·|root| is a possible tangency: `unsure`."""

_RESIDUAL = 1e-8
"""A polished root of Δ must satisfy |Δ(K)| <= this·Σ|cᵢ||K|ⁱ, else `unsure`."""


def _mul(a, b):
    """Product of two polynomials in K given as lists of coefficient arrays (ascending)."""
    out = [0.0] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            out[i + j] = out[i + j] + x * y
    return out


def _sub(a, b):
    """a − b for ascending coefficient lists (padded to one length)."""
    n = max(len(a), len(b))
    a = list(a) + [0.0] * (n - len(a))
    b = list(b) + [0.0] * (n - len(b))
    return [x - y for x, y in zip(a, b)]


def hurwitz_determinant_in_gain(D, E) -> np.ndarray:
    """Ascending coefficients in K of Δ_{n−1}(K), the last Hurwitz determinant of D + K·E.

    Parameters
    ----------
    D, E : list of ndarray
        Descending coefficient columns (one length n + 1, 3 <= n + 1 <= 5).

    Returns
    -------
    ndarray, shape (N, n)
        Column j is the coefficient of K^j (degree <= n − 1).
    """
    n = len(D) - 1
    q = [[d, e] for d, e in zip(D, E)]
    if n == 2:
        delta = q[1]
    elif n == 3:
        delta = _sub(_mul(q[1], q[2]), _mul(q[0], q[3]))
    elif n == 4:
        delta = _sub(_sub(_mul(_mul(q[1], q[2]), q[3]), _mul(q[0], _mul(q[3], q[3]))), _mul(_mul(q[1], q[1]), q[4]))
    else:
        raise ValueError(f"hurwitz_determinant_in_gain takes degree 2 to 4; got {n}")
    N = np.broadcast(*D).shape[0]
    return np.stack([np.broadcast_to(x, (N,)) for x in delta], axis=1).astype(float)


def _cubic_roots(c):
    """Real roots of c₀ + c₁K + c₂K² + c₃K³ (c₃ != 0), NaN-padded (N, 3), and a near-tangency flag."""
    a, b, d = c[:, 2] / c[:, 3], c[:, 1] / c[:, 3], c[:, 0] / c[:, 3]
    Q = (a * a - 3.0 * b) / 9.0
    R = (2.0 * a * a * a - 9.0 * a * b + 27.0 * d) / 54.0
    Q3 = Q * Q * Q
    three = R * R < Q3
    shift = a / 3.0
    out = np.full((a.size, 3), np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        sq = np.sqrt(np.where(three, Q, 0.0))
        theta = np.arccos(np.clip(R / np.where(three, np.sqrt(np.where(three, Q3, 1.0)), 1.0), -1.0, 1.0))
        for j, offset in enumerate((0.0, 2.0 * math.pi, -2.0 * math.pi)):
            out[:, j] = np.where(three, -2.0 * sq * np.cos((theta + offset) / 3.0) - shift, np.nan)
        A = -np.sign(R) * np.cbrt(np.abs(R) + np.sqrt(np.maximum(R * R - Q3, 0.0)))
        A = np.where(A == 0, 0.0, A)
        B = np.where(A != 0, Q / np.where(A != 0, A, 1.0), 0.0)
        real = A + B - shift
        imag = 0.5 * math.sqrt(3.0) * np.abs(A - B)
        pair = -0.5 * (A + B) - shift
    out[:, 0] = np.where(three, out[:, 0], real)
    tangent = ~three & (pair > 0) & (imag <= _NEAR_REAL * np.maximum(np.abs(pair), np.abs(real)))
    return out, tangent


def _gain_roots(c):
    """Positive real roots of each row of Δ(K) (ascending c, degree <= 3), NaN-padded (N, 3); and `unsure`.

    Negative roots do not matter (K > 0) and are dropped before the polish;
    a near-double root counts (`unsure`) only where its real part is positive."""
    N, width = c.shape
    roots = np.full((N, 3), np.nan)
    unsure = np.zeros(N, dtype=bool)
    nonzero = c != 0
    degree = np.where(nonzero.any(axis=1), width - 1 - np.argmax(nonzero[:, ::-1], axis=1), -1)
    unsure |= degree < 0  # Δ ≡ 0
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for deg in (1, 2, 3):
            rows = np.flatnonzero(degree == deg)
            if not rows.size:
                continue
            part = c[rows, : deg + 1]
            if deg == 1:
                found = -part[:, :1] / part[:, 1:2]
            elif deg == 2:
                pair = _quadratic(part[:, 1] / part[:, 2], part[:, 0] / part[:, 2])
                real = pair.imag == 0
                found = np.where(real, pair.real, np.nan)
                unsure[rows] |= ~real[:, 0] & (pair.real[:, 0] > 0) & (np.abs(pair.imag[:, 0]) <= _NEAR_REAL * np.abs(pair[:, 0]))
            else:
                found, tangent = _cubic_roots(part)
                unsure[rows] |= tangent
            settled, bad = _settle(part, found)
            if deg == 3:  # Cardano is accurate for the large roots; on the reversed cubic (1/K), for the small ones
                # retried: rows not settled, and rows whose roots spread over > 3 decades (a pair of lost
                # small roots would escape the parity test): max(|c₂/c₃|, √|c₁/c₃|) > 10³·∛|c₀/c₃|
                spread = np.maximum(np.abs(part[:, 2]), np.sqrt(np.abs(part[:, 1] * part[:, 3]))) > 1e3 * np.cbrt(np.abs(part[:, 0]) * part[:, 3] ** 2)
                again = np.flatnonzero(bad | spread)
                flipped = part[again, ::-1]
                live = flipped[:, 3] != 0
                small, tangent_small = _cubic_roots(np.where(live[:, None], flipped, 1.0))
                both = np.concatenate([found[again], np.where(live[:, None], 1.0 / small, np.nan)], axis=1)
                settled[again], bad[again] = _settle(part[again], both)
                bad[again] |= tangent_small & live
            unsure[rows] |= bad
            roots[rows, :deg] = settled
    return roots, unsure


def _settle(part, found):
    """Newton-polished positive roots (N, deg) from candidates `found` (N, j), and rows not settled:
    a candidate failing the residual test is dropped, one root found twice counts once, and the
    number of positive roots must have the parity of the sign change of Δ between 0⁺ and ∞."""
    deg = part.shape[1] - 1
    cols = [part[:, j:j + 1] for j in range(deg + 1)]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        found = np.where(found > 0, found, np.nan)
        for _ in range(2):
            value, slope = cols[deg], 0.0
            for j in range(deg - 1, -1, -1):
                slope = slope * found + value
                value = value * found + cols[j]
            step = value / slope
            found = np.where(np.isfinite(step), found - step, found)
        value, scale = cols[deg], np.abs(cols[deg])
        for j in range(deg - 1, -1, -1):
            value = value * found + cols[j]
            scale = scale * found + np.abs(cols[j])
        found = np.sort(np.where((found > 0) & (np.abs(value) <= _RESIDUAL * scale), found, np.inf), axis=1)
        if found.shape[1] > 1:
            found[:, 1:][np.diff(found, axis=1) <= 1e-7 * found[:, 1:]] = np.inf  # one root found twice
            found = np.sort(found, axis=1)
    count = np.sum(np.isfinite(found), axis=1)
    nonzero = part != 0
    low = np.sign(part[np.arange(part.shape[0]), np.argmax(nonzero, axis=1)])
    bad = (count > deg) | ((count % 2 == 1) != (low * np.sign(part[:, deg]) < 0))
    out = np.full((part.shape[0], deg), np.nan)
    width = min(deg, found.shape[1])
    out[:, :width] = np.where(np.isfinite(found[:, :width]), found[:, :width], np.nan)
    return out, bad


def hurwitz_gain_sets(D, E, drop_frequency=None, frequency_map=None):
    """K*, ω* and regularity of D + K·E (columns, degree 2 to 4) from the Hurwitz conditions in K.

    Parameters
    ----------
    D, E : list of ndarray
        Descending coefficient columns, one length n + 1 (3 to 5), N rows each.
    drop_frequency : ndarray, shape (N,), optional
        ω reported where the leading coefficient vanishes at K* (the bilinear
        map's z = −1: π/T); NaN by default.
    frequency_map : callable, optional
        Applied to the crossing frequencies Ω (an (N, j) array; the bilinear
        map's Ω → ω); monotone, 0 ↦ 0.

    Returns
    -------
    sets : GainSets
        As `polynomial.affine_stable_sets` gives them, at the rows not `unsure`.
    unsure : ndarray of bool, shape (N,)
        Rows this route does not settle (module docstring): decide them by
        `affine_stable_sets`.
    """
    n = len(D) - 1
    D = [np.asarray(x, dtype=float) for x in D]
    E = [np.asarray(x, dtype=float) for x in E]
    N = D[0].size
    delta = hurwitz_determinant_in_gain(D, E)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        pair, unsure = _gain_roots(delta)
        pair = np.where(pair > 0, pair, np.nan)
        q = [(d[:, None] + pair * e[:, None]) for d, e in zip(D, E)]
        omega2 = q[3] / q[1] if n >= 3 else q[2] / q[0]
        omega = np.sqrt(np.where(omega2 > 0, omega2, np.nan))
        lead = -D[0] / E[0]
        lead = np.where((E[0] != 0) & (lead > 0), lead, np.nan)
        const = -D[n] / E[n]
        const = np.where((E[n] != 0) & (const > 0), const, np.nan)
    if frequency_map is not None:
        with np.errstate(invalid="ignore"):
            omega = frequency_map(omega)
    drop = np.full(N, np.nan) if drop_frequency is None else np.asarray(drop_frequency, dtype=float)
    gain = np.concatenate([pair, lead[:, None], const[:, None]], axis=1)
    w = np.concatenate([omega, drop[:, None], np.zeros((N, 1))], axis=1)
    Dm, Em = np.stack(D, axis=1), np.stack(E, axis=1)
    finite = np.isfinite(Dm).all(axis=1) & np.isfinite(Em).all(axis=1)
    unsure |= ~finite
    scale_E = np.max(np.abs(Em), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        zero = 1e3 * np.finfo(float).eps * np.max(np.abs(Dm), axis=1) / scale_E
    tiny = np.concatenate([pair, const[:, None]], axis=1)
    unsure |= np.any(tiny <= zero[:, None], axis=1) | ~(scale_E > 0)
    key = np.where(np.isfinite(gain) & ~unsure[:, None], gain, np.inf)
    order = np.argsort(key, axis=1)
    key = np.take_along_axis(key, order, axis=1)
    w = np.take_along_axis(w, order, axis=1)
    with np.errstate(invalid="ignore"):
        unsure |= np.any(np.isfinite(key[:, 1:]) & (np.diff(key, axis=1) <= _TIE_RTOL * key[:, 1:]), axis=1)
    sets = _first_interval(D, E, key, w)
    unsure |= np.isfinite(sets.K_critical) & (sets.K_critical > 0) & ~np.isfinite(sets.frequency)
    return sets, unsure


def _first_interval(D, E, key, w) -> GainSets:
    """`polynomial._stable_sets` for sorted, distinct candidate gains `key` (inf: none) and their ω:
    the Liénard–Chipart test (`hurwitz_columns`) once per stretch, all rows and stretches at once."""
    N, m = key.shape
    lower = np.concatenate([np.zeros((N, 1)), key], axis=1)
    upper = np.concatenate([key, np.full((N, 1), np.inf)], axis=1)
    live = np.isfinite(lower)
    with np.errstate(invalid="ignore", over="ignore"):
        probe = np.where(np.isfinite(upper), 0.5 * (lower + upper), np.where(lower > 0, 2.0 * lower, 1.0))
        probe = np.where(live, probe, 1.0)
        verdicts = hurwitz_columns([(d[:, None] + probe * e[:, None]).ravel() for d, e in zip(D, E)]).reshape(N, m + 1)
    for j in range(1, m + 1):  # unused stretches take the verdict before them
        verdicts[:, j] = np.where(live[:, j], verdicts[:, j], verdicts[:, j - 1])
    first_unstable = np.where(verdicts.all(axis=1), m + 1, np.argmin(verdicts, axis=1))
    rows = np.arange(N)
    edge = np.minimum(np.maximum(first_unstable - 1, 0), m - 1)
    K_star = np.where(first_unstable > m, np.inf, np.where(verdicts[:, 0], key[rows, edge], 0.0))
    frequency = np.where(np.isfinite(K_star) & (K_star > 0), w[rows, edge], math.nan)
    later = np.arange(m + 1)[None, :] > first_unstable[:, None]
    regular = ~np.any(later & verdicts & live, axis=1)
    return GainSets(K_star, frequency, regular)
