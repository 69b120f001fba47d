"""Where the robot's disc meets an obstacle beside a route (`maps.reading.contact`, docs/maps.md, "A collision course"), and
the loop driven along the route stopping there (`maps.judging.driven.driven_loops`: a collision course)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfm_stability.maps.reading.contact import BAND_BISECTIONS, free_band, obstacle_distance
from pfm_stability.maps.reading.field import HistogramMap


def _random_grid(seed: int, shape=(30, 24), fill=0.08) -> HistogramMap:
    rng = np.random.default_rng(seed)
    cv = (rng.random(shape) < fill).astype(np.int16)
    return HistogramMap(-1.3, 0.7, 0.1, cv)


def _brute_distance(grid: HistogramMap, px: float, py: float) -> float:
    """Distance from (px, py) to the nearest occupied square, every square tried; cells outside the grid count as
    occupied (a ring of them one cell wide is enough below W/2 < c·3)."""
    c = grid.cell_size
    nx, ny = grid.shape
    best = math.inf
    for i in range(-3, nx + 3):
        for j in range(-3, ny + 3):
            outside = not (0 <= i < nx and 0 <= j < ny)
            if outside or grid.cv[i, j] > 0:
                x0, y0 = grid.x_min + i * c, grid.y_min + j * c
                dx = max(x0 - px, px - (x0 + c), 0.0)
                dy = max(y0 - py, py - (y0 + c), 0.0)
                best = min(best, math.hypot(dx, dy))
    return best


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_obstacle_distance_is_the_nearest_square_below_its_reach(seed):
    """`obstacle_distance` against every square tried (exact point–square distance), at 300 random points of a random
    grid: equal to 1e-12 m wherever the true distance is below `within` (0.27 m), and never below `within` where it
    is not (the stencil reaches far enough and no farther than it must)."""
    grid = _random_grid(seed)
    rng = np.random.default_rng(100 + seed)
    px = rng.uniform(grid.x_min - 0.2, grid.x_min + 3.2, 300)
    py = rng.uniform(grid.y_min - 0.2, grid.y_min + 2.6, 300)
    got = obstacle_distance(grid, px, py, 0.27)
    truth = np.array([_brute_distance(grid, x, y) for x, y in zip(px, py)])
    near = truth < 0.27
    assert near.sum() > 100 and (~near).sum() > 10
    assert np.abs(got[near] - truth[near]).max() < 1e-12
    assert (got[~near] >= 0.27).all()


def test_free_band_edges_are_where_the_disc_first_touches():
    """The free band across route samples of a random grid (`free_band`) against a fine scan of the brute-force
    distance along each normal: the edge is the first offset at which the disc (W = 0.4 m) touches, to the
    bisection's 2^−12 of a quarter cell (plus the fine scan's 1 mm); a side with no contact within the scan is
    ±inf; where the disc on the route itself touches, the sample is not judged (−inf, inf)."""
    grid = _random_grid(5, fill=0.05)
    W, c = 0.4, grid.cell_size
    offsets = np.arange(-40, 41) * c / 4
    rng = np.random.default_rng(6)
    n = 40
    x, y = rng.uniform(grid.x_min + 0.5, grid.x_min + 2.5, n), rng.uniform(grid.y_min + 0.5, grid.y_min + 1.9, n)
    angle = rng.uniform(0, 2 * math.pi, n)
    tx, ty = np.cos(angle), np.sin(angle)
    band = free_band(grid, grid.clearance(), x, y, tx, ty, W, offsets)
    fine = np.arange(0.0, offsets[-1] + 1e-9, 0.001)
    tolerance = c / 4 / 2**BAND_BISECTIONS + 0.001
    checked = 0
    for k in range(n):
        touches = lambda s: _brute_distance(grid, x[k] - ty[k] * s, y[k] + tx[k] * s) < W / 2  # noqa: E731
        if touches(0.0):
            assert band[0, k] == -math.inf and band[1, k] == math.inf
            continue
        for side, sign in ((0, -1.0), (1, 1.0)):
            hit = next((s for s in fine if touches(sign * s)), None)
            if hit is None:
                assert band[side, k] == sign * math.inf
            else:
                assert abs(abs(band[side, k]) - hit) <= tolerance, (k, side, band[side, k], hit)
                checked += 1
    assert checked > 20


def test_the_driven_loop_stops_where_its_disc_meets_an_obstacle():
    """A loop with no lateral force (F_n = 0: it keeps its 3 cm start offset) along a straight route whose free band
    closes to ±2 cm from arc 6 m on (`driven_loops` with the band): the run meets the obstacle at the first sample
    past 6 m, the samples of the period before are on a collision course, none earlier; past the contact the run is
    gone (its amplitude "at least" `LEAVES`). The same band within the run's first period is not judged (the start's
    transient): a band closed from the start marks nothing."""
    from pfm_stability.maps.judging.driven import LEAVES, DriveRequest, driven_loops
    from test_map_driven import _transition, _straight
    from pfm_stability.parameters import CARMEL

    robot, controller = CARMEL.robot, CARMEL.controller
    model, loop, tr = _transition(robot, controller)
    period = 2 * math.pi / model.boundary(loop).omega_critical
    spacing = robot.V * controller.T
    steps = 400
    offsets, fn, ft = _straight(0.0, steps, spacing, reach=1.0)
    arc = (np.arange(steps) + 0.5) * spacing
    route = np.zeros(steps, dtype=int)
    n = steps
    request = DriveRequest(robot.V, np.zeros((2, n), dtype=bool), np.zeros(n), np.ones(n), np.zeros(n))
    band = np.tile([-np.inf, np.inf], (n, 1))
    band[arc > 6.0] = (-0.02, 0.02)
    loop_run = driven_loops(route, arc, (offsets, fn, ft, band), [request], tr, period, taken=True)[0]
    first = int(np.argmax(arc > 6.0))
    assert loop_run.collides[first] and loop_run.collides[first - int(period / controller.T) + 1]
    assert not loop_run.collides[: first - int(round(period / controller.T)) - 1].any()
    assert (loop_run.amplitude[first + 1:] == LEAVES).all() and not loop_run.oscillates.any()
    m = int(0.8 * period / controller.T)  # a route shorter than one period's travel
    short = DriveRequest(robot.V, np.zeros((2, m), dtype=bool), np.zeros(m), np.ones(m), np.zeros(m))
    early = driven_loops(route[:m], arc[:m], (offsets, fn[:m], ft[:m], np.tile([-0.02, 0.02], (m, 1))), [short], tr, period, taken=True)
    assert m >= 8 and not early[0].collides.any()


def test_a_collision_course_is_a_stretchs_one_answer(tmp_path, monkeypatch):
    """The rule's wiring (`decide`, docs/maps.md, "A collision course"): in an open 10 × 24 m hall, stable throughout,
    the loop driven along the route is made to meet an obstacle in the hall's middle 2 m at every speed
    (`driven_loops` wrapped): those samples become one unstable stretch with cause "collision course" (never where
    the driven loop weaves: a weave is tried first), its V* is found by the same rule — no speed calms it, V* = 0 —
    and it gets a speed-mask zone; the rest of the hall stays stable."""
    from dataclasses import replace

    import pfm_stability.maps.deciding.decide as decide
    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.analysis import analyze_map
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.maps.deciding.outputs import has_zone
    from test_map_paths import CONTROLLER, ROBOT, write_map

    img = np.full((240, 100), 254, dtype=np.uint8)
    img[0, :] = img[-1, :] = img[:, 0] = img[:, -1] = 0
    real = decide.driven_loops

    def meeting(route, arc, profile, requests, *args):  # the hall's middle by route and arc (the V* search cuts subsets)
        loops = real(route, arc, profile, requests, *args)
        there = (route == middle_route) & (arc >= arcs[0]) & (arc <= arcs[1])
        return [replace(loop, collides=loop.collides | there) for loop in loops]

    plain = analyze_map(load_map(write_map(tmp_path, img)), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER), corridors=False)
    samples = plain.paths.samples
    hall_middle = (np.abs(samples.x - 5.0) < 0.5) & (np.abs(samples.y - 12.0) < 1.0)
    assert hall_middle.sum() > 5 and all(s.verdict == "stable" for s in plain.paths.stretches if s.N == 0.0)
    (middle_route,) = np.unique(samples.segment[hall_middle])
    arcs = plain.paths.arc[hall_middle].min(), plain.paths.arc[hall_middle].max()
    monkeypatch.setattr(decide, "driven_loops", meeting)
    pv = analyze_map(load_map(write_map(tmp_path, img)), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER), corridors=False).paths
    courses = [s for s in pv.stretches if s.cause == "collision course"]
    assert courses and all(s.verdict == "unstable" and s.V_critical == 0.0 and s.margin == -1.0 and has_zone(s, ROBOT.V) for s in courses)
    assert sum(s.length for s in courses) == pytest.approx(2.0, abs=0.3)
    assert all(s.verdict == "stable" for s in pv.stretches if s.cause is None and s.N == 0.0)
