"""The robot between samples: exact steering solutions (KB eq 6–7) and the quadrature of its motion (eq 14)."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pfm_stability.sim.robot import NODES, advance_position, constant_input, gauss_legendre, propagate, servo

WMAX = math.radians(120)


def _ode(tau, k, mode, v, theta0, omega0, T):
    """Reference solution of τω̇ + ω = u, θ̇ = ω, ẋ = V sin θ, ẏ = V cos θ (V = 0.8) by a tight Runge–Kutta."""

    def rhs(t, s):
        omega, theta = s[0], s[1]
        u = v if mode == "command" else k * (v - theta)
        return [(u - omega) / tau, omega, 0.8 * math.sin(theta), 0.8 * math.cos(theta)]

    sol = solve_ivp(rhs, (0, T), [omega0, theta0, 0.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-15)
    return sol.y[:, -1]


@pytest.mark.parametrize("mode", ["command", "reference"])
@pytest.mark.parametrize(
    "tau,k,T,position_tol",
    [(0.3, 2.0, 0.065, 1e-12), (0.1, 5.0, 0.2, 3e-8), (0.5, 1.0, 0.5, 2e-6)],
)
def test_closed_form_matches_ode(mode, tau, k, T, position_tol):
    """θ, ω after one period equal a DOP853 integration (rtol 1e-13) to 1e-11; x, y to the quadrature error.

    Held command (eq 6, constant u) or servo on a held reference (eq 7).
    The x, y tolerances are the measured Gauss–Legendre errors rounded up
    (module docstring of `robot`): 1.6e-13 m for CARMEL's T = 0.065 s,
    1.1e-8 m for T/τ = 2, 1.3e-6 m for T = 0.5 s.
    """
    frac, w = gauss_legendre(NODES)
    theta0, omega0 = 0.4, -1.0
    v = 1.5 if mode == "command" else theta0 + 0.3
    B = np.ones(1)
    coef = constant_input(tau * B, T * B, frac) if mode == "command" else servo(tau * B, k * B, T * B, frac)
    nodes, theta, omega = propagate(coef, theta0 * B, omega0 * B, v * B)
    x, y = advance_position(np.zeros(1), np.zeros(1), 0.8 * B, T * B, nodes, w)
    ref = _ode(tau, k, mode, v, theta0, omega0, T)
    assert omega[0] == pytest.approx(ref[0], abs=1e-11)
    assert theta[0] == pytest.approx(ref[1], abs=1e-11)
    assert x[0] == pytest.approx(ref[2], abs=position_tol)
    assert y[0] == pytest.approx(ref[3], abs=position_tol)


def test_zero_time_constant():
    """τ = 0 (ideal motor): ω = u at once (command); θ relaxes as e^(−kt) towards δ̃ (servo)."""
    frac, _ = gauss_legendre(NODES)
    one = np.ones(1)
    _, theta, omega = propagate(constant_input(0 * one, 0.1 * one, frac), 0.2 * one, 5.0 * one, 1.0 * one)
    assert omega[0] == 1.0 and theta[0] == pytest.approx(0.3)
    _, theta, omega = propagate(servo(0 * one, 2.0 * one, 0.1 * one, frac), 0.2 * one, 0 * one, 0.5 * one)
    assert theta[0] == pytest.approx(0.5 - 0.3 * math.exp(-0.2), rel=1e-14)
    assert omega[0] == pytest.approx(2.0 * (0.5 - theta[0]), rel=1e-14)


def test_quadrature_error_at_carmel_sampling():
    """The position error of one CARMEL step (T = 0.065 s) is below 1e-12 m in the worst case measured.

    Worst case: a saturated reversal ω₀ = −120°/s → u = +120°/s, over every
    initial heading; reference: 40-node Gauss–Legendre. The docstring of
    `pfm_stability.sim.robot` states 1.6e-13 m.
    """
    th0 = np.linspace(-math.pi, math.pi, 41)
    B = th0.size
    ones = np.ones(B)
    results = []
    for nodes in (NODES, 40):
        frac, w = gauss_legendre(nodes)
        coef = constant_input(0.3 * ones, 0.065 * ones, frac)
        theta_nodes, _, _ = propagate(coef, th0, -WMAX * ones, WMAX * ones)
        results.append(advance_position(np.zeros(B), np.zeros(B), 0.8 * ones, 0.065 * ones, theta_nodes, w))
    error = max(np.max(np.abs(results[0][0] - results[1][0])), np.max(np.abs(results[0][1] - results[1][1])))
    assert error < 1e-12


def test_saturated_command_keeps_rate_within_limit():
    """A held command clipped to ±ω_max moves ω monotonically towards it: |ω| <= ω_max stays exact."""
    frac, _ = gauss_legendre(NODES)
    ones = np.ones(3)
    omega = np.array([-WMAX, 0.0, WMAX])
    coef = constant_input(0.3 * ones, 0.065 * ones, frac)
    for _ in range(50):
        _, _, omega = propagate(coef, np.zeros(3), omega, WMAX * ones)
        assert np.all(np.abs(omega) <= WMAX * (1 + 1e-15))


def test_servo_closed_form_equals_scipy_expm():
    """The closed-form exp(At) of the servo equals scipy's expm (1e-13) across under-, critically and over-damped loops."""
    from scipy.linalg import expm

    frac, _ = gauss_legendre(NODES)
    tau = np.array([0.3, 0.125, 0.05, 0.3, 0.125 * (1 + 1e-10)])
    k = np.array([2.0, 2.0, 2.0, 30.0, 2.0])  # 4τk = 2.4 (under), 1 (critical), 0.4 (over), 36, ~1
    h = np.full(5, 0.1)
    coef = servo(tau, k, h, frac)
    for m in range(5):
        A = np.array([[0.0, 1.0], [-k[m] / tau[m], -1.0 / tau[m]]])
        for j, t in enumerate(list(h[m] * frac) + [h[m]]):
            E = expm(A * t)
            assert coef.theta[m, j, 0] == pytest.approx(E[0, 0], rel=1e-13, abs=1e-15)
            assert coef.theta[m, j, 1] == pytest.approx(E[0, 1], rel=1e-13, abs=1e-15)
        E = expm(A * h[m])
        assert coef.omega[m, 0] == pytest.approx(E[1, 0], rel=1e-12, abs=1e-14)
        assert coef.omega[m, 1] == pytest.approx(E[1, 1], rel=1e-12, abs=1e-14)
