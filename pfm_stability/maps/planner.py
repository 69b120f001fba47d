"""A global plan between two points of a map: the shortest path along its free-space skeleton.

The skeleton (`routes.skeleton_of`: the medial axis of the free space where the robot fits) is a graph of cells, each
joined to its 8 neighbours on it by edges of length c or c√2; a plan runs from the skeleton cell nearest its start to
the one nearest its goal by Dijkstra's shortest path (``scipy.sparse.csgraph.dijkstra``), keeping as far from the walls
as the corridor allows — where a planner with a wide inflation layer (Nav2's) would put it. Its cell centres are
simplified into a polyline (``skimage.measure.approximate_polygon``, `TOLERANCE_CELLS` cells) and joined to the
start and the goal themselves.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SkeletonPlanner", "TOLERANCE_CELLS"]

TOLERANCE_CELLS = 1.0
"""Largest distance of a plan's cells from its polyline, cells (3 cells, which straightens the skeleton's bends
towards a room's openings, raised the bookstore's recall with the small robot to 77–79 % but lowered the small
house's precision at CARMEL to 72 % over 50 drives: kept at one; docs/maps.md also gives the figures of a plan
straightened by shortcuts that keep the skeleton's room, not kept either)."""


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
        return points[np.concatenate([[True], np.hypot(*np.diff(points, axis=0).T) > 0])]
