"""The robot between samples: exact steering (KB eq 6–7), ∫Δ dt in closed form, graded quadrature of the motion (eq 14)."""

import cmath
import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.linalg import expm

from pfm_stability.sim.robot import (
    MAX_PANELS,
    NODES,
    RESOLUTION,
    Rule,
    advance_position,
    constant_input,
    constant_input_modes,
    gauss_legendre,
    graded_rule,
    node_sum,
    panel_count,
    propagate,
    servo,
    servo_modes,
    slow_rate,
)

WMAX = math.radians(120)


def _modes(mode, tau, k):
    return constant_input_modes(tau) if mode == "command" else servo_modes(tau, k)


def _rule(mode, tau, k, h):
    """The rule the engine builds for a member (`panel_count` panels of `graded_rule`)."""
    return graded_rule(h, *_modes(mode, tau, k), slow_rate(k, WMAX * np.ones_like(k)))


def _coefficients(mode, tau, k, h, size=1):
    one = np.ones(size)
    tau, k, h = tau * one, k * one, h * one
    rule = _rule(mode, tau, k, h)
    return constant_input(tau, rule) if mode == "command" else servo(tau, k, rule)


def _step(coef, theta0, omega0, v, V=0.8):
    """(x, y, θ, ω) after one interval from the origin."""
    delta, correction, theta, omega = propagate(coef, theta0, omega0, v)
    zero = np.zeros_like(theta0)
    x, y = advance_position(zero, zero, V * np.ones_like(theta0), coef.rule, theta0, delta, correction)
    return x, y, theta, omega


def _integral(coef):
    """∫₀ʰ Δ dt coefficients: the stored correction plus the rule applied to Δ."""
    J = coef.rule.t.shape[1]
    return coef.maps[:, J] + node_sum(coef.rule.w[:, :, None] * coef.maps[:, :J])


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
    [(0.3, 2.0, 0.065, 1e-13), (0.1, 5.0, 0.2, 2e-10), (0.5, 1.0, 0.5, 1e-9), (0.01, 2.0, 0.3, 1e-12), (0.01, 0.5, 1.0, 3e-10)],
)
def test_closed_form_matches_ode(mode, tau, k, T, position_tol):
    """θ, ω after one period equal a DOP853 integration (rtol 1e-13) to 1e-11; x, y to the quadrature error.

    Held command (eq 6, constant u) or servo on a held reference (eq 7), up to
    T/τ = 100. The x, y tolerances are the measured differences (2e-14 m at
    CARMEL's T, 6e-11 and 2e-10 m at T = 0.2 and 0.5 s, 1e-13 m at T/τ = 30,
    7e-11 m at T/τ = 100: the residual quadrature, see the module docstring
    of `robot`) rounded up.
    """
    theta0, omega0 = 0.4, -1.0
    v = 1.5 if mode == "command" else theta0 + 0.3
    B = np.ones(1)
    x, y, theta, omega = _step(_coefficients(mode, tau, k, T), theta0 * B, omega0 * B, v * B)
    ref = _ode(tau, k, mode, v, theta0, omega0, T)
    assert omega[0] == pytest.approx(ref[0], abs=1e-11)
    assert theta[0] == pytest.approx(ref[1], abs=1e-11)
    assert x[0] == pytest.approx(ref[2], abs=position_tol)
    assert y[0] == pytest.approx(ref[3], abs=position_tol)


def test_zero_time_constant():
    """τ = 0 (ideal motor): ω = u at once, x = V(cos θ₀ − cos θ(h))/u (command); θ relaxes as e^(−kt) to δ̃ (servo)."""
    one = np.ones(1)
    x, y, theta, omega = _step(_coefficients("command", 0.0, 2.0, 0.1), 0.2 * one, 5.0 * one, 1.0 * one)
    assert omega[0] == 1.0 and theta[0] == pytest.approx(0.3)
    assert x[0] == pytest.approx(0.8 * (math.cos(0.2) - math.cos(0.3)), rel=1e-14, abs=0.0)
    assert y[0] == pytest.approx(0.8 * (math.sin(0.3) - math.sin(0.2)), rel=1e-14, abs=0.0)
    coef = _coefficients("reference", 0.0, 2.0, 0.1)
    _, _, theta, omega = _step(coef, 0.2 * one, 0 * one, 0.5 * one)
    assert theta[0] == pytest.approx(0.5 - 0.3 * math.exp(-0.2), rel=1e-14, abs=0.0)
    assert omega[0] == pytest.approx(2.0 * (0.5 - theta[0]), rel=1e-14, abs=0.0)
    P_integral = -math.expm1(-0.2) / 2.0  # ∫₀ʰ e^(−kt) dt
    assert _integral(coef)[0] == pytest.approx([P_integral - 0.1, 0.0, 0.1 - P_integral], rel=1e-13, abs=0.0)


