"""Lateral equilibria along a route: the offset s0 where the lateral force vanishes, and N there.

At a sample point p of a segment with unit travel direction t and left normal
nrm, the robot at p + s·nrm feels the attraction t (F_ct = 1) and the repulsion
F_r(p + s·nrm). The lateral force is F_n(s) = F_r·nrm, the forward force
F_t = 1 + F_r·t. An equilibrium is a root s0 of F_n inside the free band: the run
of positions across the segment where the robot fits (clearance > W/2, measured on
both sides of p, so a sample off the corridor's axis still has the axis in its
band; `_band`), within the window's reach; with several roots the one nearest the
sample (on the medial axis) is taken and the count recorded. The environment gain is

    N = −(dF_n/ds)(s0) / F_t(s0),   1/m (KB eq 22–25 with the forward force),

with F_t the smaller of the two travel directions' 1 ± F_r·t; the samples keep
F_r·t too, so that each direction gets its own gain −(dF_n/ds)/(1 ± F_r·t) and
the end-effect rule (`verdicts.judged_run`) can tell a wall ahead (docs/maps.md).
F_t <= 0 means the repulsion stops the robot: no equilibrium.

``grid`` law: F_r is the exact window sum (`field.window_force`), averaged over the
robot's position along the segment within one cell (`PHASE_NODES`), as KB's grid law
is (`effective_force.GridWallLaw`: along a wall the sum varies by a few per cent
with that position, and a moving robot feels the mean). The band is scanned in
equal steps of at most c/2 from edge to edge (at least two, so a band narrower
than one step is still searched), and a root is a strict sign change of F_n between
neighbouring scan points or a scan point where F_n is exactly 0 between neighbours
of opposite signs (the axis of a symmetric corridor, where the two walls cancel to
the last bit, whenever it is a scan point); a stretch of exact zeros (no wall in
the window) is neutral. Each root's bracket is narrowed by safeguarded Newton steps
with the exact derivative nrm·J·nrm (`solve.newton_increasing`): the field is
smooth inside a cell; at a cell boundary it may jump (the window gains or loses a
column), and a root there is located at the jump and takes the derivative of the
cell it lies in.

``power`` law (KB's lumped f(W/d)^n, no window): the distances a, b to the first
blocked map pixel along +nrm and −nrm give a corridor of half-width L = (a + b)/2
around s0 = (a − b)/2, and N = −2P′(L) (`force_law.corridor_gain` in the middle of
that corridor). A side with no obstacle along the ray within `RAY_LENGTH` means a
single wall: no lateral equilibrium.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...laws.effective_force import GridWallLaw
from ...numerics.solve import newton_increasing
from ..reading.field import HistogramMap, window_force

__all__ = ["NEWTON_STEPS", "RAY_LENGTH", "Samples", "equilibria_at", "grid_equilibria", "lateral_force", "power_equilibria"]

NEWTON_STEPS = 12
"""Safeguarded Newton steps narrowing a root's scan bracket (`solve.newton_increasing`): a smooth root reaches
round-off in a few, a jump of F_n at a cell boundary is located to the bracket / 2^12 (~10 µm)."""
RAY_LENGTH = 50.0
"""How far a ray looks for a wall, m (`power` law)."""
RAY_STEP = 0.125
"""Step of a ray, map pixels: a wall's face is found to half a step (1/16 pixel)."""
PHASE_NODES = 4
"""Gauss–Legendre nodes of the average over the robot's position along the segment within a cell."""
SCAN_STEP_CELLS = 0.5
"""Largest spacing of the scan for sign changes of F_n, cells."""
ROOT_TOLERANCE = 1e-12
"""Absolute tolerance of a refined equilibrium offset, m (`solve.newton_increasing`: the root of a symmetric corridor
sits at s = 0, where a relative tolerance is below F_n's round-off)."""
BAND_STEP_CELLS = 0.125
"""Spacing of the positions across a segment tested for the robot's fit (`_band`), cells."""


