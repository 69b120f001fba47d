"""The batch engine: against the per-robot Python loop, events, determinism, heterogeneous batches."""

import json
import math

import numpy as np
import pytest

from pfm_stability.parameters import CARMEL
from pfm_stability.sim import make_scenario, run_batch, simulate, simulate_batch, simulate_reference
from trajectory_helpers import assert_same_to_roundoff

REFERENCE = CARMEL.controller.replace(hold="reference")
CASES = [
    ("corridor", dict(env="grid", L=0.6, offset=0.05)),  # grows into a collision
    ("kb-fig5", dict(env="grid")),  # staircase wall, corner, collision
    ("wall", dict(env="analytic", alpha=0.5)),  # analytic wall, power law
    ("straight", dict(env="grid", controller=REFERENCE)),  # servo hold, point target
    ("kb-fig3", dict(controller=REFERENCE, cell_ratio=0.02)),  # servo saturates avoiding the block
    ("kb-fig3", dict(speed_law=True)),  # VFF speed law stops the robot: trapped
    ("kb-fig6-narrow", dict(env="analytic", law="grid", controller=CARMEL.controller.replace(compute_delay=0))),
]


def test_batch_engine_equals_per_robot_loop():
    """One batch of seven different members equals seven independent per-robot loops (`simulate_reference`).

    The two share no stepping code; the steering solutions are the same closed
    forms, the window sums add the same terms in another order, so they agree
    to round-off accumulated over ~300 steps (1e-11 m, 1e-11 rad), with the
    same events at the same times (1e-9 s).
    """
    scenarios = [make_scenario(name, **kw) for name, kw in CASES]
    batch = run_batch(scenarios)
    kinds = set()
    for s, run in zip(scenarios, batch.runs):
        trajectory, event = simulate_reference(s)
        assert len(trajectory.x) == len(run.trajectory.x)
        assert np.allclose(run.trajectory.x, trajectory.x, atol=1e-11, rtol=0)
        assert np.allclose(run.trajectory.y, trajectory.y, atol=1e-11, rtol=0)
        assert np.allclose(run.trajectory.theta, trajectory.theta, atol=1e-11, rtol=0)
        assert (event is None) == (not run.events)
        if event is not None:
            assert run.events[0].type == event.type
            assert run.events[0].t == pytest.approx(event.t, abs=1e-9)
            kinds.add(event.type)
    assert kinds == {"collision", "target_reached", "trapped"}


def test_straight_run_reaches_the_target():
    """No obstacles, target 17° off the initial heading: the robot turns and reaches it (docs/simulator.md)."""
    run = simulate("straight")
    assert [e.type for e in run.events] == ["target_reached"]
    t = run.scenario.target
    assert math.hypot(run.events[0].x - t.x, run.events[0].y - t.y) <= t.radius
    assert run.events[0].t < run.scenario.duration


def test_collisions_are_reported_as_events():
    """A robot driven into a wall reports a collision event with its time; the run stops there."""
    run = simulate("corridor", env="grid", L=0.6, offset=0.05)
    event = run.event("collision")
    assert event is not None and 0 < event.t < run.scenario.duration
    assert run.t_end == pytest.approx(event.t, abs=run.scenario.controller.T)
    assert run.min_clearance <= 0
    assert not run.metrics.stable and run.metrics.time_to_collision == event.t


def test_identical_seeds_give_identical_trajectories():
    """A random start jitter drawn from the seed: same seed → bit-identical runs, another seed → another run.

    Bit for bit is legitimate here: both runs take the same code path on arrays
    of the same shapes (one member), so every SIMD kernel rounds alike.
    """
    a = simulate("corridor", L=0.8, seed=7, start_jitter=0.05)
    b = simulate("corridor", L=0.8, seed=7, start_jitter=0.05)
    c = simulate("corridor", L=0.8, seed=8, start_jitter=0.05)
    assert np.array_equal(a.trajectory.x, b.trajectory.x) and np.array_equal(a.trajectory.y, b.trajectory.y)
    assert not np.array_equal(a.trajectory.x, c.trajectory.x)


def test_heterogeneous_batch_equals_separate_runs():
    """Members with different V, k, T, hold, delay and L in one batch advance as when run alone, to round-off.

    Not bit for bit: numpy's SIMD kernels (sin, cos, exp) round an element of a
    3-member array and of a 1-member array differently on AVX-512 machines
    (docs/simulator.md, "Batches"). Tolerance `trajectory_helpers.roundoff_bound`:
    64 ε per step of the run's scale, times e^(σ⁺t) for the growing member —
    40× the measured worst, far below the millimetres a mixed-up member
    (another member's V, T or law) would show.
    """
    params = dict(
        V=[0.6, 0.8, 1.0], k=[1.5, 2.0, 3.0], T=[0.05, 0.065, 0.1], hold=["command", "reference", "command"],
        compute_delay=[0, 1, 1], L=[0.8, 0.9, 1.1],
    )
    batch = simulate_batch("corridor", env="analytic", record="trajectory", duration=8.0, **params)
    for m in range(3):
        one = simulate_batch("corridor", env="analytic", record="trajectory", duration=8.0, **{k: [v[m]] for k, v in params.items()})
        alone = one.runs[0]
        assert_same_to_roundoff(batch.runs[m].trajectory, alone.trajectory, alone.metrics.growth_rate, f"member {m}")
    assert batch.runs[2].steps == round(8.0 / 0.1)


def test_results_serialize_without_nan():
    """Every run's JSON has the documented keys and no NaN (docs/simulator.md: never a silent NaN)."""
    batch = simulate_batch("corridor", env="grid", L=[0.6, 1.0], offset=0.05, duration=12.0)
    for run in batch.runs:
        d = json.loads(json.dumps(run.to_dict(), allow_nan=False))
        assert {"events", "metrics", "inputs"} <= set(d)
        assert {"growth_rate", "angular_frequency", "oscillating", "stable"} <= set(d["metrics"])
    assert batch.collided.tolist() == [True, False]
    assert batch.growth_rate.mask.tolist() == [False, False]


def test_bad_batch_arguments():
    with pytest.raises(ValueError, match="one length"):
        simulate_batch("corridor", L=[0.8, 0.9], V=[0.5, 0.6, 0.7])
    with pytest.raises(ValueError, match="unknown parameter"):
        simulate_batch("corridor", width=1.0)
    with pytest.raises(ValueError, match="at least one"):
        run_batch([])


def test_start_inside_an_obstacle_is_a_collision_at_time_zero():
    """A random start jitter that lands the robot in a wall's cells (a cell no robot can occupy, left out of the
    window tables) is reported as a collision at t = 0 — never an internal error."""
    import numpy as np

    seed = next(s for s in range(100) if abs(np.random.default_rng(s).normal(0.0, 0.4)) > 0.45)
    run = simulate("corridor", L=0.6, seed=seed, start_jitter=0.4)
    assert [(e.type, e.t) for e in run.events] == [("collision", 0.0)]
    assert run.min_clearance < -0.05
