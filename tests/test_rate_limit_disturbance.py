"""A disturbance of a given size with the drive's yaw acceleration limit: prediction against the simulator (docs/wobble.md).

`analysis.disturbance` reads the describing-function branch for a start D m off the centre line: the speed V*(D) at or
below which it settles (V* for a small start; lower where the limiter's lag bends the branch below V*), and what it
does at the robot's speed. `validation.disturbance.disturbance_boundary` bisects the same speed in the simulator with
the smoother (the runs share nothing with the prediction but the robot). Tolerances: 5 % on V*(D) — the measured
errors are 0–3 % (CARMEL, docs/wobble.md's table), the start's projection on the oscillatory mode being the largest
approximation — with the bisection's bracket (1.5 %) inside it.
"""

import math

import pytest

from pfm_stability.analysis.disturbance import corridor_disturbance
from pfm_stability.parameters import CARMEL, Controller, Robot
from pfm_stability.validation.disturbance import disturbance_boundary
from pfm_stability.validation.wobble import WobbleCase, case_law, simulate_wobbles

CARMEL_LIMITED = CARMEL.robot.replace(yaw_accel_limit=2.0)
NARROW = (Robot(V=1.0, tau=0.2, k=3.0, W=0.5, max_steering_rate=math.radians(150.0), dead_time=0.04, plant_gain=0.9, yaw_accel_limit=2.0),
          Controller(f=1.0, n=2.0, T=1 / 11, hold="command", compute_delay=1), 0.6)
"""A skid-steer-like robot in a narrow corridor (0.35 m of play): controller at 11 Hz with a period of compute delay, a
40 ms dead time and a 2 rad/s² smoother, as the issue's third robot."""


@pytest.mark.parametrize("robot, controller, L, D", [
    (CARMEL_LIMITED, CARMEL.controller, 0.9, 0.2),
    (*NARROW, 0.05),
])
def test_disturbance_boundary_against_the_simulator(robot, controller, L, D):
    """V*(D) of the branch within 5 % of the simulated one (module docstring); for CARMEL's 0.2 m start the simulated
    boundary lies more than 8 % below V* (the limiter's effect is real, not the method's). (A 1 cm start in the narrow
    corridor: V*(D) = V* to the bracket, measured in docs/wobble.md; not repeated here for time.)"""
    b = disturbance_boundary(D, robot=robot, controller=controller, L=L, members=6, rtol=0.015)
    assert b.predicted == pytest.approx(b.simulated, rel=0.05)
    if D == 0.2:
        assert b.hi < 0.92 * b.V_critical


def test_a_large_start_grows_below_v_star():
    """CARMEL with 2 rad/s² at 0.6 m/s (0.79·V*): the prediction says a 0.1 m start settles and a 0.3 m one grows into the
    wall (cycles exist below V*: the limiter's fold); the simulator, started at each, agrees."""
    law = case_law(WobbleCase(CARMEL_LIMITED, CARMEL.controller, 0.9, 0.0, 1.0))
    robot = CARMEL_LIMITED.replace(V=0.6)
    small, large = (corridor_disturbance(robot, CARMEL.controller, law, 0.9, D) for D in (0.1, 0.3))
    assert small.settles and small.cycles_below_critical and robot.V < small.V_critical
    assert not large.settles and large.reaches_wall
    m_small, m_large = simulate_wobbles([WobbleCase(robot, CARMEL.controller, 0.9, D, 80.0) for D in (0.1, 0.3)])
    assert not m_small.collided and m_small.amplitude < 1e-3 and m_large.collided


TWO_LAGS = (Robot(V=1.0, tau=0.13486, k=2.0, W=0.5, dead_time=0.003592, plant_gain=0.29588, actuator_lag=0.023218,
                  yaw_accel_limit=2.2275),
            Controller(f=3.0, n=2.0, T=1 / 11, hold="command", compute_delay=1), 0.7)
