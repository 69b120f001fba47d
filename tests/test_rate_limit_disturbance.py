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
