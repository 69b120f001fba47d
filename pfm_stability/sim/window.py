"""Active-window lookup tables: which occupied cells a robot in a given cell sees.

The VFF window is the w_s × w_s block of cells centred on the robot's cell
(Koren & Borenstein 1991 §2), and only occupied cells contribute to eq (1–2).
Profiling the batch engine showed the window scan dominating (a 33 × 33
window is 1089 cells, a corridor fills ~66 of them), so the occupied cells of
every window are listed once per grid:

* ``wx[row], wy[row], wcv[row]`` — centres and CVs of the occupied cells in
  the window of the robot cells mapped to ``row``, padded to a common width K
  with a *sentinel* cell (CV 0, 10⁹ m away) that contributes exactly 0
  (coordinates rather than indices: a step then gathers whole rows, which
  made the whole 1000-robot step 1.3× faster than gathering cell by cell);
* ``near[row]`` — the occupied cells of the window whose square lies within
  W_max/2 + step_max of the robot cell's square: every cell the robot disc
  can touch at a sample or on its way to the next one (docs/simulator.md,
  `pfm_stability.sim.contact`);
* ``row_of_cell`` — row of each robot cell of the grid padded by h cells on
  every side (a window can see the grid from outside it). Robot cells with no
  occupied cell in their window share row 0 (empty). Cells that no robot of
  width >= W_min can reach within one step (`step_max`) of a collision-free
  position map to −1: a robot there is colliding, and the engine finds its
  clearance by brute force (`HistogramGrid.clearance`) instead.

Several grids (one per distinct environment of a batch) are concatenated by
`stack_tables` so that one gather serves every member.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..laws.effective_force import check_window_cells
from .grid import HistogramGrid

__all__ = ["WindowTable", "compile_window_table", "stack_tables", "SENTINEL_DISTANCE"]

SENTINEL_DISTANCE = 1e9
"""Coordinates (m) of the padding cell; with CV 0 its force is exactly 0."""


@dataclass(frozen=True)
class WindowTable:
    """Occupied-cell lists of the active windows of one grid (or a stack of grids).

    Attributes
    ----------
    ox, oy, ocv : ndarray
        Occupied cell centres (m) and CVs; the last entry is the sentinel.
    wx, wy, wcv : ndarray, shape (rows, K)
        Window lists: cell centres (m) and CVs, padded with the sentinel.
    near : ndarray of int32, shape (rows, K_near)
        Collision candidates, padded with the sentinel index.
    near_count : ndarray of int32, shape (rows,)
    row_of_cell : ndarray of int32
        Row per padded robot cell (flattened, i-major), −1 = unreachable.
    grids : tuple of GridGeometry
        Per grid: where its cells start in `row_of_cell` and its geometry.
    """

    ox: np.ndarray
    oy: np.ndarray
    ocv: np.ndarray
    wx: np.ndarray
    wy: np.ndarray
    wcv: np.ndarray
    near: np.ndarray
    near_count: np.ndarray
    row_of_cell: np.ndarray
    grids: tuple

    @property
    def sentinel(self) -> int:
        return self.ox.size - 1

    @property
    def rows(self) -> int:
        return self.wx.shape[0]


@dataclass(frozen=True)
class GridGeometry:
    """Where one grid's padded cells live in a (stacked) table."""

    cell_offset: int
    x_min: float
    y_min: float
    cell_size: float
    nx_padded: int
    ny_padded: int
    pad: int
    near_radius: float = 0.0

    @property
    def listed_within(self) -> float:
        """Every occupied cell whose square lies within this distance (m) of a robot cell's square is in its near list:
        the near radius, or the window's edge (h·c) if that comes first."""
        return min(self.near_radius, self.pad * self.cell_size)


def _square_gap(di, dj):
    """Gap between two cell squares whose indices differ by (di, dj), in cells."""
    gx = np.maximum(np.abs(di) - 1, 0)
    gy = np.maximum(np.abs(dj) - 1, 0)
    return np.sqrt(gx * gx + gy * gy)


def _pad_lists(keys, values, rows: int, sentinel: int):
    """Group `values` by `keys` (0 … rows−1) into a (rows, K) array padded with `sentinel`."""
    order = np.argsort(keys, kind="stable")
    keys, values = keys[order], values[order]
    counts = np.bincount(keys, minlength=rows).astype(np.int32)
    width = int(counts.max()) if counts.size and counts.max() > 0 else 1
    out = np.full((rows, width), sentinel, dtype=np.int32)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    position = np.arange(keys.size) - starts[keys]
    out[keys, position] = values
    return out, counts


