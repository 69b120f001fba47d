"""The global plans the drives of `--validate` follow (`maps.reading.planner`): shortest paths along the free-space skeleton.

docs/maps.md, "Validation by driving". The expected values are the test maps' geometry: an L-shaped corridor's
centre lines, a wall that splits a room in two.
"""

from __future__ import annotations

import numpy as np
import pytest

from pfm_stability.maps.reading.field import HistogramMap
from pfm_stability.maps.reading.planner import SkeletonPlanner
from pfm_stability.maps.reading.routes import skeleton_of

W = 0.4
"""Robot width, m."""


def _grid(free: np.ndarray, cell: float = 0.1) -> HistogramMap:
    """A histogram grid, origin (0, 0), occupied wherever `free` (index i along x, j along y) is False."""
    return HistogramMap(0.0, 0.0, cell, np.where(free, 0, 15).astype(np.int16))


def _l_corridor() -> HistogramMap:
    """A corridor 1.2 m wide (free cells) along x from 0 to 6 m, turning up along y to 6 m at its end."""
    free = np.zeros((62, 62), dtype=bool)
    free[1:61, 1:13] = True  # x 0.1–6.1 m, y 0.1–1.3 m
    free[49:61, 1:61] = True  # x 4.9–6.1 m, y up to 6.1 m
    return _grid(free)


def test_a_plan_round_a_corner_follows_the_corridors_centre_lines(monkeypatch):
    """From the centre line of one arm (y = 0.7 m) to that of the other (x = 5.5 m). Before smoothing: the centre
    lines' length, 4.75 + 4.85 m, to within three cells (each end's step to its nearest skeleton cell, a cell; the
    skeleton's cells lie half a cell off a centre line between two cell centres; the corner), the vertices between the
    ends within a cell of the centre lines. Smoothed (`smooth_plan`): the corner is rounded — the plan shortens by
    less than 0.4 m (a right angle rounded with radius r saves (2 − π/2)·r, 0.43·r) and strays at most 0.2 m from the
    centre lines at the corner ((√2 − 1)·r for r up to 0.5 m), within a cell of them farther than 0.5 m from it; every
    point where the robot fits (clearance > W/2), and the plan ends at the given points."""
    from pfm_stability.maps.reading import planner as planner_module

    grid = _l_corridor()
    skeleton, clearance = skeleton_of(grid, W)
    start, goal = (0.75, 0.7), (5.5, 5.55)
    length = lambda p: float(np.hypot(*np.diff(p, axis=0).T).sum())  # noqa: E731
    off_centre = lambda p: np.minimum(np.abs(p[:, 1] - 0.7), np.abs(p[:, 0] - 5.5))  # noqa: E731
    path = SkeletonPlanner(grid, skeleton).plan(start, goal)
    with monkeypatch.context() as m:
        m.setattr(planner_module, "smooth_plan", lambda points, spacing: points)
        jagged = SkeletonPlanner(grid, skeleton).plan(start, goal)
    assert length(jagged) == pytest.approx(9.6, abs=0.3)
    assert np.all(off_centre(jagged[1:-1]) <= 0.1 + 1e-9)
    for p in (path, jagged):
        assert tuple(p[0]) == start and tuple(p[-1]) == goal
        i, j = grid.cell_index(p[:, 0], p[:, 1])
        assert np.all(clearance[i, j] > W / 2)
    assert length(jagged) - 0.4 < length(path) <= length(jagged)
    inner = path[1:-1]
    far = np.hypot(inner[:, 0] - 5.5, inner[:, 1] - 0.7) > 0.5
    assert off_centre(inner).max() <= 0.2 and off_centre(inner[far]).max() <= 0.1 + 1e-9


def test_rooms_the_skeleton_does_not_join_have_no_plan():
    """Two rooms split by a wall: a plan from one to the other is None; within one room there is one."""
    free = np.zeros((42, 22), dtype=bool)
    free[1:20, 1:21] = free[22:41, 1:21] = True
    grid = _grid(free)
    planner = SkeletonPlanner(grid, skeleton_of(grid, W)[0])
    assert planner.plan((1.0, 1.0), (3.0, 1.0)) is None
    assert planner.plan((0.5, 0.5), (1.5, 1.5)) is not None


def test_an_empty_skeleton_has_no_plan():
    grid = _grid(np.zeros((5, 5), dtype=bool))
    assert SkeletonPlanner(grid, np.zeros((5, 5), dtype=bool)).plan((0.1, 0.1), (0.3, 0.3)) is None


