"""The corridors of a map: the medial axis of its free space, split into straight segments.

A robot of width W can stand where a free cell's clearance (distance from its centre
to the nearest occupied cell square, `HistogramMap.clearance`) exceeds W/2. The
routes are the medial axis of the free space (``skimage.morphology.medial_axis``)
restricted to those cells: a skeleton, one cell wide, equidistant from the walls,
found by topology-preserving thinning (``skimage.morphology.skeletonize``; the
distance-based ``medial_axis`` sends a ridge from every step of a staircase wall).

The skeleton is a graph: a pixel with three or more skeleton neighbours (8-connected)
is a junction, one with a single neighbour an end. Removing the junctions splits it
into branches; each branch is ordered from one end to the other and simplified into
a polyline (``skimage.measure.approximate_polygon``, tolerance `TOLERANCE_CELLS`
cells), whose straight pieces are the segments. Near a junction the corridor model
(two walls, parallel to the travel direction) does not hold: every branch end that
touched a junction is cut back by half the junction's clearance (`JUNCTION_CUT`; the
clearance is the radius of the largest free disc there), and pieces shorter than
`min_length` (default `default_min_length`: 1 m, or 1.25 robot widths if longer) are
dropped.

A segment's travel direction is from (x0, y0) to (x1, y1). The lateral verdict does
not depend on it: reversing the direction flips the normal and the lateral
coordinate together, so dF_n/ds is the same, and the forward force is taken as the
smaller of the two directions' (`pfm_stability.maps.analysis`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...extras import require
from .field import HistogramMap

__all__ = ["JUNCTION_CUT", "MIN_LENGTH", "TOLERANCE_CELLS", "Route", "RoutePath", "default_min_length", "find_paths", "find_routes", "path_of",
           "polyline_arcs", "prune_spurs", "skeleton_of"]

MIN_LENGTH = 1.0
"""Shortest segment analysed, m (default; at least 1.25 W is used): shorter pieces are bends and junction stubs."""
JUNCTION_CUT = 0.5
"""A branch end at a junction is cut back by this fraction of the junction's clearance."""
SPUR_ROUNDS = 3
"""Rounds of spur pruning (`prune_spurs`)."""
TOLERANCE_CELLS = 1.0
"""Largest distance of the skeleton from its polyline, cells."""


@dataclass(frozen=True)
class Route:
    """A straight piece of the medial axis.

    Attributes
    ----------
    x0, y0, x1, y1 : float
        End points, m (travel from 0 to 1).
    branch : int
        Index of the skeleton branch it comes from.
    """

    x0: float
    y0: float
    x1: float
    y1: float
    branch: int

    @property
    def length(self) -> float:
        """m."""
        return math.hypot(self.x1 - self.x0, self.y1 - self.y0)


@dataclass(frozen=True)
class RoutePath:
    """A route of any shape: a polyline the robot drives along (docs/maps.md, "Verdicts along every route").

    Attributes
    ----------
    points : ndarray, shape (n, 2)
        Vertices in map coordinates, m, in the order of travel (n >= 2).
    branch : int
        Index of the route (a skeleton branch, or the user's route).
    source : str
        Where it comes from: "skeleton", "path" (a Nav2 path or CSV), "waypoints" or "goals".
    goal : tuple of float or None
        A path a robot took towards a point target: that target (x, y), m (None: a goal along the route, at infinity).
    lookahead : float
        A path a robot took following a plan: how far ahead along it the point it steered at lay, m (inf: none).
    aims : ndarray, shape (n, 2), or None
        A path a robot took: the point it steered at as it passed each vertex, m (its plan's carrot, or its point
        target); None: not known (a route, whose goal lies along it).
    start : tuple of float or None
        A path a robot took: the pose it started from, (x, y) m and heading θ rad from +Y towards +X (the simulator's
        `Pose`); None: not known.
    """

    points: np.ndarray
    branch: int
    source: str = "skeleton"
    goal: tuple | None = None
    lookahead: float = math.inf
    aims: np.ndarray | None = None
    start: tuple | None = None

    @property
    def length(self) -> float:
        """m."""
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum())


def polyline_arcs(points) -> np.ndarray:
    """The arc position (m) of each vertex of a polyline: 0 at the first.

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Vertices, m.
    """
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])


