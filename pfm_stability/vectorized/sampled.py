"""The `sampled` model's characteristic polynomial D + K·E in arrays over points.

Follows `models.sampled` step by step (docs/models.md, `sampled`), for many
loops at once:

1. the continuous plant (A, B, F0, F1) of the hold (`models.sampled.continuous_plant`);
2. its δ form Ψ = (e^(AT) − I)/T, G = Γ/T in closed form (`vectorized.zoh`:
   φ-functions of the servo block, no cancellation against I);
   `continuous_plants` and `delta_plants` keep the stacked-exponential route
   (`matrix_exponential.zoh_blocks`, as `models.sampled.delta_plant`) as the
   tests' independent reference;
3. P(w) = (1 + Tw)^d·det(wI − Ψ) + F·adj(wI − Ψ)·G with F = F0 + K·F1
   (d = compute delay): Ψ's last column is zero and F has two non-zero
   entries, so the adjugate terms are a few products (`delta_columns`);
4. the bilinear map z = (1 + Tμ/2)/(1 − Tμ/2):
   Q(μ) = (1 − Tμ/2)^deg P(μ/(1 − Tμ/2)), Hurwitz exactly when the sampled loop is stable.

Only T > 0 is handled here (T = 0 is the continuous loop, KB eq 17).
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.matrix_exponential import zoh_blocks
from .zoh import delta_entries

__all__ = ["continuous_plants", "delta_plants", "delta_columns", "bilinear_columns", "bilinear_polynomials"]


def continuous_plants(tau, k, c, hold: str):
    """Stacks (A, B, F0, F1) of `models.sampled.continuous_plant` for one state size.

    τ > 0 everywhere (states ω, θ, y) or τ = 0 everywhere (θ, y).

    Parameters
    ----------
    tau, k : ndarray
        τ (s) and k (1/s), one loop per element.
    c : ndarray
        Heading gain per loop (dimensionless).
    hold : {"command", "reference"}
        What the computer holds (`parameters.HOLDS`).
    """
    N = tau.size
    lag = bool(tau.size) and tau[0] > 0
    n = 3 if lag else 2
    A = np.zeros((N, n, n))
    B = np.zeros((N, n, 1))
    F0 = np.zeros((N, n))
    F1 = np.zeros((N, n))
    if lag:
        A[:, 0, 0] = -1.0 / tau
        A[:, 1, 0] = 1.0
        A[:, 2, 1] = 1.0
        B[:, 0, 0] = 1.0 / tau
        if hold == "command":
            F0[:, 1] = k
        else:
            A[:, 0, 1] = -k / tau
    else:
        A[:, 1, 0] = 1.0
        B[:, 0, 0] = 1.0
        if hold == "command":
            F0[:, 0] = k
        else:
            A[:, 0, 0] = -k
    F1[:, -1] = 1.0
    F0[:, -2] += k * c  # zero where c = 0: KB's entries untouched
    return A, B, F0, F1


def delta_plants(A, B, T):
    """(Ψ, G) for stacks A, B and periods T > 0, as `models.sampled.delta_plant` forms them.

    Parameters
    ----------
    A, B : ndarray
        Stacks of continuous-time plants (`continuous_plants`).
    T : ndarray
        Sampling periods, s (> 0).
    """
    n = A.shape[-1]
    Phi, integral = zoh_blocks(A, T)
    t = T[:, None, None]
    small = (np.abs(A).sum(axis=1).max(axis=1) * T <= 1.0)[:, None, None]
    Psi = np.where(small, integral @ A / t, (Phi - np.eye(n)) / t)
    G = integral @ B / t
    return Psi, G[:, :, 0]


def delta_columns(tau, T, k, c, hold: str, compute_delay: int):
    """(D, E) of P(w) = D + K·E in the δ variable w, as lists of coefficient arrays (descending, one length),
    from the closed-form Ψ and G of `vectorized.zoh` (rows with T > 0, one state size).

    Ψ's last column is zero (y feeds nothing back), F0 has only its θ entry
    f (k(1 + c) for the command hold, kc for the reference hold) and F1 only
    its y entry, so det(wI − Ψ) = w·det(wI − Ψ_servo) and the adjugate terms
    F·adj(wI − Ψ)·G reduce to the sums below (expanded symbolically once).

    Parameters
    ----------
    tau, T, k : ndarray
        τ (s), T (s, > 0) and k (1/s), one loop per element.
    c : ndarray
        Heading gain per loop (dimensionless).
    hold : {"command", "reference"}
        What the computer holds (`parameters.HOLDS`).
    compute_delay : {0, 1}
        Samples from measurement to actuation.
    """
    reference = hold == "reference"
    e = delta_entries(tau, T, k, reference)
    f = k * c if reference else k * (1.0 + c)
    zero = np.zeros(tau.size)
    if "P01" in e:  # states (ω, θ, y)
        P00, P01, P10, P11, P20, P21 = (e[name] for name in ("P00", "P01", "P10", "P11", "P20", "P21"))
        g0, g1, g2 = e["g0"], e["g1"], e["g2"]
        trace = P00 + P11
        det = P00 * P11 - P01 * P10
        lead = [np.ones(tau.size), -trace, det, zero]
        base = [zero, f * g1, f * (P10 * g0 - P00 * g1), zero]
        E = [zero, g2, P20 * g0 + P21 * g1 - trace * g2, det * g2 + P21 * (P10 * g0 - P00 * g1) + P20 * (P01 * g1 - P11 * g0)]
    else:  # states (θ, y)
        P00, P10, g0, g1 = e["P00"], e["P10"], e["g0"], e["g1"]
        lead = [np.ones(tau.size), -P00, zero]
        base = [zero, f * g0, zero]
        E = [zero, g1, P10 * g0 - P00 * g1]
    if compute_delay:  # (1 + Tw)·det(wI − Ψ); the adjugate terms keep their powers
        lead = [T * lead[0]] + [T * a + b for a, b in zip(lead[1:], lead[:-1])] + [lead[-1]]
        base = [zero] + base
        E = [zero] + E
    return [a + b for a, b in zip(lead, base)], E


def bilinear_columns(tau, T, k, c, hold: str, compute_delay: int):
    """(D, E) in μ of `models.sampled.Sampled.bilinear_polynomials`, as lists of coefficient arrays
    (descending, one length), rows with T > 0 and one state size.

    Parameters
    ----------
    tau, T, k : ndarray
        τ (s), T (s, > 0) and k (1/s), one loop per element.
    c : ndarray
        Heading gain per loop (dimensionless).
    hold : {"command", "reference"}
        What the computer holds (`parameters.HOLDS`).
    compute_delay : {0, 1}
        Samples from measurement to actuation.
    """
    D, E = delta_columns(tau, T, k, c, hold, compute_delay)
    return _bilinear_columns(D, T), _bilinear_columns(E, T)


def bilinear_polynomials(tau, T, k, c, hold: str, compute_delay: int):
    """(D, E) in μ (descending, one width) of `models.sampled.Sampled.bilinear_polynomials`, rows with T > 0
    and one state size (τ > 0 everywhere or τ = 0 everywhere).

    Parameters
    ----------
    tau, T, k : ndarray
        τ (s), T (s, > 0) and k (1/s), one loop per element.
    c : ndarray
        Heading gain per loop (dimensionless).
    hold : {"command", "reference"}
        What the computer holds (`parameters.HOLDS`).
    compute_delay : {0, 1}
        Samples from measurement to actuation.
    """
    D, E = bilinear_columns(tau, T, k, c, hold, compute_delay)
    return np.stack(D, axis=1), np.stack(E, axis=1)


def _bilinear_columns(P, T):
    """Q(μ) = (1 − Tμ/2)^deg·P(μ/(1 − Tμ/2)), deg = len(P) − 1, for coefficient columns P (descending)."""
    degree = len(P) - 1
    half = -0.5 * T
    powers = [np.ones_like(T)]
    for _ in range(degree):
        powers.append(powers[-1] * half)
    out = [np.zeros_like(T) for _ in range(degree + 1)]
    for i in range(degree + 1):  # p_i μ^i (1 − Tμ/2)^(degree − i), p_i = P[degree − i]
        power = degree - i
        coefficient = P[degree - i]
        if not coefficient.any():
            continue
        for j in range(power + 1):  # C(power, j)·(−T/2)^j μ^(i + j)
            out[degree - i - j] += coefficient * (math.comb(power, j) * powers[j])
    return out