"""A plant with two lags and a slew limit, robot C's experiment's controller and corridor: what `identify` once found for
MuJoCo's robot C behind Nav2's smoother, when the engine's smoother timer drifted (τ_a = 23 ms then stood in for the
drift; the loop's dead time D + the smoother's mean wait). A realistic two-lag plant for the checks of τ_a."""
ROBOT_C = (Robot(V=1.0, tau=0.132323, k=2.0, W=0.5, dead_time=0.022395, plant_gain=0.296003, yaw_accel_limit=2.03289,
                 slip_lag=0.0095274),
           Controller(f=3.0, n=2.0, T=1 / 11, hold="command", compute_delay=1), 0.7)
"""MuJoCo's robot C as `identify` finds it behind Nav2's smoother (experiments/results/diagnose_mujoco.json, L = 0.7 m:
one lag and a slew limit; the loop's dead time is D = −2.7 ms + the smoother's mean wait 25.1 ms; its base's slide
τ_s = 9.53 ms from the drive's pose)."""
ROBOT_C_MUJOCO = (0.76918, 0.77081)
"""MuJoCo's boundary of robot C from a start 1 cm off the centre line, bisected (the same file): its bracket, m/s."""


def test_a_second_lag_enters_the_limited_boundary():
    """With a second lag τ_a and a slew limit, a small start's V*(D) and the branch's V* are the `sampled` model's linear
    V* of the same robot (to 1e-6: the limiter is linear below its threshold, so the branch at A → 0 is the linear loop,
    and its smallest cycle lies at V* to 1e-5, β·A² being of order 1e-7), with the limit and without it; for this
    two-lag plant leaving τ_a out moves V* by more than 5 %. The branch once built its loop without τ_a (V*(1 cm) came out
    the V* of the robot without its second lag, 12 % high)."""
    from pfm_stability.analysis.wobble import corridor_branch
    from pfm_stability.validation.common import predicted_boundaries, scenario_law, validation_models

    robot, controller, L = TWO_LAGS
    law = scenario_law("grid", robot, controller)
    linear = predicted_boundaries("corridor", "V", robot, controller, law, L, validation_models(controller))["sampled"]
    small = corridor_disturbance(robot, controller, law, L, 0.01)
    assert small.V_critical == pytest.approx(linear, rel=1e-6) and small.V_disturbance == pytest.approx(linear, rel=1e-6)
    for r in (robot, robot.replace(yaw_accel_limit=math.inf)):
        branch = corridor_branch(r, controller, law, L)
        assert branch.V_critical == pytest.approx(linear, rel=1e-6)
        # its smallest cycle (0.45 mm) at V*: the branch continues from the linear loop with both lags (measured 6e-7)
        assert branch.speeds[0] == pytest.approx(linear, rel=1e-5)
    without = predicted_boundaries("corridor", "V", robot.replace(actuator_lag=0.0), controller, law, L, validation_models(controller))
    assert without["sampled"] > 1.05 * linear  # τ_a matters here: leaving it out is not within the tolerance


def test_robot_cs_limited_boundary_against_mujoco():
    """Robot C as identified behind its smoother (one lag, the slew limit and its base's slide): a 1-cm start's V*(D) is
    the linear V* (to 1e-6) and lies within 3 % of MuJoCo's bisected boundary (the issue's target; measured +1.4 %, the
    bracket 0.2 % wide); without the slide it would be 4.4 % high (docs/mujoco.md, "Robots A, B and C"), outside."""
    from pfm_stability.validation.common import predicted_boundaries, scenario_law, validation_models

    robot, controller, L = ROBOT_C
    law = scenario_law("grid", robot, controller)
    linear = predicted_boundaries("corridor", "V", robot, controller, law, L, validation_models(controller))["sampled"]
    small = corridor_disturbance(robot, controller, law, L, 0.01)
    assert small.V_disturbance == pytest.approx(linear, rel=1e-6)
    assert small.V_disturbance == pytest.approx(sum(ROBOT_C_MUJOCO) / 2, rel=0.03)
    without = corridor_disturbance(robot.replace(slip_lag=0.0), controller, law, L, 0.01)
    assert without.V_disturbance > 1.03 * ROBOT_C_MUJOCO[1]