def path_of(points, branch: int = 0, source: str = "path", goal=None, lookahead: float = math.inf, aims=None,
            start=None) -> RoutePath:
    """A `RoutePath` through `points` (m; repeated points dropped); ValueError if fewer than two distinct points.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Vertices, m.
    branch : int
        Index of the route.
    source : str
        Where it comes from (`RoutePath.source`).
    goal : (float, float), optional
        The point target of the robot that took it, m (`RoutePath.goal`).
    lookahead : float
        The lookahead of the plan it followed, m (`RoutePath.lookahead`).
    aims : array_like, shape (n, 2), optional
        The point it steered at from each of `points`, m (`RoutePath.aims`).
    start : (float, float, float), optional
        The pose it started from: x, y (m), θ (rad from +Y towards +X) (`RoutePath.start`).
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    if aims is not None:
        aims = np.asarray(aims, dtype=float).reshape(-1, 2)
        if aims.shape != p.shape or not np.isfinite(aims).all():
            raise ValueError(f"a {source} route's aims must be one finite point (m) per vertex, {len(p)}; got shape {aims.shape}")
    if not np.isfinite(p).all():
        raise ValueError(f"a {source} route's points must be finite numbers (m); got {p[~np.isfinite(p).all(axis=1)][:1].tolist()}")
    keep = np.concatenate([[True], np.hypot(*np.diff(p, axis=0).T) > 1e-9]) if len(p) else np.zeros(0, dtype=bool)
    p = p[keep]
    aims = aims[keep] if aims is not None else None
    if len(p) < 2:
        raise ValueError(f"a {source} route needs at least two distinct points; got {len(p)}")
    if not lookahead > 0:
        raise ValueError(f"a {source} route's lookahead must be > 0 m; got {lookahead!r}")
    if start is not None and (np.shape(start) != (3,) or not np.isfinite(np.asarray(start, dtype=float)).all()):
        raise ValueError(f"a {source} route's start must be a pose x, y (m), heading (rad), three finite numbers; got {start!r}")
    return RoutePath(p, int(branch), source, None if goal is None else (float(goal[0]), float(goal[1])), float(lookahead), aims,
                     None if start is None else tuple(float(v) for v in start))


def find_paths(grid: HistogramMap, skeleton: np.ndarray, clearance: np.ndarray) -> list:
    """Every branch of the (pruned) skeleton as a `RoutePath`, uncut, joined to the junctions it meets.

    The branches of `find_routes` without the straight-piece split, the junction cut or the minimum length: each
    is ordered, simplified into a polyline (tolerance `TOLERANCE_CELLS` cells), and an end that touches a junction
    zone is extended to that zone's centroid, so the routes run through every junction. Branches of a single cell
    are dropped.

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    skeleton : ndarray of bool, shape (nx, ny)
        The pruned skeleton (`find_routes`).
    clearance : ndarray, shape (nx, ny)
        Distance to the nearest occupied cell, m.
    """
    from scipy.ndimage import center_of_mass, label
    from skimage.measure import approximate_polygon

    from scipy.ndimage import binary_dilation

    junction = _junctions(skeleton, _crossing_number(skeleton))
    # junction zones a few cells apart are one crossing (a branch of a cell or two between them is no corridor)
    zones, n_zones = label(binary_dilation(junction, structure=np.ones((3, 3), dtype=bool), iterations=JUNCTION_MERGE),
                           structure=np.ones((3, 3), dtype=int))
    centres = np.array(center_of_mass(junction, zones, range(1, n_zones + 1))).reshape(-1, 2)
    labels, n_branches = label(skeleton & ~junction, structure=np.ones((3, 3), dtype=int))
    nx, ny = skeleton.shape
    branches = []  # (points (m), zone at the head, zone at the tail)
    for index, path in _ordered_branches(labels, n_branches):
        ij = np.array(path, dtype=float)

        def zone_of(cell):
            near = {int(zones[cell[0] + di, cell[1] + dj]) for di, dj in _STEPS + [(0, 0)]
                    if 0 <= cell[0] + di < nx and 0 <= cell[1] + dj < ny and zones[cell[0] + di, cell[1] + dj] > 0}
            return min(near) if near else 0

        if all(zones[p] for p in path):
            continue  # a stub between junction cells of one crossing
        head, tail = zone_of(path[0]), zone_of(path[-1])
        if head:
            ij = np.vstack([centres[head - 1], ij])
        if tail and (tail != head or len(path) > 2):
            ij = np.vstack([ij, centres[tail - 1]])
        branches.append((np.column_stack(grid.cell_center(ij[:, 0], ij[:, 1])), head, tail))
    paths = []
    for k, chain in enumerate(_chains(branches)):
        simple = approximate_polygon(chain, tolerance=TOLERANCE_CELLS * grid.cell_size)
        if len(simple) >= 2 and np.hypot(*np.diff(simple, axis=0).T).sum() > 0:
            paths.append(path_of(simple, k, "skeleton"))
    return paths


JUNCTION_MERGE = 2
"""Cells by which junction zones are grown before they are told apart (`find_paths`): zones closer than that are one."""
THROUGH_ANGLE = 45.0
"""Largest turn (deg) between two branches meeting at a junction that `find_paths` joins into one route: a corridor
crossing a junction (a gap between shelves, a side door) continues; a branch turning off more sharply starts its own."""
THROUGH_REACH = 1.0
"""Length (m) of a branch end over which its direction at a junction is measured."""


def _direction_at(points: np.ndarray, at_head: bool) -> np.ndarray:
    """Unit direction from a branch's end (head or tail) into the branch, over `THROUGH_REACH` m."""
    p = points if at_head else points[::-1]
    arc = polyline_arcs(p)
    far = p[min(int(np.searchsorted(arc, THROUGH_REACH)), len(p) - 1)]
    d = far - p[0]
    n = math.hypot(*d)
    return d / n if n > 0 else d


