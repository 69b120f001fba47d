"""Where the robot's disc meets an obstacle beside a route: the free band across each sample (docs/maps.md,
"A collision course").

The robot is a disc of diameter W; it touches an obstacle when an occupied cell's square of the histogram grid lies
closer than W/2 to its centre — the simulator's collision (`sim.contact`), on the same grid. Across each route sample
p (unit normal nrm to the left of its travel direction) the **free band** is the interval (y_right, y_left) of lateral
offsets y about 0 at which the disc centred at p + y·nrm touches nothing; the loop driven along the route
(`driven.driven_loops`) meets an obstacle where its offset leaves the band. Cells outside the grid count as occupied
(`field.HistogramMap.clearance`'s convention: no route leaves the grid).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["BAND_BISECTIONS", "free_band", "obstacle_distance"]

BAND_BISECTIONS = 12
"""Halvings of the profile's step (a quarter cell) that locate each edge of the free band: 2.5 cm / 2^12 < 0.01 mm."""


def obstacle_distance(grid, px, py, within: float) -> np.ndarray:
    """Distance (m) from each point to the nearest occupied cell square of `grid`, exact where it is below `within`
    (m); elsewhere a value >= `within` (inf when no occupied square lies within reach of the point's cell).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid (cells outside it count as occupied).
    px, py : ndarray
        Points, m.
    within : float
        The distance that matters, m (> 0).
    """
    px, py = np.asarray(px, dtype=float), np.asarray(py, dtype=float)
    c = grid.cell_size
    nx, ny = grid.shape
    occupied = grid.occupied
    i, j = grid.cell_index(px, py)
    reach = int(math.ceil(within / c))
    best = np.full(px.shape, np.inf)
    for di in range(-reach, reach + 1):
        for dj in range(-reach, reach + 1):
            if math.hypot(max(abs(di) - 1, 0), max(abs(dj) - 1, 0)) * c >= within:
                continue  # no point of the cell (i, j) is this close to a square this far off
            ii, jj = i + di, j + dj
            inside = (ii >= 0) & (ii < nx) & (jj >= 0) & (jj < ny)
            full = np.ones(px.shape, dtype=bool)
            full[inside] = occupied[ii[inside], jj[inside]]
            x0, y0 = grid.x_min + ii * c, grid.y_min + jj * c
            dx = np.maximum(np.maximum(x0 - px, px - (x0 + c)), 0.0)
            dy = np.maximum(np.maximum(y0 - py, py - (y0 + c)), 0.0)
            best = np.where(full, np.minimum(best, np.hypot(dx, dy)), best)
    return best


def free_band(grid, clearance: np.ndarray, x, y, tx, ty, W: float, offsets: np.ndarray) -> np.ndarray:
    """(y_right, y_left) per sample, m, shape (2, samples): the lateral offsets either side of the route at which the
    disc of diameter W centred at p + y·nrm first touches an occupied square (module docstring), to
    2^−`BAND_BISECTIONS` of the scan's step; ±inf where it touches none within the `offsets` scanned, and (−inf, inf)
    where the disc at the route itself touches one (a gap the route squeezes through — its clearance is W/2 at cell
    centres — is the route's, not the loop's: no contact is judged there).

    Parameters
    ----------
    grid : HistogramMap
    clearance : ndarray, shape (nx, ny)
        Distance from each cell centre to the nearest occupied square, m (`HistogramMap.clearance`): a point farther
        than W/2 + c/√2 from every square by it is not checked exactly.
    x, y : ndarray
        Route samples, m.
    tx, ty : ndarray
        Unit travel directions (the normal nrm = (−ty, tx) points left).
    W : float
        Robot width, m.
    offsets : ndarray
        The lateral offsets scanned (m, increasing, evenly spaced, 0 among them: `decide.lateral_profile`'s).
    """
    x, y, tx, ty = (np.asarray(v, dtype=float) for v in (x, y, tx, ty))
    half, step = W / 2, offsets[1] - offsets[0]
    band = np.zeros((2, x.size))
    for side, sign in ((0, -1.0), (1, 1.0)):
        outward = np.abs(offsets[offsets * sign >= 0])
        outward.sort()
        n, k = np.meshgrid(np.arange(x.size), np.arange(outward.size), indexing="ij")
        hit = np.zeros(n.shape, dtype=bool)
        near = _may_touch(grid, clearance, x[n], y[n], tx[n], ty[n], sign * outward[k], half)
        hit[near] = _touches(grid, x[n[near]], y[n[near]], tx[n[near]], ty[n[near]], sign * outward[k[near]], half)
        first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
        refine = np.flatnonzero(first > 0)
        lo, hi = outward[first[refine]] - step, outward[first[refine]]  # free at lo, touching at hi
        for _ in range(BAND_BISECTIONS):
            mid = 0.5 * (lo + hi)
            now = _touches(grid, x[refine], y[refine], tx[refine], ty[refine], sign * mid, half)
            lo, hi = np.where(now, lo, mid), np.where(now, mid, hi)
        band[side] = np.where(first == 0, 0.0, sign * math.inf)
        band[side, refine] = sign * hi
    band[:, (band == 0).any(axis=0)] = np.array([[-math.inf], [math.inf]])  # the route itself touches: not judged
    return band


def _may_touch(grid, clearance, x, y, tx, ty, s, half: float) -> np.ndarray:
    """Whether the disc at p + s·nrm may touch an occupied square: its cell's clearance is below W/2 + c/√2 (the
    point lies within c/√2 of the cell's centre), or it lies outside the grid."""
    i, j = grid.cell_index(x - ty * s, y + tx * s)
    nx, ny = grid.shape
    inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
    out = np.ones(np.shape(x), dtype=bool)
    out[inside] = clearance[i[inside], j[inside]] < half + grid.cell_size / math.sqrt(2)
    return out


def _touches(grid, x, y, tx, ty, s, half: float) -> np.ndarray:
    """Whether the disc of radius `half` at p + s·nrm touches an occupied square."""
    return obstacle_distance(grid, x - ty * s, y + tx * s, half) < half
