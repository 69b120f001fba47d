"""Runs that end early: collisions on the path between two samples, a start outside the scene, what a stopped run reports.

docs/simulator.md ("Events", "What a stopped run reports", "Scenarios"). The
expected values come from the geometry worked out here: where a straight path
or an arc integrated with scipy meets a wall, the corridor's free play
L − W/2 (− c/2), and the trap rule's first sample past 10 s.
"""

import json
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from pfm_stability.cli import main
from pfm_stability.parameters import CARMEL
from pfm_stability.sim import AnalyticEnvironment, AnalyticWall, HistogramGrid, Pose, Scenario, Target, make_scenario, simulate, simulate_reference
from pfm_stability.sim.metrics import oscillation_metrics

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
V, W, TAU, K = ROBOT.V, ROBOT.W, ROBOT.tau, ROBOT.k


# ------------------------------------------------------- contact between samples
def test_a_straight_path_meets_a_wall_between_two_samples_analytic():
    """Heading 30°, a wall across the path 10 m ahead, T = 50 s (40 m per period): the run collides at the first touch.

    The held command is 0 (the wall pushes straight back along the heading,
    weaker than the pull: δ = θ), so the path is straight: the disc touches
    when the centre has gone D − W/2, at t = (D − W/2)/V = 12 s, at
    (D − W/2)(sin θ, cos θ). Before, the robot passed the wall unseen. Tolerance
    1e-9 (s, m): the contact is narrowed to 1e-12 of the period and δ = θ to round-off.
    """
    theta, D = math.radians(30.0), 10.0
    ux, uy = math.sin(theta), math.cos(theta)
    across = (math.cos(theta), -math.sin(theta))  # along the wall
    centre = (D * ux, D * uy)
    wall = AnalyticWall((centre[0] - 5 * across[0], centre[1] - 5 * across[1]), (centre[0] + 5 * across[0], centre[1] + 5 * across[1]), "right")
    scenario = Scenario("wall ahead", ROBOT, CONTROLLER.replace(T=50.0), AnalyticEnvironment((wall,)), Pose(0.0, 0.0, theta),
                        Target.direction(theta), duration=100.0)
    run = simulate(scenario)
    travelled = D - W / 2
    assert [e.type for e in run.events] == ["collision"]
    e = run.events[0]
    assert e.t == pytest.approx(travelled / V, abs=1e-9)
    assert (e.x, e.y) == pytest.approx((travelled * ux, travelled * uy), abs=1e-9)
    assert run.steps == 1 and not run.metrics.stable and run.min_clearance <= 0


def test_a_straight_path_meets_a_wall_of_cells_between_two_samples_grid():
    """A wall of cells along X at y = 10 m (centres on y = 10, faces at 10 − c/2), the robot heading +Y from the origin.

    Beyond the window (1.65 m) nothing pushes, so u = 0 and the path is
    straight: contact when y + W/2 = 10 − c/2, t = (10 − c/2 − W/2)/V =
    11.9375 s, at (0, 9.55) m — inside the first period of T = 50 s. Tolerance
    1e-9 as above.
    """
    grid = HistogramGrid.centred(-4.0, 4.0, -2.0, 12.0).draw_segment((-3.0, 10.0), (3.0, 10.0)).freeze()
    scenario = Scenario("cells ahead", ROBOT, CONTROLLER.replace(T=50.0), grid, Pose(0.0, 0.0, 0.0), Target.direction(0.0), duration=100.0)
    run = simulate(scenario)
    reach = 10.0 - 0.05 - W / 2
    assert [e.type for e in run.events] == ["collision"]
    assert run.events[0].t == pytest.approx(reach / V, abs=1e-9)
    assert (run.events[0].x, run.events[0].y) == pytest.approx((0.0, reach), abs=1e-9)


