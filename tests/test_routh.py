"""Routh–Hurwitz and Schur–Cohn tests (module `pfm_stability.numerics.routh`).

The Routh count is checked against `numpy.roots` on random polynomials
(degree 1–8, skip roots within 1e-9 of the axis) and on the textbook
special cases; KB eq (19) → (20) is checked symbolically.
"""

import numpy as np
import pytest
import sympy as sp
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from pfm_stability.numerics.routh import routh_array, routh_count, routh_stable, schur_cohn_stable

coefficient = st.floats(min_value=-10, max_value=10, allow_nan=False, allow_infinity=False)


@pytest.mark.slow  # seconds: scheduled first (tests/conftest.py)
@settings(max_examples=400, deadline=None)
@given(st.lists(coefficient, min_size=2, max_size=9))
def test_sign_changes_equal_rhp_root_count(coefficients):
    """Routh (1877): sign changes in the first column = roots with Re s > 0."""
    assume(abs(coefficients[0]) > 1e-3)
    roots = np.roots(coefficients)
    scale = max(1.0, float(np.max(np.abs(roots))))
    assume(np.all(np.abs(roots.real) > 1e-9 * scale))
    # a (near-)zero row means roots symmetric about the origin: the count is
    # only exact for the roots off the axis, so such draws are skipped
    result = routh_array(coefficients)
    assume(not result.marginal)
    assert result.sign_changes == int(np.sum(roots.real > 0))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.complex_numbers(max_magnitude=5, allow_nan=False, allow_infinity=False), min_size=1, max_size=6))
def test_routh_count_on_polynomials_built_from_roots(roots):
    """Real polynomials with known roots (conjugate pairs added): count Re > 0 exactly."""
    roots = [r for r in roots if abs(r.real) > 1e-3]
    assume(roots)
    full = np.concatenate([roots, np.conj([r for r in roots if abs(r.imag) > 1e-12])])
    poly = np.real(np.poly(full))
    assert routh_count(poly) == int(np.sum(full.real > 0))


@pytest.mark.parametrize(
    "coefficients, rhp, marginal, epsilon",
    [
        ([1, 2, 3, 4], 0, False, False),  # Routh: 2·3 > 4 → stable
        ([1, 1, 4, 4], 0, True, False),  # (s + 1)(s² + 4): pair on the axis → zero row
        ([1, 0, 3, 4], 2, False, True),  # zero in the first column (ε method): roots 0.5 ± 1.94j, −1
        ([1, 1, 2, 2, 3], 2, False, True),  # s⁴ + s³ + 2s² + 2s + 3: zero first-column entry, 2 RHP roots
        ([1, 2, 24, 48, -25, -50], 1, True, False),  # Ogata's zero-row example: roots ±1, ±5j, −2
        ([-4.0, 2.2250738585072014e-308, -1.0, 0.0, 0.0, 3.7e-207, 0.0, 1.0], 3, False, False),  # subnormal pivot → exact arithmetic (found by hypothesis)
        ([-9.0, 1e-13, 1.0, 1e-13, 0.0, 1.0], 3, False, False),  # tiny but genuine pivots (found by hypothesis)
        ([1.0, 8.996531936802499e-90, 2.0, -1.0, 0.0, 0.0, 0.0, 1.0], 2, False, False),  # 1e-90 pivot, 1/ε-sized rows (found by hypothesis)
    ],
)
def test_textbook_special_cases(coefficients, rhp, marginal, epsilon):
    """Zero-in-first-column and zero-row cases (Ogata, Modern Control Engineering §5-6)."""
    result = routh_array(coefficients)
    assert result.sign_changes == rhp == int(np.sum(np.roots(coefficients).real > 1e-12))
    assert result.marginal is marginal
    assert result.epsilon_used is epsilon
    assert routh_stable(coefficients) is (rhp == 0 and not marginal and not epsilon)


def test_symbolic_routh_of_kb_eq19_gives_eq20():
    """KB eq (19) → (20): the s¹ entry of the Routh array is k(1 − NV(τ + T))/1·(…) > 0."""
    tau, k, N, V, T = sp.symbols("tau k N V T", positive=True)
    result = routh_array([tau, sp.Integer(1), k * (1 - N * V * T), k * N * V])
    s1 = result.first_column[2]
    assert sp.simplify(s1 - k * (1 - N * V * (tau + T))) == 0
    assert sp.simplify(result.first_column[3] - k * N * V) == 0


def test_symbolic_zero_first_column_uses_epsilon_limit():
    """s³ + 3s + 4 given symbolically: the ε-substitution and its limit count 2 RHP roots."""
    result = routh_array([sp.Integer(1), sp.Integer(0), sp.Integer(3), sp.Integer(4)])
    assert result.sign_changes == 2


@settings(max_examples=300, deadline=None)
@given(st.lists(coefficient, min_size=2, max_size=9))
def test_schur_cohn_matches_root_moduli(coefficients):
    """Schur–Cohn: all roots inside the unit circle ⇔ max |z| < 1 (skip |z| within 1e-9 of 1)."""
    assume(abs(coefficients[0]) > 1e-3)
    radius = np.max(np.abs(np.roots(coefficients)))
    assume(abs(radius - 1.0) > 1e-9)
    assert schur_cohn_stable(coefficients) == bool(radius < 1.0)


def test_bad_input_is_a_value_error():
    with pytest.raises(ValueError, match="non-zero coefficient"):
        routh_array([0.0, 0.0])
    with pytest.raises(ValueError, match="finite"):
        routh_array([1.0, float("nan")])
