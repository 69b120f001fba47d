"""Fast `exact_delay` verdicts of KB eq (18) (c = 0) for the verdict-only path of `loop_verdicts`.

The crossing count of `delay.delay_verdicts_from_gain` (Cooke & van den
Driessche 1986) for a(s) + K·e^(−sT), a(s) = τs³ + s² + ks, K = kNV, when the
crossing polynomial F(y) = τ²y³ + (1 − 2kτ)y² + k²y − K² (y = ω²) has one
positive root — always when kτ <= 2 + √3, and outside the dip of |a(jω)|
when the steering loop resonates. Then F′ > 0 at the root (the crossing is
destabilizing), Z = Z₀ + 2·#{m >= 0 : T₀ + 2πm/ω < T}, and

    stable ⇔ K > 0, τK < k (Z₀ = 0) and ωT <= ψ′,

ψ′ = atan((k − τω²)/ω) taken in [0, 2π) (T₀ = ψ′/ω): the count's own
formula, one root and one arctangent per point instead of three roots and a
sum over them. The root is the cubic's largest real root in closed form
(Cardano or the trigonometric form) polished by two Newton steps (`_root`);
the few points where that is not converged are redone by the Newton
iteration of `delay._newton_cubic_roots` (one Newton loop for both).

Near an edge (`near`): the point is flagged when ωT − ψ′ changes sign
within a relative step ε of K, judged by its derivative
d(ωT − ψ′)/d ln K = [T + (k/ω² + τ)/(1 + u²)]·K²/(F′(y)·ω), u = k/ω − τω,
with a safety factor 4, or when τK is within 4ε of k. Points with three
crossings (the dip) are left to the caller (`three`).
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.delay import _newton_cubic_roots

__all__ = ["single_crossing_verdicts"]

_TWO_PI = 2.0 * math.pi
_RESONANCE = 2.0 + math.sqrt(3.0)
_SAFETY = 4.0


def _root(tau, k, K2):
    """The one positive root y of τ²y³ + (1 − 2kτ)y² + k²y − K² (τ > 0): closed form, two Newton steps.

    The largest real root of the cubic (the one positive root is the largest
    real one: F(0) = −K² < 0 and F > 0 beyond it) by Cardano's formula when
    the discriminant says one real root, by the trigonometric form when three;
    the discriminant Δ = b²c² + 4b³K² − 4ac³ − 18abcK² − 27a²K⁴ (a = τ²,
    b = 1 − 2kτ, c = k²) is evaluated in this expanded form, in which the
    b⁶ terms of R² − Q³ have cancelled (R² − Q³ = −Δ/(108a⁴)): no
    catastrophic cancellation as τ → 0. Where the shift b/(3a) exceeds
    10⁴·y (τ tiny: y = t − b/(3a) cancels) the start is the positive root of
    the quadratic limit b·y² + k²y − K² instead. Two Newton steps on all
    points then polish it. Where the last step δ is not below 10⁻⁴·y or its
    error estimate |F″/(2F′)|·δ² not below 10⁻¹⁵·y (a start still spoiled by
    cancellation, a root near a double one) the point is redone by the
    monotone Newton iteration of `delay._newton_cubic_roots` (Fourier start).
    """
    return _largest_root(tau * tau, 1.0 - 2.0 * k * tau, k * k, K2)


def _largest_root(a, b, c, D):
    """The largest real root of a·y³ + b·y² + c·y − D (a, D > 0), as `_root` describes."""
    with np.errstate(all="ignore"):
        inv_a = 1.0 / a
        h = b * inv_a
        h *= 1.0 / 3.0  # y = t − h
        inv_a2 = inv_a * inv_a
        Q = b * b
        Q -= 3.0 * a * c
        Q *= inv_a2
        Q *= 1.0 / 9.0
        aD = a * D
        R = 2.0 * b * b
        R -= 9.0 * a * c
        R *= b
        R -= 27.0 * a * aD
        R *= inv_a2
        R *= inv_a * (1.0 / 54.0)
        bc = b * c
        disc = bc * bc  # Δ, expanded: the b⁶ terms of R² − Q³ = −Δ/(108a⁴) cancelled exactly
        disc += (4.0 * b * b) * (b * D)
        disc -= (4.0 * a * c) * (c * c)
        disc -= (18.0 * bc) * aD
        disc -= 27.0 * aD * aD
        y = np.empty(a.shape)
        one = disc < 0  # one real root: Cardano, the two cube roots of one sign (no cancellation between them)
        if one.any():
            Ro, Qo = R[one], Q[one]
            A = -np.copysign(np.cbrt(np.abs(Ro) + np.sqrt(disc[one] * (-1.0 / 108.0)) * inv_a2[one]), Ro)
            y[one] = A + Qo / A - h[one]
        three = ~one
        if three.any():  # three real roots: the largest, −2√Q·cos((θ + 2π)/3) − h
            Qt = Q[three]
            sq = np.sqrt(Qt)
            theta = np.arccos(np.clip(R[three] / (Qt * sq), -1.0, 1.0))
            theta += _TWO_PI
            theta *= 1.0 / 3.0
            y[three] = -2.0 * sq * np.cos(theta) - h[three]
        # τ → 0: y = t − h cancels (h = b/(3a) ≫ y); there the quadratic limit b·y² + c·y − D is the
        # better start (its error, a·y/b < 1/(3·10⁴), is gone after two Newton steps)
        shifted = np.flatnonzero((b > 0) & ~(np.abs(h) <= 1e4 * np.abs(y)))
        if shifted.size:
            bs, cs, Ds = b[shifted], c[shifted], D[shifted]
            y[shifted] = 2.0 * Ds / (cs + np.sqrt(cs * cs + 4.0 * bs * Ds))
        a3, b2 = 3.0 * a, 2.0 * b
        for _ in range(2):
            value = a * y
            value += b
            value *= y
            value += c
            value *= y
            value -= D
            slope = a3 * y
            slope += b2
            slope *= y
            slope += c
            value /= slope
            y -= value
        # converged: the next step (≈ (F″/2F′)·δ²) is below 10⁻¹⁵·y, and the last one did not cancel y
        step = np.abs(value)
        curvature = np.abs(a3 * y + b)  # F″/2
        curvature *= step
        curvature *= step
        bad = ~((curvature <= 1e-15 * np.abs(slope) * y) & (step <= 1e-4 * y))
    redo = np.flatnonzero(bad)
    if redo.size:
        y[redo] = _newton_cubic_roots(a[redo], b[redo], c[redo], D[redo])[:, 0]
    return y


def single_crossing_verdicts(tau, T, k, K, eps):
    """(stable, near, three) for arrays with c = 0; see the module docstring.

    Parameters
    ----------
    tau, T, k, K : ndarray
        s, s, 1/s, 1/s² (flat, one length).
    eps : float
        Relative step in K within which an edge makes the point `near`.

    Returns
    -------
    stable, near, three : ndarray of bool
        `stable` and `near` are meaningless where `three` (three crossing
        frequencies: decide those points by the full crossing count).
    """
    tK = tau * K
    positive = K > 0
    stable = positive & (tK < k)
    tK -= k
    near = positive & (np.abs(tK) <= _SAFETY * eps * k)
    # three positive roots: τ²y³ + (1 − 2kτ)y² + k²y dips (kτ > 2 + √3) and K² lies inside the dip;
    # then a stabilizing crossing may undo Z₀ = 2: the caller counts them all
    three = np.zeros(K.shape, dtype=bool)
    delayed = T > 0
    resonant = np.flatnonzero(positive & delayed & (k * tau > _RESONANCE))
    if resonant.size:
        t, g = tau[resonant], k[resonant]
        a, b, c = t * t, 1.0 - 2.0 * g * t, g * g
        disc = np.sqrt(np.maximum(b * b - 3.0 * a * c, 0.0))
        c2 = (disc - b) / (3.0 * a)
        c1 = c / (3.0 * a * c2)
        K2 = K[resonant]
        K2 *= K2
        three[resonant] = (((a * c1 + b) * c1 + c) * c1 > K2) & (((a * c2 + b) * c2 + c) * c2 < K2)
    live = stable & delayed
    live &= ~three
    live = np.flatnonzero(live)
    if not live.size:
        return stable, near, three
    tau_l, T_l, k_l, K2 = tau[live], T[live], k[live], K[live]
    K2 *= K2
    a = tau_l * tau_l
    b = k_l * tau_l
    b *= -2.0
    b += 1.0
    c = k_l * k_l
    lag = tau_l > 0
    if lag.all():
        y = _largest_root(a, b, c, K2)
    else:
        y = np.empty(K2.size)
        plain = np.flatnonzero(lag)
        if plain.size:
            y[plain] = _largest_root(a[plain], b[plain], c[plain], K2[plain])
        quadratic = np.flatnonzero(~lag)  # τ = 0: y² + k²y − K², the stable formula
        kk, KK = c[quadratic], K2[quadratic]
        y[quadratic] = 2.0 * KK / (kk + np.sqrt(kk * kk + 4.0 * KK))
    w = np.sqrt(y)
    u = k_l / w
    u -= tau_l * w
    psi = np.arctan(u)
    np.add(psi, _TWO_PI, out=psi, where=psi < 0)
    wT = w * T_l
    gap = wT - psi
    slope = 3.0 * a * y
    slope += 2.0 * b
    slope *= y
    slope += c
    with np.errstate(divide="ignore", invalid="ignore"):
        u *= u
        u += 1.0
        reach = k_l / y
        reach += tau_l
        reach /= u
        reach += T_l
        reach *= K2
        slope *= w
        reach /= slope
        reach *= _SAFETY * eps
    wT += psi
    wT *= 1e-12
    reach += wT
    np.abs(gap, out=wT)
    stable[live] = gap <= 0
    near[live] |= ~(wT > reach)
    return stable, near, three
