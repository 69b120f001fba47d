"""The dead time where it acts: D delays the whole command (docs/models.md, "Plant gain and dead time").

The plant g·e^(−sD)/((τs + 1)(τ_a·s + 1)) acts on the whole command k(δ − θ), so every continuous-time model
solves a form of p0(s) + gk·s·e^(−s·h₁) + gk(cs + NV)·e^(−s(T + D)) = 0 (h₁ = D, or T + D with the heading
sampled), a quasi-polynomial with two delays (`numerics.quasi`), and the sampled loop carries the commands
on their way in a delay line (`models.sampled.DelayLine`). What is checked here, each against a route that
does not share the code under test:

* the two-delay quasi-polynomial against QPmR (spectral mapping) and cxroots (argument principle and Newton)
  on random loops far from CARMEL: the stable set's edge NV* and ω*, root counts at random gains;
* on KB's one-delay loop, against the crossing count of Cooke & van den Driessche (`numerics.delay`);
* T → 0: `exact_delay` meets `sampled` (the issue's four robots: 18–34 % apart before);
* the delay line's counts against the eigenvalues of the closed-loop matrix, its edges on |z| = 1, and a loop
  with 326 commands on their way (more than the characteristic polynomial could carry);
* the report of a robot unstable at every period: T* = 0 in every model, no "lower T" remedy, the equations.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from cli_helpers import run
from pfm_stability.models import ExactDelay, Loop, Sampled, make_model
from pfm_stability.numerics.delay import DelayLoop, kb_critical_gain
from pfm_stability.numerics.quasi import QuasiPolynomial


def _random_plants(count: int, seed: int):
    """Random loops with a dead time: τ in [0, 1] s, a second lag or none, g·k in [0.3, 10] 1/s, D in [0.01, 0.3] s,
    T in [0, 0.2] s, c = 0 or in [−0.5, 1], the heading closed by the drive or sampled."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        tau, lag, k = rng.uniform(0, 1), rng.choice([0.0, rng.uniform(0.01, 0.2)]), 10 ** rng.uniform(-0.5, 1)
        c = float(rng.choice([0.0, rng.uniform(-0.5, 1)]))
        yield Loop(tau, rng.uniform(0, 0.2), k, c=c, dead_time=rng.uniform(0.01, 0.3), actuator_lag=lag,
                   heading_sampled=bool(rng.integers(2)))


def _qpmr_roots(loop: Loop, K: float, R: float) -> np.ndarray:
    """QPmR's roots of the loop's quasi-polynomial written out here, in [−0.2, R] × [−R, R] on a grid of step R/100
    (its roots Newton-polished to 1e-10; a root of Re s >= 0 is an isolated zero of a function analytic there)."""
    qpmr = pytest.importorskip("qpmr")
    p0 = np.polymul(np.polymul([loop.tau, 1.0], [loop.actuator_lag, 1.0]), [1.0, 0.0, 0.0])
    rows = np.zeros((3, len(p0)))
    rows[0] = p0[::-1]  # ascending powers
    rows[1, 1] = loop.steering_gain
    rows[2, 0], rows[2, 1] = K, loop.steering_gain * loop.c
    delays = np.array([0.0, loop.heading_delay, loop.T + loop.dead_time])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        roots, _ = qpmr.qpmr(rows, delays, region=[-0.2, R, -R, R], e=1e-10, ds=R / 100)
    return np.asarray(roots)


