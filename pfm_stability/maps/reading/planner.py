"""A global plan between two points of a map: the shortest path along its free-space skeleton.

The skeleton (`routes.skeleton_of`: the medial axis of the free space where the robot fits) is a graph of cells, each
joined to its 8 neighbours on it by edges of length c or c√2; a plan runs from the skeleton cell nearest its start to
the one nearest its goal by Dijkstra's shortest path (``scipy.sparse.csgraph.dijkstra``), keeping as far from the walls
as the corridor allows — where a planner with a wide inflation layer (Nav2's) would put it. Its cell centres are
simplified into a polyline (``skimage.measure.approximate_polygon``, `TOLERANCE_CELLS` cells) and joined to the
start and the goal themselves.

**Smoothed as a navigation stack hands it over** (`smooth_plan`). The medial axis carries jags a navigation stack's
plan does not: a speck in a room, a shelf's end or an opening bends it by decimetres over a metre, and a robot
following such a plan by a carrot (`sim.follow`) feels each jag as a jump of its carrot — a kick the robot would not
get from Nav2, whose planners descend a smooth potential and whose smoother server (``nav2_smoother``'s Simple
Smoother) smooths the plan further. The plan is resampled every cell and smoothed as Nav2's Simple Smoother does at
its default weights (`W_DATA`, `W_SMOOTH`, `REFINEMENTS`): each point p_i of the smoothed path balances its pull to
the given point q_i against the pull to its neighbours' middle, W_DATA·(q_i − p_i) + W_SMOOTH·(p_(i−1) + p_(i+1) −
2·p_i) = 0, the ends fixed — the point Nav2's iterations converge to (its tolerance 1e-10), here by one banded solve
(``scipy.linalg.solve_banded``) — and the result smoothed so again, `REFINEMENTS` times. As in Nav2, a smoothed plan
with a point in an occupied cell (or off the map) is not used: the plan stays as it was.
"""

from __future__ import annotations

import math

import numpy as np

from .routes import polyline_arcs

__all__ = ["REFINEMENTS", "SkeletonPlanner", "TOLERANCE_CELLS", "W_DATA", "W_SMOOTH", "smooth_plan"]

TOLERANCE_CELLS = 1.0
"""Largest distance of a plan's cells from its polyline, cells (3 cells, which straightens the skeleton's bends
towards a room's openings, raised the bookstore's recall with the small robot to 77–79 % but lowered the small
house's precision at CARMEL to 72 % over 50 drives: kept at one; docs/maps.md also gives the figures of a plan
straightened by shortcuts that keep the skeleton's room, not kept either)."""
W_DATA = 0.2
"""Nav2 Simple Smoother's ``w_data`` (its default): the pull of a smoothed point to the plan's."""
W_SMOOTH = 0.3
"""Nav2 Simple Smoother's ``w_smooth`` (its default): the pull of a smoothed point to its neighbours' middle."""
REFINEMENTS = 2
"""Nav2 Simple Smoother's ``refinement_num`` (its default, with ``do_refinement`` true): the smoothed path smoothed again
this many times."""


class SkeletonPlanner:
    """Shortest paths along a map's skeleton.

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid (cell size, origin).
    skeleton : ndarray of bool, shape (nx, ny)
        The skeleton (`MapAnalysis.skeleton`).
    """

    def __init__(self, grid, skeleton: np.ndarray):
        from scipy.sparse import coo_matrix
        from scipy.spatial import cKDTree

        self.grid = grid
        i, j = np.nonzero(skeleton)
        node = np.full(skeleton.shape, -1, dtype=np.int64)
        node[i, j] = np.arange(i.size)
        rows, cols, weights = [], [], []
        nx, ny = skeleton.shape
        for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):  # each neighbour pair once
            ii, jj = i + di, j + dj
            ok = (ii >= 0) & (ii < nx) & (jj >= 0) & (jj < ny)
            other = np.full(i.size, -1, dtype=np.int64)
            other[ok] = node[ii[ok], jj[ok]]
            has = other >= 0
            rows.append(np.flatnonzero(has)), cols.append(other[has])
            weights.append(np.full(int(has.sum()), grid.cell_size * math.hypot(di, dj)))
        rows, cols, weights = np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)
        self.graph = coo_matrix((weights, (rows, cols)), shape=(i.size, i.size)).tocsr()
        self.x, self.y = grid.cell_center(i, j)
        self.tree = cKDTree(np.column_stack([self.x, self.y])) if i.size else None

    def plan(self, start, goal) -> np.ndarray | None:
        """The plan from `start` to `goal`: polyline vertices, shape (n, 2), m; None when the skeleton does not join
        them (or is empty).

        Parameters
        ----------
        start, goal : (float, float)
            Its ends, m.
        """
        from scipy.sparse.csgraph import dijkstra
        from skimage.measure import approximate_polygon

        if self.tree is None:
            return None
        (_, a), (_, b) = self.tree.query(start), self.tree.query(goal)
        _, previous = dijkstra(self.graph, directed=False, indices=int(a), return_predecessors=True)
        if a != b and previous[b] < 0:
            return None
        chain = [int(b)]
        while chain[-1] != a:
            chain.append(int(previous[chain[-1]]))
        cells = np.column_stack([self.x[chain[::-1]], self.y[chain[::-1]]])
        cells = approximate_polygon(cells, TOLERANCE_CELLS * self.grid.cell_size) if len(cells) > 2 else cells
        points = np.vstack([np.asarray(start, dtype=float), cells, np.asarray(goal, dtype=float)])
        points = points[np.concatenate([[True], np.hypot(*np.diff(points, axis=0).T) > 0])]
        smoothed = smooth_plan(points, self.grid.cell_size)
        i, j = self.grid.cell_index(smoothed[:, 0], smoothed[:, 1])
        inside = (i >= 0) & (i < self.grid.shape[0]) & (j >= 0) & (j < self.grid.shape[1])
        if not inside.all() or np.any(self.grid.cv[i, j] > 0):  # as Nav2: a smoothed plan in collision is not used
            return points
        return smoothed


def smooth_plan(points, spacing: float) -> np.ndarray:
    """The polyline `points` (m, shape (n, 2)) resampled every `spacing` m of arc (at least its two ends) and smoothed
    as Nav2's Simple Smoother converges to (module docstring): shape (m, 2), m, its ends the given ones.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Vertices, m (n >= 2, consecutive ones distinct).
    spacing : float
        Resampling step, m (> 0).
    """
    from scipy.linalg import solve_banded

    p = np.asarray(points, dtype=float)
    arc = polyline_arcs(p)
    at = np.linspace(0.0, arc[-1], max(2, int(math.ceil(arc[-1] / spacing)) + 1))
    path = np.column_stack([np.interp(at, arc, p[:, 0]), np.interp(at, arc, p[:, 1])])
    inner = path.shape[0] - 2
    if inner < 1:
        return path
    bands = np.zeros((3, inner))  # rows i = 1 .. n − 2: (W_DATA + 2·W_SMOOTH)·p_i − W_SMOOTH·(p_(i−1) + p_(i+1)) = W_DATA·q_i
    bands[0, 1:], bands[1], bands[2, :-1] = -W_SMOOTH, W_DATA + 2 * W_SMOOTH, -W_SMOOTH
    for _ in range(REFINEMENTS + 1):
        rhs = W_DATA * path[1:-1]
        rhs[0] += W_SMOOTH * path[0]
        rhs[-1] += W_SMOOTH * path[-1]
        path = np.vstack([path[:1], solve_banded((1, 1), bands, rhs), path[-1:]])
    return path
