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
