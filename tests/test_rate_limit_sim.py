"""The simulator's velocity smoother: a limit R on the rate of change of the commanded yaw rate (docs/simulator.md).

Each period the smoother moves its output from its last output towards the new command by at most R·T
(Nav2's ``velocity_smoother``, open loop, at the controller's rate), from 0 at the start; the output then
takes the command's way to the motor (compute delay, dead time, plant gain). Checked against oracles that
share no stepping code with the engine:

* scipy's ``solve_ivp`` of the continuous dynamics with the VFF command, the smoother and the delayed
  piecewise-constant input written out in the test;
* `simulate_reference`, the per-robot loop with its own smoother;
* the runs without a limit: R = inf is the engine's code of before, and a limit that never binds changes
  nothing but round-off.
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pfm_stability.parameters import CARMEL, Robot
from pfm_stability.sim import make_scenario, run_batch, simulate_reference
from pfm_stability.sim.robot import slew_limit
from pfm_stability.sim.scenario import Pose
from trajectory_helpers import assert_same_to_roundoff

W, N_EXP = 0.8, 2.0


def _cases(seed=5):
    """Four plants (τ, T, k, D, g, V, d, R) drawn at random, R small enough that the start's turn is limited."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(4):
        T = rng.uniform(0.03, 0.15)
        out.append(dict(tau=rng.uniform(0.05, 0.5), T=T, k=rng.uniform(1.0, 4.0), D=(i % 2) * rng.uniform(0.2, 1.8) * T,
                        g=rng.uniform(0.6, 1.4), V=rng.uniform(0.3, 1.0), d=int(rng.integers(0, 2)), R=rng.uniform(0.3, 2.0)))
    return out


def _scenario(case, *, L, f, offset, heading, duration, max_rate=math.radians(120.0)):
    robot = Robot(V=case["V"], tau=case["tau"], k=case["k"], W=W, max_steering_rate=max_rate, dead_time=case["D"],
                  plant_gain=case["g"], yaw_accel_limit=case["R"])
    controller = CARMEL.controller.replace(T=case["T"], f=f, n=N_EXP, hold="command", compute_delay=case["d"])
    s = make_scenario("corridor", env="analytic", L=L, offset=offset, duration=duration, robot=robot, controller=controller)
    return replace(s, start=Pose(offset, 0.0, heading))


