"""The planar simulator (`pfm_stability.sim.planar`, `sim.cycles`) against the loop models and its own rules.

The simulator imports no model; these tests do, and compare the simulated growth rate
of a lateral offset with the sampled loop's dominant pole (docs/simulator.md, "Planar robots").
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfm_stability.laws.fields import KhatibLaw
from pfm_stability.laws.force_law import PowerLaw, wall_equilibria
from pfm_stability.models.loop import Loop
from pfm_stability.models.holonomic import HolonomicLoop, kinematic_loop
from pfm_stability.models.sampled import Sampled
from pfm_stability.sim.cycles import lateral_metrics, loop_order, wall_cycle
from pfm_stability.sim.movers import Ball, PointObstacle, Target, Wall
from pfm_stability.sim.planar import (
    DiffDrive,
    Field,
    PointMass,
    Pull,
    Start,
    Steering,
    World,
    simulate_planar,
)
from pfm_stability.laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion

L = 0.5
LAW = KhatibLaw(xi=1.0, eta=0.3, rho0=2.0, m=2.0, rho_g=1.0)
ALPHA_P = 1e-3


def _corridor_run(kappa, c_h, T, delay, mass, steps=400, x0=1e-6):
    """A point mass between walls x = ±L: Khatib repulsion from both, damping 2α_v/m, target moving along y.

    With m = n = 2 the attraction is 2α_p e + 2α_v ė, linear: the lateral loop is exactly
    m ẍ = F_wall(x) − 2α_p x − 2α_v ẋ, and F_wall is odd in x (no quadratic term). The
    repulsion's scale is chosen so that κ = (−2·scale·P′(L) + 2α_p)/m is the requested one.
    """
    slope = float(LAW.slope(L))
    scale = (kappa * mass - 2.0 * ALPHA_P) / (-2.0 * slope)
    field = Field(VelocityAttraction(ALPHA_P, c_h * mass / 2.0), LAW, repulsion_scale=scale)
    world = World(Target((0.0, 0.0), (0.0, 1.0)), (Wall((-L, 0.0), (1.0, 0.0)), Wall((L, 0.0), (-1.0, 0.0))))
    run = simulate_planar(PointMass(mass), field, world, T=T, compute_delay=delay, duration=steps * T,
                          start=Start((x0, 0.0), (0.0, 1.0)))
    return lateral_metrics(run, (1.0, 0.0), window=(5 * T, steps * T), robot=PointMass(mass))


def _holonomic_cases():
    rng = np.random.default_rng(19)
    cases = [(0.2, 0.1, 0, 1.0), (0.2, 0.1, 1, 1.0), (2.0, 0.02, 0, 2.0), (1.0, 0.05, 1, 0.5)]
    for _ in range(4):
        cases.append((float(rng.uniform(0.05, 5.0)), float(rng.uniform(0.005, 0.2)), int(rng.integers(0, 2)), float(rng.uniform(0.3, 3.0))))
    return cases


@pytest.mark.parametrize("c_h, T, delay, mass", _holonomic_cases())
@pytest.mark.parametrize("side", [0.97, 1.03])
def test_holonomic_growth_rate_matches_sampled_pole(c_h, T, delay, mass, side):
    """Simulated σ of a point mass in a Khatib corridor = the holonomic `sampled` model's pole, 3 % either side of κ*.

    In the linear regime (offset 1e-6 m, a law odd about the centre) the simulated record obeys the
    sampled loop's recurrence exactly, so the linear-prediction fit returns its dominant pole to
    round-off; the 1 % tolerance is relative to the pole's modulus |s| (σ itself is near 0 at
    the boundary, where a relative error in σ alone is ill-conditioned), and the verdicts
    (sign of σ) must agree. Random (c_h, T, delay, mass) as well as hand-picked ones.
    """
    model = Sampled("command", delay)
    loop = HolonomicLoop(T, c_h)
    kappa_star = model.boundary(loop).kappa_critical
    assert math.isfinite(kappa_star) and kappa_star > 0
    kappa = side * kappa_star
    pole = model.rightmost_root(kappa, loop)
    m = _corridor_run(kappa, c_h, T, delay, mass)
    assert m.method == "linear_prediction"
    assert abs(m.growth_rate - pole.real) <= 0.01 * abs(pole)
    assert abs(m.angular_frequency - pole.imag) <= 0.01 * abs(pole)
    assert (m.growth_rate < 0) == (pole.real < 0) == (side < 1)


def _steering_wall(robot, alpha, law, F_a, alpha_v, T, delay, duration, offset=1e-7):
    """A steering robot beside the wall x = 0 pulled by F_a towards a target at infinity at α from the normal.

    The attraction is a `VelocityAttraction` with m = 1 (a pull of constant magnitude α_p = F_a)
    towards a target 1e12 m away in that direction (its bearing turns by < 1e-10 rad), plus the
    velocity part −2α_v v (stationary target): the heading gain c of docs/velocity_and_fuzzy.md.
    """
    direction = np.array([-math.cos(alpha), math.sin(alpha)])
    attraction = VelocityAttraction(F_a, alpha_v, m=1.0, n=2.0)
    eq = attraction.steering_wall_equilibria(law, alpha, robot.V, 1.0)[0]
    field = Field(attraction, law, repulsion_scale=F_a)
    world = World(Target(tuple(1e12 * direction)), (Wall((0.0, 0.0), (1.0, 0.0)),))
    run = simulate_planar(robot, field, world, T=T, compute_delay=delay, duration=duration,
                          start=Start((eq.x0 + offset, 0.0), heading=math.pi / 2))
    return eq, lateral_metrics(run, (1.0, 0.0), window=(10 * T, duration), robot=robot)


@pytest.mark.parametrize("q, hold, delay", [(0.0, "reference", 0), (0.5, "reference", 1), (0.3, "command", 0), (0.5, "command", 1)])
def test_kb_steering_with_velocity_attraction_matches_sampled_pole(q, hold, delay):
    """KB's robot (τ = 0.3, k = 2, T = 0.065) with the velocity attraction's heading gain c = q/(1 − q).

    The sampled KB model with c (models/sampled.py) is the simulator's own sampled loop, so in
    the linear regime (offset 1e-7 m, grown at most e^8-fold: the run lasts at most 8/σ) σ agrees
    to 1 % of the pole's modulus (the residual is the wall law's quadratic term at that
    amplitude; when the fit's residual exceeds `metrics.LINEAR_RESIDUAL` the peaks estimate is
    used, measured within 0.1 % of |s| here). NV ≈ 2.6 (KB's boundary ≈ 2.77): q = 0 is stable, q = 0.5 (NV doubles) unstable.
    """
    alpha, F_a, V = math.radians(60.0), 1.0, 0.8
    law = PowerLaw(f=0.68, n=2.0, W=0.3)
    alpha_v = q * F_a * math.sin(alpha) / (2.0 * V)
    robot = Steering(V, 0.3, 2.0, hold=hold)
    eq = VelocityAttraction(F_a, alpha_v, m=1.0).steering_wall_equilibria(law, alpha, V, 1.0)[0]
    loop = Loop(0.3, 0.065, 2.0, c=eq.c)
    pole = Sampled(hold, delay).rightmost_root(eq.N * V, loop)
    eq, m = _steering_wall(robot, alpha, law, F_a, alpha_v, 0.065, delay, min(25.0, 8.0 / max(pole.real, 1e-3)))
    assert math.isclose(eq.c, q / (1 - q), rel_tol=1e-12)
    assert abs(m.growth_rate - pole.real) <= 0.01 * abs(pole)
    assert abs(m.angular_frequency - pole.imag) <= 0.01 * abs(pole)


@pytest.mark.parametrize("K_s, V, delay", [(2.0, 0.8, 0), (4.0, 1.5, 1)])
def test_kinematic_steering_matches_sampled_pole(K_s, V, delay):
    """Kinematic steering (τ = 0, k = K_s, GC2002 §7) against `kinematic_loop`'s sampled model, held command.

    Same argument and tolerance as the KB case; at these gains the wall loop is unstable for
    one delay and stable for the other, so both verdicts are exercised.
    """
    alpha, law = math.radians(40.0), PowerLaw(f=0.6, n=2.0, W=0.3)
    robot = Steering(V, 0.0, K_s, hold="command")
    eq = wall_equilibria(law, alpha)[0]
    pole = Sampled("command", delay).rightmost_root(eq.N * V, kinematic_loop(K_s, 0.1))
    eq, m = _steering_wall(robot, alpha, law, 1.0, 0.0, 0.1, delay, min(30.0, 8.0 / max(pole.real, 1e-3)))
    assert abs(m.growth_rate - pole.real) <= 0.01 * abs(pole)
    assert (m.growth_rate < 0) == (pole.real < 0)


def test_loop_order_counts_states():
    """The fit's order is the sampled loop's state count: 2 + lag + delay."""
    assert loop_order(PointMass(), 1) == 3
    assert loop_order(Steering(1.0, 0.3, 2.0), 0) == 3
    assert loop_order(Steering(1.0, 0.0, 2.0), 1) == 3


# ------------------------------------------------------------------- events


def _head_on(v0, a_max=1.0, duration=20.0, x0=-1.5, **kw):
    rep = VelocityGatedRepulsion(0.2, 2.0, a_max)
    field = Field(VelocityAttraction(0.005, 0.1), rep)
    world = World(Target((0.0, 0.0)), (Ball((0.8, 0.0), 0.3),))
    return simulate_planar(PointMass(), field, world, T=0.01, duration=duration, start=Start((x0, 0.0), (v0, 0.0)), **kw)


def test_gate_and_influence_events_are_recorded():
    """A slow approach towards a ball: D crosses ρ0 and the gate (v_RO) opens and closes, at interpolated times.

    The robot starts at rest 2.2 m from the ball's surface (outside ρ0 = 2), is pulled towards the
    target at 0 and enters the influence zone; it stalls (v_RO falls to 0: gate_close).
    """
    run = _head_on(0.0, x0=-1.7, duration=40.0)
    kinds = [e.kind for e in run.events]
    assert kinds[0] == "gate_open" and "influence_enter" in kinds and "gate_close" in kinds
    assert not run.collision and run.stop_reason == "duration"
    e = run.first_event("influence_enter")
    i = round(e.time / run.T)
    D = lambda k: 0.5 - run.p[k, 0] - run.v[k, 0] ** 2 / 2.0
    assert D(i - 1) >= 2.0 > D(i + 1) or D(i) >= 2.0 > D(i + 1)
    for arr in (run.p, run.v, run.force):
        assert np.all(np.isfinite(arr))


def test_head_on_fast_start_reports_collision_unavoidable_without_nan():
    """v0 = 3 m/s at a_max = 0.5: D = ρ_s − v²/(2a_max) < 0 at once (GC2002 eq 12 undefined): an event, the run stops, no NaN."""
    run = _head_on(3.0, a_max=0.5)
    assert run.collision and run.stop_reason == "collision_unavoidable"
    assert run.events[0].kind == "collision_unavoidable" and run.events[0].obstacle == 0
    assert run.t.size == 1
    for arr in (run.p, run.v, run.force):
        assert np.all(np.isfinite(arr))
    cont = _head_on(3.0, a_max=0.5, duration=2.0, on_collision="continue")
    assert cont.stop_reason == "contact" and np.all(np.isfinite(cont.force))


def test_moving_ball_force_equals_velocity_laws_at_sample_state():
    """The force recorded at t = 0 is attraction + `VelocityGatedRepulsion.evaluate` of the moving ball (true gradient).

    A moving ball and a moving point obstacle: the simulator passes the obstacle's velocity and
    centre distance through; the sum is compared with a direct evaluation (1e-12).
    """
    rep = VelocityGatedRepulsion(0.2, 2.0, 1.0)
    att = VelocityAttraction(0.005, 0.1)
    p, v = np.array([1.0, 0.5]), np.array([0.6, 0.2])
    for obstacle, kind, where, radius in ((Ball((2.0, 1.0), 0.3, (-0.2, 0.1)), "ball", (2.0, 1.0), 0.3),
                                          (PointObstacle((2.0, 1.0), (-0.2, 0.1)), "point", (2.0, 1.0), 0.0)):
        world = World(Target((5.0, 5.0), (0.1, 0.0)), (obstacle,))
        run = simulate_planar(PointMass(), Field(att, rep), world, T=0.1, duration=0.5, start=Start(tuple(p), tuple(v)))
        expect = att.force(p, v, (5.0, 5.0), (0.1, 0.0)) + rep.evaluate(p, v, kind, where, radius, (-0.2, 0.1)).force
        assert np.allclose(run.force[0], expect, rtol=0, atol=1e-12)
        # the obstacle moves: at the last sample the centre is where + t·velocity
        last = run.p[-1], run.v[-1]
        moved = np.array(where) + run.t[-1] * np.array([-0.2, 0.1])
        r = rep.evaluate(last[0], last[1], kind, moved, radius, (-0.2, 0.1))
        expect = att.force(last[0], last[1], np.array([5.0, 5.0]) + run.t[-1] * np.array([0.1, 0.0]), (0.1, 0.0))
        expect = expect + (r.force if r.status == "active" else 0.0)
        assert np.allclose(run.force[-1], expect, rtol=0, atol=1e-12)


def test_nearest_only_ignores_the_farther_obstacle():
    """With ``nearest_only`` (the conference paper's Assumption 4) the farther of two walls exerts nothing."""
    att, law = VelocityAttraction(0.005, 0.1), KhatibLaw(xi=1.0, eta=0.3, rho0=2.0, m=2.0, rho_g=1.0)
    world = World(Target((0.0, 10.0)), (Wall((-0.5, 0.0), (1.0, 0.0)), Wall((1.0, 0.0), (-1.0, 0.0))))
    both = simulate_planar(PointMass(), Field(att, law), world, T=0.1, duration=0.1, start=Start((0.0, 0.0)))
    near = simulate_planar(PointMass(), Field(att, law, nearest_only=True), world, T=0.1, duration=0.1, start=Start((0.0, 0.0)))
    base = att.force((0.0, 0.0), (0.0, 0.0), (0.0, 10.0))
    assert math.isclose(near.force[0, 0] - base[0], float(law.force(0.5)), rel_tol=1e-12)
    assert math.isclose(both.force[0, 0] - base[0], float(law.force(0.5)) - float(law.force(1.0)), rel_tol=1e-12)


def test_diff_drive_speed_law_and_wheel_speeds():
    """GC2002 §7: v = v_opt·ρ/ρ0 near an obstacle (eq 41), v_r − v_l = Lω, v_l + v_r = 2v (eq 40, rows in CCW order)."""
    robot = DiffDrive(K_s=2.0, v_opt=0.5, rho0_speed=1.0)
    world = World(Target((5.0, 0.0)), (Wall((0.0, -0.4), (0.0, 1.0)),))
    run = simulate_planar(robot, Field(VelocityAttraction(0.05, 0.0)), world, T=0.05, duration=3.0, start=Start((0.0, 0.0), heading=1.0))
    vl, vr = run.wheel_speeds[0]
    assert math.isclose((vl + vr) / 2, 0.5 * 0.4, rel_tol=1e-12)
    assert math.isclose((vr - vl) / 0.075, 2.0 * (0.0 - 1.0), rel_tol=1e-12)
    assert np.all(np.diff(run.theta[:5]) < 0)  # turning clockwise towards the target


# -------------------------------------------------------------- bad input


@pytest.mark.parametrize("build, name", [
    (lambda: PointMass(mass=0.0), "mass"),
    (lambda: PointMass(a_max=-1.0), "a_max"),
    (lambda: Steering(0.8, -0.1, 2.0), "tau"),
    (lambda: Steering(0.8, 0.3, 2.0, hold="servo"), "hold"),
    (lambda: DiffDrive(K_s=0.0, v_opt=1.0, rho0_speed=1.0), "K_s"),
    (lambda: DiffDrive(K_s=1.0, v_opt=1.0, rho0_speed=-1.0), "rho0_speed"),
    (lambda: Ball((0.0, 0.0), -0.3), "radius"),
    (lambda: Wall((0.0, 0.0), (0.0, 0.0)), "wall normal"),
    (lambda: Target((math.nan, 0.0)), "target position"),
    (lambda: Pull(0.0, 1.0), "magnitude"),
])
def test_bad_parameters_raise_value_error_naming_them(build, name):
    """Each bad parameter gives a one-line ValueError that names it."""
    with pytest.raises(ValueError, match=name):
        build()


@pytest.mark.parametrize("kw, name", [({"T": 0.0}, "T"), ({"T": -1.0}, "T"), ({"compute_delay": 2}, "compute_delay"),
                                      ({"duration": 0.0}, "duration"), ({"on_collision": "ignore"}, "on_collision")])
def test_bad_run_options_raise_value_error(kw, name):
    """T ≤ 0, compute_delay ∉ {0, 1}, duration ≤ 0 and an unknown collision policy are refused before any step."""
    args = {"T": 0.1, "compute_delay": 0, "duration": 1.0, "start": Start((0.0, 0.0))}
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        simulate_planar(PointMass(), Field(Pull(1.0, 0.0)), World(), **args)


def test_velocity_attraction_needs_a_target():
    """A VelocityAttraction without a target is refused."""
    with pytest.raises(ValueError, match="target"):
        simulate_planar(PointMass(), Field(VelocityAttraction(0.1, 0.1)), World(), T=0.1, duration=1.0, start=Start((0.0, 0.0)))


def test_wall_cycle_bad_input():
    """wall_cycle refuses α outside (0, π/2), a static law and too short a run."""
    rep = VelocityGatedRepulsion(0.1, 2.0, 1.0)
    with pytest.raises(ValueError, match="alpha"):
        wall_cycle(rep, 1.0, 2.0, PointMass(), T=0.065)
    with pytest.raises(ValueError, match="repulsion"):
        wall_cycle(LAW, 1.0, 1.0, PointMass(), T=0.065)
    with pytest.raises(ValueError, match="duration"):
        wall_cycle(rep, 1.0, 1.0, PointMass(), T=0.065, duration=0.5)