@pytest.mark.slow
def test_two_delay_loop_against_qpmr():
    """On three random plants (`_random_plants`, seed 7): QPmR finds no root in Re s > 0 at NV*(1 − 1e-6) and exactly one
    pair at NV*(1 + 1e-6), at ±jω* to 1e-5 (its grid and polishing tolerance). The region holds every root with
    Re s >= 0 (|s| below the bound where |p0| exceeds the rest: `QuasiPolynomial._root_radius`)."""
    checked = 0
    for loop in _random_plants(8, seed=7):
        b = ExactDelay().boundary(loop)
        if not 0 < b.NV_critical < math.inf or checked == 3:
            continue
        checked += 1
        K = loop.loop_gain(b.NV_critical)
        R = 1.05 * loop.quasi_terms()._root_radius(K * 1.01)
        for factor, pairs in ((1 - 1e-6, 0), (1 + 1e-6, 1)):
            roots = _qpmr_roots(loop, K * factor, R)
            right = roots[roots.real > 0]
            assert len(right) == 2 * pairs, loop
            assert np.all(np.abs(np.abs(right.imag) - b.omega_critical) < 1e-5 * max(1.0, b.omega_critical))
    assert checked == 3


def test_two_delay_loop_against_cxroots():
    """cxroots (the argument principle on a rectangle, independent of our axis sweep) counts the roots in Re s > 0 of six
    random plants at 0.9, 1.1 and 3 times NV* (roots there lie well off the axis, where a contour through it is
    well conditioned; the edges themselves are QPmR's test): 0, 2, and our count (an integer: exact)."""
    cxroots = pytest.importorskip("cxroots")
    for loop in list(_random_plants(9, seed=11))[:6]:
        quasi = loop.quasi_terms()
        b = ExactDelay().boundary(loop)
        if not 0 < b.NV_critical < math.inf:
            continue
        for factor in (0.9, 1.1, 3.0):
            K = loop.loop_gain(b.NV_critical * factor)
            R = 1.05 * quasi._root_radius(K)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                count = cxroots.Rectangle([0.0, R], [-R, R]).count_roots(lambda s: quasi.value(s, K), lambda s: quasi.slope(s, K))
            assert count == quasi.unstable_root_count(K), (loop, factor)
            if factor < 1:
                assert count == 0
            elif factor < 2:
                assert count == 2


def test_one_delay_route_agrees_with_the_crossing_count():
    """KB's loop τs³ + s² + ks + K·e^(−sT) through the general route (the heading term undelayed, folded into p0) against
    `numerics.delay` on 30 random loops: K* (1e-9: two root finders on the same phase condition), the counts at 0.3,
    0.99, 1.01 and 3 times K*, the delay margin (1e-8) and the rightmost root (1e-8)."""
    rng = np.random.default_rng(1)
    for _ in range(30):
        tau, T, k = rng.uniform(0, 2), 10 ** rng.uniform(-3, 0.5), 10 ** rng.uniform(-1, 1.5)
        quasi, single = QuasiPolynomial([tau, 1.0, k, 0.0], [], T), DelayLoop([tau, 1.0, k, 0.0], T)
        K_star = kb_critical_gain(np.array([tau]), np.array([T]), np.array([k]))[0][0]
        assert quasi.stable_gains(1e12).gain == pytest.approx(K_star, rel=1e-9)
        for factor in (0.3, 0.99, 1.01, 3.0):
            assert quasi.unstable_root_count(factor * K_star) == single.unstable_root_count(factor * K_star)
        K = 0.5 * K_star
        assert quasi.shift_margin(K, [True]) + T == pytest.approx(single.delay_margin(K), rel=1e-8)
        assert quasi.rightmost_roots(K, 2)[0] == pytest.approx(single.rightmost_roots(K, 2)[0], rel=1e-8, abs=1e-8)


