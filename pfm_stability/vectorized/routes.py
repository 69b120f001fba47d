"""The array route of each loop model (`vectorized.loops.loop_verdicts` dispatches here).

A route takes the flat, checked points (τ, T, k, c, NV) and the options and
returns ``(Answers, boundary_index, scalar_verdicts)``: the array answers,
the points whose boundary the scalar model must give (a stable set that is
not (0, NV*), or a case the closed forms leave out), and whether the scalar
model's `is_stable` is also needed there. Every closed form below is the one
the scalar model's docstring states (docs/models.md); the tests hold each
route to the scalar model point by point. At NV = 0 every route judges the
heading loop, the roots other than the neutral lateral one (docs/models.md,
"N = 0"): the Routh conditions with K >= 0, D/s (D/μ for `sampled`: z = 1 is
μ = 0), the crossing count at K = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..numerics.delay import _RESONANCE, _kb_level_frequency, delay_verdicts_from_gain, kb_critical_gain
from ..models.pade import _pade_term
from .delay_verdicts import single_crossing_verdicts
from .hurwitz_gain import hurwitz_gain_sets
from .polynomial import affine_stable_sets, hurwitz_columns, hurwitz_stable
from .sampled import bilinear_columns

__all__ = ["Answers", "continuous", "kb_first_order", "exact_delay", "pade", "pade_polynomials", "sampled", "sampled_stable", "pade_stable", "exact_delay_stable"]

_NONE = np.zeros(0, dtype=np.int64)


@dataclass
class Answers:
    """Per-point answers of an array route (flat arrays; NaN ω where the boundary has None).

    Attributes
    ----------
    stable : ndarray of bool
        The verdict at each point's NV.
    NV_critical : ndarray
        NV*, 1/s.
    omega_critical : ndarray
        ω*, rad/s.
    regular : ndarray of bool
        The stable set is (0, NV*) (or empty).
    """

    stable: np.ndarray
    NV_critical: np.ndarray
    omega_critical: np.ndarray
    regular: np.ndarray


def _regular(n):
    return np.ones(n, dtype=bool)


def _neutral_stable(D, E, K):
    """Hurwitz test of the rows D + K·E (descending); at K = 0 of D/s, D's last coefficient being 0 (N = 0)."""
    stable = hurwitz_stable(D + K[:, None] * E)
    zero = np.flatnonzero(K == 0)
    if zero.size:
        stable[zero] = hurwitz_stable(D[zero, :-1])
    return stable


def _neutral_columns(D, E, K):
    """`_neutral_stable` for coefficient columns (`polynomial.hurwitz_columns`): at K = 0 D/μ (z = 1 left out)."""
    stable = hurwitz_columns([d + K * e for d, e in zip(D, E)])
    zero = np.flatnonzero(K == 0)
    if zero.size:
        stable[zero] = hurwitz_columns([d[zero] for d in D[:-1]])
    return stable


def continuous(points, options):
    """KB eq (17) with c: τs³ + s² + k(1 + c)s + K. Routh: stable ⇔ 0 < τK < k(1 + c) (K = 0: the heading
    loop τs² + s + k(1 + c), stable); NV* = (1 + c)/τ, ω* = √(k(1 + c)/τ) (τ = 0: stable for every NV > 0).

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    """
    tau, T, k, c, NV = points
    kc = k * (1.0 + c)
    K = k * NV
    stable = (K >= 0) & (kc - tau * K > 0)
    lag = tau > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        NV_star = np.where(lag, (1.0 + c) / np.where(lag, tau, 1.0), np.inf)
        omega = np.where(lag, np.sqrt(kc / np.where(lag, tau, 1.0)), math.nan)
    return Answers(stable, NV_star, omega, _regular(tau.size)), _NONE, False