def _theta_function(mode, tau, k, theta0, omega0, v):
    """θ(t) written out independently: constant input, or the servo's two modes (roots of τλ² + λ + k)."""
    if mode == "command":
        return lambda t: theta0 + v * t + (omega0 - v) * (-tau * math.expm1(-t / tau))
    lam1, lam2 = np.roots([tau, 1.0, k]).astype(complex)
    e0 = theta0 - v
    a1 = (omega0 - lam2 * e0) / (lam1 - lam2)
    a2 = e0 - a1
    return lambda t: v + (a1 * cmath.exp(lam1 * t) + a2 * cmath.exp(lam2 * t)).real


@pytest.mark.parametrize(
    "mode,tau,k,T,tol",
    [
        ("command", 0.3, 2.0, 0.065, 5e-13),
        ("command", 0.3, 2.0, 0.5, 1e-9),
        ("command", 0.05, 2.0, 0.2, 7e-11),
        ("command", 0.01, 2.0, 0.3, 1.1e-12),
        ("command", 0.01, 0.5, 1.0, 3e-9),
        ("reference", 0.3, 2.0, 0.2, 4e-9),
        ("reference", 0.05, 6.0, 0.2, 6e-10),
        ("reference", 0.01, 0.5, 1.0, 5e-10),
    ],
)
def test_position_error_of_a_saturated_turn(mode, tau, k, T, tol):
    """One step's position error, worst over 9 initial headings, is within 3× the module docstring's figures.

    Worst case: a saturated reversal ω₀ = −120°/s → u = +120°/s (command), or
    a held reference 0.99·ω_max/k ahead with ω₀ = −120°/s (servo, the largest
    unsaturated turn); V = 0.8 m/s. Reference: scipy's adaptive ``quad``
    (tolerance 1e-13 relative, 1e-15 absolute; tighter ones change nothing) on
    θ(t) written out independently. The old 4-node rule on
    the whole interval was off by 1.2e-6 m at T = 0.5 s and 1.2e-4 m at
    T/τ = 30.
    """
    theta0 = np.linspace(-math.pi, math.pi, 9)
    omega0 = -WMAX * np.ones_like(theta0)
    v = WMAX * np.ones_like(theta0) if mode == "command" else theta0 + 0.99 * WMAX / k
    x, y, _, _ = _step(_coefficients(mode, tau, k, T, theta0.size), theta0, omega0, v)
    points = [c * tau for c in (0.3, 1.0, 3.0, 10.0, 30.0) if c * tau < T]
    options = dict(epsabs=1e-15, epsrel=1e-13, limit=1000, points=points or None)
    error = 0.0
    for m in range(theta0.size):
        theta = _theta_function(mode, tau, k, theta0[m], omega0[m], v[m])
        x_ref = 0.8 * quad(lambda t: math.sin(theta(t)), 0, T, **options)[0]
        y_ref = 0.8 * quad(lambda t: math.cos(theta(t)), 0, T, **options)[0]
        error = max(error, abs(x[m] - x_ref), abs(y[m] - y_ref))
    assert error < tol


@pytest.mark.parametrize("mode", ["command", "reference"])
def test_linear_motion_is_exact_at_large_T_over_tau(mode):
    """For headings of ~1e-6 rad, one step's lateral motion equals V∫sin θ dt to 1e-13 relative at T/τ = 100.

    This is the motion the growth rate σ is measured from: its part linear in
    the heading is integrated in closed form, so no quadrature error enters it
    (measured 7e-15, round-off of the closed forms; the old 4-node rule on the
    whole interval was off by 2.5e-4 and 3.6e-4 relative here). Reference:
    adaptive quadrature of V sin θ(t) with θ(t) written out independently.
    """
    tau, k, T = 0.01, 0.5, 1.0
    theta0, omega0 = 1e-6, -3e-6
    v = 2e-6 if mode == "command" else -1e-6
    one = np.ones(1)
    x, _, _, _ = _step(_coefficients(mode, tau, k, T), theta0 * one, omega0 * one, v * one)
    theta = _theta_function(mode, tau, k, theta0, omega0, v)
    points = [c * tau for c in (0.3, 1.0, 3.0, 10.0, 30.0)]
    x_ref = 0.8 * quad(lambda t: math.sin(theta(t)), 0, T, epsabs=0.0, epsrel=1e-13, limit=1000, points=points)[0]
    assert x[0] == pytest.approx(x_ref, rel=1e-13, abs=0.0)


def test_saturated_command_keeps_rate_within_limit():
    """A held command clipped to ±ω_max moves ω monotonically towards it: |ω| <= ω_max stays exact."""
    ones = np.ones(3)
    omega = np.array([-WMAX, 0.0, WMAX])
    coef = _coefficients("command", 0.3, 2.0, 0.065, 3)
    for _ in range(50):
        _, _, _, omega = propagate(coef, np.zeros(3), omega, WMAX * ones)
        assert np.all(np.abs(omega) <= WMAX * (1 + 1e-15))