@dataclass(frozen=True)
class Samples:
    """Lateral equilibria at sample points (arrays of one length, one entry per sample).

    Attributes
    ----------
    x, y : ndarray
        Sample points on the segments, m.
    segment : ndarray of int
        Index of the segment of each sample.
    offset : ndarray
        s0, m, along the segment's left normal (nan where there is none).
    N : ndarray
        Environment gain, 1/m (nan where there is no equilibrium).
    forward : ndarray
        F_t at the equilibrium, units of F_ct.
    roots : ndarray of int
        Roots of F_n found in the band.
    field : ndarray of bool
        Whether the window of the sample's cell holds a wall (False: an open area, no repulsion).
    along : ndarray or None
        F_r·t at the equilibrium, units of F_ct (t: the direction from the segment's start to its end;
        nan where there is no equilibrium). The gain of one travel direction is `directional`.
    """

    x: np.ndarray
    y: np.ndarray
    segment: np.ndarray
    offset: np.ndarray
    N: np.ndarray
    forward: np.ndarray
    roots: np.ndarray
    field: np.ndarray
    along: np.ndarray | None = None

    def directional(self, index) -> tuple:
        """(N driving from start to end, N driving from end to start) at the samples `index`, 1/m.

        dF_n/ds is the same both ways (the normal and s flip together); the forward
        force is 1 + F_r·t one way and 1 − F_r·t the other (nan where it is <= 0).
        `N` is the larger of the two (the forward force the smaller).

        Parameters
        ----------
        index : int, slice or ndarray
            Which samples.
        """
        N, forward = self.N[index], self.forward[index]
        if self.along is None:
            return N, N
        slope = N * forward  # −dF_n/ds
        ft = self.along[index]
        with np.errstate(divide="ignore", invalid="ignore"):
            out = tuple(np.where(1 + sign * ft > 0, slope / (1 + sign * ft), np.nan) for sign in (1.0, -1.0))
        return out


def sample_points(routes, spacing: float):
    """(x, y, segment, tx, ty): points every ~`spacing` m along each route (cell midpoints), with the unit directions."""
    xs, ys, seg, txs, tys = [], [], [], [], []
    for k, r in enumerate(routes):
        count = max(1, round(r.length / spacing))
        u = (np.arange(count) + 0.5) / count
        tx, ty = (r.x1 - r.x0) / r.length, (r.y1 - r.y0) / r.length
        xs.append(r.x0 + u * (r.x1 - r.x0))
        ys.append(r.y0 + u * (r.y1 - r.y0))
        seg.append(np.full(count, k))
        txs.append(np.full(count, tx))
        tys.append(np.full(count, ty))
    if not xs:
        empty = np.zeros(0)
        return empty, empty, np.zeros(0, dtype=int), empty, empty
    return tuple(np.concatenate(a) for a in (xs, ys, seg, txs, tys))


def _clearance_at(grid: HistogramMap, clearance: np.ndarray, x, y) -> np.ndarray:
    """The clearance (m) at points: bilinear between the cell centres' (`HistogramMap.clearance`), 0 outside the grid.

    Exact across a straight axis-parallel wall (the clearance is linear in the distance from it); between the two
    middle cells of a corridor whose axis is a cell boundary it is their common value, below the axis' own (a
    conservative reading, and the band's edges stay exact).
    """
    c = grid.cell_size
    u = (np.asarray(x, dtype=float) - grid.x_min) / c - 0.5
    v = (np.asarray(y, dtype=float) - grid.y_min) / c - 0.5
    i0, j0 = np.floor(u).astype(np.int64), np.floor(v).astype(np.int64)
    fu, fv = u - i0, v - j0
    nx, ny = clearance.shape
    out = np.zeros(np.shape(u))
    for di, dj, weight in ((0, 0, (1 - fu) * (1 - fv)), (1, 0, fu * (1 - fv)), (0, 1, (1 - fu) * fv), (1, 1, fu * fv)):
        i, j = i0 + di, j0 + dj
        inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
        out += weight * np.where(inside, clearance[np.clip(i, 0, nx - 1), np.clip(j, 0, ny - 1)], 0.0)
    return out


