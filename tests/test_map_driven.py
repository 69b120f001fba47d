"""The loop driven along a route through the force across it (`maps.judging.driven.driven_loops`, docs/maps.md, "The loop driven
along the route"), its command form (`models.sampled.command_form`), and the drives' unmeasurable ends
(`validation.map_drives`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfm_stability.maps.judging.driven import DriveRequest, SampledTransition, driven_loops
from pfm_stability.maps.deciding.verdicts import GrowthRate, effective_gain
from pfm_stability.models import Loop, models_for
from pfm_stability.models.sampled import closed_loop_matrix, command_form
from pfm_stability.parameters import CARMEL
from test_map_paths import SHARED_CORRIDORS, corridors_root


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    """`test_map_paths.corridor_analysis`' folder: its analyses of the 1.2 m corridor are shared with that module's tests."""
    return corridors_root(tmp_path_factory)


def _driven(route, arc, stopped, profile, pull, attraction, aim, V: float, transition, period: float, taken, track=None):
    """(oscillates, amplitude, excursion) of the loop driven at one speed V: `driven_loops` with one `DriveRequest`."""
    loop = driven_loops(route, arc, profile, [DriveRequest(V, stopped, pull, attraction, aim)], transition, period, taken, track)[0]
    return loop.oscillates, loop.amplitude, loop.excursion


def _loops(seed: int, count: int):
    """Random KB loops (τ, T, k, plant gain g, dead time D) with each hold and compute delay."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        T = float(rng.uniform(0.01, 0.2))
        loop = Loop(float(rng.uniform(0.0, 0.5)), T, float(rng.uniform(0.5, 20.0)), plant_gain=float(rng.uniform(0.5, 1.5)),
                    dead_time=float(rng.choice([0.0, rng.uniform(0.0, 3 * T)])))
        hold = "reference" if loop.dead_time == 0 and loop.tau > 0 and rng.random() < 0.3 else "command"
        yield loop, hold, int(rng.integers(0, 2))


def test_command_form_rebuilds_the_closed_loop_matrix():
    """Φ_cl(K) = M − n·(F0 + K·F1) (`command_form`) against `closed_loop_matrix` at random loops (τ, T, k, g, D), both
    holds, both compute delays and random gains K, to round-off: 1e-12 relative to |Φ| (the same blocks, summed in
    another order)."""
    rng = np.random.default_rng(7)
    for loop, hold, delay in _loops(3, 40):
        M, n, F0, F1 = command_form(loop, hold, delay)
        for K in rng.uniform(-5.0, 200.0, 3):
            expected = closed_loop_matrix(loop, K, hold, delay)
            got = M - np.outer(n, F0 + K * F1)
            assert np.abs(got - expected).max() <= 1e-12 * max(1.0, np.abs(expected).max()), (loop, hold, delay, K)


def _transition(robot, controller, max_rate=math.inf):
    model = models_for(controller, ["sampled"])[0]
    loop = Loop.of(robot, controller, c=0.0)
    return model, loop, SampledTransition.of(model, loop, max_rate)


def _straight(N: float, steps: int, spacing: float, reach: float = 1.0):
    """One straight route of `steps` samples `spacing` m apart whose force across it is linear, F_n = −N·s (F_ct units,
    F_r·t = 0): the loop driven through it is the linear loop at gain N."""
    offsets = np.arange(-reach, reach + 1e-9, spacing / 4)
    fn = np.tile(-N * offsets, (steps, 1))
    return offsets, fn, np.zeros_like(fn)


