"""A base that slides: the course χ follows the heading θ through τ_s·χ̇ + χ = θ, and ẋ = V·χ (`Robot.slip_lag`,
docs/models.md, "A base that slides").

Every model's critical NV* with a slide is checked against a route that shares nothing with the package but the
equations: the sampled loop against its own discretisation written out here (scipy's matrix exponential of the
continuous states (ω, θ, χ, y), the commands on their way as a shift register, the spectral radius bisected), the
exact delay against the crossings of its quasi-polynomial found by a scan in ω, the continuous loop against numpy's
roots of its polynomial. Random loops and extreme ones, not only the MuJoCo robots'.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize
from scipy.linalg import expm

from pfm_stability.models import make_model
from pfm_stability.models.loop import Loop
from pfm_stability.parameters import Controller, Robot


def _held(A, B, h):
    """(Φ(h), Γ(h)) of ẋ = Ax + Bu with u held for h (the exponential of the augmented matrix)."""
    n = A.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n:] = A, B
    E = expm(M * h)
    return E[:n, :n], E[:n, n:]


def _radius(NV, tau, gk, T, D, compute_delay, slip):
    """Spectral radius of the sampled loop written out: states (ω, θ, χ, y), ω̇ = (g·u(t − D) − ω)/τ, θ̇ = ω,
    τ_s·χ̇ = θ − χ, ẏ = χ; u_k = −k·θ_k − k·NV·y_k held, applied (compute_delay·T + D) after t_k."""
    A = np.array([[-1 / tau, 0, 0, 0], [1, 0, 0, 0], [0, 1 / slip, -1 / slip, 0], [0, 0, 1, 0]]) if slip > 0 else \
        np.array([[-1 / tau, 0, 0], [1, 0, 0], [0, 1, 0]])
    B = np.zeros((A.shape[0], 1))
    B[0, 0] = gk / tau  # the command in units of k: u/k
    C = np.zeros(A.shape[0])
    C[1], C[-1] = -1.0, -NV
    total = compute_delay * T + D
    m = int(math.floor(total / T + 1e-12))
    eps = total - m * T
    Phi, G_T = _held(A, B, T)
    _, G_rest = _held(A, B, T - eps)
    n = A.shape[0]
    size = n + m + 1  # x, then v_(k-1) … v_(k-m-1)
    M = np.zeros((size, size))
    M[:n, :n] = Phi
    newest = G_rest[:, 0] if m == 0 else None
    if m == 0:  # v_k acts after ε within this period, v_(k-1) before it
        M[:n, :n] += np.outer(newest, C)
        M[:n, n] = (G_T - G_rest)[:, 0]
    else:
        M[:n, n + m - 1] = G_rest[:, 0]
        M[:n, n + m] = (G_T - G_rest)[:, 0]
    M[n, :n] = C
    for j in range(1, m + 1):
        M[n + j, n + j - 1] = 1.0
    return float(np.max(np.abs(np.linalg.eigvals(M))))


def _sampled_NV(tau, gk, T, D, compute_delay, slip):
    """The smallest NV > 0 at which the written-out loop's radius reaches 1 (a log scan, then Brent)."""
    grid = np.geomspace(1e-4, 1e3, 400)
    values = [_radius(x, tau, gk, T, D, compute_delay, slip) - 1.0 for x in grid]
    i = next(j for j in range(len(grid) - 1) if values[j] < 0 <= values[j + 1])
    return optimize.brentq(lambda x: _radius(x, tau, gk, T, D, compute_delay, slip) - 1.0, grid[i], grid[i + 1], xtol=1e-13, rtol=1e-12)


def _random_loops(count, seed):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield dict(tau=rng.uniform(0.05, 0.6), k=rng.uniform(0.5, 4.0), g=rng.uniform(0.3, 1.2), T=rng.uniform(0.01, 0.12),
                   D=rng.choice([0.0, rng.uniform(0.0, 0.08)]), d=int(rng.integers(0, 2)), slip=rng.uniform(0.002, 0.15))


