"""The simulator driving Nav2's controllers, and the boundary the validation bisects (docs/controllers.md, "The proof").

* The simulator's loop is the `sampled` model's: RPP's decision is linear in the small-signal regime, so the growth
  rate and frequency the linear-prediction fit measures must equal the sampled model's dominant pole with the closed
  form's gains (random robots with lag, plant gain, dead time and compute delay).
* The simulated boundary of the real algorithm in V (and RPP's lookahead) lands within 2 % of the sampled model's
  prediction with the linearised gains, on random robots (the target for RPP and Graceful).
* The memory loop (`validation.controllers.memory_loop_matrix`) with one cycle of response is the sampled model.
"""

import math

import numpy as np
import pytest

from pfm_stability.controllers.costmap import CorridorCostmap

from pfm_stability.controllers.linearize import linearize
from pfm_stability.controllers import graceful, rpp
from pfm_stability.models import Loop, make_model
from pfm_stability.parameters import Robot
from pfm_stability.sim.tracking import TrackingScenario, simulate_tracking
from pfm_stability.validation.controllers import boundary_check, memory_loop_matrix


def _robot(r, V):
    return Robot(V=V, tau=r.uniform(0.0, 0.3), k=1.0, W=0.4, dead_time=r.uniform(0.0, 0.15), plant_gain=r.uniform(0.7, 1.3),
                 max_steering_rate=20.0)


@pytest.mark.parametrize("seed", range(2))
def test_the_simulated_rpp_loop_has_the_sampled_models_pole(seed):
    """RPP on a plan with a pose every V·T (the robot meets a pose at every sample, so the lookahead does not ripple):
    σ and ω from the linear-prediction fit equal the dominant root of the sampled model with k = 2V/L, NV = V/L and the
    robot's τ, g, D, compute delay, to 1e-4 relative (the heading's second-order shortening of the step along the plan,
    ~θ², and the fit; measured 2e-6)."""
    r = np.random.default_rng(seed)
    V, L, T, d = r.uniform(0.4, 0.9), r.uniform(0.5, 1.0), 0.05, int(r.integers(0, 2))
    robot = _robot(r, V)
    params = rpp.RPPParams(lookahead_dist=L, use_regulated_linear_velocity_scaling=False)
    s = TrackingScenario("rpp", robot, T, params=params, compute_delay=d, spacing=V * T, duration=12.0, offset=0.002)
    m = simulate_tracking([s]).runs[0].metrics
    k, NV = rpp.closed_form_gains(V, L)[0], V / L
    root = make_model("sampled", hold="command", compute_delay=d).rightmost_root(NV, Loop(robot.tau, T, k, plant_gain=robot.plant_gain, dead_time=robot.dead_time))
    assert m.method == "linear_prediction"
    assert m.growth_rate == pytest.approx(root.real, rel=1e-4, abs=1e-6) and m.angular_frequency == pytest.approx(abs(root.imag), rel=1e-4)


@pytest.mark.parametrize("controller, seed", [("rpp", 0), ("graceful", 1)])
def test_the_simulated_speed_boundary_is_the_sampled_prediction(controller, seed):
    """V* of the real algorithm (bisected to 0.5 %) against the sampled model with the linearised gains: within 2 % (the
    target; the plan's poses every 1 cm make the lookahead ripple by ±0.5 cm, the fit and the bisection's
    bracket the rest; measured 0.02–0.3 %)."""
    r = np.random.default_rng(seed)
    robot = _robot(r, 1.0).replace(dead_time=r.uniform(0.08, 0.2))
    params = rpp.RPPParams(use_regulated_linear_velocity_scaling=False) if controller == "rpp" else graceful.GracefulParams(v_angular_max=20.0)
    template = TrackingScenario(controller, robot, 0.05, params=params, spacing=0.01, duration=15.0, offset=0.003,
                                compute_delay=int(r.integers(0, 2)))
    b = boundary_check(template, "V", 0.2, 4.0, members=5, rtol=5e-3)
    assert b.simulated_lo <= b.simulated_hi and abs(b.relative_error) < 0.02