@pytest.mark.parametrize("tau, k, g, D", [(0.3, 2, 0.7, 0.13), (0.5, 3, 1.1, 0.08), (0.2, 6, 0.8, 0.05), (0.4, 1.5, 1, 0.2)])
def test_exact_delay_meets_the_sampled_loop_as_the_period_vanishes(tau, k, g, D):
    """Command hold, no compute delay: `exact_delay`'s NV* is within 1 % of `sampled`'s at T = 5 ms and within 0.1 %
    at 0.5 ms (the hold's O(T): at T → 0 both are p0 + gk(s + NV)e^(−sD)); with D on the field's term alone it was
    18–34 % above at 5 ms (the issue's four robots). `pade` (order 6) is within 1e-4 of `exact_delay` there."""
    sampled, exact = Sampled("command", 0), ExactDelay()
    for T, tolerance in ((0.005, 1e-2), (0.0005, 1e-3)):
        loop = Loop(tau, T, k, plant_gain=g, dead_time=D)
        e, s = exact.boundary(loop).NV_critical, sampled.boundary(loop).NV_critical
        assert abs(e / s - 1) < tolerance
        assert make_model("pade", pade_order=6).boundary(loop).NV_critical == pytest.approx(e, rel=1e-4)


def test_the_delay_line_counts_like_the_eigenvalues():
    """On 30 random plants with τ_a, c and both compute delays (D up to 0.5 s, T 10–200 ms): the delay line's verdict
    (winding number, `DelayLine.outside`) equals the eigenvalues' at NV = 0 (the heading loop), 0.3, 0.97, 1.03 and
    2·NV*, and at NV* the largest pole has |z| = 1 to 1e-8 (eigenvalues of an O(10) matrix against a root of Im K(θ))."""
    rng = np.random.default_rng(2)
    for _ in range(30):
        loop = Loop(rng.uniform(0, 0.6), rng.uniform(0.01, 0.2), rng.uniform(0.3, 5), c=float(rng.choice([0, rng.uniform(-0.5, 1)])),
                    plant_gain=rng.uniform(0.5, 1.5), dead_time=rng.uniform(0.005, 0.5), actuator_lag=float(rng.choice([0, rng.uniform(0, 0.1)])))
        model = Sampled("command", int(rng.integers(2)))
        b = model.boundary(loop)
        for NV in (0.0, 0.3 * b.NV_critical, 0.97 * b.NV_critical, 1.03 * b.NV_critical, 2 * b.NV_critical + 0.1):
            z = 1 + loop.T * model._judged_eigenvalues(NV, loop)
            assert model.is_stable(NV, loop) == bool(np.all(np.abs(z) < 1)), (loop, NV)
        if b.NV_critical > 0:
            assert np.abs(model.eigenvalues(b.NV_critical, loop)).max() == pytest.approx(1.0, abs=1e-8)


def test_hundreds_of_periods_in_flight():
    """T = 0.4 ms with D = 0.13 s: 326 commands on their way, past what a characteristic polynomial in z resolves (64).
    NV* is within 0.2 % of the T → 0 limit's (`exact_delay`, O(T)); at 0.98 and 1.02·NV* the delay line's verdict is
    the eigenvalues' (a 330-dimensional matrix), and T* of a point the limit cannot bear is 0."""
    loop = Loop(0.3, 0.0004, 2.0, plant_gain=0.7, dead_time=0.13)
    model = Sampled("command", 1)
    NV_star = model.boundary(loop).NV_critical
    assert NV_star == pytest.approx(ExactDelay().boundary(loop.replace(T=0.0)).NV_critical, rel=2e-3)
    for NV in (0.98 * NV_star, 1.02 * NV_star):
        assert model.is_stable(NV, loop) == bool(np.all(np.abs(model.eigenvalues(NV, loop)) < 1))
    assert model.critical_delay(1.02 * NV_star, loop) == 0.0


