"""Vectorized exact-delay verdicts (docs/models.md, `exact_delay`) against the scalar crossing count."""

import math

import numpy as np
import pytest

from pfm_stability.analysis.criteria import analyze_corridor, analyze_wall
from pfm_stability.numerics.delay import DelayLoop
from pfm_stability.models import ExactDelay, Loop
from pfm_stability.parameters import Controller, Corridor, Robot, Wall
from pfm_stability.vectorized import delay_verdicts_from_gain, exact_delay_verdicts


@pytest.mark.slow  # seconds: scheduled first (tests/conftest.py)
def test_verdicts_and_margins_equal_scalar_route_over_extreme_ranges():
    """3000 points with τ from 0 to 3 s (down to 1e-6), T from 0 to 20 s, k from
    0.05 to 100 1/s (resonant steering loops included), K over six decades:
    identical root counts, delay margins to 1e-11 relative (both are closed
    form up to polished polynomial roots)."""
    rng = np.random.default_rng(2)
    n = 3000
    tau = np.exp(rng.uniform(np.log(1e-6), np.log(3), n))
    tau[:100] = 0
    T = np.exp(rng.uniform(np.log(1e-4), np.log(20), n))
    T[100:150] = 0
    k = np.exp(rng.uniform(np.log(0.05), np.log(100), n))
    K = np.exp(rng.uniform(np.log(1e-3), np.log(1e3), n))
    stable, Z, margin = delay_verdicts_from_gain(tau, T, k, K)
    assert np.any(k * tau > 2 + math.sqrt(3)) and np.any(~stable) and np.any(stable)
    for i in range(n):
        a = [tau[i], 1.0, k[i], 0.0] if tau[i] > 0 else [1.0, k[i], 0.0]
        q = DelayLoop(a, T[i])
        assert q.unstable_root_count(K[i]) == Z[i]
        assert margin[i] == pytest.approx(q.delay_margin(K[i]), rel=1e-11)


def test_parameter_arrays_match_the_scenario_analysis():
    """Every parameter may vary per point: wall and corridor arrays give the
    `exact_delay` verdict of `analyze_wall` / `analyze_corridor` point by point."""
    rng = np.random.default_rng(4)
    n = 40
    V, tau, T = rng.uniform(0.2, 1.5, n), rng.uniform(0.05, 0.8, n), rng.uniform(0.0, 0.3, n)
    k, f, n_exp, W = rng.uniform(0.5, 6, n), rng.uniform(0.2, 3, n), rng.uniform(1, 3, n), rng.uniform(0.4, 1.0, n)
    alpha, L = rng.uniform(0.1, 1.4, n), W / 2 + rng.uniform(0.1, 2.0, n)
    wall = exact_delay_verdicts(V, tau, T, k, f, n_exp, W, alpha=alpha)
    corridor = exact_delay_verdicts(V, tau, T, k, f, n_exp, W, L=L)
    for i in range(n):
        robot, controller = Robot(V[i], tau[i], k[i], W[i]), Controller(f[i], n_exp[i], T[i])
        w = analyze_wall(robot, controller, Wall(alpha[i]), [ExactDelay()])
        c = analyze_corridor(robot, controller, Corridor(L[i]), [ExactDelay()])
        assert wall.NV[i] == pytest.approx(w.NV, rel=1e-12)
        assert bool(wall.stable[i]) == (w.models["exact_delay"].verdict == "stable")
        assert bool(corridor.stable[i]) == (c.models["exact_delay"].verdict == "stable")


def test_broadcasting_shapes_and_relative_margin():
    grid = exact_delay_verdicts(0.8, 0.3, np.array([0.0, 0.065, 0.2])[:, None], 2.0, 0.8, 2, 0.8, L=np.array([0.7, 0.9, 1.5])[None, :])
    assert grid.stable.shape == (3, 3)
    assert np.all(np.isfinite(grid.relative_delay_margin) | (grid.relative_delay_margin == np.inf))
    # wider corridor → larger margin
    assert np.all(np.diff(grid.delay_margin, axis=1) >= 0)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(V=[0.8, -1.0]), r"V must be a finite number in \(0, 100\] m/s; got -1.0 \(point 1\)"),
        (dict(T=np.nan), r"T must be a finite number in \[0, 100\] s; got nan"),
        (dict(L=0.3), r"L must be a finite number in \(W/2, 10000\] m = \(0.4, 10000\] m; got 0.3"),
        (dict(n=0.0), r"n must be a finite number in \[0.01, 10\]"),
    ],
)
def test_bad_arrays_name_parameter_and_point(kwargs, message):
    args = dict(V=0.8, tau=0.3, T=0.065, k=2.0, f=0.8, n=2.0, W=0.8, L=0.9)
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        exact_delay_verdicts(**args)


