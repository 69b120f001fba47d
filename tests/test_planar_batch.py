"""The batched planar stepper (`sim.planar_batch`) against the former scalar stepper, kept in `tests/planar_oracle.py`.

The oracle is the per-robot loop the simulator had before it was batched (Python floats,
one obstacle after the other); these tests run random members of every kind — point
masses with and without saturation, steering robots of both holds (with a rate limit),
differential drives; velocity attraction towards moving targets and constant pulls;
velocity-gated repulsion of the three variants, a static Khatib law, none; walls, balls
and points, fixed and moving; nearest-only; compute delay 0 and 1; both collision
policies — all in ONE batch, and compare each run with the oracle's: same samples, same
events (kinds, obstacles, order), states within the round-off bound of
`trajectory_helpers.roundoff_bound` (docs/simulator.md, "Batches"), the same wall cycles.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from planar_oracle import simulate_scalar
from trajectory_helpers import EPS, ROUNDOFF_PER_STEP, assert_same_to_roundoff, roundoff_bound

from pfm_stability.laws.fields import KhatibLaw
from pfm_stability.laws.velocity_laws import VARIANTS, VelocityAttraction, VelocityGatedRepulsion
from pfm_stability.sim.movers import Ball, PointObstacle, Target, Wall
from pfm_stability.sim.planar import (
    DiffDrive,
    Field,
    PlanarMember,
    PointMass,
    Pull,
    Start,
    Steering,
    World,
    measure_wall_cycle,
    simulate_planar,
    simulate_planar_batch,
    wall_cycle,
    wall_member,
)
from pfm_stability.sim.results import Trajectory

LAW = KhatibLaw(xi=1.0, eta=0.3, rho0=2.0, m=2.0, rho_g=1.0)


def _robot(rng, kind):
    if kind == "mass":
        return PointMass(float(rng.uniform(0.5, 2.0)), float(rng.choice([math.inf, rng.uniform(0.3, 2.0)])))
    if kind == "command":
        return Steering(float(rng.uniform(0.3, 1.2)), float(rng.choice([0.0, rng.uniform(0.05, 0.5)])), float(rng.uniform(0.5, 4.0)),
                        hold="command", max_rate=float(rng.choice([math.inf, rng.uniform(0.5, 3.0)])))
    if kind == "reference":
        return Steering(float(rng.uniform(0.3, 1.2)), float(rng.uniform(0.0, 0.5)), float(rng.uniform(0.5, 4.0)), hold="reference")
    return DiffDrive(K_s=float(rng.uniform(0.5, 4.0)), v_opt=float(rng.uniform(0.2, 1.0)), rho0_speed=float(rng.uniform(0.3, 2.0)))


def _obstacle(rng):
    moving = tuple(rng.uniform(-0.2, 0.2, 2)) if rng.random() < 0.4 else (0.0, 0.0)
    kind = rng.integers(0, 3)
    if kind == 0:
        angle = rng.uniform(0, 2 * math.pi)
        normal = (math.cos(angle), math.sin(angle))
        return Wall(tuple(-rng.uniform(0.3, 2.0) * np.array(normal)), normal, moving)
    centre = tuple(rng.uniform(-2.5, 2.5, 2))
    return Ball(centre, float(rng.uniform(0.1, 0.5)), moving) if kind == 1 else PointObstacle(centre, moving)


def random_member(rng) -> PlanarMember:
    """A random member near the origin (target within 4 m, obstacles within 2.5 m), 60–200 samples.

    A steering or differential-drive robot whose velocity attraction is dominated by its
    velocity part feels a force opposite to its motion and turns bang-bang (θ_f ≈ θ + π):
    a chaotic regime where round-off grows at its own rate (measured: 1e-16 to 1e-10 m in
    150 samples), beyond `roundoff_bound` at σ = 0; those robots get α_v ≤ α_p/4.
    """
    robot = _robot(rng, rng.choice(["mass", "command", "reference", "diff"]))
    if rng.random() < 0.6:
        alpha_p = float(rng.uniform(0.01, 0.3))
        alpha_v = float(rng.uniform(0.0, 0.3 if isinstance(robot, PointMass) else alpha_p / 4))
        attraction = VelocityAttraction(alpha_p, alpha_v, float(rng.choice([1.0, 2.0])), 2.0)
    else:
        attraction = Pull(float(rng.uniform(0.2, 2.0)), float(rng.uniform(-math.pi, math.pi)))
    choice = rng.integers(0, 3)
    repulsion = (VelocityGatedRepulsion(float(rng.uniform(0.02, 0.3)), float(rng.uniform(0.5, 2.0)), float(rng.uniform(0.5, 3.0)),
                                        str(rng.choice(VARIANTS)), float(rng.choice([0.0, 0.05])))
                 if choice == 0 else LAW if choice == 1 else None)
    field = Field(attraction, repulsion, repulsion_scale=float(rng.uniform(0.2, 2.0)), nearest_only=bool(rng.random() < 0.3))
    world = World(Target(tuple(rng.uniform(-4, 4, 2)), tuple(rng.uniform(-0.1, 0.1, 2))),
                  tuple(_obstacle(rng) for _ in range(rng.integers(0, 4))))
    start = Start(tuple(rng.uniform(-0.3, 0.3, 2)), tuple(rng.uniform(-0.5, 0.5, 2)))
    T = float(rng.uniform(0.02, 0.1))
    return PlanarMember(robot, field, world, start, T=T, duration=float(rng.integers(60, 200)) * T,
                        compute_delay=int(rng.integers(0, 2)), on_collision=str(rng.choice(["stop", "continue"])))


def _oracle(member: PlanarMember):
    return simulate_scalar(member.robot, member.field, member.world, T=member.T, compute_delay=member.compute_delay,
                           duration=member.duration, start=member.start, on_collision=member.on_collision)


def _trajectory(t, p, theta):
    return Trajectory(t, p[:, 0], p[:, 1], np.zeros_like(t) if theta is None else theta)


@pytest.fixture(scope="module")
def random_batch():
    """40 random members (seed 2026) and two head-on approaches to a ball (GC2002 eq 23's scene, D ≤ 0 on the way:
    ``collision_unavoidable``, stopping or continuing), run as one batch, and each by the oracle."""
    rng = np.random.default_rng(2026)
    members = [random_member(rng) for _ in range(40)]
    ball = World(Target((0.0, 0.0)), (Ball((0.8, 0.0), 0.3),))
    field = Field(VelocityAttraction(0.005, 0.1), VelocityGatedRepulsion(0.2, 2.0, 0.5))
    for policy in ("stop", "continue"):
        members.insert(20, PlanarMember(PointMass(1.0, 0.5), field, ball, Start((-1.5, 0.0), (1.6, 0.0)), T=0.01, duration=2.0,
                                        on_collision=policy))
    return members, simulate_planar_batch(members), [_oracle(m) for m in members]


@pytest.mark.xdist_group("planar_random_batch")  # its module fixture once per suite (tests/conftest.py)
def test_batch_matches_scalar_oracle_on_random_members(random_batch):
    """Every member of a mixed batch of 42 members agrees with the former scalar stepper run alone.

    Same number of samples and stop reason; p and θ within `roundoff_bound` (64 ε per step of
    the run's scale, σ = 0: these runs are bounded, and the differences measured are 0 to a few
    ULP — numpy's vectorized hypot, arctan2 and power against Python's math, and a 2-vector
    dot product with or without fused multiply-add); v within the same bound of its own scale.
    """
    members, batch, oracle = random_batch
    kinds = set()
    for i, (member, run, want) in enumerate(zip(members, batch.runs, oracle)):
        label = f"member {i} ({type(member.robot).__name__})"
        assert run.t.size == want.t.size, label
        assert run.stop_reason == want.stop_reason, label
        assert np.array_equal(run.t, want.t), label
        position, heading = roundoff_bound(_trajectory(want.t, want.p, want.theta), 0.0)
        assert np.all(np.hypot(*(run.p - want.p).T) <= position + 1e-300), label
        if want.theta is not None:
            assert np.all(np.abs(run.theta - want.theta) <= heading + 1e-300), label
        else:
            assert run.theta is None
        k = np.arange(want.t.size) + 1.0
        speed_scale = float(np.max(np.abs(want.v))) or 1.0
        assert np.all(np.hypot(*(run.v - want.v).T) <= ROUNDOFF_PER_STEP * EPS * k * speed_scale), label
        assert (run.wheel_speeds is None) == (want.wheel_speeds is None), label
        kinds.add((type(member.robot).__name__, getattr(member.robot, "hold", ""), type(member.field.repulsion).__name__))
    assert len(kinds) >= 8  # the draw covers the robots × repulsions


@pytest.mark.xdist_group("planar_random_batch")  # its module fixture once per suite (tests/conftest.py)
def test_batch_forces_match_scalar_oracle(random_batch):
    """The recorded forces agree with the oracle's to 1e-9 of the run's largest force.

    The force is a function of the state whose slope near an obstacle reaches ~η/D³ (1e3–1e6
    per metre here), so round-off differences of the state (≤ 1e-13 m) show up amplified in it;
    1e-9 relative is ≥ 1e3 above that and far below any force of interest.
    """
    members, batch, oracle = random_batch
    for i, (run, want) in enumerate(zip(batch.runs, oracle)):
        scale = float(np.max(np.abs(want.force))) or 1.0
        assert np.max(np.abs(run.force - want.force)) <= 1e-9 * scale, f"member {i}"
        if want.wheel_speeds is not None:
            assert np.allclose(run.wheel_speeds, want.wheel_speeds, rtol=0, atol=1e-12), f"member {i}"


@pytest.mark.xdist_group("planar_random_batch")  # its module fixture once per suite (tests/conftest.py)
def test_batch_events_identical_to_scalar_oracle(random_batch):
    """Events: the same kinds on the same obstacles in the same order; times equal to 1e-9 s.

    A crossing time is interpolated between two samples from quantities that agree to
    round-off, so it agrees to round-off too (divided by the quantity's change over a period,
    ≥ 1e-6 here); 1e-9 s is far below the sampling periods (≥ 0.02 s). The draw holds every
    kind of event.
    """
    members, batch, oracle = random_batch
    seen = set()
    for i, (run, want) in enumerate(zip(batch.runs, oracle)):
        got = [(e.kind, e.obstacle) for e in run.events]
        assert got == [(e.kind, e.obstacle) for e in want.events], f"member {i}"
        times = np.array([e.time for e in run.events]) - np.array([e.time for e in want.events])
        assert np.all(np.abs(times) <= 1e-9), f"member {i}"
        assert run.collision == want.collision
        seen.update(k for k, _ in got)
    assert seen == {"gate_open", "gate_close", "influence_enter", "influence_exit", "contact", "collision_unavoidable"}


@pytest.mark.xdist_group("planar_random_batch")  # its module fixture once per suite (tests/conftest.py)
def test_member_alone_equals_member_in_batch(random_batch):
    """A member run alone (`simulate_planar`, a batch of one) agrees with its run inside the mixed batch.

    Bit for bit is not promised (numpy's SIMD kernels round an array's body and tail
    differently): `assert_same_to_roundoff` with σ = 0, the runs being bounded.
    """
    members, batch, _ = random_batch
    for i in (0, 7, 19, 33):
        m = members[i]
        alone = simulate_planar(m.robot, m.field, m.world, T=m.T, compute_delay=m.compute_delay, duration=m.duration,
                                start=m.start, on_collision=m.on_collision)
        inside = batch.runs[i]
        assert_same_to_roundoff(_trajectory(alone.t, alone.p, alone.theta), _trajectory(inside.t, inside.p, inside.theta), 0.0, f"member {i}")
        assert [(e.kind, e.obstacle) for e in alone.events] == [(e.kind, e.obstacle) for e in inside.events]


def test_members_stop_independently():
    """Masking: in one batch a member stops at t = 0 (unavoidable collision), one at a contact, one runs its
    full duration and one is shorter; each has exactly the samples and events of its run alone (the oracle)."""
    ball = World(Target((0.0, 0.0)), (Ball((0.8, 0.0), 0.3),))
    field = Field(VelocityAttraction(0.005, 0.1), VelocityGatedRepulsion(0.2, 2.0, 0.5))
    members = [
        PlanarMember(PointMass(1.0, 0.5), field, ball, Start((-1.5, 0.0), (3.0, 0.0)), T=0.01, duration=2.0),
        PlanarMember(PointMass(1.0, 0.5), field, ball, Start((-1.5, 0.0), (3.0, 0.0)), T=0.01, duration=2.0, on_collision="continue"),
        PlanarMember(PointMass(1.0, 0.5), field, ball, Start((-1.5, 0.0), (0.2, 0.0)), T=0.01, duration=3.0),
        PlanarMember(Steering(0.8, 0.3, 2.0), Field(Pull(1.0, 0.0)), World(), Start((0.0, 0.0)), T=0.05, duration=1.0),
    ]
    batch = simulate_planar_batch(members)
    assert [r.stop_reason for r in batch.runs] == ["collision_unavoidable", "contact", "duration", "duration"]
    for member, run in zip(members, batch.runs):
        want = _oracle(member)
        assert run.t.size == want.t.size and run.stop_reason == want.stop_reason
        assert [(e.kind, e.obstacle) for e in run.events] == [(e.kind, e.obstacle) for e in want.events]
    assert batch.robot_steps == sum(r.t.size - 1 for r in batch.runs)


@pytest.mark.parametrize("robot, delay", [(Steering(0.8, 0.3, 2.0, hold="command"), 1), (Steering(0.8, 0.3, 2.0, hold="command"), 0),
                                          (Steering(0.8, 0.3, 2.0, hold="reference"), 1), (PointMass(1.0, 1.0), 1)])
def test_wall_cycle_equals_oracle_cycle(robot, delay):
    """`wall_cycle` (through the batch) measures the same cycle as the oracle's run of the same wall, to 1e-9.

    The wall runs of GC2002's velocity-gated repulsion (η = 0.1, ρ0 = 2, a_max = 1, F_a = 1,
    α = 60°, T = 0.065 s, 20 s): a relay, whose gate decisions the two steppers take alike;
    the measures are means, extrema and turning-point times of states equal to round-off,
    so 1e-9 (relative, or absolute for the period in s) leaves a 1e5 margin.
    """
    rep, alpha = VelocityGatedRepulsion(0.1, 2.0, 1.0), math.radians(60.0)
    member = wall_member(rep, 1.0, alpha, robot, T=0.065, compute_delay=delay, duration=20.0)
    got = wall_cycle(rep, 1.0, alpha, robot, T=0.065, compute_delay=delay, duration=20.0).to_dict()
    want = measure_wall_cycle(_oracle(member)).to_dict()
    for key, value in want.items():
        if isinstance(value, float):
            assert math.isclose(got[key], value, rel_tol=1e-9, abs_tol=1e-12), key
        else:
            assert got[key] == value, key


def test_wall_cycles_in_one_batch_equal_one_at_a_time():
    """Four wall runs (T, delay, robot varied) as one batch measure the cycles of six separate `wall_cycle` calls (1e-9)."""
    rep, alpha = VelocityGatedRepulsion(0.1, 2.0, 1.0), math.radians(60.0)
    cases = [(Steering(0.8, 0.3, 2.0, hold="command"), 0.065, 0), (Steering(0.8, 0.3, 2.0, hold="command"), 0.1, 1),
             (PointMass(1.0, 1.0), 0.065, 1), (Steering(0.8, 0.0, 2.0, hold="command"), 0.1, 1)]
    batch = simulate_planar_batch([wall_member(rep, 1.0, alpha, r, T=T, compute_delay=d, duration=15.0) for r, T, d in cases])
    for (robot, T, d), run in zip(cases, batch.runs):
        alone = wall_cycle(rep, 1.0, alpha, robot, T=T, compute_delay=d, duration=15.0).to_dict()
        for key, value in measure_wall_cycle(run).to_dict().items():
            if isinstance(value, float):
                assert math.isclose(value, alone[key], rel_tol=1e-9, abs_tol=1e-12), (key, T, d)
            else:
                assert value == alone[key], (key, T, d)


def test_point_mass_motion_is_exact_under_constant_force():
    """Independent route: a point mass under a constant pull F (no saturation) is at p0 + v0 t + F t²/(2m) at every sample.

    The stepper applies p += vT + aT²/2, v += aT; the sum over k steps equals the closed
    form up to the round-off of k additions (tolerance 1e-12 m over 50 samples of metres).
    """
    F, angle, m = 0.7, 0.4, 2.0
    run = simulate_planar(PointMass(m), Field(Pull(F, angle)), World(), T=0.1, duration=5.0, start=Start((1.0, -1.0), (0.3, 0.2)))
    a = F / m * np.array([math.cos(angle), math.sin(angle)])
    want = np.array([1.0, -1.0]) + np.outer(run.t, [0.3, 0.2]) + 0.5 * np.outer(run.t**2, a)
    assert np.allclose(run.p, want, rtol=0, atol=1e-12)


def test_diff_drive_arc_is_exact():
    """Independent route: a differential drive with a constant command follows the circle of radius v/ω.

    With no obstacle (ρ = inf, v = v_opt) and a pull perpendicular to the start heading, the
    first period's command is ω = K_s·π/2; its end point is on the circle through the start
    with centre p0 + (v/ω)·(−sin θ0, cos θ0), at arc angle ωT (closed form, 1e-12 m).
    """
    robot = DiffDrive(K_s=1.5, v_opt=0.6, rho0_speed=1.0)
    run = simulate_planar(robot, Field(Pull(1.0, math.pi / 2)), World(), T=0.2, duration=0.2, start=Start((0.5, 0.5), heading=0.0))
    omega, v, T = 1.5 * math.pi / 2, 0.6, 0.2
    R = v / omega
    want = np.array([0.5 + R * math.sin(omega * T), 0.5 + R * (1 - math.cos(omega * T))])
    assert np.allclose(run.p[1], want, rtol=0, atol=1e-12)
    assert math.isclose(run.theta[1], omega * T, rel_tol=1e-12)


def test_non_finite_state_raises_naming_the_member():
    """A member whose attraction overflows (m = 10: F ∝ ‖e‖⁹, overshooting further every period) raises
    FloatingPointError naming it; its batch-mate is not blamed."""
    calm = PlanarMember(PointMass(), Field(Pull(1.0, 0.0)), World(), Start((0.0, 0.0)), T=1.0, duration=200.0)
    wild = PlanarMember(PointMass(), Field(VelocityAttraction(1.0, 0.0, m=10.0)), World(Target((0.0, 0.0))), Start((10.0, 0.0)),
                        T=1.0, duration=200.0)
    with pytest.raises(FloatingPointError, match="member 1"):
        simulate_planar_batch([calm, wild])


def test_batch_bad_input():
    """An empty batch, or something else than a PlanarMember, is refused with a one-line ValueError."""
    with pytest.raises(ValueError, match="members"):
        simulate_planar_batch([])
    with pytest.raises(ValueError, match="members"):
        simulate_planar_batch([object()])
    with pytest.raises(ValueError, match="T"):
        PlanarMember(PointMass(), Field(Pull(1.0, 0.0)), World(), Start((0.0, 0.0)), T=0.0, duration=1.0)


@pytest.mark.parametrize("J", [1, 4, 12, 32, 33, 64])
def test_node_sum_is_cumsum_bit_for_bit(J):
    """`sim.robot.node_sum` (a column at a time for short rules) equals numpy's sequential cumsum bit for bit.

    Both add the nodes left to right, so the results are identical, not merely close: the
    zero-weight padding of a batch's shorter rules still adds nothing (docs/simulator.md, "Batches").
    """
    from pfm_stability.sim.robot import node_sum

    rng = np.random.default_rng(J)
    for shape in ((50, J), (50, J, 3)):
        a = rng.normal(size=shape) * 10.0 ** rng.integers(-8, 8, size=shape)
        assert np.array_equal(node_sum(a), np.cumsum(a, axis=1)[:, -1])
