"""Oscillation metrics (docs/simulator.md, measuring oscillation) on signals whose σ and ω are known exactly."""

import json
import math

import numpy as np
import pytest

from pfm_stability.sim.metrics import HYSTERESIS, oscillation_metrics, turning_points

T = 0.065


def _t(duration=20.0):
    return np.arange(0, duration, T)


@pytest.mark.parametrize("sigma,omega", [(-0.3, 2.0), (0.15, 2.5), (-1.2, 1.1)])
def test_linear_prediction_recovers_a_sampled_damped_oscillation(sigma, omega):
    """x_k = e^(σkT)cos(ωkT + φ) + a slower mode + an offset is a linear recurrence: σ, ω exact to 1e-9.

    (Order-4 fit: the oscillating pair, one real mode, the offset constant.)
    """
    t = _t()
    x = 0.01 * np.exp(sigma * t) * np.cos(omega * t + 0.4) + 0.004 * np.exp(-3.0 * t) + 0.2
    m = oscillation_metrics(t, x, T, order=4)
    assert m.method == "linear_prediction"
    assert m.growth_rate == pytest.approx(sigma, abs=1e-9)
    assert m.angular_frequency == pytest.approx(omega, abs=1e-9)
    assert m.stable == (sigma < 0) and m.oscillating == (sigma > 0)


def test_peaks_estimate_when_the_signal_is_not_linear():
    """A sampled-peak fit of a noisy envelope: σ, ω within the phase quantization of the samples.

    The turning points are quantized to T, so the swing amplitudes carry
    |Δ ln a| ≲ 1 − cos(ωT/2) ≈ 0.7 % and the mean half-period ≲ T/(2·count);
    over 20 s that bounds |Δσ| ≲ 2e-3 1/s and |Δω|/ω ≲ 1 %.
    """
    t = _t()
    x = 0.05 * np.exp(0.1 * t) * np.cos(2.3 * t) + 1e-4 * np.sign(np.sin(37 * t))  # square-wave ripple: not linear
    m = oscillation_metrics(t, x, T, order=4)
    assert m.method == "peaks"
    assert m.growth_rate == pytest.approx(0.1, abs=2e-3)
    assert m.angular_frequency == pytest.approx(2.3, rel=1e-2)
    assert m.oscillating and not m.stable


def test_limit_cycle_is_detected_with_its_amplitude():
    """A constant-amplitude nonlinear oscillation (clipped sine, amplitude 0.1 m) is a limit cycle."""
    t = _t(30.0)
    x = np.clip(0.15 * np.sin(2.0 * t), -0.1, 0.1)
    m = oscillation_metrics(t, x, T)
    assert m.limit_cycle and m.oscillating and not m.stable
    assert m.amplitude == pytest.approx(0.1, rel=1e-3)


def test_undefined_cases_give_none_and_a_reason_never_nan():
    """Too few samples, or a growing drift with no oscillation, give σ = None with a reason; JSON has no NaN.

    A monotone settling (tanh) is a decay: σ < 0, stable, not oscillating.
    Too few samples is not stable (nothing measured), nor is a drift (not
    settling); a constant offset is (docs/simulator.md, measuring oscillation).
    """
    short = oscillation_metrics(_t()[:5], np.zeros(5), T)
    assert short.growth_rate is None and "fewer than" in short.reason and not short.stable
    t = _t()
    drift = oscillation_metrics(t, 0.01 * t**2, T)
    assert drift.growth_rate is None and drift.reason and not drift.oscillating and not drift.stable
    settle = oscillation_metrics(t, np.tanh(t / 5.0), T)
    assert settle.growth_rate < 0 and settle.stable and not settle.oscillating
    collided = oscillation_metrics(t, np.tanh(t / 5.0), T, collision_time=3.0)
    assert not collided.stable and collided.time_to_collision == 3.0
    for m in (short, drift, settle, collided):
        json.dumps(m.to_dict(), allow_nan=False)
    flat = oscillation_metrics(t, np.full(t.size, 0.3), T)
    assert flat.growth_rate is None and flat.stable


def test_non_finite_input_raises():
    t = _t()
    x = np.zeros(t.size)
    x[5] = math.nan
    with pytest.raises(FloatingPointError):
        oscillation_metrics(t, x, T)


def test_turning_points_ignore_ripple_below_the_hysteresis():
    """Zigzag: 6 half-periods of a sine → 6 turning points; a ripple below 1 % of the range adds none."""
    t = np.linspace(0, 3 * 2 * math.pi, 3000)
    x = np.sin(t) + 0.004 * np.sin(40 * t)
    assert turning_points(x, HYSTERESIS * 2.0).size == 6