def _arc_contact(u, x0, wall_x):
    """(t, x, y) where the arc from (x0, 0) heading +Y under a held command u (ω₀ = 0, KB eq 6) reaches x = wall_x.

    θ(t) = u(t − τ(1 − e^(−t/τ))), x = x0 + V∫sin θ, y = V∫cos θ, by scipy's
    quad (1e-13) and brentq: the test's own integration of the motion.
    """
    theta = lambda t: u * (t - TAU * -math.expm1(-t / TAU))
    x = lambda t: x0 + V * quad(lambda s: math.sin(theta(s)), 0.0, t, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    hi = 1.0
    while x(hi) > wall_x:
        hi *= 1.5
    t = brentq(lambda s: x(s) - wall_x, 0.0, hi, xtol=1e-14, rtol=1e-15)
    return t, x(t), V * quad(lambda s: math.cos(theta(s)), 0.0, t, epsabs=0.0, epsrel=1e-13, limit=200)[0]


def test_corridor_at_T_100_s_collides_on_the_arc_analytic():
    """`simulate --scenario corridor --env analytic --T 100`: the first held command turns the robot into the left wall.

    u = k·δ₀ with δ₀ = atan2(F_x, 1), F_x = f(W/(L + x₀))² − f(W/(L − x₀))²
    (KB eq 1–5 with the power law, x₀ = 0.02 m, L = 1 m); the arc meets the
    disc's contact line x = −(L − W/2) where `_arc_contact` integrates it.
    Tolerance 1e-8 (s, m): quad and brentq to ~1e-13, the simulator's position
    quadrature to ~1e-13 m per period.
    """
    L, x0, f = 1.0, 0.02, CONTROLLER.f
    fx = f * (W / (L + x0)) ** 2 - f * (W / (L - x0)) ** 2
    u = K * math.atan2(fx, 1.0)
    t, x, y = _arc_contact(u, x0, -(L - W / 2))
    run = simulate("corridor", env="analytic", controller=CONTROLLER.replace(T=100.0), duration=300.0)
    e = run.events[0]
    assert e.type == "collision" and e.t == pytest.approx(t, abs=1e-8)
    assert (e.x, e.y) == pytest.approx((x, y), abs=1e-8)
    assert not run.metrics.stable and run.metrics.growth_rate is None


def test_corridor_at_T_100_s_collides_in_the_grid_and_is_not_stable(capsys):
    """`simulate --scenario corridor --T 100` (grid; 120 s: a longer run only lengthens the walls): collision at the cell
    faces x = −(L − c/2 − W/2), never "stable: yes".

    The held command comes from the window sum done here cell by cell (KB eq
    1–2 over the 33 × 33 cells around the robot's cell, ρ the run's calibrated
    ratio), then the arc as above. Before, a 300 s run ended at x = −8.6 m,
    through the wall, "trapped" and "stable: yes". Tolerance 1e-8 as above.
    """
    scenario = make_scenario("corridor", controller=CONTROLLER.replace(T=100.0), duration=120.0)
    grid, rho, h = scenario.environment, scenario.cell_ratio, scenario.window_cells // 2
    i, j = grid.cell_index(0.02, 0.0)
    ci, cj = np.nonzero(grid.cv[i - h : i + h + 1, j - h : j + h + 1])
    cx, cy = grid.cell_center(ci + i - h, cj + j - h)
    dx, dy = 0.02 - cx, 0.0 - cy
    d = np.hypot(dx, dy)
    fx = float(np.sum(rho * 15 * W**2 * dx / d**3))
    fy = float(np.sum(rho * 15 * W**2 * dy / d**3))
    u = K * math.atan2(fx, 1.0 + fy)
    t, x, y = _arc_contact(u, 0.02, -(1.0 - 0.05 - W / 2))
    assert main(["simulate", "--scenario", "corridor", "--T", "100", "--duration", "120", "--format", "json", "--quiet"]) == 0
    out = json.loads(capsys.readouterr().out)
    event = out["events"][0]
    assert event["type"] == "collision" and event["t"] == pytest.approx(t, abs=1e-8)
    assert (event["x"], event["y"]) == pytest.approx((x, y), abs=1e-8)
    assert out["metrics"]["stable"] is False
    assert main(["simulate", "--scenario", "corridor", "--T", "100", "--duration", "120", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "stable: no (collision)" in text and f"{t:.4g} s simulated of the 120 s asked (stopped by the collision event)" in text


def test_reference_loop_finds_the_same_contact():
    """`simulate_reference` walks the path its own way (32 instants, fresh steering solutions, `bisect_root`):
    the same first touch as the engine at T = 100 s (1e-9 s: both narrow the contact to ~1e-12 of the period)."""
    scenario = make_scenario("corridor", env="analytic", controller=CONTROLLER.replace(T=100.0), duration=300.0)
    _, event = simulate_reference(scenario)
    run = simulate(scenario)
    assert event.type == "collision" and event.t == pytest.approx(run.events[0].t, abs=1e-9)


# ------------------------------------------------------------- start offset
@pytest.mark.parametrize("env,play", [("grid", 1.0 - W / 2 - 0.05), ("analytic", 1.0 - W / 2)])
def test_corridor_offset_must_leave_the_robot_inside(env, play, capsys):
    """|offset| < L − W/2 (− c/2 for the grid's cell walls), L = 1 m: inside it starts there, outside it is refused (exit 2)."""
    inside = make_scenario("corridor", env=env, offset=play - 1e-3, duration=1.0)
    assert inside.start.x == pytest.approx(play - 1e-3, abs=1e-12)
    for offset in (5.0, play + 1e-3, -play - 1e-3):
        with pytest.raises(ValueError, match=rf"offset must be a finite number in \({-play:.12g}, {play:.12g}\) m .*; got {offset!r}"):
            make_scenario("corridor", env=env, offset=offset)
    assert main(["simulate", "--scenario", "corridor", "--env", env, "--offset", "5", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"({-play:.12g}, {play:.12g}) m" in err and "got 5.0" in err and err.count("\n") == 1 and "Traceback" not in err


def test_wall_offset_must_leave_the_robot_clear_of_the_wall():
    """Beside a wall: offset > W/2 − d0 with d0 = W(f/cos α)^(1/n) (KB eq 23, power law, α = 45°)."""
    d0 = W * (CONTROLLER.f / math.cos(math.radians(45.0))) ** 0.5
    low = W / 2 - d0
    assert make_scenario("wall", env="analytic", offset=low + 1e-3, duration=1.0).start.x == pytest.approx(-d0 - low - 1e-3, abs=1e-9)
    with pytest.raises(ValueError, match=r"offset must be a finite number in \(-0\.45"):
        make_scenario("wall", env="analytic", offset=low - 1e-3)


def test_a_narrow_corridor_halves_the_default_offset():
    """The default 0.02 m does not fit when L − W/2 < 0.02 m: half the free play instead, never a value the user did not give refused."""
    scenario = make_scenario("corridor", env="analytic", L=W / 2 + 0.01, duration=1.0)
    assert scenario.start.x == pytest.approx(0.005, abs=1e-12)


# ------------------------------------------------------- what a run reports
def test_a_run_stopped_early_reports_the_time_simulated_and_why(capsys):
    """V = 1 mm/s, 999999 s asked: the trap rule (0.5 m of progress within 10 s) stops it at the first sample past
    10 s, k = 154 (154 × 0.065 = 10.01 s); the report says so instead of "999999 s simulated"."""
    k = math.floor(10.0 / 0.065) + 1
    assert main(["simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "999999", "--V", "0.001", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert f"{k * 0.065:.4g} s simulated of the 999999 s asked (stopped by the trapped event), {k} samples" in text
    assert "less than 0.5 m of progress towards the target in 10 s" in text


def test_unmeasurable_and_drifting_runs_are_not_stable():
    """docs/simulator.md: fewer than 8 samples → not stable ("not measurable"); σ undefined → stable only when settling:
    a drift 0.01t² moves 3× more over the second half than the first, a steady drift as much, a constant not at all."""
    t = np.arange(200) * 0.065
    short = oscillation_metrics(t[:5], np.zeros(5), 0.065)
    assert not short.stable and "not measurable" in short.reason
    drift = oscillation_metrics(t, 0.01 * t**2, 0.065)
    assert drift.growth_rate is None and not drift.stable and "is not settling" in drift.reason
    steady = oscillation_metrics(t, 0.01 * t, 0.065)
    assert not steady.stable
    flat = oscillation_metrics(t, np.zeros(t.size), 0.065)  # a robot that never moves sideways
    assert flat.growth_rate is None and flat.stable
