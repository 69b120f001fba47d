"""Bisection (module `pfm_stability.numerics.solve`) against scipy's brentq."""

import math

import pytest
from scipy.optimize import brentq

from pfm_stability.numerics.solve import bisect_root, expand_bracket

CASES = [
    (lambda x: x**3 - 2, 0.0, 2.0),
    (lambda x: math.exp(x) - 1e6, 0.0, 100.0),  # mpmath's Anderson–Björck returns 49.98 here
    (lambda x: math.atan(x) - 1e-9, -1.0, 10.0),
    (lambda x: math.tanh(50 * (x - 0.3)), 0.0, 1.0),
    (lambda x: 1e-20 * (x - 0.5), 0.0, 1.0),
]


@pytest.mark.parametrize("func, lo, hi", CASES)
def test_bisection_agrees_with_brentq(func, lo, hi):
    """Same root as brentq to 1e-12 relative (bisection stops at 1e-13 relative bracket width)."""
    expected = brentq(func, lo, hi, xtol=1e-300, rtol=1e-14, maxiter=500)
    assert bisect_root(func, lo, hi) == pytest.approx(expected, rel=1e-12, abs=1e-300)


def test_no_sign_change_is_an_error():
    with pytest.raises(ValueError, match="no sign change"):
        bisect_root(lambda x: x * x + 1, -1.0, 1.0)


def test_expand_bracket_finds_far_roots_both_ways():
    assert expand_bracket(lambda x: x - 1e6, 1.0) == (524288.0, 1048576.0)
    lo, hi = expand_bracket(lambda x: x - 1e-6, 1.0, upward=False)
    assert lo < 1e-6 < hi
    assert expand_bracket(lambda x: 1.0, 1.0, steps=10) is None


def test_newton_with_the_moving_roots_alone_finds_the_same_roots():
    """`newton_increasing(..., moving=True)` evaluates only the roots not yet converged (a converged root stays put:
    its step is 0 and f the same) and returns the same roots, to a few ULP, as evaluating every bracket each step — smooth
    roots (quadratic convergence) and jumps (bisection to the bracket's width) together, 200 random brackets;
    and it evaluates fewer points."""
    import numpy as np

    from pfm_stability.numerics.solve import newton_increasing

    rng = np.random.default_rng(4)
    root = rng.uniform(-1.0, 1.0, 200)
    jump = rng.random(200) < 0.3  # a step function: F jumps across the root
    scale = rng.uniform(0.1, 10.0, 200)
    calls = {"all": 0, "moving": 0}

    def f(x, idx):
        d = x - root[idx]
        value = np.where(jump[idx], np.sign(d) + 0.1 * d, scale[idx] * (d + 0.3 * d ** 3))
        slope = np.where(jump[idx], 0.1, scale[idx] * (1 + 0.9 * d ** 2))
        return value, slope

    def everyone(x):
        calls["all"] += x.size
        return f(x, np.arange(x.size))

    def moving(x, idx):
        calls["moving"] += x.size
        return f(x, idx)

    lo, hi = root - rng.uniform(0.01, 1.0, 200), root + rng.uniform(0.01, 1.0, 200)
    expected = newton_increasing(everyone, lo, hi, atol=1e-9, iterations=30)
    got = newton_increasing(moving, lo, hi, atol=1e-9, iterations=30, moving=True)
    # a few ULP of roots in (-2, 2), not bit for bit: f is evaluated on arrays of other lengths in the two runs (numpy's
    # SIMD kernels may round an element differently), which moves a converged Newton root by about an ULP; a root
    # given another root's f, or left at a bisection midpoint, is off by orders of magnitude more
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)
    assert np.abs(got - root).max() < 1e-6 and calls["moving"] < calls["all"]
