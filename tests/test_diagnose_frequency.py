"""The frequency `diagnose` measures (`pfm_stability.analysis.frequency`, docs/diagnose.md "The measured frequency").

The truth is known in closed form: a record e^(σt)·cos(ωt + φ) (the loop's dominant mode) plus a start transient
B·e^(−t/τ_t)·sin(Ωt + ψ) (the loop's faster modes, excited by a start off the centre line: Ω 3–6 ω, τ_t 5–20 % of a
period) and a constant offset, sampled every 0.1 s (diagnose's bins) with 0.5 mm of noise (the odometry's), over 2–3
periods: the short runs on which the turning points' estimate (`sim.metrics.oscillation_metrics`, what diagnose
reported) is 16–18 % high. Tolerances: the new estimate within 5 % of ω (the brief's target) in every such run; its
95 % interval holds ω in at least 90 % of them (a 95 % interval misses one run in twenty by design; 90 % leaves room
for the binomial spread of 30-odd runs: P(fewer than 90 %) < 0.1 at a true 95 %).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfm_stability.analysis.frequency import MIN_CROSSINGS, crossing_frequency, zero_crossings
from pfm_stability.analysis.stretches import LateralOffset
from pfm_stability.sim.metrics import oscillation_metrics
from pfm_stability.validation.diagnose import _measure

STEP, NOISE = 0.1, 0.0005


def record(rng: np.random.Generator, *, periods=(2.0, 3.0), transient: float = 2.0):
    """(t, x, ω) of one short run: the dominant mode, a start transient of relative size up to `transient`, noise."""
    w, sigma = rng.uniform(1.2, 3.5), rng.uniform(-0.15, 0.15)
    P = 2 * math.pi / w
    t = np.arange(0.0, rng.uniform(*periods) * P, STEP)
    fast, decay, B = rng.uniform(3, 6) * w, rng.uniform(0.05, 0.2) * P, transient * rng.uniform(-1, 1)
    x = 0.03 * (np.exp(sigma * t) * np.cos(w * t + rng.uniform(0, 2 * math.pi))
                + B * np.exp(-t / decay) * np.sin(fast * t + rng.uniform(0, 2 * math.pi)))
    return t, x + 0.003 * rng.uniform(-1, 1) + rng.normal(0.0, NOISE, t.size), w


@pytest.fixture(scope="module")
def short_runs():
    """The seeded runs whose turning-point estimate is 16–18 % high (the issue's failure), with both estimates."""
    rng = np.random.default_rng(5)
    rows = []
    for _ in range(1500):
        t, x, w = record(rng)
        old = oscillation_metrics(t, x, STEP).angular_frequency
        if old is not None and 0.16 <= old / w - 1 <= 0.18:
            rows.append((w, old, crossing_frequency(t, x)))
    return rows


def test_short_runs_with_a_start_transient_are_measured_within_5_percent(short_runs):
    assert len(short_runs) >= 20  # enough runs of the failure to say something
    errors = [abs(f.omega / w - 1) for w, _, f in short_runs]
    assert max(errors) <= 0.05, sorted(errors)[-5:]
    assert sum(f.dropped > 0 for _, _, f in short_runs) >= 1  # the transient's crossings were dropped somewhere


def test_the_stated_interval_holds_the_truth(short_runs):
    with_interval = [(w, f) for w, _, f in short_runs if not f.few_periods]
    assert len(with_interval) >= 0.9 * len(short_runs)
    held = sum(f.low <= w <= f.high for w, f in with_interval)
    assert held >= 0.9 * len(with_interval), (held, len(with_interval))
    assert all(f.low < f.omega < f.high for _, f in with_interval)


@pytest.mark.parametrize("sigma", [-0.2, 0.0, 0.15])
def test_a_clean_mode_is_its_frequency_and_its_centre(sigma):
    """Without transient or noise, about a centre of 7 mm: the crossings of e^(σt)·cos(ωt) are exactly π/ω apart, so ω is
    exact to the crossings' interpolation (linear between 0.1-s samples: 1e-3 relative) and nothing is dropped."""
    t = np.arange(0.0, 12.0, STEP)
    x = 0.007 + 0.02 * np.exp(sigma * t) * np.cos(2.1 * t + 0.4)
    f = crossing_frequency(t, x)
    assert f.omega == pytest.approx(2.1, rel=1e-3) and f.dropped == 0 and not f.few_periods
    assert f.low <= 2.1 <= f.high and f.centre == pytest.approx(0.007, abs=5e-4)
    assert f.crossings + f.dropped == zero_crossings(t, x, 0.007, 0.001).size  # every crossing of the mode (h below the last swing)


def test_a_start_transient_is_dropped():
    """A first half-swing twice as long as the rest (the robot drifting in from far off the centre line) is not part of
    the oscillation: its crossing is dropped and ω is the mode's."""
    t = np.arange(0.0, 14.0, 0.05)
    phase = np.where(t < 1.5, 0.5 * 2.0 * t, 2.0 * t - 1.5)  # half the speed of phase over the first 1.5 s
    x = 0.02 * np.cos(phase + math.pi / 2 - 0.3)
    f = crossing_frequency(t, x)
    assert f.dropped >= 1 and f.omega == pytest.approx(2.0, rel=0.01)
    assert f.established > 1.0


def test_too_few_periods_are_said_and_carry_no_interval():
    """One and a third periods hold three crossings, below `MIN_CROSSINGS`: ω from their spacing (one whole period, so
    the centre is right: 3 %, the crossings' interpolation), no interval, and diagnose's measurement says so (text
    and JSON)."""
    t = np.arange(0.0, 1.35 * 2 * math.pi / 2.0, STEP)
    x = 0.02 * np.sin(2.0 * t + 0.3)
    f = crossing_frequency(t, x)
    assert f.crossings < MIN_CROSSINGS and f.few_periods and f.low is None and f.high is None
    assert f.omega == pytest.approx(2.0, rel=0.03)
    _, measured, _ = _measure(LateralOffset(t, x, STEP, 0.9, t.size, STEP))
    d = measured.to_dict()
    assert d["frequency"]["few_periods"] is True and d["omega_interval"] is None
    from pfm_stability.cli.diagnose import _measured

    assert "too few periods" in _measured(measured)


def test_diagnose_measures_the_established_frequency(short_runs):
    """Diagnose's measurement of a stretch (`validation.diagnose._measure`) reports the crossings' ω and interval, not the
    turning points': on the issue's runs its ω is the truth's within 5 % where the old one was 16–18 % high."""
    rng = np.random.default_rng(5)
    checked = 0
    while checked < 5:
        t, x, w = record(rng)
        old = oscillation_metrics(t, x, STEP).angular_frequency
        if old is None or not 0.16 <= old / w - 1 <= 0.18:
            continue
        metrics, measured, _ = _measure(LateralOffset(t, x, STEP, 0.9, t.size, STEP))
        if measured.omega is None:  # no σ measured: nothing to compare
            continue
        assert metrics.angular_frequency == pytest.approx(old)
        assert measured.omega == pytest.approx(w, rel=0.05)
        assert measured.to_dict()["omega_interval"] is not None or measured.few_periods
        checked += 1


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="one length"):
        crossing_frequency(np.arange(3.0), np.arange(4.0))
    with pytest.raises(ValueError, match="finite"):
        crossing_frequency(np.arange(3.0), np.array([0.0, np.nan, 1.0]))
    f = crossing_frequency(np.arange(10.0), np.zeros(10))  # a constant: no crossing, no estimate
    assert f.omega is None and f.few_periods and f.crossings == 0


def test_a_swing_growing_into_the_walls_keeps_its_small_swings():
    """A growing oscillation whose period lengthens steadily by 3 % a period (a corridor run nearing the walls): no
    crossing is a start transient (each period is within 5 % of the next three), so ω is the whole run's mean rate of
    phase — not the large swings' alone (what comparing with all later periods measured: 5 % low on such a run)."""
    t = np.arange(0.0, 20.0, STEP)
    w0, drift = 3.0, 0.03 / (2 * math.pi / 3.0)  # ω falls by 3 % per period of 2π/3 s
    omega = w0 * (1 - drift * t)
    phase = np.cumsum(omega) * STEP
    x = 0.02 * np.exp(0.08 * t) * np.sin(phase)
    f = crossing_frequency(t, x)
    assert f.dropped == 0
    mean_rate = (phase[-1] - phase[0]) / (t[-1] - t[0])
    assert f.omega == pytest.approx(mean_rate, rel=0.01)