@pytest.mark.parametrize("case", list(_random_loops(10, 11)) + [
    dict(tau=0.1323, k=2.0, g=0.296, T=1 / 11, D=0.0224, d=1, slip=0.009),  # MuJoCo's robot C, its slide measured
    dict(tau=0.3, k=2.0, g=1.0, T=0.065, D=0.0, d=1, slip=1.0),  # a slide slower than the drive
    dict(tau=0.05, k=8.0, g=1.0, T=0.002, D=0.0, d=0, slip=0.001),  # a fast loop, a short slide
])
def test_sampled_critical_gain_against_the_loop_written_out(case):
    """The `sampled` model's NV* with a slide is the written-out loop's to 1e-7 (both are root-finding to ~1e-12 on the
    same equations; the tolerance leaves room for the model's crossing search), it is below the NV* without the slide
    (the slide lags the field's path), and the verdicts at 0.99 and 1.01·NV* are the written-out radius's."""
    loop = Loop(case["tau"], case["T"], case["k"], plant_gain=case["g"], dead_time=case["D"], slip_lag=case["slip"])
    model = make_model("sampled", hold="command", compute_delay=case["d"])
    NV = model.boundary(loop).NV_critical
    expected = _sampled_NV(case["tau"], case["g"] * case["k"], case["T"], case["D"], case["d"], case["slip"])
    assert NV == pytest.approx(expected, rel=1e-7)
    assert NV < model.boundary(loop.replace(slip_lag=0.0)).NV_critical
    for factor in (0.99, 1.01):
        stable = _radius(factor * NV, case["tau"], case["g"] * case["k"], case["T"], case["D"], case["d"], case["slip"]) < 1.0
        assert model.is_stable(factor * NV, loop) == stable


def _quasi(s, NV, tau, gk, T, D, slip):
    """(τ_s s + 1)(τs³ + s² + gk·s·e^(−sD)) + gk·NV·e^(−s(T + D)): the exact delay loop with a slide."""
    return (slip * s + 1) * (tau * s**3 + s**2 + gk * s * np.exp(-s * D)) + gk * NV * np.exp(-s * (T + D))


@pytest.mark.parametrize("case", list(_random_loops(8, 5)))
def test_exact_delay_critical_gain_is_the_first_crossing_of_the_quasi_polynomial(case):
    """`exact_delay`'s NV* with a slide is the smallest positive NV at which the quasi-polynomial has a root on the
    imaginary axis, found independently: NV(ω) = −(τ_s jω + 1)(τ(jω)³ + (jω)² + gk·jω·e^(−jωD))·e^(jω(T + D))/gk is
    real at a crossing; its zeros of Im in ω are scanned on a fine grid and refined (Brent), and the smallest positive
    real NV is the boundary when the loop is stable as NV → 0+ (the heading loop, checked here by the model). To 1e-7."""
    tau, gk, T, D, slip = case["tau"], case["g"] * case["k"], case["T"] * (1 + case["d"]), case["D"], case["slip"]
    loop = Loop(tau, T, case["k"], plant_gain=case["g"], dead_time=D, slip_lag=slip)
    model = make_model("exact_delay")
    assert model.is_stable(1e-6, loop)

    def nv(w):
        s = 1j * w
        return -(slip * s + 1) * (tau * s**3 + s**2 + gk * s * np.exp(-s * D)) * np.exp(s * (T + D)) / gk

    w = np.geomspace(1e-3, 2e3, 200_000)
    im = nv(w).imag
    crossings = [optimize.brentq(lambda x: nv(x).imag, w[i], w[i + 1], xtol=1e-14) for i in np.flatnonzero(np.sign(im[:-1]) != np.sign(im[1:]))]
    positive = [nv(x).real for x in crossings if nv(x).real > 0]
    NV = model.boundary(loop).NV_critical
    assert NV == pytest.approx(min(positive), rel=1e-7)
    b = model.boundary(loop)
    assert abs(_quasi(1j * b.omega_critical, NV, tau, gk, T, D, slip)) < 1e-6 * gk * NV


@pytest.mark.parametrize("slip", [0.01, 0.1, 1.0])
def test_continuous_critical_gain_from_numpys_roots(slip):
    """`continuous` with a slide: (τ_s s + 1)(τs³ + s² + gk·s) + gk·NV; its NV* is where numpy's roots of that
    polynomial first reach Re s = 0 (bisected on the largest real part), to 1e-8."""
    tau, k, g = 0.3, 2.0, 0.8
    loop = Loop(tau, 0.0, k, plant_gain=g, slip_lag=slip)
    gk = g * k
    poly = lambda NV: np.polyadd(np.polymul([slip, 1.0], [tau, 1.0, gk, 0.0]), [gk * NV])  # noqa: E731
    worst = lambda NV: max(np.roots(poly(NV)).real)  # noqa: E731
    NV = optimize.brentq(worst, 1e-6, 1e4, xtol=1e-14, rtol=1e-13)
    assert make_model("continuous").boundary(loop).NV_critical == pytest.approx(NV, rel=1e-8)


def test_the_sampled_loop_meets_the_exact_delay_as_T_goes_to_zero():
    """With a slide and a dead time, `sampled` (command hold, no compute delay) tends to `exact_delay` as T → 0: the
    held command's half-period lag is the difference, T/2 of a delay of T + D (0.6 % at T = 1 ms here)."""
    loop = Loop(0.2, 0.001, 3.0, plant_gain=0.9, dead_time=0.05, slip_lag=0.03)
    sampled = make_model("sampled", hold="command", compute_delay=0).boundary(loop).NV_critical
    exact = make_model("exact_delay").boundary(loop).NV_critical
    assert sampled == pytest.approx(exact, rel=0.01) and sampled < exact