def test_report_of_a_robot_no_period_helps():
    """τ = 0.3 s, k = 2, g = 0.7, D = 0.13 s, V = 0.8 m/s, L = 0.9 m, command hold, compute delay 1: the loop's T → 0
    limit p0 + gk(s + NV)e^(−sD) is unstable (NV = 2.25 against its NV* 2.00), so no period helps: T* = 0 in every delay
    model (it read D/63 = 0.0021 s when a delay loop stood in for the sampled one below 64 periods), no "lower T" remedy,
    and the Models section prints the equations solved."""
    code, out, err = run(["report", "--tau", "0.3", "--T", "0.1", "--k", "2", "--V", "0.8", "--L", "0.9", "--plant-gain", "0.7",
                          "--dead-time", "0.13", "--hold", "command", "--compute-delay", "1", "--format", "json"])
    assert code == 0 and err == ""
    report = json.loads(out)
    assert report["models"]["exact_delay"]["equation"] == "tau s^3 + s^2 + g k s exp(-s D) + g k N V exp(-s (T + D)) = 0"
    for name in ("kb_first_order", "pade", "exact_delay", "sampled"):
        verdict = report["corridor"][name]
        assert verdict["verdict"] == "unstable" and verdict["T_critical"] == 0.0
        assert "T" not in verdict["to_stabilize"]


@pytest.mark.parametrize("loop", [Loop(0.3, 0.0, 2.0, actuator_lag=0.05), Loop(0.3, 0.0, 2.0, heading_sampled=True),
                                  Loop(0.0, 0.05, 2.0, actuator_lag=0.05)], ids=["T=0, tau_a", "T=0, heading sampled", "tau=0, tau_a"])
def test_loops_without_a_delay_or_a_first_lag(loop):
    """The general loop's edges: no delay at all (T = D = 0) is the polynomial loop in every continuous-time model
    (NV* = `continuous`'s, 1e-12); a lone second lag is the motor's lag (τ = 0, τ_a > 0 is stored as τ = τ_a, and every
    model answers as for that first-order plant); every query answers a float (no error, no NaN)."""
    for name in ("continuous", "kb_first_order", "pade", "exact_delay", "sampled"):
        model = make_model(name, hold="command", compute_delay=1)
        b = model.boundary(loop)
        if loop.T == 0 and name != "sampled":
            assert b.NV_critical == pytest.approx(make_model("continuous").boundary(loop).NV_critical, rel=1e-12)
        NV = 0.5 * b.NV_critical
        answers = (model.critical_delay(NV, loop), model.critical_dead_time(NV, loop), model.critical_gain_k(NV, loop))
        assert all(isinstance(x, float) and not math.isnan(x) for x in answers), (name, answers)
        assert model.is_stable(NV, loop) and not model.is_stable(-1.0, loop)
    assert Loop(0.0, 0.05, 2.0, actuator_lag=0.05) == Loop(0.05, 0.05, 2.0)


def test_the_sampled_searches_stay_inside_the_delay_line():
    """T = 1 µs with D = 0.01 s: 10⁴ commands in flight. T* and k* answer; D* beyond the longest dead time the delay line
    carries at this period ((10⁵ − 2)·T = 0.1 s) is not given (None: the loop is still stable there), and no search
    refuses a dead time the user never gave (it used to probe D up to 10 s, 10⁷ periods)."""
    loop, model = Loop(0.3, 1e-6, 2.0, dead_time=0.01), Sampled("command", 1)
    NV = 0.5 * model.boundary(loop).NV_critical
    assert model.critical_dead_time(NV, loop) is None
    assert 0 < model.critical_delay(NV, loop) < 1 and model.critical_gain_k(NV, loop) > 1