def test_servo_closed_form_equals_scipy_expm():
    """The closed-form exp(At) and ∫₀ʰ exp(At) dt of the servo equal scipy's expm (1e-13) across damping regimes.

    Under-, critically and over-damped loops and τ = 0; the integral against
    Van Loan's block exponential expm([[A, I], [0, 0]]h), whose top-right block
    is ∫₀ʰ exp(At) dt.
    """
    frac, weights = gauss_legendre(NODES)
    tau = np.array([0.3, 0.125, 0.05, 0.3, 0.125 * (1 + 1e-10)])
    k = np.array([2.0, 2.0, 2.0, 30.0, 2.0])  # 4τk = 2.4 (under), 1 (critical), 0.4 (over), 36, ~1
    h = np.full(5, 0.1)
    coef = servo(tau, k, Rule(h[:, None] * frac, h[:, None] * weights, h))
    J = NODES
    integral = _integral(coef)
    for m in range(5):
        A = np.array([[0.0, 1.0], [-k[m] / tau[m], -1.0 / tau[m]]])
        for j, t in enumerate(h[m] * frac):
            E = expm(A * t)
            assert coef.maps[m, j, 0] == pytest.approx(E[0, 0] - 1.0, rel=1e-12, abs=1e-15)
            assert coef.maps[m, j, 1] == pytest.approx(E[0, 1], rel=1e-13, abs=1e-15)
        E = expm(A * h[m])
        assert coef.maps[m, J + 1, :2] == pytest.approx(E[0], rel=1e-13, abs=1e-15)
        assert coef.maps[m, J + 2, :2] == pytest.approx(E[1], rel=1e-12, abs=1e-14)
        block = np.zeros((4, 4))
        block[:2, :2], block[:2, 2:] = A, np.eye(2)
        F = expm(block * h[m])[0, 2:]
        assert integral[m, :2] == pytest.approx([F[0] - h[m], F[1]], rel=1e-10, abs=1e-15)


def test_constant_input_integral():
    """∫₀ʰ Δ dt of a held command equals adaptive quadrature (1e-13) of Δ(t) = a(t)ω₀ + (t − a(t))u to 1e-12."""
    tau, h = np.array([0.3, 0.01, 0.0]), np.array([0.065, 1.0, 0.1])
    integral = _integral(_coefficients("command", tau, np.full(3, 2.0), h, 3))
    for m in range(3):
        a = lambda t: -tau[m] * math.expm1(-t / tau[m]) if tau[m] > 0 else 0.0
        a_int = quad(a, 0, h[m], epsabs=0.0, epsrel=1e-13, limit=200)[0]
        assert integral[m] == pytest.approx([0.0, a_int, h[m] ** 2 / 2 - a_int], rel=1e-12, abs=0.0)


def test_graded_rule():
    """The composite rule: one panel (the plain 4-node rule) at CARMEL's T; panels ~τ wide at the start at large T/τ.

    Weights sum to h, nodes increase inside (0, h), each panel is exact for
    polynomials of degree 2·NODES − 1, a member's rule does not depend on the
    other members (padding: zero weights at t = h), and the first panel spans
    at most `RESOLUTION` rad of the fastest mode (width <= RESOLUTION·τ).
    """
    tau = np.array([0.3, 0.3, 0.01, 0.01])
    k = np.array([2.0, 2.0, 2.0, 0.5])
    h = np.array([0.065, 0.065 / 8, 0.3, 1.0])
    rule = _rule("command", tau, k, h)
    counts = panel_count(h, *constant_input_modes(tau), slow_rate(k, WMAX * np.ones(4)))
    assert counts.tolist()[:2] == [1, 1] and 1 < counts[2] < counts[3] <= MAX_PANELS
    frac, weights = gauss_legendre(NODES)
    # bit for bit is legitimate: one panel is t = 0 + (h − 0)·frac, w = (h − 0)·weights, correctly rounded
    # products and sums (IEEE 754) whatever the array shape or SIMD kernel
    assert np.array_equal(rule.t[0, :NODES], 0.065 * frac) and np.array_equal(rule.w[0, :NODES], 0.065 * weights)
    assert np.all(rule.w[0, NODES:] == 0) and np.all(rule.t[0, NODES:] == 0.065)
    assert np.sum(rule.w, axis=1) == pytest.approx(h, rel=1e-14)
    for m in range(4):
        J = NODES * counts[m]
        assert np.all(np.diff(rule.t[m, :J]) > 0) and 0 < rule.t[m, 0] and rule.t[m, J - 1] < h[m]
        assert np.sum(rule.w[m] * rule.t[m] ** 7) == pytest.approx(h[m] ** 8 / 8, rel=1e-13)
    first = np.sum(rule.w[2:, :NODES], axis=1)  # width of the first panel
    assert np.all(first < RESOLUTION * tau[2:])
    # alone vs in a batch of 4: the breakpoints come from expm1 in arrays of other shapes, which numpy's SIMD
    # kernels may round differently (docs/simulator.md, "Batches"); the bisection then moves them by a few ULP
    # of h. 64 ε·h allows that and nothing else: another member's rule would differ by a whole panel
    alone = _rule("command", tau[2:3], k[2:3], h[2:3])
    J = alone.t.shape[1]
    assert np.allclose(alone.t[0], rule.t[2, :J], rtol=0, atol=64 * np.finfo(float).eps * h[2])
    assert np.allclose(alone.w[0], rule.w[2, :J], rtol=0, atol=64 * np.finfo(float).eps * h[2])
    assert np.all(rule.w[2, J:] == 0)
