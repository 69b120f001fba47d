"""Polynomial loop models: continuous (KB 17), kb_first_order (19–20), pade (18 + Padé).

Every critical gain is checked by a route other than the one that computed it:
the roots of the characteristic polynomial on both sides of the boundary.
"""

import math

import numpy as np
import pytest

from conftest import random_loops
from pfm_stability.numerics.crossings import affine_crossings, first_stable_interval
from pfm_stability.models import MODEL_NAMES, Continuous, ExactDelay, KBFirstOrder, Loop, Pade, make_model, pade_coefficients

control = pytest.importorskip("control")


@pytest.mark.parametrize("m", range(1, 13))
@pytest.mark.parametrize("T", [0.0, 0.065, 1.0, 3.0])
def test_pade_coefficients_equal_python_control(m, T):
    """Golub & Van Loan closed form = python-control's `pade` (to 1e-12 relative)."""
    num, den = pade_coefficients(T, m)
    ref_num, ref_den = control.pade(T, m)
    np.testing.assert_allclose(num, ref_num, rtol=1e-12, atol=0)
    np.testing.assert_allclose(den, ref_den, rtol=1e-12, atol=0)


@pytest.mark.parametrize("tau, T, k, K", random_loops(12, seed=3))
def test_pade_converges_to_exact_delay(tau, T, k, K):
    """K*(Padé m) → K*(exact) as m grows: error below 1e-8 relative by m = 8 and
    never larger at m = 8 than at m = 1 (Padé(m,m) matches e^(−sT) to O(s^(2m+1)))."""
    loop = Loop(tau, T, k)
    exact = ExactDelay().boundary(loop).NV_critical
    errors = [abs(Pade(m).boundary(loop).NV_critical / exact - 1) for m in (1, 2, 4, 8)]
    assert errors[-1] < 1e-8
    assert errors[-1] <= errors[0]


def test_pade_order_one_differs_from_kb_first_order(carmel_loop):
    """Padé(1,1) is all-pass, KB's 1 − sT is not: their NV* differ, and for
    CARMEL Padé(1,1) is the closer one to the exact delay."""
    exact = ExactDelay().boundary(carmel_loop).NV_critical
    pade1 = Pade(1).boundary(carmel_loop).NV_critical
    kb = KBFirstOrder().boundary(carmel_loop).NV_critical
    assert abs(pade1 - kb) > 1e-3 * kb
    assert abs(pade1 - exact) < abs(kb - exact)


@pytest.mark.parametrize("tau, T, k, K", random_loops(20, seed=5))
def test_closed_forms_of_continuous_and_kb(tau, T, k, K):
    """(17): NV* = 1/τ, ω* = √(k/τ). (19)–(20): NV* = 1/(τ+T), ω* = √(k/(τ+T)),
    whatever k. The generic crossing computation must reproduce both (1e-10)."""
    loop = Loop(tau, T, k)
    c = Continuous().boundary(loop)
    assert c.NV_critical == pytest.approx(1 / tau, rel=1e-10)
    assert c.omega_critical == pytest.approx(math.sqrt(k / tau), rel=1e-10)
    kb = KBFirstOrder().boundary(loop)
    assert kb.NV_critical == pytest.approx(1 / (tau + T), rel=1e-10)
    assert kb.omega_critical == pytest.approx(math.sqrt(k / (tau + T)), rel=1e-10)


@pytest.mark.parametrize("name", MODEL_NAMES)
@pytest.mark.parametrize("tau, T, k, K", random_loops(8, seed=9))
def test_verdict_flips_at_the_boundary(name, tau, T, k, K):
    """Every model: stable at 0.999·NV*, unstable at 1.001·NV*, by its own
    independent verdict (Routh, crossing count, eigenvalues); the rightmost root
    at NV* has real part ≈ 0 (|σ| < 1e-6·|ω*|). Where the model says NV* = 0 with an
    empty stable set (the sampled command hold at large kT: docs/models.md), the
    same independent verdict must find no stable NV from 1e-4 to 1e3 1/s either, and
    the rightmost root must lie in the right half-plane."""
    model = make_model(name, pade_order=4, hold="command", compute_delay=0)
    loop = Loop(tau, T, k)
    b = model.boundary(loop)
    assert math.isfinite(b.NV_critical), "every model of this set is bounded (tau > 0, T > 0)"
    if b.NV_critical == 0:
        assert b.stable_set == ()
        for NV in np.geomspace(1e-4, 1e3, 29):
            assert not model.is_stable(NV, loop)
            assert model.rightmost_root(NV, loop).real > 0
        return
    assert model.is_stable(0.999 * b.NV_critical, loop)
    assert not model.is_stable(1.001 * b.NV_critical, loop)
    root = model.rightmost_root(b.NV_critical, loop)
    assert abs(root.real) < 1e-6 * max(1.0, abs(root.imag))
    assert abs(abs(root.imag) - b.omega_critical) < 1e-6 * b.omega_critical


@pytest.mark.parametrize("tau, T, k, K", random_loops(10, seed=21))
def test_polynomial_boundary_matches_root_scan(tau, T, k, K):
    """The first crossing gain of D + K·E equals the first K on a fine geometric
    grid where numpy.roots finds Re s > 0 (grid ratio 1.001 → 1e-3 tolerance)."""
    d, e = Pade(3).polynomials(Loop(tau, T, k))
    star = first_stable_interval(d, e, "s").gain
    grid = np.geomspace(star / 3, star * 3, 2200)
    unstable = [np.max(np.roots(np.polyadd(d, g * np.asarray(e))).real) > 0 for g in grid]
    first = grid[np.argmax(unstable)]
    assert first == pytest.approx(star, rel=1.1e-3)


def test_tau_zero_and_T_zero_are_defined():
    """τ = 0: continuous is stable for all NV (NV* = inf); KB gives 1/T; T = 0: every model equals continuous."""
    loop = Loop(0.0, 0.05, 2.0)
    assert math.isinf(Continuous().boundary(loop).NV_critical)
    assert KBFirstOrder().boundary(loop).NV_critical == pytest.approx(20.0)
    both_zero = Loop(0.0, 0.0, 2.0)
    for name in MODEL_NAMES:
        assert math.isinf(make_model(name).boundary(both_zero).NV_critical)
    no_delay = Loop(0.3, 0.0, 2.0)
    for name in MODEL_NAMES:
        assert make_model(name).boundary(no_delay).NV_critical == pytest.approx(1 / 0.3, rel=1e-9)


def test_crossings_lie_on_the_imaginary_axis():
    """Every crossing (K, ω) of D + K·E makes jω a root (residual ≤ 1e-9 of the terms)."""
    d, e = Pade(5).polynomials(Loop(0.4, 0.3, 3.0))
    crossings = affine_crossings(d, e, "s")
    assert len(crossings) >= 2
    for c in crossings:
        value = np.polyval(np.polyadd(d, c.gain * np.asarray(e)), 1j * c.frequency)
        scale = np.polyval(np.abs(np.polyadd(d, c.gain * np.asarray(e))), c.frequency)
        assert abs(value) < 1e-9 * scale


def test_invalid_model_options():
    with pytest.raises(ValueError, match="model must be one of"):
        make_model("banana")
    with pytest.raises(ValueError, match=r"pade_order must be an integer in \[1, 12\]"):
        Pade(0)
    with pytest.raises(ValueError, match="NV must be a finite number"):
        Continuous().is_stable(float("nan"), Loop(0.3, 0.0, 1.0))
    with pytest.raises(ValueError, match="tau must be a finite number"):
        Loop(-1.0, 0.0, 1.0)