def _ivp_run(case, *, L, f, offset, heading, steps, max_rate):
    """(x, y, θ) at t_0 … t_steps, integrated by solve_ivp piece by piece (module docstring).

    u_k = clip(k·wrap(δ_k − θ_k), ±ω_max); the smoother v_k = v_(k−1) + clip(u_k − v_(k−1), ±R·T), v_(−1) = 0;
    the motor's input g·v_(k−m−1) over [t_k, t_k + ε) and g·v_(k−m) after, m and ε from d·T + D, v before t_0 = v_0.
    """
    tau, T, k, D, g, V, d, R = (case[key] for key in ("tau", "T", "k", "D", "g", "V", "d", "R"))
    m = d + math.floor(D / T)
    eps = D - math.floor(D / T) * T

    def rhs(_, s, v):
        theta, omega, _, _ = s
        return [omega, (v - omega) / tau, V * math.sin(theta), V * math.cos(theta)]

    state = np.array([heading, 0.0, offset, 0.0])
    out, smoothed, last = [state.copy()], [], 0.0
    for j in range(steps):
        theta, _, x, _ = state
        fx = -f * (W / (L - x)) ** N_EXP + f * (W / (L + x)) ** N_EXP
        wrapped = (math.atan2(fx, 1.0) - theta + math.pi) % (2 * math.pi) - math.pi
        u = min(max(k * wrapped, -max_rate), max_rate)
        last += min(max(u - last, -R * T), R * T)
        smoothed.append(last)
        before, after = smoothed[max(j - m - 1, 0)], smoothed[max(j - m, 0)]
        for length, v in ((eps, before), (T - eps, after)):
            if length > 0:
                state = solve_ivp(rhs, (0.0, length), state, args=(g * v,), method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
        out.append(state.copy())
    out = np.array(out)
    return out[:, 2], out[:, 3], out[:, 0]


def test_runs_equal_solve_ivp_with_the_smoother():
    """Four random plants with a limit R (0.3–2 rad/s²), dead times within and beyond a period, both compute delays:
    x, y, θ at every sample equal solve_ivp's to 1e-8 of V·T.

    Started 0.3 m off centre in a 2 m corridor with heading 0.3 rad, so the first commands jump by more than R·T and
    the smoother ramps them (checked: the oracle's smoother binds in every case); 30 periods. DOP853 at rtol 1e-13
    resolves each constant-input piece; the engine's own error is ~1e-10 of V·T at worst (docs/simulator.md). A
    smoother that ramped from the first command instead of 0, or sat after the delay line's start rule, moves the
    robot by ~R·T·T·V ≫ 1e-8·V·T.
    """
    cases = _cases()
    steps, L, f, offset, heading = 30, 2.0, 0.5, 0.3, 0.3
    scenarios = [_scenario(c, L=L, f=f, offset=offset, heading=heading, duration=steps * c["T"]) for c in cases]
    for c, run in zip(cases, run_batch(scenarios).runs):
        x, y, theta = _ivp_run(c, L=L, f=f, offset=offset, heading=heading, steps=steps, max_rate=math.radians(120.0))
        step = c["V"] * c["T"]
        label = ", ".join(f"{key}={value:.3g}" for key, value in c.items())
        assert not run.events, label
        assert np.max(np.hypot(run.trajectory.x - x, run.trajectory.y - y)) <= 1e-8 * step, label
        assert np.max(np.abs(run.trajectory.theta - theta)) <= 1e-8 * step / W, label
        assert c["k"] * heading > c["R"] * c["T"]  # the first command is more than one period's change: the smoother binds


def test_reference_loop_equals_the_engine():
    """`simulate_reference` (the per-robot loop, its own smoother in Python floats) equals the engine to 1e-11 m, in a
    batch that mixes a limited grid corridor growing into a collision, a limited analytic member with a dead time and a
    member without a limit."""
    limited = CARMEL.robot.replace(yaw_accel_limit=0.8)
    members = [make_scenario("corridor", env="grid", L=0.6, offset=0.05, robot=limited.replace(V=1.1), duration=30.0),
               make_scenario("corridor", env="analytic", L=0.9, offset=0.2, duration=15.0,
                             robot=limited.replace(dead_time=0.09, plant_gain=0.8, yaw_accel_limit=1.7)),
               make_scenario("corridor", env="analytic", L=0.9, offset=0.2, duration=15.0)]
    batch = run_batch(members)
    for s, run in zip(members, batch.runs):
        trajectory, event = simulate_reference(s)
        for name in ("x", "y", "theta"):
            assert np.allclose(getattr(run.trajectory, name), getattr(trajectory, name), atol=1e-11, rtol=0), name
        assert (event is None) == (not run.events)
    assert batch.runs[0].collided


def test_without_a_limit_the_runs_of_before():
    """R = inf runs the code of before: an unlimited member in a batch with limited ones equals its run in a batch without
    any to round-off; and a limit that never binds (a 1e-4 m start, where every change is far below R·T) gives the
    unlimited run to round-off (`trajectory_helpers.assert_same_to_roundoff`), while one that binds does not."""
    plain = make_scenario("corridor", env="analytic", L=0.9, offset=0.1, duration=20.0)
    limited = replace(plain, robot=plain.robot.replace(yaw_accel_limit=0.5))
    alone, mixed = run_batch([plain]).runs[0], run_batch([limited, plain]).runs[1]
    assert_same_to_roundoff(mixed.trajectory, alone.trajectory, 0.0, "unlimited member beside a limited one")
    small = replace(plain, start=Pose(1e-4, 0.0, 0.0))
    runs = run_batch([small, replace(small, robot=small.robot.replace(yaw_accel_limit=0.5))]).runs
    assert_same_to_roundoff(runs[1].trajectory, runs[0].trajectory, max(runs[0].metrics.growth_rate, 0.0), "limit never binding")
    binding = run_batch([limited]).runs[0].trajectory  # (it grows into a wall: 0.5 rad/s² is far too slow for CARMEL)
    n = binding.x.size
    assert np.max(np.abs(binding.x - alone.trajectory.x[:n])) > 1e-3


def test_slew_limit_is_nav2s_open_loop_rule():
    """`slew_limit` is Nav2's ``applyConstraints`` with accel = decel: v + clip(u − v, ±R·T) (its value on hand-worked
    numbers, and inf passes the command through, to round-off)."""
    previous, command = np.array([0.0, 0.5, -0.2, 1.0]), np.array([1.0, 0.4, -1.0, -1.0])
    assert np.allclose(slew_limit(previous, command, np.full(4, 0.3)), [0.3, 0.4, -0.5, 0.7], atol=1e-15)
    # v + (u − v) is u to round-off only (two roundings of numbers below 1): 2 ULP of 1; a limit that binds moves it by ≥ 0.1 here
    np.testing.assert_allclose(slew_limit(previous, command, np.full(4, np.inf)), command, rtol=0, atol=2 * np.finfo(float).eps)


def test_a_limit_with_a_servo_is_refused():
    """A servo (``hold="reference"``) closes k(δ − θ) continuously: there is no sequence of commands to smooth; one line
    naming both."""
    with pytest.raises(ValueError, match=r"yaw_accel_limit needs hold=command .* got 2.0 rad/s\^2"):
        make_scenario("corridor", robot=CARMEL.robot.replace(yaw_accel_limit=2.0), controller=CARMEL.controller.replace(hold="reference"))