@pytest.mark.parametrize("ratio", [0.5, 0.9, 1.3])
def test_a_linear_force_drives_the_linear_loop(ratio, monkeypatch):
    """Through a force linear across the route (gain N, no rate limit) the driven loop is the linear sampled loop:
    its lateral position step by step equals x_(k+1) = Φ(NV)·x_k (`closed_loop_matrix`, an independent product)
    started at the same offset, below, near and above NV*. The robot steers to the resultant's direction,
    atan(N·y) ≈ N·y − (N·y)³/3: started 1 µm off and compared while |y| <= 0.1 mm, the cubic term is below 1e-7 of
    the command (N·y <= 5e-4 here), so the two agree to 1e-12 m + 1e-6·|y| (round-off and that term, with margin)."""
    import pfm_stability.maps.judging.driven as driven

    monkeypatch.setattr(driven, "PREDICTION_OFFSET", 1e-6)
    robot, controller = CARMEL.robot, CARMEL.controller
    model, loop, tr = _transition(robot, controller)
    N = ratio * model.boundary(loop).NV_critical / robot.V
    spacing = robot.V * controller.T
    steps = 400
    profile = _straight(N, steps, spacing, reach=5.0)
    arc = (np.arange(steps) + 0.5) * spacing
    route = np.zeros(steps, dtype=int)
    stopped = np.zeros((2, steps), dtype=bool)
    captured = {}
    import pfm_stability.maps.judging.episodes as episodes

    original = episodes.lateral_episodes

    def spy(t, lateral, period, *args):
        captured.setdefault("lateral", lateral.copy())
        return original(t, lateral, period, *args)

    monkeypatch.setattr(episodes, "lateral_episodes", spy)
    _driven(route, arc, stopped, profile, np.zeros(steps), np.ones(steps), np.zeros(steps), robot.V, tr, 1.0, taken=True)
    lateral = captured["lateral"]
    Phi = closed_loop_matrix(loop, loop.loop_gain(N * robot.V), model.hold, model.compute_delay)
    x = np.zeros(Phi.shape[0])
    x[tr.lateral_index] = 1e-6 / robot.V  # the driven loop's start, the state x/V
    expected = []
    for _ in range(lateral.size):
        expected.append(robot.V * x[tr.lateral_index])
        x = Phi @ x
    expected = np.array(expected)
    small = np.abs(expected) <= 1e-4
    n = int(np.argmin(small)) if not small.all() else small.size
    assert n >= 50 and N * 1e-4 <= 5e-4
    assert np.all(np.abs(lateral[:n] - expected[:n]) <= 1e-12 + 1e-6 * np.abs(expected[:n]))