def _nav2_simple_smoother(points: np.ndarray, spacing: float, w_data=0.2, w_smooth=0.3, tolerance=1e-10, max_its=1000,
                          refinements=2) -> np.ndarray:
    """Nav2's Simple Smoother as its source iterates it (``nav2_smoother/src/simple_smoother.cpp``, ``smoothImpl``):
    Gauss–Seidel sweeps over the interior points, each moved by w_data·(original − new) + w_smooth·(next + previous −
    2·new) in place, until a sweep moves the points by less than `tolerance` in all (or `max_its` sweeps); then again
    on its own result, `refinements` times. The path is first resampled every `spacing` m of arc, as the plan is."""
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    at = np.linspace(0.0, arc[-1], max(2, int(np.ceil(arc[-1] / spacing)) + 1))
    original = np.column_stack([np.interp(at, arc, points[:, 0]), np.interp(at, arc, points[:, 1])])
    for _ in range(refinements + 1):
        new = original.copy()
        for _ in range(max_its):
            change = 0.0
            for i in range(1, len(new) - 1):
                before = new[i].copy()
                new[i] += w_data * (original[i] - new[i]) + w_smooth * (new[i + 1] + new[i - 1] - 2 * new[i])
                change += float(np.abs(new[i] - before).sum())
            if change < tolerance:
                break
        original = new
    return original


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_plan_is_smoothed_as_nav2s_simple_smoother_converges(seed):
    """`smooth_plan` solves for the point Nav2's Simple Smoother iterates to (its default weights): on random jagged
    polylines (6–12 vertices, jags up to 0.5 m, resampled every 0.1 m) the two agree to 1e-8 m (Nav2's sweeps stop
    when they move the points by less than 1e-10 m in all; the contraction per sweep is about 0.6, so the remaining
    error is a few times that); the ends stay where they were; the jags shrink (the largest turn between consecutive
    resampled segments is smaller than the jagged plan's)."""
    from pfm_stability.maps.reading.planner import smooth_plan

    rng = np.random.default_rng(seed)
    n = int(rng.integers(6, 13))
    points = np.column_stack([np.cumsum(rng.uniform(0.3, 1.0, n)), rng.uniform(-0.5, 0.5, n)])
    smoothed = smooth_plan(points, 0.1)
    reference = _nav2_simple_smoother(points, 0.1)
    assert smoothed.shape == reference.shape
    assert np.abs(smoothed - reference).max() <= 1e-8
    assert np.array_equal(smoothed[0], points[0]) and np.array_equal(smoothed[-1], points[-1])

    def sharpest(path):
        heading = np.unwrap(np.arctan2(*np.diff(path, axis=0).T[::-1]))
        return np.abs(np.diff(heading)).max()

    jagged = _nav2_simple_smoother(points, 0.1, refinements=0, max_its=0)  # resampled, not smoothed
    assert sharpest(smoothed) < sharpest(jagged)


def test_a_straight_plan_stays_straight_and_a_smoothed_plan_in_collision_is_not_used(monkeypatch):
    """A straight corridor's plan is a fixed point of the smoothing (evenly resampled collinear points: each is its
    neighbours' middle) — the L corridor's plan keeps its corner's cells free; and with the smoothing pushed into a
    wall (a plan whose smoothed points would enter an occupied cell) the planner returns the unsmoothed plan, as
    Nav2's smoother refuses a path in collision."""
    from pfm_stability.maps.reading import planner as planner_module
    from pfm_stability.maps.reading.planner import smooth_plan

    line = np.array([[0.0, 1.0], [3.0, 1.0]])
    straight = smooth_plan(line, 0.1)
    assert np.abs(straight[:, 1] - 1.0).max() <= 1e-12
    assert np.diff(straight[:, 0]) == pytest.approx(np.full(straight.shape[0] - 1, 0.1))
    grid = _l_corridor()
    skeleton, clearance = skeleton_of(grid, W)
    planner = SkeletonPlanner(grid, skeleton)
    path = planner.plan((0.75, 0.7), (5.5, 5.55))
    i, j = grid.cell_index(path[:, 0], path[:, 1])
    assert not grid.occupied[i, j].any()
    for wall in ((3.0, 3.0), (3.0, -5.0)):  # an occupied cell inside the grid; a point outside it (the map says nothing)
        with monkeypatch.context() as m:
            m.setattr(planner_module, "smooth_plan", lambda points, spacing: np.vstack([points[:1], [wall], points[-1:]]))
            kept = planner.plan((0.75, 0.7), (5.5, 5.55))
            m.setattr(planner_module, "smooth_plan", lambda points, spacing: points)
            jagged = planner.plan((0.75, 0.7), (5.5, 5.55))
        assert np.array_equal(kept, jagged)
