"""The numpy matrix exponential (module `matrix_exponential`) against scipy's expm and closed forms."""

import math

import numpy as np
import pytest
import scipy.linalg

from pfm_stability.numerics.matrix_exponential import expm, zoh_blocks


@pytest.mark.parametrize("n", [2, 3, 4, 6])
@pytest.mark.parametrize("scale", [1e-8, 1e-2, 1.0, 5.0])
def test_equals_scipy_on_random_stacks(n, scale):
    """40 random (half of them triangular) matrices per case, one batched call; agreement with
    scipy.linalg.expm to 1e-11 relative to the largest entry (both are Padé [13/13] with
    scaling and squaring; the squarings amplify round-off with the norm: ~2e-12 seen at the
    norms of ~30 of these random matrices)."""
    rng = np.random.default_rng(n + int(math.log10(scale) + 20))
    M = rng.normal(size=(40, n, n)) * scale
    M[::2] = np.triu(M[::2])
    ours = expm(M)
    for m, e in zip(M, ours):
        ref = scipy.linalg.expm(m)
        assert np.max(np.abs(e - ref)) <= 1e-11 * np.max(np.abs(ref))


def test_zoh_blocks_closed_form():
    """Steering plant ω̇ = (u − ω)/τ, θ̇ = ω: e^(AT) and ∫e^(As)ds against their closed forms
    evaluated with 30 digits (mpmath), for periods of 3e-6 τ to 100 τ: 1e-13 relative
    (the smallest entries, O(T²/τ), are the ones cancellation would destroy)."""
    import mpmath as mp

    tau = 0.3
    A = np.array([[-1 / tau, 0.0], [1.0, 0.0]])
    T = np.array([1e-6, 1e-3, 0.065, 3.0, 30.0])
    Phi, integral = zoh_blocks(A, T)
    with mp.workdps(30):
        x = [mp.mpf(t) / mp.mpf(tau) for t in T]
        e = np.array([float(mp.exp(-v)) for v in x])
        a = np.array([float(mp.mpf(tau) * (1 - mp.exp(-v))) for v in x])  # ∫₀ᵀ e^(−s/τ) ds
        b = np.array([float(mp.mpf(tau) ** 2 * (v - 1 + mp.exp(-v))) for v in x])  # ∫₀ᵀ a(s) ds
    np.testing.assert_allclose(Phi[:, 0, 0], e, rtol=1e-13)
    np.testing.assert_allclose(Phi[:, 1, 0], a, rtol=1e-13)
    np.testing.assert_allclose(integral[:, 0, 0], a, rtol=1e-13)
    np.testing.assert_allclose(integral[:, 1, 0], b, rtol=1e-13)
    np.testing.assert_allclose(integral[:, 1, 1], T, rtol=1e-14)


@pytest.mark.parametrize("tau", [1e-4, 0.3])
@pytest.mark.parametrize("T", [1e-6, 0.065, 10.0, 100.0])
def test_stiff_steering_plants_equal_scipy(tau, T):
    """The sampled loop's own plant (ω, θ, y with the servo closed), T/τ from 3e-6 to 1e6:
    e^(AT) and ∫e^(As)ds equal scipy's to 1e-12 of the largest entry, 1e-10 when ‖A‖T > 1e4
    (each of the ~20 squarings can double the round-off; scipy keeps the diagonal of
    triangular matrices exact, this implementation does not)."""
    A = np.array([[-1 / tau, -2.0 / tau, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    Phi, integral = zoh_blocks(A, T)
    M = np.zeros((6, 6))
    M[:3, :3], M[:3, 3:] = A * T, np.eye(3) * T
    ref = scipy.linalg.expm(M)
    tolerance = 1e-10 if 3 * T / tau > 1e4 else 1e-12
    assert np.max(np.abs(Phi - ref[:3, :3])) <= tolerance * np.max(np.abs(ref[:3, :3]))
    assert np.max(np.abs(integral - ref[:3, 3:])) <= tolerance * np.max(np.abs(ref[:3, 3:]))


def test_scalar_period_returns_matrices():
    Phi, integral = zoh_blocks(np.zeros((2, 2)), 0.5)
    np.testing.assert_allclose(Phi, np.eye(2), rtol=1e-15)
    np.testing.assert_allclose(integral, 0.5 * np.eye(2), rtol=1e-15)
