"""The matrix exponential of stacks of small matrices, in numpy alone.

Why not `scipy.linalg.expm`: importing ``scipy.linalg`` takes ~0.3 s, more than
half of the report's whole cold-start budget, and on a stack of matrices it
loops in Python, one LAPACK call per matrix. The loop models need the
exponential of 3 × 3 to 6 × 6 matrices, hundreds at a time (a sampled loop
at every period of a scan). This is the scaling-and-squaring algorithm with
the [13/13] Padé approximant (Higham, "The scaling and squaring method for
the matrix exponential revisited", SIAM J. Matrix Anal. Appl. 26, 2005 —
scipy's own choice for large norms), vectorized over the stack; the tests
check it against `scipy.linalg.expm` and against closed forms: 1e-12 of the
largest entry, 1e-10 for the stiffest loops (‖A‖T ~ 10⁶, where each of the
~20 squarings can double the round-off).

`zoh_blocks` gives what a zero-order hold needs, e^(AT) and ∫₀ᵀ e^(As) ds,
from one exponential of the augmented matrix [[A, I], [0, 0]]·T
(Van Loan, "Computing integrals involving the matrix exponential", IEEE TAC
23, 1978).
"""

from __future__ import annotations

import numpy as np

__all__ = ["expm", "zoh_blocks"]

_THETA_13 = 5.371920351148152
"""Largest 1-norm for which Padé [13/13] is accurate to double precision (Higham 2005, Table 2.3)."""

_B = (
    64764752532480000.0, 32382376266240000.0, 7771770303897600.0, 1187353796428800.0, 129060195264000.0,
    10559470521600.0, 670442572800.0, 33522128640.0, 1323241920.0, 40840800.0, 960960.0, 16380.0, 182.0, 1.0,
)


def expm(M) -> np.ndarray:
    """e^M for a square matrix or a stack of them, shape (..., n, n).

    Each matrix is scaled by 2^(−s) with the smallest s that brings its
    1-norm under θ₁₃, its [13/13] Padé approximant is formed, and the result
    squared s times (only the matrices that need it).

    Parameters
    ----------
    M : array_like, shape (..., n, n)
        Finite real entries.

    Returns
    -------
    ndarray, shape (..., n, n)
    """
    M = np.asarray(M, dtype=float)
    shape = M.shape
    n = shape[-1]
    A = M.reshape((-1, n, n))
    norm = np.abs(A).sum(axis=1).max(axis=1)
    with np.errstate(divide="ignore"):
        s = np.maximum(0, np.ceil(np.log2(np.where(norm > 0, norm, 1.0) / _THETA_13))).astype(int)
    A = A / (2.0 ** s)[:, None, None]
    eye = np.broadcast_to(np.eye(n), A.shape)
    A2 = A @ A
    A4 = A2 @ A2
    A6 = A4 @ A2
    b = _B
    U = A @ (A6 @ (b[13] * A6 + b[11] * A4 + b[9] * A2) + b[7] * A6 + b[5] * A4 + b[3] * A2 + b[1] * eye)
    V = A6 @ (b[12] * A6 + b[10] * A4 + b[8] * A2) + b[6] * A6 + b[4] * A4 + b[2] * A2 + b[0] * eye
    R = np.linalg.solve(V - U, V + U)
    R[norm == 0] = np.eye(n)  # exactly I (the solve leaves 1 − ulp)
    for step in range(int(s.max(initial=0))):
        more = s > step
        R[more] = R[more] @ R[more]
    return R.reshape(shape)


def zoh_blocks(A, T):
    """(e^(AT), ∫₀ᵀ e^(As) ds) for a matrix A (n × n) and an array of periods T.

    Parameters
    ----------
    A : array_like, shape (n, n) or (m, n, n)
        One matrix for every period, or one per period.
    T : array_like, shape () or (m,)
        Periods, s, >= 0.

    Returns
    -------
    Phi, integral : ndarray, shape (m, n, n) (or (n, n) for scalar T and one A)
    """
    A = np.asarray(A, dtype=float)
    T = np.asarray(T, dtype=float)
    scalar = T.ndim == 0 and A.ndim == 2
    T = np.atleast_1d(T)
    n = A.shape[-1]
    A = np.broadcast_to(A, (T.size, n, n))
    M = np.zeros((T.size, 2 * n, 2 * n))
    M[:, :n, :n] = A
    M[:, :n, n:] = np.eye(n)
    E = expm(M * T[:, None, None])
    Phi, integral = E[:, :n, :n], E[:, :n, n:]
    return (Phi[0], integral[0]) if scalar else (Phi, integral)