def _two_lag_poles(tau, lag, T, gk, K, D, d):
    """Closed-loop poles of the held command with the drive g·e^(−sD)/((τs + 1)(τ_a·s + 1)), built here from scipy's expm
    in the states (z, ω, θ, x/V): over [t_k, t_k+1) the motor's input is v_(k−m−1) for the first ε and v_(k−m) after,
    m·T + ε = d·T + D, v_k = −gk·θ_k − K·y_k (the held command times g). The state adds the commands on their way."""
    from scipy.linalg import expm

    A = np.array([[-1 / lag, 0, 0, 0], [1 / tau, -1 / tau, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]])
    B = np.array([1 / lag, 0, 0, 0])

    def zoh(h):  # (Φ(h), Γ(h)) of the input held over h
        M = np.zeros((5, 5))
        M[:4, :4], M[:4, 4] = A * h, B * h
        E = expm(M)
        return E[:4, :4], E[:4, 4]

    whole = int(math.floor(D / T + 1e-12))
    eps = D - whole * T
    m = d + whole
    lines = m + (eps > 1e-12)
    n = 4 + lines
    Phi_rest, Gamma_rest = zoh(T - eps)
    Phi_eps, Gamma_eps = zoh(eps)
    F = np.array([0, 0, gk, K])
    Acl = np.zeros((n, n))
    # x_(k+1) = Φ(T−ε)[Φ(ε)x + Γ(ε)v_(k−m−1)] + Γ(T−ε)v_(k−m); v_(k−j) is state 4 + j − 1 (j >= 1), v_k = −F·x
    def column(j):  # where v_(k−j) lives: j = 0 is the new command, −F·x
        return None if j == 0 else 4 + j - 1
    Acl[:4, :4] = Phi_rest @ Phi_eps
    for j, gamma in ((m + 1, Phi_rest @ Gamma_eps), (m, Gamma_rest)):
        if eps <= 1e-12 and j == m + 1:
            continue
        c = column(j)
        if c is None:
            Acl[:4, :4] -= np.outer(gamma, F)
        else:
            Acl[:4, c] += gamma
    if lines:
        Acl[4, :4] = -F  # v_k enters the line
        for j in range(1, lines):
            Acl[4 + j, 4 + j - 1] = 1.0
    return np.linalg.eigvals(Acl)


def test_sampled_second_lag_equals_the_closed_loop_built_here():
    """Eight random plants with a second lag τ_a, D below and above T, both compute delays: the sampled model's largest
    pole modulus equals the test's own closed loop (`_two_lag_poles`) at 0.4, 0.9 and 1.3·NV* to 1e-9 (eigenvalues of
    6–9-dimensional matrices of O(1) entries, formed two ways: the δ form and Tustin crossings against expm of the raw
    blocks), and at NV* the test's loop is on the unit circle (1e-8)."""
    rng = np.random.default_rng(17)
    for _ in range(8):
        tau, lag, T = rng.uniform(0.05, 0.4), rng.uniform(0.01, 0.1), rng.uniform(0.02, 0.15)
        k, g, D, d = rng.uniform(0.5, 4.0), rng.uniform(0.6, 1.4), rng.uniform(0.0, 2.5) * T, int(rng.integers(2))
        loop, model = Loop(tau, T, k, plant_gain=g, dead_time=D, actuator_lag=lag), Sampled("command", d)
        NV_star = model.boundary(loop).NV_critical
        assert NV_star > 0
        for factor in (0.4, 0.9, 1.3):
            NV = factor * NV_star
            ours = np.abs(model.eigenvalues(NV, loop)).max()
            theirs = np.abs(_two_lag_poles(tau, lag, T, g * k, g * k * NV, D, d)).max()
            assert ours == pytest.approx(theirs, rel=1e-9)
        assert np.abs(_two_lag_poles(tau, lag, T, g * k, g * k * NV_star, D, d)).max() == pytest.approx(1.0, abs=1e-8)


def test_a_fast_motor_with_a_dead_time():
    """τ = 1e-6 s with D = 0.05 s (the motor's pole 10⁶ rad/s beyond everything the delay does): exact_delay's NV* equals
    Padé(12)'s (1e-9: both converge on the same loop; it used to exceed the axis sweep's grid budget) and τ = 0's within
    1e-4 (the lag's own O(τ·ω*) effect)."""
    fast, ideal = Loop(1e-6, 0.065, 2.0, dead_time=0.05), Loop(0.0, 0.065, 2.0, dead_time=0.05)
    NV = ExactDelay().boundary(fast).NV_critical
    assert NV == pytest.approx(make_model("pade", pade_order=12).boundary(fast).NV_critical, rel=1e-9)
    assert NV == pytest.approx(ExactDelay().boundary(ideal).NV_critical, rel=1e-4)
