"""`sampled` model (docs/models.md) against python-control, a bracketing root finder
on the spectral radius, and a direct simulation of the continuous plant."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from conftest import random_loops
from pfm_stability.models import Continuous, Loop, Sampled
from pfm_stability.models.sampled import continuous_plant, discretize

control = pytest.importorskip("control")

STRUCTURES = [(h, c) for h in ("command", "reference") for c in (0, 1)]


@pytest.mark.parametrize("hold", ["command", "reference"])
@pytest.mark.parametrize("tau", [0.0, 0.3, 1.2])
def test_discretization_equals_python_control(hold, tau):
    """Φ, Γ (Van Loan's augmented exponential) = control.sample_system(..., 'zoh') to 1e-12."""
    loop = Loop(tau, 0.065, 2.0)
    A, B, _, _ = continuous_plant(loop, hold)
    Phi, Gamma = discretize(A, B, loop.T)
    n = A.shape[0]
    sys_d = control.sample_system(control.ss(A, B, np.eye(n), np.zeros((n, 1))), loop.T, method="zoh")
    np.testing.assert_allclose(Phi, sys_d.A, atol=1e-12)
    np.testing.assert_allclose(Gamma, sys_d.B, atol=1e-12)


def _spectral_radius(model, NV, loop):
    return float(np.max(np.abs(model.eigenvalues(NV, loop))))


@pytest.mark.parametrize("hold, delay", STRUCTURES)
@pytest.mark.parametrize("tau, T, k, K", random_loops(6, seed=31, T=(0.01, 0.3), k=(0.3, 6.0)))
def test_critical_gain_equals_bracketing_on_spectral_radius(hold, delay, tau, T, k, K):
    """NV* from the unit-circle crossings = brentq on ρ(Φ_cl(NV)) − 1 (1e-9)."""
    model = Sampled(hold, delay)
    loop = Loop(tau, T, k)
    star = model.boundary(loop).NV_critical
    if not 0 < star < math.inf:
        pytest.skip("no finite boundary")
    bracketed = brentq(lambda nv: _spectral_radius(model, nv, loop) - 1.0, 0.5 * star, 1.5 * star, xtol=1e-14, rtol=1e-12)
    assert bracketed == pytest.approx(star, rel=1e-9)


@pytest.mark.parametrize("hold, delay", STRUCTURES)
def test_eigenvalues_and_jury_agree(hold, delay):
    """Verdict from eigenvalues = Schur–Cohn (Jury) verdict on 200 random NV (skip |ρ − 1| < 1e-9)."""
    rng = np.random.default_rng(7)
    model = Sampled(hold, delay)
    agree = 0
    for _ in range(200):
        loop = Loop(rng.uniform(0, 1), rng.uniform(0.005, 0.4), rng.uniform(0.2, 8))
        NV = rng.uniform(0.05, 6)
        rho = _spectral_radius(model, NV, loop)
        if abs(rho - 1) < 1e-9:
            continue
        assert model.is_stable(NV, loop) == model.jury_stable(NV, loop) == (rho < 1)
        agree += 1
    assert agree > 190


def _simulate_linear_loop(loop, NV, hold, delay, periods):
    """The sampled loop by direct ODE integration of the continuous plant (RK45, 1e-12)."""
    tau, T, k = loop.tau, loop.T, loop.k
    K = k * NV

    def rhs(t, s, held):
        w, th, y = s
        u = held if hold == "command" else k * (held - th)
        dw = (u - w) / tau if tau > 0 else 0.0
        return [dw, w if tau > 0 else u, th]

    state = np.array([0.0, 0.0, 1e-3])
    pending = None
    ys = []
    for _ in range(periods):
        w, th, y = state
        if hold == "command":
            value = -k * th - K * y  # u_k = k(δ_k − θ_k), δ_k = −N·x_k = −(K/k)·y_k
        else:
            value = -(K / k) * y  # δ_k held
        held, pending = (value, None) if delay == 0 else (pending if pending is not None else 0.0, value)
        sol = solve_ivp(rhs, (0, T), state, args=(held,), rtol=1e-12, atol=1e-15, method="RK45")
        state = sol.y[:, -1]
        ys.append(state[2])
    return np.array(ys)


@pytest.mark.parametrize("hold, delay", STRUCTURES)
def test_dominant_pole_matches_simulated_growth(hold, delay):
    """σ = ln|z|/T of the dominant pole = growth of the directly simulated loop:
    the envelope ratio over 150 periods, measured on |y| peaks (tolerance 2 %
    of σ: peak sampling at period T quantizes the envelope)."""
    loop = Loop(0.3, 0.065, 2.0)
    model = Sampled(hold, delay)
    star = model.boundary(loop).NV_critical
    for NV in (0.8 * star, 1.2 * star):
        s = model.rightmost_root(NV, loop)
        y = _simulate_linear_loop(loop, NV, hold, delay, 150)
        t = loop.T * np.arange(1, len(y) + 1)
        peaks = [i for i in range(1, len(y) - 1) if abs(y[i]) >= abs(y[i - 1]) and abs(y[i]) >= abs(y[i + 1])]
        late = [i for i in peaks if t[i] > 3.0]
        slope = np.polyfit(t[late], np.log(np.abs(y[late])), 1)[0]
        assert slope == pytest.approx(s.real, rel=0.02, abs=0.01)
        assert (slope > 0) == (NV > star)


def test_structure_ordering_for_carmel(carmel_loop):
    """What the structures imply: a compute delay adds a full period of lag, so
    NV* drops (cd = 1 < cd = 0); the `reference` servo feeds θ back continuously
    (no hold in the inner loop), so it tolerates more than `command`."""
    nv = {s: Sampled(*s).boundary(carmel_loop).NV_critical for s in STRUCTURES}
    assert nv[("command", 1)] < nv[("command", 0)]
    assert nv[("reference", 1)] < nv[("reference", 0)]
    assert nv[("reference", 0)] > nv[("command", 0)]
    assert nv[("reference", 1)] > nv[("command", 1)]


@pytest.mark.parametrize("hold, delay", STRUCTURES)
def test_sampled_tends_to_continuous_as_T_vanishes(hold, delay):
    """T → 0: the sampled loop becomes (17); NV* → 1/τ (1 % at T = 1e-4 s) and T = 0 is exactly (17)."""
    assert Sampled(hold, delay).boundary(Loop(0.3, 1e-4, 2.0)).NV_critical == pytest.approx(1 / 0.3, rel=1e-2)
    assert Sampled(hold, delay).boundary(Loop(0.3, 0.0, 2.0)).NV_critical == Continuous().boundary(Loop(0.3, 0.0, 2.0)).NV_critical


def test_unstable_inner_loop_gives_zero_critical_gain():
    """cd = 1, command hold, large k: the sampled steering loop itself is unstable,
    so no NV is stable (NV* = 0), and the eigenvalues agree at a small NV."""
    loop = Loop(0.3, 0.065, 20.0)
    model = Sampled("command", 1)
    assert model.boundary(loop).NV_critical == 0.0
    assert not model.is_stable(1e-6, loop)


def _mp_spectral_radius(loop, hold, delay, NV, digits=40):
    """ρ(Φ_cl) in 40-digit arithmetic: mpmath's expm of the Van Loan matrix and mpmath's eig.

    Independent of the model's numpy exponential, δ form and bilinear polynomials.
    """
    import mpmath as mp

    with mp.workdps(digits):
        A, B, F0, F1 = continuous_plant(loop, hold)
        n = A.shape[0]
        M = mp.zeros(n + 1, n + 1)
        for i in range(n):
            for j in range(n):
                M[i, j] = mp.mpf(A[i, j])
            M[i, n] = mp.mpf(B[i, 0])
        E = mp.expm(M * mp.mpf(loop.T))
        K = mp.mpf(loop.k) * mp.mpf(NV)
        F = [mp.mpf(F0[j]) + K * mp.mpf(F1[j]) for j in range(n)]
        size = n + delay
        C = mp.zeros(size, size)
        for i in range(n):
            for j in range(n):
                C[i, j] = E[i, j] - (0 if delay else E[i, n] * F[j])
            if delay:
                C[i, n] = E[i, n]
        if delay:
            for j in range(n):
                C[n, j] = -F[j]
        return max(abs(z) for z in mp.eig(C, left=False, right=False))


@pytest.mark.parametrize("hold, delay", STRUCTURES)
@pytest.mark.parametrize("T", [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0])
def test_critical_gain_to_1e8_from_a_microsecond_to_ten_seconds(hold, delay, T):
    """NV* is accurate to 1e-8 relative for T from 1e-6 to 10 s (requirement: 1e-7): the
    40-digit spectral radius is < 1 at NV*(1 − 1e-8) and > 1 at NV*(1 + 1e-8). The old
    z-polynomial lost 1e-3 at T = 1e-4 and returned 0 at T <= 1e-5 (cancellation as z → 1).
    Where NV* = 0 the loop must be unstable at every NV: checked at 12 values over 9 decades."""
    loop = Loop(0.3, T, 2.0)
    NV = Sampled(hold, delay).boundary(loop).NV_critical
    if NV == 0:
        assert all(_mp_spectral_radius(loop, hold, delay, nv) > 1 for nv in np.geomspace(1e-6, 1e3, 12))
        return
    assert _mp_spectral_radius(loop, hold, delay, NV * (1 - 1e-8)) < 1 < _mp_spectral_radius(loop, hold, delay, NV * (1 + 1e-8))


@pytest.mark.parametrize("hold, delay", STRUCTURES)
@pytest.mark.parametrize("tau, T, k, K", random_loops(3, seed=53, tau=(0.0, 2.0), T=(1e-6, 1e-3), k=(0.1, 50.0)))
def test_critical_gain_at_short_periods_far_from_carmel(hold, delay, tau, T, k, K):
    """Random τ, k and periods of 1 µs to 1 ms: the same 40-digit check at 1e-8."""
    loop = Loop(tau, T, k)
    NV = Sampled(hold, delay).boundary(loop).NV_critical
    if not 0 < NV < math.inf:
        pytest.skip("no finite boundary (checked elsewhere)")
    assert _mp_spectral_radius(loop, hold, delay, NV * (1 - 1e-8)) < 1 < _mp_spectral_radius(loop, hold, delay, NV * (1 + 1e-8))


def test_unstable_at_any_NV_for_the_filed_parameters():
    """τ = 1.07 s, T = 0.112 s, k = 6.47 1/s, command hold with a compute delay: NV* = 0, an
    empty stable set, and the 40-digit spectral radius exceeds 1 at every one of 12 NV over 9 decades."""
    loop = Loop(1.07, 0.112, 6.47)
    b = Sampled("command", 1).boundary(loop)
    assert b.NV_critical == 0.0 and b.stable_set == () and b.omega_critical is None
    assert all(_mp_spectral_radius(loop, "command", 1, nv) > 1 for nv in np.geomspace(1e-6, 1e3, 12))


def test_real_negative_dominant_pole_has_a_finite_rate():
    """A dominant pole on the negative real axis (τ = 0, kT = 2.015) gives σ = ln|z|/T and
    ω = π/T, not NaN; z from python-control's ZOH discretization and numpy eigenvalues (1e-12)."""
    loop = Loop(0.0, 0.065, 31.0)
    model = Sampled("command", 0)
    A, B, F0, F1 = continuous_plant(loop, "command")
    d = control.sample_system(control.ss(A, B, np.eye(2), np.zeros((2, 1))), loop.T, method="zoh")
    z = np.linalg.eigvals(d.A - d.B @ (F0 + loop.k * 0.5 * F1)[None, :])
    dominant = z[np.argmax(np.abs(z))]
    assert dominant.real < 0 and abs(dominant.imag) < 1e-12
    root = model.rightmost_root(0.5, loop)
    assert root.real == pytest.approx(math.log(abs(dominant)) / loop.T, rel=1e-12)
    assert root.imag == pytest.approx(math.pi / loop.T, rel=1e-12)