def test_the_limited_cycle_of_a_two_lag_loop_against_the_loop_iterated():
    """The two-lag plant (`TWO_LAGS`) behind its limit, with a linear field and no saturation: the harmonic
    balance's cycle of 0.24 m where the limiter lags (its phase 0.09 rad, below V*) against the sampled loop iterated
    with the limiter written out here (Nav2's rule, g·R·T a period, the commands in flight the first one), started at
    the offset that separates decay from growth (bisected), run at the speed the balance gives with a linear heading
    (V = Aω/Θ, as the iterated loop's heading is linear): the cycle it lingers on within 3 % (measured 1.3 %; the
    limiter's third harmonic is the first-harmonic balance's error)."""
    import numpy as np

    from pfm_stability.analysis.limiter import limited_balance, motor_loop
    from pfm_stability.laws.force_law import corridor_gain
    from pfm_stability.models.sampled import command_form, continuous_plant
    from pfm_stability.validation.common import scenario_law

    robot, controller, L = TWO_LAGS
    robot = robot.replace(max_steering_rate=100.0)
    N = corridor_gain(scenario_law("grid", robot, controller), L)
    A = np.array([0.2436])
    b = limited_balance(robot, controller, lambda y: -N * np.asarray(y), A, np.full(1, N), "sampled")
    assert 0.05 < b.limiter_lags[0] < 0.2
    V = A[0] * b.omegas[0] / b.headings[0]
    assert V < 0.9 * b.NV_critical / N
    loop = motor_loop(robot, controller)
    M, n, F0, F1 = command_form(loop, "command", controller.compute_delay)
    plant = continuous_plant(loop, "command")[0].shape[0]
    F, step = F0 + loop.k * N * V * F1, robot.plant_gain * robot.yaw_accel_limit * controller.T

    def run(offset, steps):
        x = np.zeros(M.shape[0])
        x[plant - 1] = offset / V
        last = float(np.clip(-F @ x, -step, step))
        x[plant:] = last
        ys = np.empty(steps)
        for i in range(steps):
            last += min(max(-F @ x - last, -step), step)
            x = M @ x + n * last
            ys[i] = x[plant - 1] * V
        return ys

    lo, hi = 0.01, 0.5
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if np.max(np.abs(run(mid, 2500)[-300:])) > 1.0 else (mid, hi)
    y = np.abs(run(lo, 1200))
    peaks = y[1:-1][(y[1:-1] >= y[:-2]) & (y[1:-1] >= y[2:])]
    assert np.median(peaks[5:25]) == pytest.approx(A[0], rel=0.03)


@pytest.mark.parametrize("alpha", [20.0, 45.0])
def test_a_second_lag_enters_the_wall_branch_too(alpha):
    """The wall's branch and a small start's V*(D) at a wall discontinuity (α = 20° and 45°) take the second lag τ_a as
    the corridor's do (`test_a_second_lag_enters_the_limited_boundary`): both equal the `sampled` model's linear V* of
    the two-lag plant (`TWO_LAGS`) (to 1e-6: the limiter is linear below its threshold), and leaving τ_a out moves that V*
    by more than 5 % (so the check can fail)."""
    from pfm_stability.analysis.disturbance import wall_disturbance
    from pfm_stability.analysis.wobble import wall_branch
    from pfm_stability.validation.common import predicted_boundaries, scenario_law, validation_models

    robot, controller, _ = TWO_LAGS
    alpha = math.radians(alpha)  # the analyses take α in rad
    law = scenario_law("grid", robot, controller)
    linear = predicted_boundaries("wall", "V", robot, controller, law, alpha, validation_models(controller))["sampled"]
    small = wall_disturbance(robot, controller, law, alpha, 0.01)
    assert small.V_critical == pytest.approx(linear, rel=1e-6) and small.V_disturbance == pytest.approx(linear, rel=1e-6)
    assert wall_branch(robot, controller, law, alpha).V_critical == pytest.approx(linear, rel=1e-6)
    without = predicted_boundaries("wall", "V", robot.replace(actuator_lag=0.0), controller, law, alpha, validation_models(controller))
    assert without["sampled"] > 1.05 * linear