def _chains(branches) -> list:
    """The branches joined through junctions where they continue within `THROUGH_ANGLE` (greedy, straightest
    first; each branch end joins at most one other): a list of point arrays, m."""
    ends = {}
    for b, (points, head, tail) in enumerate(branches):
        for at_head, zone in ((True, head), (False, tail)):
            if zone:
                ends.setdefault(zone, []).append((b, at_head, _direction_at(points, at_head)))
    link = {}
    limit = -math.cos(math.radians(THROUGH_ANGLE))
    for zone in sorted(ends):
        pairs = sorted(((float(np.dot(d1, d2)), (b1, h1), (b2, h2)) for i, (b1, h1, d1) in enumerate(ends[zone])
                        for (b2, h2, d2) in ends[zone][i + 1:] if b1 != b2), key=lambda item: item[0])
        for score, e1, e2 in pairs:
            if score <= limit and e1 not in link and e2 not in link:
                link[e1], link[e2] = e2, e1
    seen, chains = set(), []
    order = sorted(range(len(branches)), key=lambda b: ((b, True) in link and (b, False) in link, b))  # chain ends first
    for start in order:
        if start in seen:
            continue
        # walk back to a free end (or round a loop), then forward
        b, at_head = start, True
        while (b, at_head) in link and link[(b, at_head)][0] != start:
            nb, nh = link[(b, at_head)]
            b, at_head = nb, not nh
        pieces, current, entering_head = [], b, at_head
        while current not in seen:
            seen.add(current)
            pts = branches[current][0]
            pieces.append(pts if entering_head else pts[::-1])
            exit_end = (current, not entering_head)
            if exit_end not in link:
                break
            current, entering = link[exit_end]
            entering_head = entering
        chains.append(np.vstack(pieces))
    return chains


def skeleton_of(grid: HistogramMap, W: float):
    """(skeleton, clearance): the medial axis of the free space where a robot of width W fits, and the clearance (m).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    W : float
        Robot width, m.
    """
    require("maps", "finding a map's corridors")
    from skimage.morphology import skeletonize

    clearance = grid.clearance()
    free = ~_close_diagonal_gaps(grid.occupied)
    if not free.any():
        return np.zeros(grid.shape, dtype=bool), clearance
    padded = np.pad(free, 1, constant_values=False)
    skeleton = skeletonize(padded)[1:-1, 1:-1]
    return skeleton & (clearance > W / 2), clearance


