"""Path targets (`Target.follow`, `sim.follow`): the pure-pursuit carrot, the batch engine against the per-robot loop.

docs/simulator.md, "What is simulated" (targets). The expected values are geometry: the carrot of a robot beside a
straight path is its foot point plus the lookahead, the progress never goes back, and the part of a path that passes
close again later is not taken for the robot's place.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pfm_stability.sim import make_scenario, run_batch, simulate_reference
from pfm_stability.sim.follow import PathFollower
from pfm_stability.sim.scenario import Target


def _follower(*targets):
    return PathFollower(list(targets))


def test_carrot_is_the_foot_point_plus_the_lookahead_and_progress_never_goes_back():
    """A robot 0.3 m beside a straight path at arc 2 m: its progress moves by at most the lookahead (L = 1.5 m) per
    sample, to 1.5 m then 2 m, its carrot at arc 3.5 m; moved back to arc 1 m, its progress stays at 2 m; near the
    end the carrot is the end. Exact to round-off (1e-12 m)."""
    f = _follower(Target.follow([(0, 0), (0, 5), (0, 10)], 1.5))
    f.advance(np.array([0.3]), np.array([2.0]))
    assert f.s[0] == pytest.approx(1.5, abs=1e-12)
    f.advance(np.array([0.3]), np.array([2.0]))
    assert f.s[0] == pytest.approx(2.0, abs=1e-12)
    assert np.allclose(f.carrot(), ([0.0], [3.5]), atol=1e-12)
    f.advance(np.array([-0.2]), np.array([1.0]))
    assert f.s[0] == pytest.approx(2.0, abs=1e-12)
    for y in np.arange(3.0, 9.5, 0.5):
        f.advance(np.array([0.0]), np.array([y]))
    assert f.s[0] == pytest.approx(9.0, abs=1e-12)
    assert np.allclose(f.carrot(), ([0.0], [10.0]), atol=1e-12)


def test_a_hairpin_is_not_cut_short_and_paths_of_any_length_batch_together():
    """A hairpin: out 4 m along y, 0.6 m across, back. A robot at the start lies 0.6 m from the way back (arc 8.6 m),
    but only the arc within one lookahead (1 m) is searched: its progress is its own foot point, 0.5 m. A second,
    shorter path in the same batch (padded with its last vertex) gives its own carrot; a diagonal segment's carrot
    lies on it at the lookahead's arc."""
    hairpin = Target.follow([(0, 0), (0, 4), (0.6, 4), (0.6, 0)], 1.0)
    short = Target.follow([(0, 0), (3, 4)], 2.0)
    f = _follower(hairpin, short)
    f.advance(np.array([0.55, 0.0]), np.array([0.5, 0.0]))
    assert f.s == pytest.approx([0.5, 0.0], abs=1e-12)
    cx, cy = f.carrot()
    assert (cx[0], cy[0]) == pytest.approx((0.0, 1.5), abs=1e-12)
    assert (cx[1], cy[1]) == pytest.approx((1.2, 1.6), abs=1e-12)
    for _ in range(40):  # walking the hairpin's way: the progress follows it round the bend
        x, y = f.carrot()
        f.advance(x, y)
    assert f.s == pytest.approx([8.6, 5.0], abs=1e-12)


def test_bad_paths_are_refused_with_the_values_given():
    for points, lookahead, words in (([(0, 0)], 1.0, "at least two distinct points; got 1"),
                                     ([(0, 0), (0, 0)], 1.0, "at least two distinct points; got 1"),
                                     ([(0, 0), (math.nan, 1)], 1.0, "finite"),
                                     ([(0, 0), (0, 1)], 0.0, "lookahead must be a finite number in (0, inf) m; got 0.0"),
                                     ([0, 1, 2], 1.0, "shape (3,)")):
        with pytest.raises(ValueError, match=None) as info:
            Target.follow(points, lookahead)
        assert words in str(info.value)


def test_path_targets_in_the_batch_engine_equal_the_per_robot_loop():
    """Three path-following runs — round KB's wall corner (figure 5), a weaving path in a corridor to its end, and one
    stopped by the VFF speed law before a block (trapped: its progress along the path stalls) — batched with a
    point-target run, against `simulate_reference`, whose carrot is its own per-segment loop: the same trajectories to round-off (1e-11 m and
    rad over ~300 steps, as tests/test_sim_engine.py) and the same events (1e-9 s)."""
    fig5 = make_scenario("kb-fig5", env="grid")
    turn = math.radians(30.0)
    corner = [(fig5.start.x, fig5.start.y), (fig5.start.x + 2.0, 4.0), (fig5.start.x + 2.0 + 14 * math.sin(turn), 4.0 + 14 * math.cos(turn))]
    corridor = make_scenario("corridor", env="grid", L=1.0, offset=0.05)
    blocked = make_scenario("kb-fig3", speed_law=True)  # the VFF speed law stops it before the block
    members = [dataclasses.replace(fig5, target=Target.follow(corner, 2.0, 0.3)),
               dataclasses.replace(corridor, target=Target.follow([(0, 0), (0, 3), (0.3, 6), (0, 12)], 1.0, 0.3)),
               dataclasses.replace(blocked, target=Target.follow([(blocked.start.x, blocked.start.y), (blocked.start.x, 30.0)], 1.5)),
               make_scenario("straight", env="grid")]
    kinds = set()
    for s, run in zip(members, run_batch(members).runs):
        trajectory, event = simulate_reference(s)
        assert len(trajectory.x) == len(run.trajectory.x)
        for a, b in ((run.trajectory.x, trajectory.x), (run.trajectory.y, trajectory.y), (run.trajectory.theta, trajectory.theta)):
            assert np.allclose(a, b, atol=1e-11, rtol=0)
        assert (event is None) == (not run.events)
        if event is not None:
            assert run.events[0].type == event.type and run.events[0].t == pytest.approx(event.t, abs=1e-9)
            kinds.add(event.type)
    assert {"target_reached", "trapped"} <= kinds
