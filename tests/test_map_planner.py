"""The global plans the drives of `--validate` follow (`maps.planner`): shortest paths along the free-space skeleton.

docs/maps.md, "Validation by driving". The expected values are the test maps' geometry: an L-shaped corridor's
centre lines, a wall that splits a room in two.
"""

from __future__ import annotations

import numpy as np
import pytest

from pfm_stability.maps.field import HistogramMap
from pfm_stability.maps.planner import SkeletonPlanner
from pfm_stability.maps.routes import skeleton_of

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


def test_a_plan_round_a_corner_follows_the_corridors_centre_lines():
    """From the centre line of one arm (y = 0.7 m) to that of the other (x = 5.5 m): the centre lines' length,
    4.75 + 4.85 m, to within three cells (each end's step to its nearest skeleton cell, a cell; the skeleton's cells lie
    half a cell off a centre line between two cell centres; the corner); every vertex where the robot fits
    (clearance > W/2), the vertices between the ends within a cell of the centre lines, and the plan ends at the given
    points."""
    grid = _l_corridor()
    skeleton, clearance = skeleton_of(grid, W)
    start, goal = (0.75, 0.7), (5.5, 5.55)
    path = SkeletonPlanner(grid, skeleton).plan(start, goal)
    assert tuple(path[0]) == start and tuple(path[-1]) == goal
    length = float(np.hypot(*np.diff(path, axis=0).T).sum())
    assert length == pytest.approx(9.6, abs=0.3)
    i, j = grid.cell_index(path[:, 0], path[:, 1])
    assert np.all(clearance[i, j] > W / 2)
    inner = path[1:-1]
    assert np.all(np.minimum(np.abs(inner[:, 1] - 0.7), np.abs(inner[:, 0] - 5.5)) <= 0.1 + 1e-9)


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