def _close_diagonal_gaps(occupied: np.ndarray) -> np.ndarray:
    """`occupied` with every corner-only gap closed: of two free cells between two diagonally touching occupied cells,
    one becomes occupied.

    A wall drawn one cell per cell length at an angle (diagonal walls, docs/maps.md) touches itself only at corners;
    the skeleton (8-connected free space) would leak through every such corner into the next room and break the
    corridor into junction stubs. No robot passes a corner, so the routes are found on the closed walls (the field
    is still the map's).
    """
    closed = occupied.copy()
    closed[1:, :-1] |= occupied[:-1, :-1] & occupied[1:, 1:] & ~occupied[1:, :-1] & ~occupied[:-1, 1:]
    closed[1:, 1:] |= occupied[:-1, 1:] & occupied[1:, :-1] & ~occupied[:-1, :-1] & ~occupied[1:, 1:]
    return closed


_RING = [(0, 1), (1, 1), (1, 0), (1, -1), (0, -1), (-1, -1), (-1, 0), (-1, 1)]
"""The 8 neighbours in circular order."""


def _crossing_number(mask: np.ndarray) -> np.ndarray:
    """Separate groups of skeleton neighbours around each skeleton cell (0 elsewhere).

    1 at an end, 2 along a branch (also at the corners of a staircase, where a cell
    has three neighbours in two touching groups), >= 3 at a junction.
    """
    padded = np.pad(mask, 1)
    nx, ny = mask.shape
    ring = [padded[1 + di:1 + di + nx, 1 + dj:1 + dj + ny] for di, dj in _RING]
    groups = sum((~ring[k] & ring[(k + 1) % 8]).astype(np.int32) for k in range(8))
    alone = ~np.any(ring, axis=0)
    return np.where(mask, np.where(alone, 0, np.maximum(groups, 1)), 0)


_STEPS = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


def _order(cells: set, start) -> list:
    """Walk a branch (a set of (i, j) cells, a path or a loop) from `start`, each step to an unvisited neighbour."""
    path, seen = [start], {start}
    current = start
    while True:
        nxt = [(current[0] + di, current[1] + dj) for di, dj in _STEPS if (current[0] + di, current[1] + dj) in cells]
        nxt = [p for p in nxt if p not in seen]
        if not nxt:
            return path
        # prefer 4-neighbours: the diagonal shortcut would skip a cell of the branch
        nxt.sort(key=lambda p: abs(p[0] - current[0]) + abs(p[1] - current[1]))
        current = nxt[0]
        path.append(current)
        seen.add(current)


def _cut(points: np.ndarray, start_cut: float, end_cut: float) -> np.ndarray:
    """The polyline `points` (m) without its first `start_cut` and last `end_cut` metres of arc length."""
    if len(points) < 2:
        return points[:0]
    arc = polyline_arcs(points)
    lo, hi = start_cut, arc[-1] - end_cut
    if hi - lo <= 0:
        return points[:0]
    keep = (arc > lo) & (arc < hi)
    ends = [np.array([np.interp(lo, arc, points[:, k]) for k in (0, 1)]), np.array([np.interp(hi, arc, points[:, k]) for k in (0, 1)])]
    return np.vstack([ends[0], points[keep], ends[1]])


def default_min_length(W: float) -> float:
    """Shortest segment analysed by default, m: the larger of `MIN_LENGTH` and 1.25 W (a robot length and a quarter).

    Parameters
    ----------
    W : float
        Robot width, m.
    """
    return max(MIN_LENGTH, 1.25 * W)


def find_routes(grid: HistogramMap, W: float, min_length: float | None = None) -> tuple[list[Route], np.ndarray, np.ndarray]:
    """The straight segments of the medial axis where a robot of width W fits (module docstring).

    Parameters
    ----------
    grid : HistogramMap
    W : float
        Robot width, m.
    min_length : float, optional
        Shortest segment kept, m (default `default_min_length`).

    Returns
    -------
    (routes, skeleton, clearance)
        The segments (ordered by branch, then along it), the skeleton (nx, ny) bool
        and the clearance (nx, ny), m.
    """
    from scipy.ndimage import label
    from skimage.measure import approximate_polygon

    min_length = default_min_length(W) if min_length is None else min_length
    skeleton, clearance = skeleton_of(grid, W)
    skeleton = prune_spurs(skeleton, clearance, grid.cell_size)
    junction = _junctions(skeleton, _crossing_number(skeleton))
    labels, n_branches = label(skeleton & ~junction, structure=np.ones((3, 3), dtype=int))
    near_junction = _junction_radius(junction, clearance)
    c = grid.cell_size
    routes = []
    for index, path in _ordered_branches(labels, n_branches):
        ij = np.array(path, dtype=float)
        points = np.column_stack(grid.cell_center(ij[:, 0], ij[:, 1]))
        cut0, cut1 = JUNCTION_CUT * near_junction(path[0]), JUNCTION_CUT * near_junction(path[-1])
        points = _cut(points, cut0, cut1)
        if len(points) < 2:
            continue
        simple = approximate_polygon(points, tolerance=TOLERANCE_CELLS * c)
        for p, q in zip(simple[:-1], simple[1:]):
            route = Route(float(p[0]), float(p[1]), float(q[0]), float(q[1]), index)
            if route.length >= min_length:
                routes.append(route)
    return routes, skeleton, clearance