def kb_first_order(points, options):
    """KB eq (19) with c: τs³ + a₁s² + (k(1 + c) − KT)s + K, a₁ = 1 − kcT.

    Routh (τ > 0): stable ⇔ a₁ > 0, K > 0 and a₁(k(1 + c) − KT) > τK (K = 0:
    the heading loop τs² + a₁s + k(1 + c), stable ⇔ a₁ > 0, the same conditions);
    NV* = a₁(1 + c)/(τ + a₁T), ω*² = k(1 + c)/(τ + a₁T) (KB eq 20 for c = 0);
    a₁ <= 0: unstable at every NV. τ = 0: the quadratic a₁s² + … is stable
    for 0 < K < k(1 + c)/T when a₁ > 0. a₁ = 0 exactly (a degree drop) goes to
    the scalar model.

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    """
    tau, T, k, c, NV = points
    K = k * NV
    a1 = 1.0 - (k * c) * T
    a2 = k * (1.0 + c) - K * T
    stable = (a1 > 0) & (K >= 0) & (a2 > 0) & (a1 * a2 - tau * K > 0)
    denominator = tau + a1 * T
    live = (a1 > 0) & (denominator > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        NV_star = np.where(live, a1 * (1.0 + c) / np.where(live, denominator, 1.0), np.where(a1 > 0, np.inf, 0.0))
        omega = np.where(live, np.sqrt(k * (1.0 + c) / np.where(live, denominator, 1.0)), math.nan)
    return Answers(stable, NV_star, omega, _regular(tau.size)), np.flatnonzero(a1 == 0), True


def exact_delay(points, options):
    """KB eq (18): K* by KB's three levels and stable ⇔ 0 < K < K* (c = 0); the crossing count (c ≠ 0).

    With c ≠ 0 the stable set may be several intervals (`models.heading`):
    the boundary of those loops comes from the scalar model (cached per loop),
    the verdict still from the crossing count, which also decides K = 0 (the
    heading loop τs² + s + k + kc·e^(−sT)).

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    """
    tau, T, k, c, NV = points
    K = k * NV
    heading = c != 0
    stable = np.empty(tau.size, dtype=bool)
    counted = np.flatnonzero(heading | (K == 0))
    if counted.size:
        stable[counted] = delay_verdicts_from_gain(tau[counted], T[counted], k[counted], K[counted], c[counted])[0]
    plain, rows = (np.flatnonzero(~heading), np.flatnonzero(heading)) if heading.any() else (slice(None), _NONE)
    NV_star = np.zeros(tau.size)
    omega = np.full(tau.size, math.nan)
    K_star, w = _kb_critical_gain(tau[plain], T[plain], k[plain])
    # c = 0: the stable set is (0, K*) (every crossing destabilizing, `delay.kb_critical_gain`), so the
    # crossing count and K < K* agree except within round-off of K*, where the verdict is "undecided"
    stable[plain] = np.where(K[plain] == 0, stable[plain], (K[plain] > 0) & (K[plain] < K_star))
    NV_star[plain] = K_star / k[plain]
    omega[plain] = np.where(np.isfinite(K_star), w, math.nan)
    return Answers(stable, NV_star, omega, _regular(tau.size)), rows, False


def _kb_critical_gain(tau, T, k):
    """`delay.kb_critical_gain`, the same floats, with one level instead of three where kτ <= 2 + √3
    (there its levels m_c and m_c + 1 are both m = 0: the minimum is level 0's gain)."""
    resonant = (k * tau > _RESONANCE) | (T == 0)
    if resonant.all():
        return kb_critical_gain(tau, T, k)
    K_star, w = np.empty(tau.size), np.empty(tau.size)
    if resonant.any():
        K_star[resonant], w[resonant] = kb_critical_gain(tau[resonant], T[resonant], k[resonant])
    plain = ~resonant
    t, d, g = tau[plain], T[plain], k[plain]
    w[plain] = _kb_level_frequency(t, d, g, np.zeros(t.size))
    K_star[plain] = w[plain] * np.sqrt((g - t * w[plain] * w[plain]) ** 2 + w[plain] * w[plain])
    return K_star, w


def pade_polynomials(tau, T, k, c, order):
    """Rows of D = (τs³ + s² + ks)·Q_m + kc·s·P_m and E = P_m (`models.pade.Pade.batch_polynomials` in arrays).

    Parameters
    ----------
    tau, T, k : ndarray
        τ (s), T (s, > 0) and k (1/s), one loop per element.
    c : ndarray
        Heading gain per loop (dimensionless).
    order : int
        Padé order m, 1 … 12.
    """
    m = order
    coefficients = np.array([_pade_term(m, j) for j in range(m + 1)])
    powers = T[:, None] ** np.arange(m + 1)
    den = (coefficients * powers)[:, ::-1]
    num = (coefficients * powers * (-1.0) ** np.arange(m + 1))[:, ::-1]
    plant = np.stack([tau, np.ones_like(tau), k, np.zeros_like(tau)], axis=1)
    D = np.zeros((tau.size, m + 4))
    for i in range(4):
        D[:, i:i + m + 1] += plant[:, i, None] * den
    E = np.zeros_like(D)
    E[:, 3:] = num
    heading = k * c
    rows = np.flatnonzero(heading)
    if rows.size:
        D[rows, 2:m + 3] += heading[rows, None] * num[rows]
    return D, E


def pade(points, options):
    """KB eq (18) with Padé(m, m): Routh on D + K·E for the verdict, the crossing route for K*.

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    """
    tau, T, k, c, NV = points
    D, E = pade_polynomials(tau, T, k, c, options["pade_order"])
    stable = _neutral_stable(D, E, k * NV)
    sets = affine_stable_sets(D, E)
    return Answers(stable, sets.K_critical / k, sets.frequency, sets.regular), np.flatnonzero(~sets.regular), False


def _sampled_groups(tau, T):
    """Rows of the two state sizes with T > 0 (τ > 0: ω, θ, y; τ = 0: θ, y)."""
    return [g for g in (np.flatnonzero((T > 0) & (tau > 0)), np.flatnonzero((T > 0) & (tau == 0))) if g.size]


def sampled(points, options):
    """The sampled loop: Routh on the bilinear D + K·E for the verdict, its crossings for K*
    (plus the degree drop, a pole through z = −1 at ω = π/T), frequencies mapped back by
    ω = 2·atan(ΩT/2)/T; T = 0 is the continuous loop (KB eq 17), as `models.sampled` takes it.
    K* from the Hurwitz conditions in K (`vectorized.hurwitz_gain`); the rows that route leaves
    `unsure` from the crossings (`polynomial.affine_stable_sets`).

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    """
    tau, T, k, c, NV = points
    answers, _, _ = continuous(points, options)
    for group in _sampled_groups(tau, T):
        t = T[group]
        Dc, Ec = bilinear_columns(tau[group], t, k[group], c[group], options["hold"], options["compute_delay"])
        answers.stable[group] = _neutral_columns(Dc, Ec, k[group] * NV[group])
        sets, unsure = hurwitz_gain_sets(Dc, Ec, math.pi / t, lambda w: 2.0 * np.arctan(w * t[:, None] / 2.0) / t[:, None])
        K_star, frequency, regular = sets.K_critical, sets.frequency, sets.regular
        rows = np.flatnonzero(unsure)
        if rows.size:  # the crossing route where the Hurwitz route is not conclusive
            D, E = np.stack([x[rows] for x in Dc], axis=1), np.stack([x[rows] for x in Ec], axis=1)
            with np.errstate(divide="ignore", invalid="ignore"):
                drop = -D[:, :1] / E[:, :1]
            drop = np.where((E[:, :1] != 0) & (drop > 0), drop, np.nan)
            tr = t[rows, None]
            crossing = affine_stable_sets(D, E, drop, np.broadcast_to(math.pi / tr, drop.shape), lambda w: 2.0 * np.arctan(w * tr / 2.0) / tr)
            K_star[rows], frequency[rows], regular[rows] = crossing.K_critical, crossing.frequency, crossing.regular
        answers.NV_critical[group] = K_star / k[group]
        answers.omega_critical[group] = frequency
        answers.regular[group] = regular
    return answers, np.flatnonzero(~answers.regular), False


def _bracketed(tests):
    """(stable at K, near) from the tests at K, K(1 − ε), K(1 + ε): near where they differ."""
    at, below, above = tests
    return at, (below != at) | (above != at)


def sampled_stable(points, options, K, eps):
    """(stable, near) of the sampled loop at gains K: near where the test at K(1 ± ε) differs
    (one polynomial per point, tested at three gains; T = 0: KB eq 17 by Routh).

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    K : ndarray
        The gains kNV at which to test, 1/s².
    eps : float
        Relative step ε of the neighbouring gains K(1 ± ε).
    """
    tau, T, k, c, NV = points
    gains = (K, K * (1.0 - eps), K * (1.0 + eps))
    out = [(g >= 0) & (k * (1.0 + c) - tau * g > 0) for g in gains]
    for group in _sampled_groups(tau, T):
        D, E = bilinear_columns(tau[group], T[group], k[group], c[group], options["hold"], options["compute_delay"])
        for verdicts, g in zip(out, gains):
            verdicts[group] = _neutral_columns(D, E, g[group])
    return _bracketed(out)


def pade_stable(points, options, K, eps):
    """(stable, near) of the Padé loop at gains K (Routh at K and K(1 ± ε)).

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    K : ndarray
        The gains kNV at which to test, 1/s².
    eps : float
        Relative step ε of the neighbouring gains K(1 ± ε).
    """
    tau, T, k, c, NV = points
    D, E = pade_polynomials(tau, T, k, c, options["pade_order"])
    return _bracketed([_neutral_stable(D, E, g) for g in (K, K * (1.0 - eps), K * (1.0 + eps))])


def exact_delay_stable(points, options, K, eps):
    """(stable, near) of KB eq (18) (with c) at gains K: one crossing by `single_crossing_verdicts`;
    three crossings flagged `near` (the caller decides them with the boundary, all chunks' in one
    call: a few per thousand random points); heading gains and K = 0 (the heading loop) by the crossing
    count at K and K(1 ± ε).

    Parameters
    ----------
    points : tuple of ndarray
        The flat, checked (τ, T, k, c, NV): s, s, 1/s, dimensionless, 1/s (`loops.loop_arrays`).
    options : dict
        ``hold``, ``compute_delay`` and ``pade_order`` (checked by `loops.loop_verdicts`).
    K : ndarray
        The gains kNV at which to test, 1/s².
    eps : float
        Relative step ε of the neighbouring gains K(1 ± ε).
    """
    tau, T, k, c, NV = points
    stable, near, three = single_crossing_verdicts(tau, T, k, K, eps)
    near |= three
    rest = np.flatnonzero((c != 0) | (K == 0))
    if rest.size:
        gain = K[rest]
        # one call for the three gains K, K(1 − ε), K(1 + ε) (few points: the call's overhead dominates)
        t, d, g, h = (np.tile(x[rest], 3) for x in (tau, T, k, c))
        tests = delay_verdicts_from_gain(t, d, g, np.concatenate([gain, gain * (1.0 - eps), gain * (1.0 + eps)]), h)[0]
        stable[rest], near[rest] = _bracketed(tests.reshape(3, rest.size))
    return stable, near