def test_heading_gain_counts_and_margins_equal_the_generic_delay_loop():
    """A heading gain c per point (half in [−0.99, 1), half log-uniform up to 100, 50 at c = 0),
    τ from 0 to 3 s, T from 0 to 20 s, k over four decades: the array count of
    τs³ + s² + ks + (kcs + K)e^(−sT) equals the generic `DelayLoop` (np.roots of |a|² − |b|², a
    Routh array) point by point, delay margins to 1e-11 relative (both closed form up to polished
    polynomial roots; observed 2e-14)."""
    rng = np.random.default_rng(2)
    n = 1200
    tau = np.exp(rng.uniform(np.log(1e-6), np.log(3), n))
    tau[:40] = 0
    T = np.exp(rng.uniform(np.log(1e-4), np.log(20), n))
    T[40:60] = 0
    k = np.exp(rng.uniform(np.log(0.05), np.log(100), n))
    K = np.exp(rng.uniform(np.log(1e-3), np.log(1e3), n))
    c = np.where(np.arange(n) % 2, rng.uniform(-0.99, 1, n), np.exp(rng.uniform(0, np.log(100), n)))
    c[60:110] = 0
    stable, Z, margin = delay_verdicts_from_gain(tau, T, k, K, c)
    assert np.any(stable) and np.any(~stable) and np.any(Z >= 4)
    for i in range(n):
        q = DelayLoop([tau[i], 1.0, k[i], 0.0] if tau[i] > 0 else [1.0, k[i], 0.0], T[i], delayed=[k[i] * c[i], 0.0])
        assert q.unstable_root_count(K[i]) == Z[i]
        assert margin[i] == pytest.approx(q.delay_margin(K[i]), rel=1e-11)


def test_heading_gain_arrays_give_the_models_verdicts():
    """`exact_delay_verdicts(..., c=)` on wall and corridor arrays: the verdict of
    `ExactDelay().is_stable(NV, Loop(τ, T, k, c=c))` point by point (c < 0 and c > 0); c=None,
    c=0 and c=zeros are KB's arrays bit for bit; c broadcasts; a c outside [−0.99, 100] is named
    with its point."""
    rng = np.random.default_rng(6)
    n = 60
    V, tau, T = rng.uniform(0.2, 1.5, n), rng.uniform(0.05, 0.8, n), rng.uniform(0.0, 0.3, n)
    k, f, n_exp, W = rng.uniform(0.5, 6, n), rng.uniform(0.2, 3, n), rng.uniform(1, 3, n), rng.uniform(0.4, 1.0, n)
    alpha, L = rng.uniform(0.1, 1.4, n), W / 2 + rng.uniform(0.1, 2.0, n)
    c = np.where(np.arange(n) % 2, rng.uniform(-0.99, 0, n), rng.uniform(0, 3, n))
    for geometry in (dict(alpha=alpha), dict(L=L)):
        out = exact_delay_verdicts(V, tau, T, k, f, n_exp, W, c=c, **geometry)
        assert np.any(out.stable) and np.any(~out.stable)
        for i in range(n):
            assert bool(out.stable[i]) == ExactDelay().is_stable(float(out.NV[i]), Loop(tau[i], T[i], k[i], c=float(c[i])))
        plain = exact_delay_verdicts(V, tau, T, k, f, n_exp, W, **geometry)
        for zero in (0.0, np.zeros(n)):
            same = exact_delay_verdicts(V, tau, T, k, f, n_exp, W, c=zero, **geometry)
            for name in ("stable", "unstable_roots", "delay_margin", "NV"):
                assert np.array_equal(getattr(same, name), getattr(plain, name))
    grid = exact_delay_verdicts(0.8, 0.3, 0.065, 2.0, 0.8, 2, 0.8, L=0.9, c=np.array([-0.5, 0.0, 0.5, 2.0]))
    assert grid.stable.shape == (4,)
    with pytest.raises(ValueError, match=r"c must be a finite number in \[-0.99, 100\]; got -1.5 .*\(point 2\)"):
        exact_delay_verdicts(0.8, 0.3, 0.065, 2.0, 0.8, 2, 0.8, L=0.9, c=[0.0, 0.5, -1.5])
