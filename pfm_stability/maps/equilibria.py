"""Lateral equilibria along a route: the offset s0 where the lateral force vanishes, and N there.

At a sample point p of a segment with unit travel direction t and left normal
nrm, the robot at p + s·nrm feels the attraction t (F_ct = 1) and the repulsion
F_r(p + s·nrm). The lateral force is F_n(s) = F_r·nrm, the forward force
F_t = 1 + F_r·t. An equilibrium is a root s0 of F_n inside the free band (where
the robot fits: |s| < clearance − W/2, and within the window's reach); with
several roots the one nearest the medial axis is taken and the count recorded.
The environment gain is

    N = −(dF_n/ds)(s0) / F_t(s0),   1/m (KB eq 22–25 with the forward force),

with F_t the smaller of the two travel directions' 1 ± F_r·t; the samples keep
F_r·t too, so that each direction gets its own gain −(dF_n/ds)/(1 ± F_r·t) and
the end-effect rule (`verdicts.judged_run`) can tell a wall ahead (docs/maps.md).
F_t <= 0 means the repulsion stops the robot: no equilibrium.

``grid`` law: F_r is the exact window sum (`field.window_force`), averaged over the
robot's position along the segment within one cell (`PHASE_NODES`), as KB's grid law
is (`effective_force.GridWallLaw`: along a wall the sum varies by a few per cent
with that position, and a moving robot feels the mean). The band is
scanned every c/2 for sign changes of F_n, and each root is refined by Newton
steps with the exact derivative nrm·J·nrm inside its bracket (the field is
smooth inside a cell; at a cell boundary it may jump, and a root there is kept at
the jump with the derivative of the cell it lies in).

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

from ..effective_force import GridWallLaw
from .field import HistogramMap, window_force

__all__ = ["NEWTON_STEPS", "RAY_LENGTH", "Samples", "grid_equilibria", "power_equilibria"]

NEWTON_STEPS = 8
"""Newton steps refining a root inside its scan bracket (quadratic convergence: 8 reach round-off)."""
RAY_LENGTH = 50.0
"""How far a ray looks for a wall, m (`power` law)."""
RAY_STEP = 0.125
"""Step of a ray, map pixels: a wall's face is found to half a step (1/16 pixel)."""
PHASE_NODES = 4
"""Gauss–Legendre nodes of the average over the robot's position along the segment within a cell."""
SCAN_STEP_CELLS = 0.5
"""Spacing of the scan for sign changes of F_n, cells."""


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
        Whether any repulsion acts on the axis (False: an open area, no wall in the window).
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


def _band(grid: HistogramMap, clearance: np.ndarray, x, y, W: float, reach: float):
    """Half-width of the free band at each point: clearance of its cell − W/2, at most `reach`, m."""
    i, j = grid.cell_index(x, y)
    nx, ny = grid.shape
    inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
    cl = np.where(inside, clearance[np.clip(i, 0, nx - 1), np.clip(j, 0, ny - 1)], 0.0)
    return np.minimum(cl - W / 2, reach)


def _lateral(grid, law, x, y, tx, ty, s, jacobian=False):
    """F_n, F_r·t (and dF_n/ds) at p + s·nrm, nrm = (−ty, tx), averaged over the robot's position along t within one cell.

    The average is over u in [−c/2, c/2) (Gauss–Legendre, `PHASE_NODES` nodes), the
    convention of the grid's wall law (`effective_force.GridWallLaw`: the robot
    passes every position in its cell many times before the oscillation builds up).
    """
    from ..solve import gauss_legendre

    nodes, weights = gauss_legendre(PHASE_NODES)
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


def grid_equilibria(grid: HistogramMap, law: GridWallLaw, routes, clearance: np.ndarray, W: float) -> Samples:
    """Equilibria and N at samples every cell along `routes` with the exact window sum (module docstring)."""
    c = grid.cell_size
    x, y, seg, tx, ty = sample_points(routes, c)
    band = _band(grid, clearance, x, y, W, law.reach)
    step = SCAN_STEP_CELLS * c
    count = np.maximum(0, np.floor(np.maximum(band, 0) / step).astype(np.int64))
    # the scan: s = −count·step … +count·step for each sample, flattened
    lengths = 2 * count + 1
    owner = np.repeat(np.arange(x.size), lengths)
    first = np.concatenate([[0], np.cumsum(lengths)[:-1]]) if x.size else np.zeros(0, dtype=np.int64)
    position = np.arange(owner.size) - first[owner] - count[owner]
    s = position * step
    fn, _ = _lateral(grid, law, x[owner], y[owner], tx[owner], ty[owner], s)
    field = np.zeros(x.size, dtype=bool)
    field[owner[position == 0]] = fn[position == 0] != 0  # a wall inside the window at the axis
    # strict sign changes between neighbours of the same sample: a stretch where F_n is exactly 0 (no wall in
    # the window) is neutral, not an equilibrium
    same = owner[1:] == owner[:-1]
    change = same & (fn[1:] * fn[:-1] < 0)
    pairs = np.flatnonzero(change)
    roots = np.bincount(owner[pairs], minlength=x.size) if pairs.size else np.zeros(x.size, dtype=np.int64)
    # the root nearest the axis: smallest |midpoint| of its bracket per sample
    mid = np.abs(s[pairs] + step / 2)
    order = np.lexsort((mid, owner[pairs]))
    chosen = pairs[order]
    firsts = np.unique(owner[chosen], return_index=True)[1]
    chosen = chosen[firsts]
    k = owner[chosen]
    lo, hi = s[chosen], s[chosen + 1]
    flo, fhi = fn[chosen], fn[chosen + 1]
    s0 = np.where(fhi != flo, lo - flo * (hi - lo) / np.where(fhi != flo, fhi - flo, 1.0), lo)
    for _ in range(NEWTON_STEPS):
        f, _, df = _lateral(grid, law, x[k], y[k], tx[k], ty[k], s0, jacobian=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            proposed = s0 - f / df
        s0 = np.clip(np.where(np.isfinite(proposed), proposed, s0), lo, hi)
    f, ft, df = _lateral(grid, law, x[k], y[k], tx[k], ty[k], s0, jacobian=True)
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
    """Equilibria and N at samples every cell along `routes` for a distance law (module docstring, ``power``)."""
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
