"""The general describing-function solver (analysis.describing) against python-control and closed forms."""

import math

import control
import numpy as np
import pytest
from scipy import integrate

from pfm_stability.analysis.describing import (
    describing_function,
    harmonic_balance,
    harmonic_content,
    saturation_df,
    saturation_df_for_output,
    sine_df,
)

AMPLITUDES = np.geomspace(1.01, 20.0, 300)
FREQUENCIES = np.geomspace(0.05, 50.0, 600)


def G(s):
    """python-control's documented example loop 8/(s³ + 2s² + 2s + 1)."""
    return 8.0 / (s**3 + 2 * s**2 + 2 * s + 1)


def test_python_control_example_closed_form():
    """8/(s³ + 2s² + 2s + 1) with a unit saturation: amplitude 3.344 at ω = √2 (python-control's documentation), to 1e-3.

    Independent route: G(j√2) = −8/3 (Im G = 0 there by hand), so N(A) = 3/8 and A solves the
    saturation's closed form; the documented 3.344 to 1e-3 in A, ω = √2 to 1e-9 (Newton's tolerance).
    """
    cycles = harmonic_balance(G, lambda A: saturation_df(A, 1.0), AMPLITUDES, FREQUENCIES)
    assert len(cycles) == 1
    cycle = cycles[0]
    assert cycle.amplitude == pytest.approx(3.344, abs=1e-3)
    assert cycle.omega == pytest.approx(math.sqrt(2.0), rel=1e-9)
    assert cycle.stable


def test_python_control_example_against_describing_function_response():
    """The same cycle from python-control's own solver (`describing_function_response` with `saturation_nonlinearity`),
    with the DF by our quadrature: both to 1e-3 (python-control interpolates on its amplitude grid; our
    trapezoid on 256 nodes carries the saturation kink's O(1/nodes²) error, 2e-5 in A)."""
    response = control.describing_function_response(control.tf([8], [1, 2, 2, 1]), control.saturation_nonlinearity(1),
                                                    np.linspace(1, 4, 60), omega=np.logspace(-1, 3, 400))
    (A_ct, w_ct), = response.intersections
    saturation = lambda x: np.clip(x, -1.0, 1.0)
    (cycle,) = harmonic_balance(G, lambda A: describing_function(saturation, A), AMPLITUDES, FREQUENCIES)
    assert cycle.amplitude == pytest.approx(A_ct, abs=1e-3)
    assert cycle.omega == pytest.approx(w_ct, abs=1e-3)


def test_quadrature_matches_python_control_describing_function():
    """`describing_function` of the saturation against python-control's (`control.describing_function`) at random amplitudes,
    to 2e-5 (the kink's trapezoid error with 256 nodes; python-control's own quadrature is not exact either)."""
    rng = np.random.default_rng(3)
    sat = control.saturation_nonlinearity(1.3)
    for A in rng.uniform(0.2, 30.0, 8):
        assert describing_function(lambda x: np.clip(x, -1.3, 1.3), A).real == pytest.approx(
            control.describing_function(sat, A).real, abs=2e-5)


def test_quadrature_is_exact_for_polynomials_and_smooth_laws():
    """x³ has N(A) = 3A²/4 exactly (the trapezoid on the circle integrates trigonometric polynomials exactly);
    sin x has 2J₁(A)/A (`sine_df`); a smooth odd law against scipy's adaptive quad of the definition, to 1e-12."""
    A = np.array([0.1, 1.0, 3.7])
    assert np.allclose(describing_function(lambda x: x**3, A).real, 0.75 * A**2, rtol=1e-14, atol=0)
    assert np.allclose(describing_function(np.sin, A).real, sine_df(A), rtol=1e-13)
    F = lambda x: np.tanh(2 * x) + 0.3 * x**5
    for a in (0.05, 0.8, 2.5):
        b1 = integrate.quad(lambda t: F(a * math.sin(t)) * math.sin(t), 0, 2 * math.pi, epsabs=1e-14, epsrel=1e-13)[0] / math.pi
        assert describing_function(F, a).real == pytest.approx(b1 / a, rel=1e-12)


def test_saturation_closed_form_and_its_inverse():
    """`saturation_df` against the quadrature (to 1e-6 with 8192 nodes); `saturation_df_for_output` inverts E·N(E) = U
    to 1e-12 at random E; U <= M gives 1, U >= 4M/π gives 0 (no input makes that fundamental)."""
    rng = np.random.default_rng(7)
    M = 0.7
    E = rng.uniform(0.1, 40.0, 50)
    assert np.allclose(saturation_df(E, M), describing_function(lambda x: np.clip(x, -M, M), E, nodes=8192).real, atol=1e-6)
    U = E * saturation_df(E, M)
    assert np.allclose(saturation_df_for_output(U, M), saturation_df(E, M), rtol=1e-12, atol=1e-12)
    assert saturation_df_for_output(0.5 * M, M) == 1.0
    assert saturation_df_for_output(4 * M / math.pi, M) == 0.0


def test_harmonic_content():
    """A relay's third harmonic is 1/3 of its fundamental (square wave: 4/π·(sin θ + sin 3θ/3 + …)), to 2e-3 (a jump: O(1/nodes));
    x³'s is exactly 1/3 (sin³θ = (3 sin θ − sin 3θ)/4); a linear F has none."""
    assert harmonic_content(np.sign, 1.0) == pytest.approx(1 / 3, abs=2e-3)
    assert harmonic_content(lambda x: x**3, 2.0) == pytest.approx(1 / 3, rel=1e-12)
    assert harmonic_content(lambda x: 2 * x, 2.0) == pytest.approx(0.0, abs=1e-14)


def test_loeb_test_dead_zone_cycle_is_unstable():
    """A dead zone of half-width 1 has N(A) = 1 − N_sat(A) rising with A, so the same loop's cycle (N = 3/8) is unstable
    (Slotine & Li §5.4: −1/N(A) enters the encircled region as A grows); the saturation's is stable.
    The amplitude solves the closed form 1 − N_sat(A) = 3/8 (scipy brentq) to 1e-9."""
    from scipy.optimize import brentq

    (cycle,) = harmonic_balance(G, lambda A: 1.0 - saturation_df(A, 1.0), AMPLITUDES, FREQUENCIES)
    assert not cycle.stable
    assert cycle.amplitude == pytest.approx(brentq(lambda A: 1 - saturation_df(A, 1.0) - 0.375, 1.0, 10.0, xtol=1e-14), rel=1e-9)


def test_bad_amplitude_is_refused():
    """A non-positive amplitude is a ValueError naming it, not a NaN."""
    with pytest.raises(ValueError, match="A > 0"):
        describing_function(np.sin, [1.0, 0.0])
    with pytest.raises(ValueError, match="two amplitudes"):
        harmonic_balance(G, sine_df, [1.0], FREQUENCIES)
