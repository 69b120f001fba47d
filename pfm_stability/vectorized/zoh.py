"""Closed-form zero-order hold of the `sampled` model's plants, in arrays over points.

Every plant of `models.sampled.continuous_plant` is a servo block M (2 × 2
for τ > 0: states ω, θ; 1 × 1 for τ = 0: state θ) followed by the
integrator ẏ = θ:

    A = [[M, 0], [e_θᵀ, 0]],   B = (b, 0),

with, for τ > 0, M = [[−1/τ, −κ/τ], [1, 0]], b = (1/τ, 0) (κ = 0 for the
``command`` hold, κ = k for the ``reference`` hold) and, for τ = 0, M = −κ,
b = 1. With the φ-functions φ₁(X) = Σ Xⁱ/(i + 1)!, φ₂(X) = Σ Xⁱ/(i + 2)! of
X = MT the δ form of `models.sampled.delta_plant` is exact and free of the
cancellation of e^(AT) − I:

    Ψ = (e^(AT) − I)/T = [[M·φ₁(X), 0], [e_θᵀφ₁(X), 0]],
    G = Γ/T            = (φ₁(X)·b, T·e_θᵀφ₂(X)·b).

A function of a 2 × 2 matrix X is αI + βX (Cayley–Hamilton: X² = sX − pI
with s = tr X, p = det X), so each φ is two numbers per point. They come
from the Taylor series of φ₂ at X/2ʲ (spectral radius <= 1/4, 13 terms:
truncation < 10⁻¹⁷), φ₁ = I + Yφ₂, e^Y = I + Yφ₁, then j doublings
(Higham's scaling and squaring for φ-functions):

    e^(2Y) = (e^Y)²,  φ₁(2Y) = φ₁(Y)(e^Y + I)/2,  φ₂(2Y) = (φ₁(Y)² + 2φ₂(Y))/4.

No exponential of a stacked matrix, no eigenvalue: a few hundred flops per
point. The tests hold Ψ and G to `vectorized.sampled.delta_plants` (the
stacked `matrix_exponential.zoh_blocks`) and the resulting polynomials to
the scalar model's.
"""

from __future__ import annotations

import numpy as np

__all__ = ["phi_functions", "delta_entries"]

_TERMS = 13
"""Taylor terms of φ₂ at spectral radius <= 1/4: 4⁻¹³/15! ≈ 10⁻²⁰."""

_RADIUS = 0.25

_INVERSE_FACTORIALS = [1.0]
for _i in range(1, _TERMS + 3):
    _INVERSE_FACTORIALS.append(_INVERSE_FACTORIALS[-1] / _i)


def _times(a, b, c, d, s, p):
    """(αI + βY)(γI + δY) = (αγ − βδp)I + (αδ + βγ + βδs)Y for Y with trace s, determinant p."""
    bd = b * d
    return a * c - bd * p, a * d + b * c + bd * s


def _taylor(s, p):
    """(α, β) of e^Y, φ₁(Y), φ₂(Y) for Y of trace s and determinant p, spectral radius <= 1/4."""
    a = np.full(s.shape, _INVERSE_FACTORIALS[_TERMS + 2])
    b = np.zeros(s.shape)
    for i in range(_TERMS - 1, -1, -1):  # Horner: φ₂ = Σ_{i <= 13} Yⁱ/(i + 2)!
        a, b = -b * p, a + b * s  # (αI + βY)·Y
        a += _INVERSE_FACTORIALS[i + 2]
    a2, b2 = a, b
    a1, b1 = -b2 * p + 1.0, a2 + b2 * s  # φ₁ = I + Y·φ₂
    a0, b0 = -b1 * p + 1.0, a1 + b1 * s  # e^Y = I + Y·φ₁
    return a0, b0, a1, b1, a2, b2


def phi_functions(s, p):
    """(α₁, β₁, α₂, β₂): φ₁(X) = α₁I + β₁X and φ₂(X) = α₂I + β₂X for 2 × 2 (or 1 × 1: p = 0) matrices X.

    Parameters
    ----------
    s, p : ndarray
        Trace and determinant of X (a 1 × 1 matrix x is s = x, p = 0, and
        φ(x) = α + βx).

    Returns
    -------
    tuple of ndarray
    """
    s = np.asarray(s, dtype=float)
    p = np.asarray(p, dtype=float)
    radius = np.abs(s) + np.sqrt(np.abs(p))  # >= the spectral radius
    j = np.maximum(np.frexp(radius / _RADIUS)[1], 0)
    scale = np.ldexp(1.0, -j)
    sy, py = s * scale, p * scale * scale
    e0, e1, a1, b1, a2, b2 = _taylor(sy, py)
    rounds = int(j.max()) if j.size else 0
    for r in range(1, rounds + 1):
        live = j >= r
        if live.all():
            e0, e1, a1, b1, a2, b2, sy, py = _double(e0, e1, a1, b1, a2, b2, sy, py)
        else:
            rows = np.flatnonzero(live)
            parts = _double(*(x[rows] for x in (e0, e1, a1, b1, a2, b2, sy, py)))
            for x, new in zip((e0, e1, a1, b1, a2, b2, sy, py), parts):
                x[rows] = new
    # each row was doubled j times: its β's are coefficients of X itself
    return a1, b1, a2, b2


def _double(e0, e1, a1, b1, a2, b2, s, p):
    """φ-functions of 2Y from those of Y; the β's re-expressed on 2Y."""
    f0, f1 = _times(a1, b1, a1, b1, s, p)  # φ₁²
    n2a, n2b = 0.25 * (f0 + 2.0 * a2), 0.25 * (f1 + 2.0 * b2)
    n1a, n1b = _times(a1, b1, e0 + 1.0, e1, s, p)
    n0a, n0b = _times(e0, e1, e0, e1, s, p)
    return n0a, 0.5 * n0b, 0.5 * n1a, 0.25 * n1b, n2a, 0.5 * n2b, 2.0 * s, 4.0 * p


def delta_entries(tau, T, k, reference: bool):
    """Non-zero entries of Ψ and G (δ form) for rows with T > 0, one state size.

    τ > 0 everywhere (3 states ω, θ, y) or τ = 0 everywhere (θ, y).

    Parameters
    ----------
    tau, T, k : ndarray
        τ (s), T (s, > 0) and k (1/s), one loop per element.
    reference : bool
        The reference hold (True) or the command hold.

    Returns
    -------
    dict
        τ > 0: P00, P01, P10, P11 (the servo block of Ψ), P20, P21 (its y
        row), g0, g1, g2. τ = 0: P00, P10, g0, g1.
    """
    kappa = k if reference else np.zeros_like(k)
    if tau.size and tau[0] > 0:
        inv = 1.0 / tau
        x = T * inv
        a1, b1, a2, b2 = phi_functions(-x, kappa * T * x)
        f00 = a1 - b1 * x
        f01 = -b1 * kappa * x
        f10 = b1 * T
        f11 = a1
        return {
            "P00": -(f00 + kappa * f10) * inv,
            "P01": -(f01 + kappa * f11) * inv,
            "P10": f00,
            "P11": f01,
            "P20": f10,
            "P21": f11,
            "g0": f00 * inv,
            "g1": f10 * inv,
            "g2": T * T * b2 * inv,
        }
    z = -kappa * T
    a1, b1, a2, b2 = phi_functions(z, np.zeros_like(z))
    phi1 = a1 + b1 * z
    phi2 = a2 + b2 * z
    return {"P00": -kappa * phi1, "P10": phi1, "g0": phi1, "g1": T * phi2}
