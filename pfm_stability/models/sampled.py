"""`sampled`: the discrete-time loop a real VFF controller closes (DESIGN §4).

Linearized loop (Koren & Borenstein 1991 eq 6, 7, 10, 14): steering motor
τω̇ + ω = u, heading θ̇ = ω, lateral offset ẋ = Vθ, and the reference
δ = −N·x. With y = x/V the loop gain appears as K = kNV only:

    ω̇ = (u − ω)/τ,   θ̇ = ω,   ẏ = θ,   δ = −(K/k)·y.

(τ = 0: ω = u and the state is (θ, y).) Two structures (``hold``):

* ``"command"``: the computer samples θ_k and δ_k and holds
  u_k = k(δ_k − θ_k) = −kθ_k − K·y_k over [t_k, t_k+1) (CARMEL's case);
* ``"reference"``: the computer samples δ_k and holds it; the steering servo
  closes u = k(δ_k − θ(t)) continuously.

``compute_delay`` = 1 applies the value computed at t_k over [t_k+1, t_k+2)
(one more state: the stored command). The plant is discretized with a
zero-order hold, Φ = e^(AT), Γ = ∫₀ᵀ e^(As) ds·B (the exponential of the
augmented matrix [[A, B], [0, 0]]·T; python-control's ``sample_system`` is the
test oracle), and closed with the sampled feedback. Because the feedback is
affine in K, det(zI − Φ_cl(K)) = D(z) + K·E(z): the unit-circle crossings and
K* follow from module `crossings`; the verdict for a given K comes from the
closed-loop eigenvalues, cross-checked by the Schur–Cohn (Jury) test.

T = 0 is the continuous loop of KB eq (17) (`continuous`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..checks import check_choice, check_integer
from ..parameters import HOLDS
from ..routh import schur_cohn_stable
from .base import AffineGainModel, Boundary, Loop, _check_NV
from .continuous import Continuous

__all__ = ["Sampled", "continuous_plant", "discretize", "closed_loop_matrix"]


def continuous_plant(loop: Loop, hold: str):
    """Continuous part of the sampled loop: (A, B, F0, F1).

    The held input is v_k = −(F0 + K·F1)·state_k, and ẋ = A x + B v between
    samples. States: (ω, θ, y) for τ > 0, (θ, y) for τ = 0; y = x/V (s).

    Parameters
    ----------
    loop : Loop
    hold : {"command", "reference"}

    Returns
    -------
    A, B, F0, F1 : ndarray
    """
    check_choice("hold", hold, HOLDS)
    tau, k = loop.tau, loop.k
    if tau > 0:
        if hold == "command":
            A = np.array([[-1 / tau, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
            F0 = np.array([0.0, k, 0.0])
        else:
            A = np.array([[-1 / tau, -k / tau, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
            F0 = np.zeros(3)
        B = np.array([[1 / tau], [0.0], [0.0]])
        F1 = np.array([0.0, 0.0, 1.0])
    else:
        if hold == "command":
            A = np.array([[0, 0], [1, 0]], dtype=float)
            F0 = np.array([k, 0.0])
        else:
            A = np.array([[-k, 0], [1, 0]], dtype=float)
            F0 = np.zeros(2)
        B = np.array([[1.0], [0.0]])
        F1 = np.array([0.0, 1.0])
    return A, B, F0, F1


def discretize(A, B, T: float):
    """Zero-order-hold discretization: Φ = e^(AT), Γ = ∫₀ᵀ e^(As) ds B.

    Computed as the exponential of [[A, B], [0, 0]]·T (Van Loan 1978).
    """
    from scipy.linalg import expm

    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A
    M[:n, n:] = B
    E = expm(M * T)
    return E[:n, :n], E[:n, n:]


@lru_cache(maxsize=4096)
def _discrete_plant(loop: Loop, hold: str):
    A, B, F0, F1 = continuous_plant(loop, hold)
    Phi, Gamma = discretize(A, B, loop.T)
    for array in (Phi, Gamma, F0, F1):
        array.setflags(write=False)
    return Phi, Gamma, F0, F1


def closed_loop_matrix(loop: Loop, K: float, hold: str, compute_delay: int) -> np.ndarray:
    """Φ_cl of the sampled loop for gain K = kNV (1/s²).

    Parameters
    ----------
    loop : Loop
        T must be > 0.
    K : float
        Loop gain kNV, 1/s².
    hold : {"command", "reference"}
    compute_delay : {0, 1}

    Returns
    -------
    ndarray
        State transition matrix over one period; with compute_delay = 1 the
        last state is the command waiting to be applied.
    """
    Phi, Gamma, F0, F1 = _discrete_plant(loop, hold)
    F = (F0 + K * F1)[None, :]
    if compute_delay == 0:
        return Phi - Gamma @ F
    top = np.hstack([Phi, Gamma])
    bottom = np.hstack([-F, np.zeros((1, 1))])
    return np.vstack([top, bottom])


class Sampled(AffineGainModel):
    """The sampled-data VFF loop with zero-order hold.

    Parameters
    ----------
    hold : {"command", "reference"}
        What is held between samples (DESIGN §4).
    compute_delay : {0, 1}
        Samples between measurement and actuation.
    """

    name = "sampled"
    equation = "det(zI - Phi_cl(kNV)) = 0, ZOH, period T"
    domain = "z"

    def __init__(self, hold: str = "command", compute_delay: int = 0):
        self.hold = check_choice("hold", hold, HOLDS)
        self.compute_delay = check_integer("compute_delay", compute_delay, 0, 1)

    def __repr__(self) -> str:
        return f"Sampled(hold={self.hold!r}, compute_delay={self.compute_delay})"

    def closed_loop(self, NV: float, loop: Loop) -> np.ndarray:
        """Φ_cl for NV (1/s)."""
        return closed_loop_matrix(loop, loop.k * _check_NV(NV), self.hold, self.compute_delay)

    def polynomials(self, loop: Loop):
        """D(z) = det(zI − Φ_cl(0)), E(z) = det(zI − Φ_cl(1)) − D(z)."""
        d = np.poly(closed_loop_matrix(loop, 0.0, self.hold, self.compute_delay))
        e = np.poly(closed_loop_matrix(loop, 1.0, self.hold, self.compute_delay)) - d
        # the difference of two characteristic polynomials carries round-off of the size of D
        e[np.abs(e) <= 100 * np.finfo(float).eps * np.max(np.abs(d))] = 0.0
        return d, e

    def compute_boundary(self, loop: Loop) -> Boundary:
        if loop.T == 0:
            b = Continuous().boundary(loop)
            return Boundary(self.name, b.NV_critical, b.omega_critical, b.K_critical)
        return super().compute_boundary(loop)

    def eigenvalues(self, NV: float, loop: Loop) -> np.ndarray:
        """Closed-loop eigenvalues z (T > 0)."""
        return np.linalg.eigvals(self.closed_loop(NV, loop))

    def is_stable(self, NV: float, loop: Loop) -> bool:
        """Spectral radius of Φ_cl < 1 (T = 0: the continuous verdict)."""
        if loop.T == 0:
            return Continuous().is_stable(NV, loop)
        return bool(np.max(np.abs(self.eigenvalues(NV, loop))) < 1.0)

    def jury_stable(self, NV: float, loop: Loop) -> bool:
        """Schur–Cohn (Jury) verdict on det(zI − Φ_cl), independent of the eigenvalues."""
        return schur_cohn_stable(self.characteristic(NV, loop))

    def rightmost_root(self, NV: float, loop: Loop) -> complex:
        """Dominant pole as s = ln(z)/T: σ = ln|z|/T (1/s), ω = arg(z)/T (rad/s)."""
        if loop.T == 0:
            return Continuous().rightmost_root(NV, loop)
        z = self.eigenvalues(NV, loop)
        radius = np.abs(z)
        top = z[radius >= radius.max() * (1 - 1e-12)]
        z = top[np.argmax(top.imag)]
        return complex(np.log(z) / loop.T)