def _band(grid: HistogramMap, clearance: np.ndarray, x, y, tx, ty, W: float, reach: float):
    """(low, high): the free band across the segment at each point, s in [low, high] along nrm = (−ty, tx), m.

    The run of positions where the robot fits (`_clearance_at` > W/2), within the window's `reach` on both sides,
    that holds the point itself or, when the point does not fit, lies nearest to it; found on a grid of
    `BAND_STEP_CELLS` (its edges are the last positions on that grid that fit). Both sides are measured, so a point
    off the corridor's axis (a skeleton half a cell to one side of a symmetric corridor's axis, a polyline within a
    cell of its skeleton) still has the axis in its band. low > high: the robot fits nowhere across the point.
    """
    step = BAND_STEP_CELLS * grid.cell_size
    half = int(math.floor(reach / step))
    offsets = np.arange(-half, half + 1) * step
    fits = _clearance_at(grid, clearance, x[:, None] - ty[:, None] * offsets, y[:, None] + tx[:, None] * offsets) > W / 2
    # the fitting position nearest to the point, then the run of fitting positions around it
    distance = np.where(fits, np.abs(offsets), np.inf)
    centre = np.argmin(distance, axis=1)
    rows = np.arange(x.size)
    any_fit = np.isfinite(distance[rows, centre])
    index = np.arange(offsets.size)
    gap_below = np.where(~fits & (index <= centre[:, None]), index, -1).max(axis=1)
    gap_above = np.where(~fits & (index >= centre[:, None]), index, offsets.size).min(axis=1)
    low, high = offsets[np.minimum(gap_below + 1, offsets.size - 1)], offsets[np.maximum(gap_above - 1, 0)]
    return np.where(any_fit, low, 1.0), np.where(any_fit, high, -1.0)


def lateral_force(grid, law, x, y, tx, ty, s, jacobian=False, phase_nodes: int = PHASE_NODES):
    """F_n, F_r·t (and dF_n/ds) at p + s·nrm, nrm = (−ty, tx), averaged over the robot's position along t within one cell.

    The average is over u in [−c/2, c/2) (Gauss–Legendre, `PHASE_NODES` nodes), the
    convention of the grid's wall law (`effective_force.GridWallLaw`: the robot
    passes every position in its cell many times before the oscillation builds up).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : GridWallLaw
        KB's grid law.
    x, y : ndarray
        Points p, m.
    tx, ty : ndarray
        Unit travel directions t at them.
    s : ndarray
        Lateral offsets along nrm = (−ty, tx), m.
    jacobian : bool
        Also return dF_n/ds (1/m).
    phase_nodes : int
        Gauss–Legendre nodes of the average along t (`PHASE_NODES`).
    """
    from ...numerics.solve import gauss_legendre

    nodes, weights = gauss_legendre(phase_nodes)
    u = nodes * grid.cell_size / 2
    nx_, ny_ = -ty, tx
    qx = (x + s * nx_)[:, None] + u[None, :] * tx[:, None]
    qy = (y + s * ny_)[:, None] + u[None, :] * ty[:, None]
    out = [o @ (weights / 2) for o in window_force(grid, law, qx, qy, jacobian=jacobian)]
    fn = out[0] * nx_ + out[1] * ny_
    ft = out[0] * tx + out[1] * ty
    if not jacobian:
        return fn, ft
    jxx, jxy, jyy = out[2:]
    return fn, ft, nx_ * nx_ * jxx + 2 * nx_ * ny_ * jxy + ny_ * ny_ * jyy


def _walls_in_window(grid: HistogramMap, law: GridWallLaw, x, y, extra: int = 0) -> np.ndarray:
    """Whether the window of each point's cell, widened by `extra` cells each way, holds an occupied cell (False: an
    open area, no repulsion)."""
    h = law.window_cells // 2 + extra
    nx, ny = grid.shape
    counts = np.zeros((nx + 1, ny + 1), dtype=np.int64)
    counts[1:, 1:] = np.cumsum(np.cumsum(grid.occupied, axis=0), axis=1)  # summed-area table
    i, j = grid.cell_index(x, y)
    i0, i1 = np.clip(i - h, 0, nx), np.clip(i + h + 1, 0, nx)
    j0, j1 = np.clip(j - h, 0, ny), np.clip(j + h + 1, 0, ny)
    return (counts[i1, j1] - counts[i0, j1] - counts[i1, j0] + counts[i0, j0]) > 0


