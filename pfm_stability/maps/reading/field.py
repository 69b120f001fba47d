"""The robot's histogram grid of a map and the VFF repulsion it exerts (Koren & Borenstein 1991 §2, eq 1–2).

The robot's grid is not the map's pixel grid: KB's VFF uses square cells of side
c (``cell_size``, 0.1 m) and an active window of w × w cells (``window_cells``, 33),
both fixed in metres, so that maps of any resolution give the same physics.
`histogram_of` reduces a map onto that grid, aligned with the map's origin: cell
(i, j) covers [x0 + i·c, x0 + (i+1)·c) × [y0 + j·c, y0 + (j+1)·c) and is occupied
when the centre of any occupied map pixel falls into it (unknown pixels count as
occupied unless ``unknown="free"``). Occupied cells carry the certainty value C =
`effective_force.DEFAULT_CV`, free cells 0. When the map's resolution equals c the
two grids are the same.

Forces are in units of F_ct. The repulsion at a robot position p is the window sum
of the simulator (`pfm_stability.sim.vff.window_repulsion`)

    F_r(p) = Σ_{cells of the window of p's cell} ρ·C·Wⁿ/dⁿ · (p − c_ij)/d,   d = |p − c_ij|,

ρ = F_cr/F_ct per cell, the window the w × w block of cells centred on the cell that
contains p. Inside one cell the window is fixed, so the field is smooth there and
`window_force` gives it exactly with its Jacobian (vectorized over points × the
occupied cells of their windows). At the cell centres the sum is a correlation of
the certainty grid with a w × w kernel (the centre term, at d = 0, excluded):
`centre_field` computes the whole map at once with an FFT convolution.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...laws.effective_force import DEFAULT_CV, GridWallLaw
from .occupancy import OccupancyMap
from ...numerics.cells import CellGrid

__all__ = ["CHUNK_ENTRIES", "UNKNOWN_AS", "HistogramMap", "centre_field", "histogram_of", "window_force"]

UNKNOWN_AS = ("occupied", "free")
"""How unknown map cells count: as obstacles (default, the safe reading) or as free space."""
CHUNK_ENTRIES = 4_000_000
"""Window cells (point × occupied cell) `window_force` sums at once (memory: ~60 bytes each)."""


@dataclass(frozen=True)
class HistogramMap(CellGrid):
    """The robot's histogram grid of a map.

    Attributes
    ----------
    x_min, y_min : float
        Lower-left corner (the map's origin), m.
    cell_size : float
        Cell side c, m.
    cv : ndarray of int16, shape (nx, ny)
        Certainty values, index i along x and j along y (`pfm_stability.sim.grid.HistogramGrid`'s layout).
    """

    x_min: float
    y_min: float
    cell_size: float
    cv: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """(nx, ny)."""
        return self.cv.shape

    @property
    def occupied(self) -> np.ndarray:
        """Occupied cells, shape (nx, ny)."""
        return self.cv > 0


    def clearance(self) -> np.ndarray:
        """Distance from each cell centre to the nearest occupied cell square, m, shape (nx, ny).

        The outside of the grid counts as occupied (the map says nothing there, so
        no route leaves it); 0 in occupied cells.
        """
        from scipy.ndimage import distance_transform_edt

        padded = np.pad(~self.occupied, 1, constant_values=False)
        if not padded.any():
            return np.zeros(self.shape)
        d = distance_transform_edt(padded)[1:-1, 1:-1] * self.cell_size
        return np.where(self.occupied, 0.0, np.maximum(d - self.cell_size / 2, 0.0))


def histogram_of(occupancy: OccupancyMap, cell_size: float = 0.1, unknown: str = "occupied", cv: int = DEFAULT_CV) -> HistogramMap:
    """Reduce a map onto the robot's histogram grid (module docstring).

    Parameters
    ----------
    occupancy : OccupancyMap
    cell_size : float
        Cell side c, m.
    unknown : {"occupied", "free"}
        How unknown map cells count.
    cv : int
        Certainty value of an occupied cell.
    """
    if unknown not in UNKNOWN_AS:
        raise ValueError(f"unknown must be one of {', '.join(UNKNOWN_AS)}; got {unknown!r}")
    blocked = occupancy.occupied | (occupancy.unknown if unknown == "occupied" else False)
    r, c = occupancy.resolution, cell_size
    nx = max(1, math.ceil(occupancy.width * r / c - 1e-9))
    ny = max(1, math.ceil(occupancy.height * r / c - 1e-9))
    rows, cols = np.nonzero(blocked)
    i = np.minimum(np.floor((cols + 0.5) * r / c).astype(np.int64), nx - 1)
    j = np.minimum(np.floor((rows + 0.5) * r / c).astype(np.int64), ny - 1)
    grid = np.zeros((nx, ny), dtype=np.int16)
    grid[i, j] = cv
    grid.flags.writeable = False
    return HistogramMap(float(occupancy.origin[0]), float(occupancy.origin[1]), float(c), grid)


def _scale(law: GridWallLaw) -> float:
    return law.ratio * law.W**law.n


def window_force(grid: HistogramMap, law: GridWallLaw, px, py, *, jacobian: bool = False):
    """The exact window sum F_r/F_ct at points, and optionally its Jacobian (module docstring).

    Parameters
    ----------
    grid : HistogramMap
    law : GridWallLaw
        Cell ratio ρ, exponent n, width W, window side w (its cell size must be the grid's).
    px, py : array_like
        Points, m (any shape; a point inside an occupied cell's centre gives inf/nan there).
    jacobian : bool
        Also return ∂F/∂p.

    Returns
    -------
    (fx, fy) or (fx, fy, jxx, jxy, jyy) : ndarray shaped like `px`
        Repulsion in units of F_ct; the Jacobian in 1/m (symmetric: jxy = jyx).
    """
    px, py = np.broadcast_arrays(np.asarray(px, dtype=float), np.asarray(py, dtype=float))
    shape = px.shape
    px, py = px.ravel(), py.ravel()
    h = law.window_cells // 2
    nx, ny = grid.shape
    i, j = grid.cell_index(px, py)
    far = (i < -h) | (j < -h) | (i >= nx + h) | (j >= ny + h)  # windows entirely outside the grid: no force
    stride = ny + 2 * h  # cells keyed from (−h, −h): one window list per distinct cell
    cells, point_cell = np.unique((np.clip(i, -h, nx + h - 1) + h) * stride + np.clip(j, -h, ny + h - 1) + h, return_inverse=True)
    point_cell = point_cell.ravel()
    ci, cj, cv, start, count = _window_lists(grid.cv, cells // stride - h, cells % stride - h, h)
    count = np.where(far, 0, count[point_cell])
    window_start = start[point_cell]
    out = [np.zeros(px.size) for _ in range(5 if jacobian else 2)]
    n = law.n
    c = grid.cell_size
    for p0, p1 in _point_chunks(count):
        # the chunk's points take the occupied cells of their cells' windows: CSR expansion
        taken = count[p0:p1]
        p = np.repeat(np.arange(p1 - p0), taken)
        e = np.repeat(window_start[p0:p1] - (np.cumsum(taken) - taken), taken) + np.arange(p.size)
        dx = px[p0:p1][p] - (grid.x_min + (ci[e] + 0.5) * c)
        dy = py[p0:p1][p] - (grid.y_min + (cj[e] + 0.5) * c)
        r2 = dx * dx + dy * dy
        with np.errstate(divide="ignore", invalid="ignore"):
            w = cv[e] * r2 ** (-(n + 1) / 2)
            terms = [w * dx, w * dy]
            if jacobian:
                w2 = (n + 1) * w / r2
                terms += [w - w2 * dx * dx, -w2 * dx * dy, w - w2 * dy * dy]
        for o, t in zip(out, terms):
            o[p0:p1] = np.bincount(p, weights=t, minlength=p1 - p0)
    s = _scale(law)
    return tuple(s * o.reshape(shape) for o in out)


def _point_chunks(count: np.ndarray):
    """(first, stop) of consecutive points whose window cells (`count` each) add up to about `CHUNK_ENTRIES`: a
    point's cells all in one chunk, so that its sum is one `np.bincount`'s, in window order."""
    if count.size == 0:
        return
    ends = np.cumsum(count)
    first = 0
    while first < count.size:
        stop = int(np.searchsorted(ends, (ends[first - 1] if first else 0) + CHUNK_ENTRIES, side="right"))
        stop = max(stop, first + 1)
        yield first, stop
        first = stop


def _window_lists(cv_grid: np.ndarray, ii, jj, h: int):
    """Occupied cells of the windows of the cells (ii, jj) (indices into the grid, may be up to h outside).

    Returns (ci, cj, cv, start, count): the occupied cells' grid indices and CVs of all windows one after the other
    (each window's column by column, i then j ascending), and where each window's list starts and its length. The
    occupied cells sorted by (i, j) answer each window column's range [j − h, j + h] by two binary searches
    (``np.searchsorted``), instead of gathering every cell of every window.
    """
    nx, ny = cv_grid.shape
    oi, oj = np.nonzero(cv_grid)  # sorted by i, then j
    key = oi * ny + oj
    ocv = cv_grid[oi, oj].astype(float)
    column = ii[:, None] + np.arange(-h, h + 1)[None, :]  # (windows, w)
    inside = (column >= 0) & (column < nx)
    j_low, j_high = np.clip(jj - h, 0, ny), np.clip(jj + h + 1, 0, ny)  # the window's rows [j_low, j_high)
    base = np.where(inside, column, 0) * ny
    first = np.searchsorted(key, base + j_low[:, None])
    runs = np.where(inside & (j_high > j_low)[:, None], np.searchsorted(key, base + j_high[:, None]) - first, 0)
    count = runs.sum(axis=1)
    start = np.concatenate([[0], np.cumsum(count)[:-1]]) if count.size else count
    runs, first = runs.ravel(), first.ravel()
    index = np.repeat(first - (np.cumsum(runs) - runs), runs) + np.arange(int(runs.sum()))
    return oi[index], oj[index], ocv[index], start, count


def window_kernels(law: GridWallLaw):
    """(kx, ky), shape (w, w): the force of one cell of C = 1 at window offset (a, b) on a robot at the centre."""
    h = law.window_cells // 2
    c = law.cell_size
    offsets = np.arange(-h, h + 1) * c
    ax, by = np.meshgrid(offsets, offsets, indexing="ij")
    r2 = ax * ax + by * by
    r2[h, h] = 1.0  # the centre term (d = 0) is excluded
    w = np.where((ax == 0) & (by == 0), 0.0, r2 ** (-(law.n + 1) / 2)) * _scale(law)
    return -ax * w, -by * w


def centre_field(grid: HistogramMap, law: GridWallLaw):
    """(fx, fy), shape (nx, ny): F_r/F_ct at every cell centre (an occupied cell's own term excluded), by FFT.

    F(i, j) = Σ_{a, b} C(i + a, j + b)·k(a, b), a correlation of the certainty grid
    with the window kernel (`window_kernels`), computed as a convolution with the
    flipped kernel (``scipy.signal.fftconvolve``); cells outside the grid are empty.

    Parameters
    ----------
    grid : HistogramMap
        Certainty values and cell size.
    law : GridWallLaw
        The window and its force constants.
    """
    from scipy.signal import fftconvolve

    kx, ky = window_kernels(law)
    cv = grid.cv.astype(float)
    return (fftconvolve(cv, kx[::-1, ::-1], mode="same"), fftconvolve(cv, ky[::-1, ::-1], mode="same"))