def test_the_steering_rate_limit_holds_an_unstable_loop_in_a_cycle():
    """At 1.5·NV* the linear loop grows until the heading reference saturates (decimetres); with the robot's steering-rate limit
    (120°/s) the driven loop settles on a cycle that stays inside it (1.2 cm; the VFF simulator's is about 2 cm in the
    grid corridor at 1.4 V*, docs/maps.md: the driven loop's saturated cycles run smaller than the simulator's). The robot
    of the map tests' straight corridor (k = 20 1/s, τ = 0.1 s, T = 25 ms), whose command reaches the limit at a
    heading error of 0.1 rad (CARMEL's k = 2 1/s only past 1 rad, after the run has left)."""
    robot = CARMEL.robot.replace(W=0.4, tau=0.1, k=20.0, V=1.0)
    controller = CARMEL.controller.replace(T=0.025, f=2.0)
    model, loop, tr = _transition(robot, controller, robot.max_steering_rate)
    assert tr.rate_limit == pytest.approx(robot.plant_gain * robot.max_steering_rate)
    N = 1.5 * model.boundary(loop).NV_critical / robot.V
    spacing = robot.V * controller.T
    steps = 3000
    profile = _straight(N, steps, spacing, reach=5.0)
    arc = (np.arange(steps) + 0.5) * spacing
    _, amplitude, excursion = _driven(np.zeros(steps, dtype=int), arc, np.zeros((2, steps), dtype=bool), profile, np.zeros(steps), np.ones(steps), np.zeros(steps),
                           robot.V, tr, 2 * math.pi / model.boundary(loop).omega_critical, taken=False)
    assert 0.005 < amplitude.max() < 0.1  # the cycle, inside the profile: it never left
    # on the settled cycle (the run's second half, less its last period) the farthest it strays from its one-period
    # average is the cycle's amplitude too: within 5 % of the held weave (1.23 against 1.21 cm measured)
    settled = slice(steps // 2, steps - 200)
    assert excursion[settled] == pytest.approx(amplitude[settled], rel=0.05)
    unlimited = SampledTransition.of(model, loop)
    _, free, _ = _driven(np.zeros(steps, dtype=int), arc, np.zeros((2, steps), dtype=bool), profile, np.zeros(steps), np.ones(steps), np.zeros(steps), robot.V, unlimited,
                      2 * math.pi / model.boundary(loop).omega_critical, taken=False)
    # without the limit only the heading reference's own bound holds it (the resultant's direction, |atan| < π/2):
    # a cycle of decimetres (0.45 m here), not centimetres
    assert free.max() >= 10 * amplitude.max()


def test_effective_gain_of_a_window_that_decays_faster_than_any_uniform_gain():
    """A window whose gain varies can decay faster than the most damped uniform gain (found on the TurtleBot sandbox
    at W 0.3 m, V 0.5 m/s, seed 1: a bisection with no sign change, a traceback): N_eff is then that most damped gain,
    and a growth rate inside the uniform range still bisects to σ(N_eff·V) = σ̄ (1e-9 1/s)."""
    robot, controller = CARMEL.robot, CARMEL.controller
    model, loop, _ = _transition(robot, controller)
    boundary = model.boundary(loop)
    growth = GrowthRate(lambda NV: model.rightmost_root(NV, loop), boundary.NV_critical)
    least = growth.NV_least
    fastest = float(growth(least))
    assert effective_gain(fastest - 0.1, least / robot.V, robot.V, growth, boundary.NV_critical) == pytest.approx(least / robot.V)
    sigma = 0.5 * fastest
    N = effective_gain(sigma, 0.5 * least / robot.V, robot.V, growth, boundary.NV_critical)
    assert abs(float(growth(N * robot.V)) - sigma) <= 1e-9


@SHARED_CORRIDORS
@pytest.mark.parametrize("stall", [None, 1.5])
def test_a_drives_last_three_periods_are_not_measured(root, stall, monkeypatch):
    """A drive that reaches its goal (or collides) in less than three periods after passing a sample could not have
    shown an episode there: those samples are counted as unmeasured, never scored. On the stable corridor (0.7 V*,
    no episode) every drive's last 3·P·V metres of own path (less its first period) are unmeasured, to within a few
    samples of its path (the match is to the nearest sample, 0.1 m apart) per drive.

    A drive that stalls ended when its progress stopped, `stall_time` before the simulator calls it trapped: the same
    drives relabelled as stalled, with a stall time of 1.5 s (0.8 m at this V, more than the 0.3 m tolerance), have
    their last (3·P + 1.5 s)·V metres unmeasured."""
    from dataclasses import replace

    from test_map_paths import _report, corridor_analysis

    import pfm_stability.validation.map_drives as map_drives
    from pfm_stability.sim.events import Event

    if stall is not None:
        real = map_drives.run_batch

        def stalled(scenarios, **options):
            outcome = real(scenarios, **options)
            runs = [replace(r, events=(Event("trapped", r.t_end, 0.0, 0.0),)) for r in outcome.runs]
            return replace(outcome, runs=tuple(runs))

        monkeypatch.setattr(map_drives, "run_batch", stalled)
        monkeypatch.setattr(map_drives, "stall_time", lambda V: stall)
    V_star = _report(0.6).models["sampled"].critical["V_critical"]
    analysis = corridor_analysis(0.6, 0.7 * V_star, root)
    result = map_drives.drive_map(analysis, 4, seed=3)
    assert result.counts["episodes"] == 0
    assert result.counts.get("ended_trapped", 0) == (len(result.drives) if stall else 0)
    period, V = result.inputs["period"], analysis.robot.V
    expected = 0.0
    for d in result.drives:
        length = d.duration * V
        expected += max(0.0, min((3 * period + (stall or 0.0)) * V, length - max(0.0, min(period, 0.25 * d.duration) * V)))
    assert result.lengths["drive_paths_unmeasured"] == pytest.approx(expected, abs=0.3 * len(result.drives))
    assert result.lengths["predicted_unstable_unmeasured"] == 0.0


@SHARED_CORRIDORS
def test_goal_paths_are_judged_as_the_robot_drove_them(root):
    """`--goals`: the paths the simulated robot took between goals are judged as taken (`maps.analysis.TAKEN_SOURCES`),
    the way they were driven only (their reverse direction is not judged: N nan), while the skeleton's routes keep both
    directions; the same path added as the user's own route (source "path") is judged both ways."""
    from test_map_paths import _report, corridor_analysis

    from pfm_stability.maps.analysis import add_routes
    from pfm_stability.maps.reading.routes import path_of
    from pfm_stability.validation.map_drives import goal_routes

    V_star = _report(0.6).models["sampled"].critical["V_critical"]
    analysis = corridor_analysis(0.6, 0.7 * V_star, root)
    (driven,) = goal_routes(analysis, [(0.65, 3.0), (0.65, 15.0)])
    assert driven.source == "goals"
    both = add_routes(analysis, [driven, path_of(driven.points, 0, "path")])
    pv = both.paths
    skeleton, goal, user = 0, len(pv.paths) - 2, len(pv.paths) - 1
    on = lambda r: pv.samples.segment == r  # noqa: E731
    assert np.isnan(pv.N_reverse[on(goal)]).all() and np.isfinite(pv.N_forward[on(goal)]).any()
    assert np.isfinite(pv.N_reverse[on(user)]).any() and np.isfinite(pv.N_reverse[on(skeleton)]).any()


@pytest.mark.slow
def test_a_path_taken_beside_a_wall_steers_against_the_goals_pull_along_it(tmp_path):
    """On a path the robot took beside a wall (its goal off to the side holds it there against the wall's push), the
    goal's attraction along the path is √(1 − P²), P the wall's mean push across one cell that it balances, so the
    lateral gain is N = −(dF_n/ds)/(√(1 − P²) + F_r·t) (docs/maps.md, "Paths taken"); the same line as a route (its
    goal along it) keeps N = −(dF_n/ds)/(1 + F_r·t). A small robot (W 0.3 m, V 0.5 m/s, CARMEL's loop) 0.7, 0.9 and
    1.2 m from a straight wall, mid-way along it (its ends 5 m away, outside the window). Expected values from the force itself: P by scipy's adaptive quadrature over the cell
    (the code: the trapezoid rule on quarter cells), dF_n/ds by a central difference (h = 0.1 mm; the code: the window
    sum's Jacobian). Tolerance 1e-3 relative: the 5-node trapezoid's error on this smooth push (~1e-4 here) and the
    difference's O(h²)."""
    import sys
    from pathlib import Path

    from scipy.integrate import quad

    sys.path.insert(0, str(Path(__file__).parent))
    from test_map_paths import write_map

    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.analysis import analyze_map, judge_routes
    from pfm_stability.maps.deciding.equilibria import lateral_force
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.maps.reading.routes import path_of

    img = np.full((100, 30), 254, dtype=np.uint8)
    img[:, :3] = 0  # a wall 3 cells thick along y, x in [0, 0.3) m, 10 m long
    robot, controller = CARMEL.robot.replace(W=0.3, V=0.5), CARMEL.controller
    analysis = analyze_map(load_map(write_map(tmp_path, img)), robot, controller, make_law("grid", robot, controller))
    grid, law, c = analysis.grid, analysis.law, analysis.grid.cell_size
    distances = (0.7, 0.9, 1.2)
    lines = [path_of([[d, 2.5], [d, 7.5]], k, "goals") for k, d in enumerate(distances)]
    pv = judge_routes(analysis, lines + lines, taken=[True] * 3 + [False] * 3)
    one = lambda v: np.array([v], dtype=float)  # noqa: E731
    for k, d in enumerate(distances):

        def push(s):
            return float(lateral_force(grid, law, one(d), one(5.0), one(0.0), one(1.0), one(s))[0][0])

        P = quad(push, -c / 2, c / 2, limit=200)[0] / c
        along = float(lateral_force(grid, law, one(d), one(5.0), one(0.0), one(1.0), one(0.0))[1][0])
        slope = -(push(1e-4) - push(-1e-4)) / 2e-4
        assert 0.2 < abs(P) < 0.6  # the goal's pull is well off the path's direction: √(1 − P²) from 0.98 to 0.8
        taken, route = (int(np.argmin(np.abs(pv.arc + 1e9 * (pv.samples.segment != r) - 2.5))) for r in (k, k + 3))
        assert pv.N_forward[taken] == pytest.approx(slope / (math.sqrt(1 - P * P) + along), rel=1e-3), d
        assert pv.N_forward[route] == pytest.approx(slope / (1 + along), rel=1e-3), d


def test_wobble_agreement_compares_the_weaves_where_either_passed_the_threshold():
    """`wobble_agreement` by hand: of six samples (lengths 1, 1, 2, 1, 1, 5 m), one agrees in size (2 against 2 cm:
    ratio 1), one is a third of the simulated (1 against 3 cm), one held no predicted weave (ratio 0), one no simulated
    weave (ratio inf), one is where the loop left the corridor (counted apart) and one where neither passed 1.5 cm
    (left out): 5 m compared, 1 m within a factor 2 (20 %); the ratios sorted by length weight (0: 2 m, 1/3, 1, inf:
    1 m each) reach 25, 50 and 75 % of the 5 m at 0, 1/3 and 1 (exactly: samples' values, not interpolated). Nothing
    past the threshold gives no figure (None), not agreement."""
    from pfm_stability.validation.map_drives import wobble_agreement

    got = wobble_agreement([0.02, 0.01, 0.0, 0.03, 2.0, 0.004], [0.02, 0.03, 0.02, 0.0, 0.01, 0.004], [1, 1, 2, 1, 1, 5], 1.0)
    assert got.length == 5.0 and got.left == 1.0
    assert got.within == pytest.approx(0.2, rel=1e-12)
    assert got.ratio_quartiles == pytest.approx((0.0, 1 / 3, 1.0), rel=1e-12)
    quiet = wobble_agreement([0.01, 0.004], [0.014, 0.0], [1.0, 1.0], 1.0)
    assert quiet.length == 0.0 and quiet.within is None and quiet.ratio_quartiles is None
    assert quiet.to_dict()["within"] is None and got.to_dict()["ratio_quartiles"][2] == pytest.approx(1.0)


def test_speeds_driven_together_are_each_speed_driven_alone():
    """`driven_loops` steps the runs of several speeds together (the V* search's ladder and halvings, `stretch_speed`);
    each speed's `DrivenLoop` is what that speed driven alone gives (`_driven`): the same episodes, and the weave and
    excursion to 1e-12 relative (a run's arithmetic is its own; only the batched matrix product's blocking may
    differ in the last bits). Two routes of different gains — one of them driven at one speed only — at three speeds
    (k = 20 1/s; 1.3·NV* at the fastest speed on the first route, which grows until it leaves; the others damped)."""

    robot = CARMEL.robot.replace(W=0.4, tau=0.1, k=20.0, V=1.0)
    controller = CARMEL.controller.replace(T=0.025, f=2.0)
    model, loop, tr = _transition(robot, controller)
    NV_star = model.boundary(loop).NV_critical
    period = 2 * math.pi / model.boundary(loop).omega_critical
    steps = 1200
    spacing = robot.V * controller.T
    profiles = [_straight(1.3 * NV_star / robot.V, steps, spacing, reach=2.0), _straight(0.6 * NV_star / robot.V, steps, spacing, reach=2.0)]
    offsets = profiles[0][0]
    profile = (offsets, np.concatenate([p[1] for p in profiles]), np.concatenate([p[2] for p in profiles]))
    route = np.repeat([0, 1], steps)
    arc = np.tile((np.arange(steps) + 0.5) * spacing, 2)
    n = route.size
    def goal(P):  # a goal's pull P across the path (each speed its own: a mixed-up request shows)
        return dict(stopped=np.zeros((2, n), dtype=bool), pull=np.full(n, P), attraction=np.full(n, math.sqrt(1 - P * P)), aim=np.zeros(n))

    asked = ((1.0, None, 0.0), (0.8, np.array([True, False]), 0.05), (0.55, None, -0.02))
    requests = [DriveRequest(V, routes=routes, **goal(P)) for V, routes, P in asked]
    together = driven_loops(route, arc, profile, requests, tr, period, taken=False)
    assert together[0].oscillates[route == 0].any() and not together[2].oscillates.any()  # the case exercises a weave
    for (V, routes, P), loop_together in zip(asked, together):
        keep = np.ones(n, dtype=bool) if routes is None else routes[route]
        alone = driven_loops(route[keep], arc[keep], (offsets, profile[1][keep], profile[2][keep]),
                             [DriveRequest(V, **{k: v[..., keep] for k, v in goal(P).items()})], tr, period, taken=False)[0]
        assert np.array_equal(loop_together.oscillates[keep], alone.oscillates)
        for name in ("amplitude", "excursion"):
            assert np.allclose(getattr(loop_together, name)[keep], getattr(alone, name), rtol=1e-12, atol=1e-15), name
        assert not loop_together.oscillates[~keep].any() and not loop_together.amplitude[~keep].any()