def test_rpp_lookahead_boundary_is_the_sampled_prediction():
    """L*, the shortest stable lookahead of RPP in a corridor (the regulated speed from its cost), simulated within 2 % of
    the sampled prediction (measured 0.09 %)."""
    robot = Robot(V=0.8, tau=0.15, k=1.0, W=0.4, dead_time=0.07, plant_gain=1.2, max_steering_rate=20.0)
    template = TrackingScenario("rpp", robot, 0.05, spacing=0.01, duration=15.0, offset=0.003, costmap=CorridorCostmap(half_width=1.0))
    b = boundary_check(template, "lookahead_dist", 0.1, 2.0, members=5, rtol=5e-3)
    assert b.stable_above and abs(b.relative_error) < 0.02


@pytest.mark.parametrize("seed", range(3))
def test_the_memory_loop_with_one_cycle_is_the_sampled_model(seed):
    """memory_loop_matrix closes the sampled model's own plant (command_form) by the controller; with the one-step gains
    only, its spectral radius is the sampled model's |z| of the dominant pole (1e-12: the same matrices)."""
    r = np.random.default_rng(seed)
    robot = _robot(r, 0.7)
    s = TrackingScenario("rpp", robot, 0.05, compute_delay=int(r.integers(0, 2)))
    g = linearize("rpp", s.controller_params(), s.costmap)
    radius = np.max(np.abs(np.linalg.eigvals(memory_loop_matrix(g, s))))
    root = make_model("sampled", hold="command", compute_delay=s.compute_delay).rightmost_root(
        g.NV, Loop(robot.tau, 0.05, g.k_theta, plant_gain=robot.plant_gain, dead_time=robot.dead_time))
    assert radius == pytest.approx(math.exp(root.real * 0.05), rel=1e-12)


def test_tracking_scenarios_refuse_what_they_cannot_run():
    """A start off the corridor (|offset| + W/2 beyond the walls), an unknown controller: one-line ValueErrors."""
    robot = Robot(V=0.5, tau=0.1, k=1.0, W=0.4)
    with pytest.raises(ValueError, match="offset"):
        TrackingScenario("rpp", robot, 0.05, costmap=CorridorCostmap(half_width=0.5), offset=0.35)
    with pytest.raises(ValueError, match="controller"):
        TrackingScenario("teb", robot, 0.05)


def test_mujoco_runs_a_nav2_controller_on_a_straight_corridor():
    """engines.mujoco with EngineOptions(controller="rpp"): the MuJoCo robot tracks the corridor's centre line from a
    10 cm start (the offset shrinks below 3 cm within 5 s, no collision): the same controller interface as the
    simulator's, on a plant nobody here wrote. Skipped without the optional extra."""
    pytest.importorskip("mujoco", reason="the optional extra 'mujoco' is not installed")
    from pfm_stability.engines.mujoco import EngineOptions, run_scenario
    from pfm_stability.parameters import Controller
    from pfm_stability.sim.presets import make_scenario

    scenario = make_scenario("corridor", robot=Robot(V=0.5, tau=0.25, k=2.0, W=0.5), controller=Controller(f=3.0, n=2.0, T=0.05),
                             L=1.0, offset=0.1, duration=5.0)
    run = run_scenario(scenario, EngineOptions(controller="rpp"))
    assert not run.events and abs(run.offset[-1]) < 0.03 and abs(run.offset[0]) == pytest.approx(0.1, abs=1e-3)


def test_the_tracking_simulator_passes_the_drive_s_smoother():
    """A robot with a yaw acceleration limit R: the tracking simulator's commanded yaw rate goes through the same smoother
    as the VFF simulator's (`sim.robot.CommandPath`): started 0.3 m off the plan, the yaw rate of an RPP robot never
    changes by more than R·T per period (τ = 0: the yaw rate is the held command, from rest), to round-off; without the
    limit its first command alone is more than four times that."""
    robot = Robot(V=0.5, tau=0.0, k=1.0, W=0.4, max_steering_rate=10.0)
    T, R = 0.05, 0.5
    runs = [simulate_tracking([TrackingScenario("rpp", r, T, spacing=0.025, duration=2.0, offset=0.3)], record="trajectory").runs[0]
            for r in (robot, robot.replace(yaw_accel_limit=R))]
    rates = [np.concatenate([[0.0], np.diff(run.trajectory.theta) / T]) for run in runs]  # τ = 0: the held command, from rest
    assert np.max(np.abs(np.diff(rates[1]))) <= R * T * (1 + 1e-9)
    assert np.max(np.abs(np.diff(rates[0]))) > 4 * R * T