def _brackets(owner: np.ndarray, s: np.ndarray, fn: np.ndarray):
    """Roots of F_n on the scans: (sample, low, high, start, F_n(low)) of every bracket (module docstring).

    A bracket is a strict sign change between neighbouring scan points of one sample (start: its secant root), or
    a scan point where F_n is exactly 0 between neighbours of opposite signs (start: that point, the bracket's
    middle — the symmetric axis of a corridor lands there whenever the axis is a scan point). A stretch of two or
    more exact zeros (no wall in the window) is neutral, not an equilibrium.
    """
    sign = np.sign(fn)
    pair = np.flatnonzero((owner[1:] == owner[:-1]) & (sign[1:] * sign[:-1] < 0))
    lo, hi, flo, fhi = s[pair], s[pair + 1], fn[pair], fn[pair + 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        secant = lo - flo * (hi - lo) / (fhi - flo)  # opposite signs: fhi − flo != 0 (nan only beside an infinite F_n)
    secant = np.clip(np.where(np.isfinite(secant), secant, (lo + hi) / 2), lo, hi)
    zero = np.flatnonzero((owner[2:] == owner[:-2]) & (sign[1:-1] == 0) & (sign[2:] * sign[:-2] < 0)) + 1
    return (np.concatenate([owner[pair], owner[zero]]), np.concatenate([lo, s[zero - 1]]), np.concatenate([hi, s[zero + 1]]),
            np.concatenate([secant, s[zero]]), np.concatenate([flo, fn[zero - 1]]))


def grid_equilibria(grid: HistogramMap, law: GridWallLaw, routes, clearance: np.ndarray, W: float) -> Samples:
    """Equilibria and N at samples every cell along `routes` with the exact window sum (module docstring).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : GridWallLaw
        KB's grid law (window, cell size, certainty value).
    routes : list of Route
        The segments (`routes.find_routes`).
    clearance : ndarray, shape (nx, ny)
        Distance to the nearest occupied cell, m, per histogram cell.
    W : float
        Robot width, m.
    """
    x, y, seg, tx, ty = sample_points(routes, grid.cell_size)
    return equilibria_at(grid, law, x, y, tx, ty, seg, clearance, W)


def equilibria_at(grid: HistogramMap, law: GridWallLaw, x, y, tx, ty, segment, clearance: np.ndarray, W: float,
                  newton_steps: int = NEWTON_STEPS) -> Samples:
    """Equilibria and N at given points with travel directions (`grid_equilibria` for any route; module docstring).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : GridWallLaw
        KB's grid law (window, cell size, certainty value).
    x, y : ndarray
        Sample points, m.
    tx, ty : ndarray
        Unit travel directions at them.
    segment : ndarray of int
        The route of each point.
    clearance : ndarray, shape (nx, ny)
        Distance to the nearest occupied cell, m, per histogram cell.
    W : float
        Robot width, m.
    newton_steps : int
        Safeguarded Newton steps per root (`NEWTON_STEPS`: a jump located to the bracket / 2^12).
    """
    c = grid.cell_size
    x, y, tx, ty = (np.asarray(v, dtype=float) for v in (x, y, tx, ty))
    seg = np.asarray(segment)
    low, high = _band(grid, clearance, x, y, tx, ty, W, law.reach)
    # a sample whose band lies where no window holds a wall has F_n = 0 exactly across it: no root, no scan needed
    # (the band reaches at most `law.reach` from the sample, so every window of it lies in the widened one)
    walls_near = _walls_in_window(grid, law, x, y, extra=int(math.ceil(law.reach / c)) + 2)  # + the cell phase
    span = np.where((high > low) & walls_near, high - low, 0.0)
    # the scan: `steps` equal steps of at most c/2 from low to high, both ends included (at least two steps, so a
    # band narrower than one step still has a middle point), flattened over the samples
    steps = np.where(span > 0, np.maximum(2, np.ceil(span / (SCAN_STEP_CELLS * c))), 0).astype(np.int64)
    lengths = np.where(steps > 0, steps + 1, 0)
    owner = np.repeat(np.arange(x.size), lengths)
    first = np.cumsum(lengths) - lengths
    position = np.arange(owner.size) - first[owner]
    s = low[owner] + position * (span / np.maximum(steps, 1))[owner]
    fn, _ = lateral_force(grid, law, x[owner], y[owner], tx[owner], ty[owner], s)
    field = _walls_in_window(grid, law, x, y)
    k_all, lo_all, hi_all, start_all, sign_lo = _brackets(owner, s, fn)
    roots = np.bincount(k_all, minlength=x.size)
    # the root nearest the sample point (on the medial axis) per sample
    order = np.lexsort((np.abs(start_all), k_all))
    chosen = order[np.unique(k_all[order], return_index=True)[1]]
    k, lo, hi = k_all[chosen], lo_all[chosen], hi_all[chosen]
    # F_n made increasing on each bracket (F_n(lo) < 0 < F_n(hi) after the sign), narrowed by safeguarded Newton: a
    # smooth root converges quadratically, a sign change at a cell boundary (where the window, and so F_n, jumps)
    # to the jump, to the bracket / 2^NEWTON_STEPS
    sign = np.where(sign_lo[chosen] < 0, 1.0, -1.0)

    def increasing(at, index):  # the roots still moving alone (a window sum per point is the costly part)
        kk = k[index]
        f, _, df = lateral_force(grid, law, x[kk], y[kk], tx[kk], ty[kk], at, jacobian=True)
        return sign[index] * f, sign[index] * df

    s0 = newton_increasing(increasing, lo, hi, atol=ROOT_TOLERANCE, iterations=newton_steps, moving=True)
    f, ft, df = lateral_force(grid, law, x[k], y[k], tx[k], ty[k], s0, jacobian=True)
    forward = 1.0 - np.abs(ft)
    offset, N, F_t, along = (np.full(x.size, np.nan) for _ in range(4))
    offset[k] = s0
    F_t[k] = forward
    along[k] = ft
    with np.errstate(divide="ignore", invalid="ignore"):
        N[k] = np.where(forward > 0, -df / forward, np.nan)
    return Samples(x, y, seg, offset, N, F_t, roots, field, along)


def _ray_distance(blocked: np.ndarray, resolution: float, origin, x, y, dx, dy) -> np.ndarray:
    """Distance from each point along (dx, dy) to the first blocked map pixel, m (inf if none within `RAY_LENGTH`)."""
    step = resolution * RAY_STEP
    steps = int(math.ceil(RAY_LENGTH / step))
    height, width = blocked.shape
    out = np.full(x.shape, np.inf)
    todo = np.arange(x.size)
    for k in range(1, steps + 1):
        if todo.size == 0:
            break
        d = k * step
        i = np.floor((x[todo] + d * dx[todo] - origin[0]) / resolution).astype(np.int64)
        j = np.floor((y[todo] + d * dy[todo] - origin[1]) / resolution).astype(np.int64)
        inside = (i >= 0) & (i < width) & (j >= 0) & (j < height)
        hit = np.zeros(todo.size, dtype=bool)
        hit[inside] = blocked[j[inside], i[inside]]
        out[todo[hit]] = d - step / 2
        todo = todo[~hit & inside]
    return out


def power_equilibria(grid: HistogramMap, law, routes, clearance: np.ndarray, W: float, blocked: np.ndarray, resolution: float,
                     origin) -> Samples:
    """Equilibria and N at samples every cell along `routes` for a distance law (module docstring, ``power``).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : ForceLaw
        A distance law (KB's lumped power law).
    routes : list of Route
        The segments (`routes.find_routes`).
    clearance : ndarray, shape (nx, ny)
        Distance to the nearest occupied cell, m, per histogram cell.
    W : float
        Robot width, m.
    blocked : ndarray of bool, shape (height, width)
        Map pixels a ray stops at (occupied, and unknown if it counts as occupied).
    resolution : float
        Map pixel size, m.
    origin : (float, float, float)
        The map's origin (x, y in m, yaw).
    """
    x, y, seg, tx, ty = sample_points(routes, grid.cell_size)
    a = _ray_distance(blocked, resolution, origin, x, y, -ty, tx)
    b = _ray_distance(blocked, resolution, origin, x, y, ty, -tx)
    L = (a + b) / 2
    ok = np.isfinite(L) & (L > W / 2)
    offset, N = np.full(x.size, np.nan), np.full(x.size, np.nan)
    offset[ok] = (a[ok] - b[ok]) / 2
    N[ok] = -2.0 * np.asarray(law.slope(L[ok]), dtype=float)
    return Samples(x, y, seg, offset, N, np.where(ok, 1.0, np.nan), ok.astype(np.int64), np.isfinite(a) | np.isfinite(b),
                   np.where(ok, 0.0, np.nan))