def _ordered_branches(labels: np.ndarray, count: int):
    """(index, cells from one end to the other) of each labelled branch of two or more cells (`_order`)."""
    for index, cells in enumerate(_branch_cells(labels, count)):
        if len(cells) < 2:
            continue
        cell_set = set(cells)
        branch_count = {p: sum((p[0] + di, p[1] + dj) in cell_set for di, dj in _STEPS) for p in cells}
        ends = [p for p in cells if branch_count[p] <= 1]
        yield index, _order(cell_set, min(ends) if ends else min(cells))


def _junctions(skeleton: np.ndarray, crossing: np.ndarray) -> np.ndarray:
    """Junction zones: skeleton cells with three or more neighbour groups, and their skeleton neighbours.

    Branches meet over a few cells, not at one: taking the neighbours in keeps a
    spur from staying connected to a corridor through a diagonal step.
    """
    from scipy.ndimage import binary_dilation

    return skeleton & binary_dilation(crossing >= 3, structure=np.ones((3, 3), dtype=bool))


def prune_spurs(skeleton: np.ndarray, clearance: np.ndarray, cell_size: float, rounds: int = SPUR_ROUNDS) -> np.ndarray:
    """The skeleton without its spurs: branches from a junction to a free end no longer than the junction's clearance + 2 cells.

    A medial axis sends a spur into every corner and every bump of a wall (a wall
    pixel of noise is enough); such a spur leaves the corridor's axis towards the
    wall, so it is as long as the clearance there. Removing them (a few rounds: a
    removed spur can leave another behind) leaves the corridors and their real
    junctions.

    Parameters
    ----------
    skeleton : ndarray of bool, shape (nx, ny)
        The medial axis.
    clearance : ndarray, shape (nx, ny)
        Distance to the nearest occupied cell, m.
    cell_size : float
        Cell side, m.
    rounds : int
        Pruning rounds at most.
    """
    from scipy.ndimage import label

    skeleton = skeleton.copy()
    for _ in range(rounds):
        crossing = _crossing_number(skeleton)
        junction = _junctions(skeleton, crossing)
        labels, count = label(skeleton & ~junction, structure=np.ones((3, 3), dtype=int))
        radius = _junction_radius(junction, clearance)
        removed = False
        for cells in _branch_cells(labels, count):
            touching = [radius(p) for p in cells if radius(p) > 0]
            free_end = any(crossing[p] == 1 for p in cells)
            if touching and free_end and len(cells) * cell_size <= max(touching) + 2 * cell_size:
                i, j = np.array(cells).T
                skeleton[i, j] = False
                removed = True
        if not removed:
            break
    return skeleton


def _branch_cells(labels: np.ndarray, count: int):
    """The cells (i, j) of each labelled branch, in label order (deterministic)."""
    flat = labels.ravel()
    order = np.argsort(flat, kind="stable")
    sorted_labels = flat[order]
    starts = np.searchsorted(sorted_labels, np.arange(1, count + 2))
    ny = labels.shape[1]
    for k in range(count):
        idx = order[starts[k]:starts[k + 1]]
        yield [(int(v // ny), int(v % ny)) for v in idx]


def _junction_radius(junction: np.ndarray, clearance: np.ndarray):
    """A function (i, j) → how far to cut a branch end at that cell, m: the largest clearance of an adjacent junction."""
    ji, jj = np.nonzero(junction)
    radius = {(int(a), int(b)): float(clearance[a, b]) for a, b in zip(ji, jj)}

    def cut(cell) -> float:
        near = [radius[(cell[0] + di, cell[1] + dj)] for di, dj in _STEPS if (cell[0] + di, cell[1] + dj) in radius]
        return max(near) if near else 0.0

    return cut
