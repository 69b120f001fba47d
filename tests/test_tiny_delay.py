"""A loop delay below `parameters.T_RESOLUTION` (1e-12 s) is a continuous controller, everywhere.

Regression: `plot rlocus --T 9.2e-252`, `plot gain-vs-k --T 2.2e-309` and
`report --T 1e-300` raised overflow warnings in the sampled model
(|λ|² of the δ-form poles) and in the exact-delay critical gain (the level
band π/T, the level frequency √(k/T)) instead of answering. The answer must
be the T = 0 answer exactly (same floats: the models see T = 0), from the
scalar models, the vectorized verdicts and the command line, with every
warning an error.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from pfm_stability.cli import main
from pfm_stability.models import Loop, make_model
from pfm_stability.parameters import MODEL_NAMES, T_RESOLUTION
from pfm_stability.vectorized import loop_verdicts

TINY = [5e-324, 2.2250738585072014e-309, 9.226837874867525e-252, 1e-100, 1e-13]


@pytest.mark.parametrize("T", TINY)
def test_loop_stores_a_tiny_delay_as_zero(T):
    """Loop(τ, T, k) with T < 1e-12 s has T = 0; at the resolution itself T is kept."""
    assert Loop(0.3, T, 2.0).T == 0.0
    assert Loop(0.3, T_RESOLUTION, 2.0).T == T_RESOLUTION


@pytest.mark.parametrize("T", TINY)
@pytest.mark.parametrize("name", MODEL_NAMES)
def test_every_model_answers_a_tiny_delay_as_the_continuous_loop(name, T):
    """NV* and the verdict at NV = 2 equal those at T = 0 (same floats), with warnings as errors."""
    model = make_model(name, hold="command", compute_delay=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tiny, zero = model.boundary(Loop(0.3, T, 2.0)), model.boundary(Loop(0.3, 0.0, 2.0))
        assert tiny.NV_critical == zero.NV_critical
        assert model.is_stable(2.0, Loop(0.3, T, 2.0)) == model.is_stable(2.0, Loop(0.3, 0.0, 2.0))


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_vectorized_verdicts_take_a_tiny_delay_as_zero(name):
    """`loop_verdicts` at tiny T equals `loop_verdicts` at T = 0 (all columns), with warnings as errors.

    Verdicts exactly; NV* and margins to 4 ULP (an array of T against a scalar T: numpy may take
    different SIMD paths for the two shapes)."""
    NV = np.array([0.5, 2.0, 3.0, 5.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tiny = loop_verdicts(name, 0.3, np.array(TINY[:4]), 2.0, NV)
        zero = loop_verdicts(name, 0.3, 0.0, 2.0, NV)
    assert np.array_equal(tiny.stable, zero.stable) and np.array_equal(tiny.verdict, zero.verdict)
    ulp4 = 4 * np.finfo(float).eps
    np.testing.assert_allclose(tiny.NV_critical, zero.NV_critical, rtol=ulp4, atol=0)
    np.testing.assert_allclose(tiny.margin, zero.margin, rtol=ulp4, atol=0)


@pytest.mark.parametrize("argv", [["plot", "rlocus"], ["plot", "gain-vs-k"]])
def test_plots_at_a_tiny_delay(tmp_path, capsys, argv):
    """The two command lines hypothesis found: exit 0 and a PNG, no warning."""
    out = tmp_path / "p.png"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        code = main([*argv, "--out", str(out), "--T", "9.226837874867525e-252"])
    assert code == 0, capsys.readouterr().err
    assert out.stat().st_size > 0


def test_report_at_a_tiny_delay_is_the_continuous_report(capsys):
    """`report --T 1e-300` gives every model's verdict and NV* of `report --T 0`."""
    answers = []
    for T in ("1e-300", "0"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert main(["report", "--alpha", "20", "--L", "0.9", "--T", T, "--format", "json"]) == 0
        answers.append(json.loads(capsys.readouterr().out))
    for env in ("wall", "corridor"):
        tiny, zero = (json.dumps(a[env], sort_keys=True) for a in answers)
        assert tiny == zero


@pytest.mark.parametrize("D", TINY)
@pytest.mark.parametrize("name", MODEL_NAMES)
def test_a_tiny_dead_time_is_none_in_every_model(name, D):
    """A dead time below 1e-12 s is stored as 0 (its Padé coefficients D^m would underflow: `report --door-obstacle posts
    --dead-time 2.2e-309` overflowed in the companion matrix, which the fuzzer found): NV* equals the loop's without a
    dead time (same floats), with warnings as errors."""
    model = make_model(name, hold="command", compute_delay=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tiny = model.boundary(Loop(0.3, 0.065, 2.0, plant_gain=0.8, dead_time=D))
        zero = model.boundary(Loop(0.3, 0.065, 2.0, plant_gain=0.8))
    assert Loop(0.3, 0.065, 2.0, dead_time=D).dead_time == 0.0 and tiny.NV_critical == zero.NV_critical


def test_the_report_the_fuzzer_found_with_a_tiny_dead_time(capsys):
    """`report --door-obstacle posts --dead-time 2.2e-309 --L 1.0` answers (exit 0), with warnings as errors."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["report", "--door-obstacle", "posts", "--dead-time", "2.225073858507203e-309", "--L", "1.0"]) == 0, capsys.readouterr().err


@pytest.mark.parametrize("T", TINY)
def test_holonomic_loop_stores_a_tiny_delay_as_zero(T):
    """HolonomicLoop(T, c_h) follows `Loop`: T < 1e-12 s is a continuous controller (T = 0), the resolution itself is kept."""
    from pfm_stability.models.holonomic import HolonomicLoop

    assert HolonomicLoop(T, 0.2).T == 0.0
    assert HolonomicLoop(T_RESOLUTION, 0.2).T == T_RESOLUTION


@pytest.mark.parametrize("T", [1e-12, 3e-12, 1e-9, 1e-6, 1e-3, 0.1])
def test_holonomic_damping_ranges_down_to_the_shortest_delay(T):
    """Every holonomic model's damping range at κ = 24 1/s² exists down to T = 1e-12 s (regression: Padé's ends, ~31/T,
    left the c_h range, and the exact-delay upper end failed to bracket where cos(π/2) rounds to 6e-17).

    Exact delay against an independent route: the ends are c = ω sin(ωT) at the two roots of ω² cos(ωT) = κ; for
    ωT well inside (0, π/2) scipy's brentq on that equation gives them (rel 1e-9), and for κT² < 1e-6 the asymptotes
    κT (1 + O(κT²)) and π/(2T) (1 + O(κT²)) hold (rel 1e-5)."""
    import math

    from scipy.optimize import brentq

    from pfm_stability.models.holonomic import HolonomicLoop
    from pfm_stability.models import make_model

    kappa = 24.0
    loop = HolonomicLoop(T, 0.2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in ("continuous", "kb_first_order", "pade", "exact_delay", "sampled"):
            (lo, hi), = make_model(name, pade_order=3, compute_delay=1).damping_range(kappa, loop)
            assert 0 <= lo < hi and (lo > 0 or name == "continuous"), name
        (lo, hi), = make_model("exact_delay").damping_range(kappa, loop)
    if kappa * T * T < 1e-6:
        assert lo == pytest.approx(kappa * T, rel=1e-5) and hi == pytest.approx(math.pi / (2 * T), rel=1e-5)
    else:
        g = lambda w: w * w * math.cos(w * T) - kappa  # noqa: E731
        peak = 1.0768739863118038 / T  # maximiser of u² cos u, u = ωT
        ends = [w * math.sin(w * T) for w in (brentq(g, 1e-12, peak, xtol=1e-300, rtol=1e-15),
                                              brentq(g, peak, 0.999999 * math.pi / (2 * T), xtol=1e-300, rtol=1e-15))]
        assert (lo, hi) == pytest.approx(tuple(ends), rel=1e-9)


@pytest.mark.parametrize("T", ["1e-12", "1e-9", "1e-6"])
def test_holonomic_report_at_tiny_delays(capsys, T):
    """report --robot holonomic at a delay of a picosecond to a microsecond answers (exit 0, no warning) with the
    pure-delay T* of the closed form atan2(c_h ω, κ)/ω, ω² = (c_h² + √(c_h⁴ + 4κ²))/2 (rel 1e-6: bisection tolerance)."""
    import math

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        code = main(["report", "--robot", "holonomic", "--law", "velocity", "--L", "0.5", "--eta", "0.3", "--rho0", "2",
                     "--alpha-v", "0.1", "--T", T, "--format", "json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0
    kappa, c_h = data["environment"]["corridor"]["kappa"], data["environment"]["corridor"]["c_h"]
    w = math.sqrt((c_h**2 + math.sqrt(c_h**4 + 4 * kappa**2)) / 2)
    assert data["corridor"]["exact_delay"]["T_critical"] == pytest.approx(math.atan2(c_h * w, kappa) / w, rel=1e-6)
