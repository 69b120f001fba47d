"""Hurwitz tests and stable gain sets of D + K·E, in arrays over points.

Each row of a coefficient array is one point's polynomial (descending powers;
leading zeros allowed: a row's degree is that of its first non-zero entry).

* `hurwitz_stable`: the Routh array built for all rows at once (its first
  column, one array operation per entry); a row whose first column holds a 0
  or a non-finite value (the ε and auxiliary-polynomial cases) is decided by
  the scalar `routh.routh_array`, exactly as the models decide it.
* `affine_stable_sets`: the scalar route of `crossings.first_stable_interval`
  (domain "s") for every row at once. A root of D + K·E lies on the imaginary
  axis at s = jω for real K exactly where Im(D(jω)·conj E(jω)) = 0 — an odd
  polynomial in ω, i.e. ω times a polynomial h(y) in y = ω² — and then
  K = −Re(D/E)(jω). The non-negative real roots of h (closed forms up to
  degree 2, batched companion eigenvalues above; every root polished by
  Newton's method), with y = 0, give every crossing gain; one Routh test
  between consecutive gains (and beyond the last) decides each stretch.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.routh import routh_array

__all__ = ["hurwitz_stable", "hurwitz_columns", "affine_stable_sets", "GainSets", "real_roots", "leading_zeros"]

_REAL_ROOT_TOL = 1e-7
"""|Im y| <= this·max(1, |y|) counts as a real root (as `crossings` takes the roots in ω)."""


def leading_zeros(P) -> np.ndarray:
    """Number of leading exact zeros of each row (the row's degree is width − 1 − this).

    Parameters
    ----------
    P : ndarray, shape (N, width)
        Coefficient rows, descending powers.
    """
    nonzero = P != 0
    first = np.argmax(nonzero, axis=1)
    return np.where(nonzero.any(axis=1), first, P.shape[1])


def hurwitz_stable(P) -> np.ndarray:
    """Every root of each row in Re s < 0 (Routh), rows of any degree >= 0.

    Parameters
    ----------
    P : ndarray, shape (N, n + 1)
        Descending coefficients, one polynomial per row.

    Returns
    -------
    ndarray of bool, shape (N,)
        A constant (degree 0) is stable when non-zero; an all-zero row is not.
    """
    P = np.asarray(P, dtype=float)
    out = np.zeros(P.shape[0], dtype=bool)
    zeros = leading_zeros(P)
    for lead in np.unique(zeros):
        rows = np.flatnonzero(zeros == lead)
        if lead >= P.shape[1]:
            continue
        Q = P[rows, lead:]
        Q = Q * np.sign(Q[:, :1])
        stable, unsure = _routh_rows(Q)
        out[rows] = stable
        for i in np.flatnonzero(unsure):
            out[rows[i]] = routh_array(Q[i]).stable
    return out


def _routh_rows(Q):
    """(first column all > 0, first column has a 0 or a non-finite entry) for rows with Q[:, 0] > 0."""
    n = Q.shape[1] - 1
    if n == 0:
        return np.ones(Q.shape[0], dtype=bool), np.zeros(Q.shape[0], dtype=bool)
    width = n // 2 + 1
    upper = np.zeros((Q.shape[0], width + 1))
    lower = np.zeros((Q.shape[0], width + 1))
    even, odd = Q[:, 0::2], Q[:, 1::2]
    upper[:, : even.shape[1]] = even
    lower[:, : odd.shape[1]] = odd
    positive = np.ones(Q.shape[0], dtype=bool)
    unsure = np.zeros(Q.shape[0], dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(n):
            pivot = lower[:, 0]
            unsure |= (pivot == 0) | ~np.isfinite(pivot)
            positive &= pivot > 0
            nxt = np.zeros_like(upper)
            nxt[:, :-1] = (pivot[:, None] * upper[:, 1:] - upper[:, :1] * lower[:, 1:]) / pivot[:, None]
            upper, lower = lower, nxt
    return positive & ~unsure, unsure


def _axis_parts(P):
    """Ascending coefficients in y = ω² of Re P(jω) and of Im P(jω)/ω, for rows P (descending)."""
    asc = P[:, ::-1]
    re = asc[:, 0::2].copy()
    im = asc[:, 1::2].copy()
    re[:, 1::2] *= -1.0
    im[:, 1::2] *= -1.0
    return re, im


def _polymul_asc(a, b):
    out = np.zeros((a.shape[0], a.shape[1] + b.shape[1] - 1))
    for i in range(a.shape[1]):
        out[:, i:i + b.shape[1]] += a[:, i:i + 1] * b
    return out


def _polyval_asc(c, x):
    out = np.zeros_like(x)
    for j in range(c.shape[-1] - 1, -1, -1):
        out = out * x + c[..., j]
    return out


def real_roots(c, low: float = 0.0) -> np.ndarray:
    """Real roots >= `low` of each row's polynomial (ascending coefficients), NaN-padded, Newton-polished.

    Parameters
    ----------
    c : ndarray, shape (N, d + 1)
        Ascending coefficients; trailing zeros (a lower degree) allowed.
    low : float
        Only roots >= `low` are returned.

    Returns
    -------
    ndarray, shape (N, d)
        Roots (any order), NaN where a row has fewer. A near-real pair
        (|Im| <= 1e-7·max(1, |y|)) counts as real: an extra crossing only
        splits a stretch that the Routh test then decides as one.
    """
    N, width = c.shape
    d = width - 1
    out = np.full((N, max(d, 1)), np.nan)
    if d <= 0:
        return out
    nonzero = c != 0
    degree = np.where(nonzero.any(axis=1), width - 1 - np.argmax(nonzero[:, ::-1], axis=1), 0)
    for deg in np.unique(degree):
        if deg == 0:
            continue
        rows = np.flatnonzero(degree == deg)
        monic = c[rows, :deg] / c[rows, deg:deg + 1]  # ascending, without the leading 1
        if deg == 1:
            roots = -monic
        elif deg == 2:
            roots = _quadratic(monic[:, 1], monic[:, 0])
        else:
            companion = np.zeros((rows.size, deg, deg))
            companion[:, 0, :] = -monic[:, ::-1]
            companion[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
            roots = np.linalg.eigvals(companion)
        real = np.abs(roots.imag) <= _REAL_ROOT_TOL * np.maximum(np.abs(roots), 1.0)
        y = np.where(real, roots.real, np.nan)
        y = _newton(c[rows, :deg + 1], y)
        y[~(y >= low - _REAL_ROOT_TOL)] = np.nan
        out[rows, :deg] = np.maximum(y, low) if np.isfinite(low) else y
    return out


def _quadratic(b, c0):
    """Roots of y² + b·y + c0 (complex where the discriminant is negative), without cancellation."""
    disc = b * b - 4.0 * c0
    root = np.sqrt(np.abs(disc))
    q = -0.5 * (b + np.copysign(root, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        real = np.stack([q, np.where(q != 0, c0 / q, 0.0)], axis=1).astype(complex)
    pair = np.stack([-0.5 * b + 0.5j * root, -0.5 * b - 0.5j * root], axis=1)
    return np.where((disc >= 0)[:, None], real, pair)


def _newton(c, y, steps: int = 3):
    """A few Newton steps on rows of ascending polynomials (a step that does not lower |p| is refused)."""
    dc = c[:, 1:] * np.arange(1, c.shape[1])
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for _ in range(steps):
            p = _polyval_asc(c[:, None, :], y)
            dp = _polyval_asc(dc[:, None, :], y)
            step = p / dp
            trial = y - step
            better = np.isfinite(trial) & (np.abs(_polyval_asc(c[:, None, :], trial)) <= np.abs(p))
            y = np.where(better, trial, y)
    return y


class GainSets:
    """Stable gain sets of rows of D + K·E (`affine_stable_sets`).

    Each parameter is kept as the attribute of the same name.

    Parameters
    ----------
    K_critical : ndarray
        K*: the end of the stable interval (0, K*) (``inf``: stable for every
        K > 0; 0: unstable for every small K > 0).
    frequency : ndarray
        ω at K*, rad/s (the lowest crossing frequency at that gain); NaN where
        K* is 0 or infinite.
    regular : ndarray of bool
        The stable set is (0, K*) (or empty): no other stable interval.
    """

    def __init__(self, K_critical, frequency, regular):
        self.K_critical = K_critical
        self.frequency = frequency
        self.regular = regular


def affine_stable_sets(D, E, extra_gains=None, extra_frequencies=None, frequency_map=None) -> GainSets:
    """K* of D + K·E for every row (domain "s"), as `crossings.first_stable_interval` finds it.

    Parameters
    ----------
    D, E : ndarray, shape (N, n + 1)
        Descending coefficients (one width; leading zeros allowed).
    extra_gains, extra_frequencies : ndarray, shape (N, j), optional
        More crossings (NaN: none), e.g. a degree drop of a bilinear map.
    frequency_map : callable, optional
        Applied to the crossing frequencies ω (an (N, j) array) before the
        extra ones join them (the bilinear map's Ω → ω); monotone.

    Returns
    -------
    GainSets
    """
    D = np.asarray(D, dtype=float)
    E = np.asarray(E, dtype=float)
    N = D.shape[0]
    d_re, d_im = _axis_parts(D)
    e_re, e_im = _axis_parts(E)
    h = _polymul_asc(d_im, e_re) - _polymul_asc(d_re, e_im)
    y = np.concatenate([np.zeros((N, 1)), real_roots(h)], axis=1)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ev_re, ev_im = _polyval_asc(e_re[:, None, :], y), _polyval_asc(e_im[:, None, :], y)
        dv_re, dv_im = _polyval_asc(d_re[:, None, :], y), _polyval_asc(d_im[:, None, :], y)
        w = np.sqrt(y)
        # −D/E at jω with D = dv_re + jω·dv_im, E = ev_re + jω·ev_im
        modulus = ev_re * ev_re + y * ev_im * ev_im
        gain = -(dv_re * ev_re + y * dv_im * ev_im) / modulus
    zero = 1e3 * np.finfo(float).eps * np.max(np.abs(D), axis=1) / np.max(np.abs(E), axis=1)
    gain = np.where((modulus > 0) & np.isfinite(gain) & (gain > zero[:, None]), gain, np.nan)
    if frequency_map is not None:
        with np.errstate(invalid="ignore"):
            w = frequency_map(w)
    if extra_gains is not None:
        gain = np.concatenate([gain, extra_gains], axis=1)
        w = np.concatenate([w, extra_frequencies], axis=1)
    return _stable_sets(D, E, gain, w)


def _stable_sets(D, E, gain, w) -> GainSets:
    """`crossings.stable_interval` for rows: crossing gains (NaN: none) and frequencies → GainSets."""
    N, m = gain.shape
    key = np.where(np.isfinite(gain), gain, np.inf)
    order = np.lexsort((np.where(np.isfinite(w), w, np.inf), key), axis=1) if N else np.zeros((0, m), int)
    rows = np.arange(N)[:, None]
    key, w = key[rows, order], w[rows, order]
    edges = np.concatenate([np.zeros((N, 1)), key], axis=1)  # segments (edges[j], edges[j+1]) and beyond the last
    upper = np.concatenate([key, np.full((N, 1), np.inf)], axis=1)
    lower = edges
    probe = np.where(np.isfinite(upper), 0.5 * (lower + upper), np.where(lower > 0, 2.0 * lower, 1.0))
    live = np.isfinite(lower) & (upper > lower)
    flat = np.flatnonzero(live.ravel())
    verdicts = np.zeros(live.size, dtype=bool)
    if flat.size:
        row = flat // (m + 1)
        verdicts[flat] = hurwitz_stable(D[row] + probe.ravel()[flat, None] * E[row])
    verdicts = verdicts.reshape(live.shape)
    # a zero-width or unused segment (repeated gain, no more crossings) takes the verdict before it
    for j in range(1, m + 1):
        verdicts[:, j] = np.where(live[:, j], verdicts[:, j], verdicts[:, j - 1])
    first_unstable = np.where(verdicts.all(axis=1), m + 1, np.argmin(verdicts, axis=1))
    K_star = np.where(verdicts[:, 0], np.concatenate([key, np.full((N, 1), np.inf)], axis=1)[np.arange(N), np.minimum(first_unstable - 1, m)], 0.0)
    K_star = np.where(first_unstable > m, np.inf, K_star)
    later_stable = np.zeros(N, dtype=bool)
    for j in range(m + 1):
        later_stable |= (j > first_unstable) & verdicts[:, j] & live[:, j]
    at = np.isfinite(K_star) & (K_star > 0)
    match = (key == K_star[:, None]) & at[:, None]
    frequency = np.where(at, w[np.arange(N), np.argmax(match, axis=1)], math.nan)
    return GainSets(K_star, frequency, ~later_stable)


def hurwitz_columns(Q) -> np.ndarray:
    """`hurwitz_stable` for polynomials given as coefficient columns (descending, 1 to 5 of them).

    Liénard–Chipart in closed form: with the leading coefficient made
    positive, every coefficient > 0 and, for degree 3, q₁q₂ > q₀q₃, for
    degree 4, q₁q₂q₃ > q₀q₃² + q₁²q₄ (the Hurwitz determinants Δ₂, Δ₃; Routh's
    first column is q₀, q₁, Δ₂/q₁, Δ₃/Δ₂, q₄). Rows whose leading
    coefficient is 0 or not finite (a lower degree) go to `hurwitz_stable`.

    Parameters
    ----------
    Q : sequence of ndarray
        The coefficient columns, descending powers: Q[i][r] is row r's coefficient of s^(len(Q) − 1 − i).
    """
    lead = Q[0]
    sign = np.sign(lead)
    q = [x * sign for x in Q]
    n = len(q) - 1
    stable = np.ones(lead.shape, dtype=bool)
    for x in q:
        stable &= x > 0
    if n == 3:
        stable &= q[1] * q[2] > q[0] * q[3]
    elif n == 4:
        stable &= q[1] * q[2] * q[3] > q[0] * q[3] * q[3] + q[1] * q[1] * q[4]
    elif n > 4:
        raise ValueError(f"hurwitz_columns takes degree <= 4; got {n}")
    odd = np.flatnonzero(~np.isfinite(lead) | (lead == 0))
    if odd.size:
        stable[odd] = hurwitz_stable(np.stack([x[odd] for x in Q], axis=1))
    return stable
