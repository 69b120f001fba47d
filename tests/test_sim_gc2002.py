"""Ge & Cui 2002's simulations (GC2002 Figs 8, 10–12, eq 23 and the velocity-gated wall) with the planar simulator.

Reference numbers are the closed forms of `pfm_stability.models.tracking` and `velocity_laws`
and figures recomputed independently (docs/velocity_and_fuzzy.md); each tolerance is the
sampling error of the period used, stated per test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfm_stability.sim.cycles import wall_cycle
from pfm_stability.sim.movers import Ball, Target
from pfm_stability.sim.planar import (
    Field,
    PointMass,
    Start,
    Steering,
    World,
    simulate_planar,
)
from pfm_stability.models.tracking import tracking_dynamics
from pfm_stability.laws.velocity_laws import (
    VelocityAttraction,
    VelocityGatedRepulsion,
    stall_band,
)

TARGET = Target((10.0, 10.0), (0.1, -0.05))


def _track(attraction, T, duration):
    return simulate_planar(PointMass(1.0), Field(attraction), World(TARGET), T=T, duration=duration, start=Start((1.0, 1.0)))


def _error(run):
    return np.array(TARGET.position) + run.t[:, None] * np.array(TARGET.velocity) - run.p


def _first_within(run, radius):
    """First time ‖e‖ <= radius, interpolated linearly between samples (s), or None."""
    r = np.hypot(*_error(run).T)
    i = np.flatnonzero(r <= radius)
    if i.size == 0:
        return None
    k = int(i[0])
    return float(run.t[k - 1] + run.T * (r[k - 1] - radius) / (r[k - 1] - r[k]))


def test_fig8_critical_damping_error_at_50s_matches_closed_form():
    """ζ = 1 (α_p = 0.005, α_v = 0.1): e(50 s) = (0.397539, 0.347004) by `tracking` and by simulation.

    The force is held over T = 0.01 s (ZOH): the simulated error differs from the continuous
    closed form by O(T), measured 1.9e-4 m (4.7e-4 relative); tolerance 1e-3 relative.
    """
    run = _track(VelocityAttraction(0.005, 0.1), 0.01, 50.0)
    closed = tracking_dynamics(0.005, 0.1).error(50.0, np.array([9.0, 9.0]), np.array([0.1, -0.05]))
    assert np.allclose(closed, [0.397539, 0.347004], atol=1e-6)
    assert np.allclose(_error(run)[-1], closed, rtol=1e-3, atol=0)


@pytest.mark.parametrize("alpha_v, expected", [(0.02, 145.46), (0.1, 69.46), (0.2, 183.94)])
def test_fig8_first_time_within_10cm(alpha_v, expected):
    """ζ = 0.2 / 1 / 2: first ‖e‖ <= 0.1 m at 145.46 / 69.46 / 183.94 s (T = 0.02 s).

    The hold shifts the response by about T/2 = 0.01 s; tolerance 0.1 s (0.07 %–0.15 %).
    """
    run = _track(VelocityAttraction(0.005, alpha_v), 0.02, expected + 2.0)
    assert _first_within(run, 0.1) == pytest.approx(expected, abs=0.1)


def test_fig8_undamped_error_stays_in_its_band():
    """ζ = 0: ‖e‖ oscillates within [1.0602, 12.7329] m (period 62.83 s), never within 0.1 m.

    A ZOH of an undamped oscillator grows by σ ≈ ω_n²T/4 = 2.5e-5 1/s at T = 0.01 s (0.2 %
    over the 70 s run); tolerance 0.5 %.
    """
    run = _track(VelocityAttraction(0.005, 0.0), 0.01, 70.0)
    r = np.hypot(*_error(run).T)
    assert r.min() == pytest.approx(1.0602, rel=5e-3)
    assert r.max() == pytest.approx(12.7329, rel=5e-3)


def test_fig10_larger_m_reaches_1m_sooner():
    """Fig 10 (n = 2, α_p = 0.005, α_v = 0.2): ‖e‖ <= 1 m at 274.6 / 98.0 / 6.3 s for m = 1.5 / 2 / 3.

    T = 0.05 s (0.005 s for m = 3, whose fast start moves the crossing by 1.3 % at 0.05 s); the
    crossing times move by O(T) and the m = 1.5 approach is a slow crawl; tolerance 1 %.
    """
    times = []
    for m, expected, T in ((1.5, 274.6, 0.05), (2.0, 98.0, 0.05), (3.0, 6.3, 0.005)):
        run = _track(VelocityAttraction(0.005, 0.2, m=m), T, expected + 3.0)
        times.append(_first_within(run, 1.0))
        assert times[-1] == pytest.approx(expected, rel=1e-2)
    assert times[0] > times[1] > times[2]


def test_fig11_larger_n_is_quicker():
    """Fig 11 (m = 2, α_p = 0.005, α_v = 0.2): ‖e‖ <= 1 m at 98.0 s for n = 2 and 39.1 s for n = 3 (T = 0.05 s, 1 %)."""
    t2 = _first_within(_track(VelocityAttraction(0.005, 0.2, n=2.0), 0.05, 100.0), 1.0)
    t3 = _first_within(_track(VelocityAttraction(0.005, 0.2, n=3.0), 0.05, 42.0), 1.0)
    assert t2 == pytest.approx(98.0, rel=1e-2) and t3 == pytest.approx(39.1, rel=1e-2) and t3 < t2


def test_fig12_hard_landing_closing_speed():
    """Fig 12 (m = 1, n = 2, α_p = 0.05, α_v = 0.4): the closing speed −d‖e‖/dt tends to α_p/(2α_v) = 0.0625 m/s.

    `VelocityAttraction.hard_landing_speed` gives it in closed form; the simulated closing speed at
    t = 150 s (the angular momentum has decayed as e^(−2α_v t)) agrees to 1 % (T = 0.05 s).
    """
    att = VelocityAttraction(0.05, 0.4, m=1.0, n=2.0)
    assert att.hard_landing_speed() == pytest.approx(0.0625, rel=1e-12)
    run = _track(att, 0.05, 150.0)
    r = np.hypot(*_error(run).T)
    closing = -(r[-1] - r[-21]) / (run.t[-1] - run.t[-21])
    assert closing == pytest.approx(0.0625, rel=1e-2)


# --------------------------------------------------------------- eq (23)


def _eq23(v0, variant, a_max, duration=40.0, T=0.02):
    rep = VelocityGatedRepulsion(0.2, 2.0, a_max, variant=variant)
    world = World(Target((0.0, 0.0)), (Ball((0.8, 0.0), 0.3),))
    return simulate_planar(PointMass(), Field(VelocityAttraction(0.005, 0.1), rep), world, T=T, duration=duration,
                           start=Start((-1.5, 0.0), (v0, 0.0)))


@pytest.mark.parametrize("variant, a_max, v_min", [("paper_eq23", 0.5, 0.330), ("paper_eq23", 2.0, 0.322), ("squared", 1.0, 0.956)])
def test_eq23_minimal_landing_speed_and_stall_band(variant, a_max, v_min):
    """1-D runs of eq (23): 2 % above the minimal speed the robot reaches the target, 2 % below it stalls in the band.

    Readings C (``paper_eq23``: 0.330 / 0.322 m/s at a_max = 0.5 / 2) and B (``squared``: 0.956 at
    a_max = 1). At T = 0.02 s the sampled threshold moves by < 1 % (measured at T = 0.01 s:
    landing at +1 %, stall at −1 %), hence ±2 %. The stalled robot rests (|v| < 1e-3 m/s)
    inside `velocity_laws.stall_band` (C: (−0.35650, 0), B: (−0.90344, 0)).
    """
    band = stall_band(VelocityGatedRepulsion(0.2, 2.0, a_max, variant=variant), VelocityAttraction(0.005, 0.1), 0.5)
    (lo, hi), = band.intervals
    land = _eq23(1.02 * v_min, variant, a_max)
    assert land.p[:, 0].max() >= 0.0 and not land.collision
    stall = _eq23(0.98 * v_min, variant, a_max)
    assert stall.p[:, 0].max() < 0.0 and not stall.collision
    assert lo <= stall.p[-1, 0] <= hi and abs(stall.v[-1, 0]) < 1e-3


def test_eq23_stall_band_edges():
    """The bands of the three readings at a_max = 1: A the whole influence region (−1.5, 0), B (−0.90344, 0), C (−0.35650, 0)."""
    att = VelocityAttraction(0.005, 0.1)
    edges = [stall_band(VelocityGatedRepulsion(0.2, 2.0, 1.0, variant=v), att, 0.5).intervals[0][0] for v in ("gradient", "squared", "paper_eq23")]
    assert edges == pytest.approx([-1.5, -0.90344, -0.35650], abs=1e-5)


def test_eq23_fast_start_is_undefined_at_once():
    """v0 >= 1.42 m/s at a_max = 0.5: D = 2 − v0² <= 0 at t = 0, a ``collision_unavoidable`` event, no NaN; 1.40 m/s is defined."""
    fast = _eq23(1.42, "paper_eq23", 0.5, duration=1.0)
    assert fast.stop_reason == "collision_unavoidable" and fast.events[0].time == 0.0
    assert np.all(np.isfinite(fast.force))
    slower = _eq23(1.40, "paper_eq23", 0.5, duration=0.1)
    assert slower.first_event("collision_unavoidable") is None or slower.first_event("collision_unavoidable").time > 0.0


# ------------------------------------------------------- velocity-gated wall

REPULSION = VelocityGatedRepulsion(0.1, 2.0, 1.0)
ALPHA = math.radians(60.0)


def test_holonomic_robot_rests_inside_filippov_band():
    """A point mass at a velocity-gated wall (η = 0.1, F_a = 1, α = 60°) comes to rest inside d <= d_s = √(η/(F_a cos α)) = 0.4472 m.

    Without compute delay the sampled relay's chatter is 0.6 mm; with one sample of delay
    5 mm, within its sampling-chatter bound (`cycles.REST_TOLERANCE`).
    """
    d_s = REPULSION.non_smooth_wall(1.0, ALPHA).d_s
    assert d_s == pytest.approx(0.4472, abs=1e-4)
    for delay in (0, 1):
        c = wall_cycle(REPULSION, 1.0, ALPHA, PointMass(), T=0.065, compute_delay=delay, duration=60.0)
        assert c.at_rest and c.period is None and c.heading_amplitude is None
        assert 0.0 < c.min_distance and c.mean_distance + c.peak_to_peak < d_s and not c.touches_wall


def test_steering_relay_limit_cycle():
    """KB's robot (V = 0.8, τ = 0.3, k = 2, T = 0.065 s, held command) at the same wall: a relay limit cycle.

    The cycle stays inside the rest band (mean d < d_s), never touches the wall, and grows with
    the loop delay: one sample of compute delay gives 0.09 m peak-to-peak, 0.23 rad, period 1.26 s
    (simulated; docs/simulator.md compares these with the published runs), against 0.01 m,
    0.05 rad without it. Halving T shrinks the cycle (to 0.21 of its peak-to-peak, measured): it
    is a sampling artefact of the relay, vanishing as T → 0.
    """
    robot = Steering(0.8, 0.3, 2.0, hold="command")
    one = wall_cycle(REPULSION, 1.0, ALPHA, robot, T=0.065, compute_delay=1, duration=40.0)
    none = wall_cycle(REPULSION, 1.0, ALPHA, robot, T=0.065, compute_delay=0, duration=40.0)
    half = wall_cycle(REPULSION, 1.0, ALPHA, robot, T=0.0325, compute_delay=1, duration=40.0)
    for c in (one, none, half):
        assert not c.at_rest and c.period is not None and not c.touches_wall and c.mean_distance < 0.4472
    assert one.peak_to_peak > 3 * none.peak_to_peak and one.heading_amplitude > 2 * none.heading_amplitude
    assert one.period == pytest.approx(1.26, rel=0.05) and one.heading_amplitude == pytest.approx(0.234, rel=0.05)
    assert half.peak_to_peak / one.peak_to_peak < 0.5