def compile_window_table(
    grid: HistogramGrid, window_cells: int = 33, W_min: float = 0.0, W_max: float = 0.0, step_max: float = 0.0
) -> WindowTable:
    """Window and collision lists of one grid.

    Parameters
    ----------
    grid : HistogramGrid
    window_cells : int
        Window side w_s, odd, >= 3.
    W_min, W_max : float
        Smallest and largest robot width that will use the table, m: the
        collision lists reach W_max/2 + step_max (inside the window), and
        robot cells are left out (row −1) when every point of them is closer
        than W_min/2 − step_max to an obstacle.
    step_max : float
        Longest distance a robot travels in one sampling period, m (V·T).
    """
    from scipy.ndimage import distance_transform_edt

    h = check_window_cells(window_cells) // 2
    c = grid.cell_size
    nx, ny = grid.shape
    nxp, nyp = nx + 2 * h, ny + 2 * h
    occ_i, occ_j = np.nonzero(grid.cv)
    m = occ_i.size
    ox, oy = grid.cell_center(occ_i, occ_j)
    ocv = grid.cv[occ_i, occ_j].astype(float)
    sentinel = m
    ox = np.append(ox.astype(float), SENTINEL_DISTANCE)
    oy = np.append(oy.astype(float), SENTINEL_DISTANCE)
    ocv = np.append(ocv, 0.0)

    # reachable robot cells: some point of the cell has clearance > W_min/2
    padded = np.ones((nxp, nyp), dtype=bool)
    padded[occ_i + h, occ_j + h] = False
    if m:
        centre_distance = distance_transform_edt(padded) * c
    else:
        centre_distance = np.full((nxp, nyp), math.inf)
    # clearance(p) <= |p − occupied centre| − c/2 <= D + c/√2 − c/2 for p in the cell; a robot
    # clear of obstacles at t_k (clearance > W/2) ends the period with clearance > W/2 − step_max
    reachable = centre_distance > W_min / 2 - step_max + c / 2 - c / math.sqrt(2) - 1e-12

    offsets = np.arange(-h, h + 1)
    di, dj = [a.ravel() for a in np.meshgrid(offsets, offsets, indexing="ij")]
    ri = (occ_i[:, None] + h + di[None, :]).ravel()
    rj = (occ_j[:, None] + h + dj[None, :]).ravel()
    occ_index = np.repeat(np.arange(m, dtype=np.int32), di.size)
    keep = reachable[ri, rj]
    cell_key = ri[keep] * nyp + rj[keep]
    occ_index = occ_index[keep]
    near_radius = W_max / 2 + step_max
    near_mask = _square_gap(di, dj) * c <= near_radius + 1e-12
    near_keep = np.tile(near_mask, m)[keep]

    # rows: 0 = empty window; then one row per reachable robot cell that sees something
    cells_with_lists, row_key = np.unique(cell_key, return_inverse=True)
    rows = cells_with_lists.size + 1
    row_of_cell = np.where(reachable.ravel(), 0, -1).astype(np.int32)
    row_of_cell[cells_with_lists] = np.arange(1, rows, dtype=np.int32)
    row_key = row_key + 1
    table, _ = _pad_lists(row_key, occ_index, rows, sentinel)
    near, near_count = _pad_lists(row_key[near_keep], occ_index[near_keep], rows, sentinel)
    geometry = GridGeometry(0, grid.x_min, grid.y_min, c, nxp, nyp, h, near_radius)
    return WindowTable(ox, oy, ocv, ox[table], oy[table], ocv[table], near, near_count, row_of_cell, (geometry,))


def stack_tables(tables) -> WindowTable:
    """Concatenate the tables of several grids into one (rows, cells and occupied indices offset).

    Parameters
    ----------
    tables : sequence of WindowTable
        One table per grid.
    """
    tables = list(tables)
    if len(tables) == 1:
        return tables[0]
    width = max(t.wx.shape[1] for t in tables)
    near_width = max(t.near.shape[1] for t in tables)
    sentinel = sum(t.sentinel for t in tables)
    occ, windows, near, counts, cells, grids = [], [], [], [], [], []
    occ_offset = row_offset = cell_offset = 0
    for t in tables:
        m = t.sentinel
        occ.append((t.ox[:m], t.oy[:m], t.ocv[:m]))
        windows.append(tuple(_pad_columns(a, width, fill) for a, fill in ((t.wx, SENTINEL_DISTANCE), (t.wy, SENTINEL_DISTANCE), (t.wcv, 0.0))))
        shifted = np.where(t.near != t.sentinel, t.near + occ_offset, sentinel)
        near.append(_pad_columns(shifted, near_width, sentinel))
        counts.append(t.near_count)
        # row 0 (the empty window) of every table is all sentinel: keep pointing at the first one
        cells.append(np.where(t.row_of_cell > 0, t.row_of_cell + row_offset, t.row_of_cell))
        for g in t.grids:
            grids.append(GridGeometry(g.cell_offset + cell_offset, g.x_min, g.y_min, g.cell_size, g.nx_padded, g.ny_padded, g.pad, g.near_radius))
        occ_offset += m
        row_offset += t.rows
        cell_offset += t.row_of_cell.size
    ox, oy, ocv = (np.concatenate([o[i] for o in occ]) for i in range(3))
    return WindowTable(
        np.append(ox, SENTINEL_DISTANCE),
        np.append(oy, SENTINEL_DISTANCE),
        np.append(ocv, 0.0),
        *(np.vstack([w[i] for w in windows]) for i in range(3)),
        np.vstack(near).astype(np.int32),
        np.concatenate(counts),
        np.concatenate(cells),
        tuple(grids),
    )


def _pad_columns(a, width, fill):
    out = np.full((a.shape[0], width), fill, dtype=a.dtype)
    out[:, : a.shape[1]] = a
    return out