def test_a_vanishing_slide_is_none_and_bad_values_are_refused():
    """τ_s·g·k below 10⁻⁹ is stored as 0 (no slide: KB's loop, the same answers); a negative, NaN or too long slide is
    refused with the allowed range."""
    assert Loop(0.3, 0.065, 2.0, slip_lag=1e-12).slip_lag == 0.0 and Loop(0.3, 0.065, 2.0, slip_lag=1e-12).kb_form
    for bad in (-0.01, math.nan, 11.0):
        with pytest.raises(ValueError, match="slip_lag"):
            Robot(V=1.0, tau=0.3, k=2.0, W=0.5, slip_lag=bad)


def test_the_simulator_refuses_a_slide():
    """The simulator's robot goes where it points: a robot with a slide is refused in one line, not simulated as
    another robot."""
    from pfm_stability.sim.scenario import check_first_order

    with pytest.raises(ValueError, match="slip_lag must be 0 for the simulator"):
        check_first_order(Robot(V=1.0, tau=0.3, k=2.0, W=0.5, slip_lag=0.01))


def test_the_limited_branch_starts_at_the_linear_boundary_with_a_slide():
    """The harmonic balance with the drive's slew limit carries the slide (the course's amplitude, `limiter.lag_gain`):
    a small start's V*(D) is the `sampled` model's linear V* with the slide (to 1e-6: the limiter is linear below its
    threshold), and the slide moves it (so the check can fail)."""
    from pfm_stability.analysis.disturbance import corridor_disturbance
    from pfm_stability.validation.common import predicted_boundaries, scenario_law, validation_models

    robot = Robot(V=1.0, tau=0.1323, k=2.0, W=0.5, plant_gain=0.296, dead_time=0.0224, yaw_accel_limit=2.03, slip_lag=0.009)
    controller = Controller(f=3.0, n=2.0, T=1 / 11, hold="command", compute_delay=1)
    law = scenario_law("grid", robot, controller)
    linear = predicted_boundaries("corridor", "V", robot, controller, law, 0.7, validation_models(controller))["sampled"]
    small = corridor_disturbance(robot, controller, law, 0.7, 0.01)
    assert small.V_disturbance == pytest.approx(linear, rel=1e-6)
    without = predicted_boundaries("corridor", "V", robot.replace(slip_lag=0.0), controller, law, 0.7, validation_models(controller))
    assert without["sampled"] > 1.02 * linear


def test_report_prints_the_equation_with_the_slide_and_refuses_a_bad_one():
    """`report --slip-lag` lists τ_s among the inputs, prints the equations it solved with (τ_s s + 1), and its JSON
    validates; a negative value exits 2 with one line naming it and the range."""
    import json

    from cli_helpers import VALIDATOR, run as run_cli

    code, out, err = run_cli(["report", "--preset", "carmel", "--L", "0.9", "--slip-lag", "0.02"])
    assert code == 0, err
    assert "tau_s (course's lag)" in out and "(tau_s s + 1)(tau s^3 + s^2 + g k s) + g k N V exp(-s T) = 0" in out
    code, out, err = run_cli(["report", "--preset", "carmel", "--L", "0.9", "--slip-lag", "0.02", "--format", "json"])
    assert code == 0, err
    data = json.loads(out)
    assert [e.message for e in VALIDATOR.iter_errors(data)] == []
    assert data["inputs"]["slip_lag"]["value"] == 0.02
    code, out, err = run_cli(["report", "--preset", "carmel", "--L", "0.9", "--slip-lag", "-1"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "-1" in err and "slip" in err


def test_a_path_tracking_report_lists_the_slide_its_loop_closes_through():
    """`report --controller rpp --slip-lag` lists τ_s among the plant's inputs (`report.path.PLANT`), its JSON validates,
    and the slide reaches RPP's loop: each model's NV* with a 0.1-s slide is below NV* without it (a lag in the loop
    lowers its boundary; `analysis.path_tracking` builds the loop with the robot's slip_lag)."""
    import json

    from cli_helpers import VALIDATOR, run as run_cli

    answers = {}
    for slide in ("0", "0.1"):
        code, out, err = run_cli(["report", "--controller", "rpp", "--L", "1.0", "--slip-lag", slide, "--format", "json"])
        assert code == 0, err
        data = json.loads(out)
        assert [e.message for e in VALIDATOR.iter_errors(data)] == []
        assert data["inputs"]["slip_lag"]["value"] == float(slide)
        answers[slide] = data["path"]
    for model in ("sampled", "exact_delay", "continuous"):
        assert answers["0.1"][model]["NV_critical"] < answers["0"][model]["NV_critical"], model
