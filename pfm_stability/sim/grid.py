"""The histogram grid of the VFF method (Koren & Borenstein 1991 §2; docs/simulator.md).

Square cells of side c (default 0.1 m) hold integer certainty values (CV,
0 … `cv_max`, default 15). Cell (i, j) covers
[x_min + i·c, x_min + (i+1)·c) × [y_min + j·c, y_min + (j+1)·c); its centre is
the point a cell's repulsion comes from (KB eq 1: "d is the distance between
the cell and the center of the vehicle"). X is lateral, Y along the corridor.

Drawing helpers mark the cells an obstacle occupies: `draw_segment` (a wall
of any orientation, one cell thick: every cell the segment passes through,
found by sampling it every c/16), `draw_polyline`, `draw_rectangle` and
`draw_polygon` (filled by cell centre, outline always marked), `draw_protrusion`
(a bump on a wall), and `draw_gap` / `clear_rectangle` (openings). `add_readings` is the VFF update
from a range sensor (KB §2: each reading adds 1 to the CV of the cell it falls
in, up to `cv_max`; the MuJoCo engine's ray casts, docs/mujoco.md). A segment
lying exactly on a cell boundary marks the cells on its +X / +Y side; put walls
on cell centres (`HistogramGrid.centred`) for symmetric corridors.

The grid is a builder: drawing mutates it until `freeze` makes it read-only
(preset grids are frozen and shared between the members of a batch).
"""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_integer, check_number
from ..laws.effective_force import DEFAULT_CV
from ..numerics.cells import CellGrid

__all__ = ["HistogramGrid"]

_SEGMENT_SAMPLES_PER_CELL = 16


class HistogramGrid(CellGrid):
    """A rectangular histogram grid of certainty values.

    Parameters
    ----------
    x_min, y_min : float
        Lower-left corner, m.
    width, height : float
        Extent, m, > 0; rounded up to whole cells.
    cell_size : float
        Cell side c, m, > 0 (KB: 0.1 m).
    cv_max : int
        Largest certainty value, and the default CV of drawn obstacles (15).
    """

    def __init__(self, x_min, y_min, width, height, *, cell_size=0.1, cv_max=DEFAULT_CV):
        self.x_min = check_number("x_min", x_min, unit="m")
        self.y_min = check_number("y_min", y_min, unit="m")
        width = check_number("width", width, 0.0, unit="m")
        height = check_number("height", height, 0.0, unit="m")
        self.cell_size = check_number("cell_size", cell_size, 0.0, unit="m")
        self.cv_max = check_integer("cv_max", cv_max, 1, 32767)
        nx = math.ceil(width / self.cell_size - 1e-9)
        ny = math.ceil(height / self.cell_size - 1e-9)
        if nx * ny > 50_000_000:
            raise ValueError(f"grid must have at most 5e7 cells; got {nx} x {ny}")
        self.cv = np.zeros((nx, ny), dtype=np.int16)
        self.frozen = False

    @classmethod
    def centred(cls, x_lo, x_hi, y_lo, y_hi, *, cell_size=0.1, cv_max=DEFAULT_CV) -> "HistogramGrid":
        """A grid covering [x_lo, x_hi] × [y_lo, y_hi] whose cell *centres* lie on multiples of c.

        Then x = 0 is a cell centre: a robot there has a symmetric window, and
        walls drawn at x = ±L (L a multiple of c) sit on cell centres.

        Parameters
        ----------
        x_lo, x_hi, y_lo, y_hi : float
            The area to cover, m.
        cell_size : float
            Cell side c, m.
        cv_max : int
            Largest certainty value (`HistogramGrid`).
        """
        c = check_number("cell_size", cell_size, 0.0, unit="m")
        x0 = (math.floor(x_lo / c) - 0.5) * c
        y0 = (math.floor(y_lo / c) - 0.5) * c
        x1 = (math.ceil(x_hi / c) + 0.5) * c
        y1 = (math.ceil(y_hi / c) + 0.5) * c
        return cls(x0, y0, x1 - x0, y1 - y0, cell_size=c, cv_max=cv_max)

    # ------------------------------------------------------------ geometry
    @property
    def shape(self) -> tuple[int, int]:
        """(nx, ny): cells along X and Y."""
        return self.cv.shape

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max), m."""
        nx, ny = self.shape
        c = self.cell_size
        return (self.x_min, self.x_min + nx * c, self.y_min, self.y_min + ny * c)


    def occupied(self):
        """Centres and CVs of the occupied cells: (x, y, cv) float arrays, ordered by (i, j)."""
        i, j = np.nonzero(self.cv)
        x, y = self.cell_center(i, j)
        return x, y, self.cv[i, j].astype(float)

    def occupied_at(self, x, y) -> np.ndarray:
        """True where the point lies in an occupied cell (False outside the grid).

        Parameters
        ----------
        x, y : array_like
            Points, m.
        """
        i, j = self.cell_index(x, y)
        nx, ny = self.shape
        inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
        out = np.zeros(np.shape(i), dtype=bool)
        out[inside] = self.cv[i[inside], j[inside]] > 0
        return out

    def clearance(self, x, y) -> np.ndarray:
        """Distance from each point to the nearest occupied cell square, m (``inf`` if none).

        Exact and brute force (every occupied cell); the simulator uses the
        compiled near-cell lists of `pfm_stability.sim.window` instead.

        Parameters
        ----------
        x, y : array_like
            Points, m.
        """
        ox, oy, _ = self.occupied()
        x = np.atleast_1d(np.asarray(x, dtype=float))
        y = np.atleast_1d(np.asarray(y, dtype=float))
        if ox.size == 0:
            return np.full(x.shape, math.inf)
        half = self.cell_size / 2
        gx = np.maximum(np.abs(x[..., None] - ox) - half, 0.0)
        gy = np.maximum(np.abs(y[..., None] - oy) - half, 0.0)
        return np.sqrt(np.min(gx * gx + gy * gy, axis=-1))

    # ------------------------------------------------------------- drawing
    def _cv_value(self, cv) -> int:
        if cv is None:
            return self.cv_max
        return check_integer("cv", cv, 0, self.cv_max)

    def freeze(self) -> "HistogramGrid":
        """Make the grid read-only (shared preset grids); drawing then raises ValueError."""
        self.frozen = True
        self.cv.flags.writeable = False
        return self

    def copy(self) -> "HistogramGrid":
        """An unfrozen copy to draw on."""
        nx, ny = self.shape
        c = self.cell_size
        out = HistogramGrid(self.x_min, self.y_min, nx * c, ny * c, cell_size=c, cv_max=self.cv_max)
        out.cv[:] = self.cv
        return out

    def _mark(self, i, j, value: int) -> None:
        if self.frozen:
            raise ValueError("grid is frozen (a shared preset grid); draw on grid.copy()")
        nx, ny = self.shape
        keep = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
        self.cv[i[keep], j[keep]] = value

    def _segment_cells(self, p0, p1):
        (x0, y0), (x1, y1) = p0, p1
        length = math.hypot(x1 - x0, y1 - y0)
        count = max(2, math.ceil(length / self.cell_size * _SEGMENT_SAMPLES_PER_CELL) + 1)
        s = np.linspace(0.0, 1.0, count)
        return self.cell_index(x0 + s * (x1 - x0), y0 + s * (y1 - y0))

    def add_readings(self, x, y, increment: int = 1) -> "HistogramGrid":
        """The VFF update (KB §2): each range reading at (x, y) adds `increment` to its cell's CV, capped at `cv_max`.

        Several readings in one cell add up; readings outside the grid are ignored.

        Parameters
        ----------
        x, y : array_like
            Where the readings fell (the sensor's hit points), m.
        increment : int
            CV added per reading (KB: 1).
        """
        if self.frozen:
            raise ValueError("grid is frozen (a shared preset grid); draw on grid.copy()")
        increment = check_integer("increment", increment, 1, self.cv_max)
        i, j = self.cell_index(np.ravel(x), np.ravel(y))
        nx, ny = self.shape
        keep = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
        cells, counts = np.unique(np.ravel_multi_index((i[keep], j[keep]), self.shape), return_counts=True)
        flat = self.cv.reshape(-1)  # a view: the grid's cells in (i, j) order
        flat[cells] = np.minimum(flat[cells].astype(np.int64) + increment * counts, self.cv_max)
        return self

    def draw_segment(self, p0, p1, cv=None) -> "HistogramGrid":
        """Mark every cell the segment p0 → p1 (m) passes through: a wall of any orientation.

        Parameters
        ----------
        p0, p1 : (float, float)
            The segment's ends, m.
        cv : int, optional
            Certainty value of its cells (default `cv_max`).
        """
        self._mark(*self._segment_cells(p0, p1), self._cv_value(cv))
        return self

    def draw_polyline(self, points, cv=None) -> "HistogramGrid":
        """`draw_segment` for each consecutive pair of points (a wall with corners).

        Parameters
        ----------
        points : sequence of (float, float)
            The corners, m.
        cv : int, optional
            Certainty value of its cells (default `cv_max`).
        """
        for p0, p1 in zip(points[:-1], points[1:]):
            self.draw_segment(p0, p1, cv)
        return self

    def draw_polygon(self, vertices, cv=None, filled=True) -> "HistogramGrid":
        """Mark the outline of a polygon (m) and, if `filled`, every cell whose centre is inside.

        Parameters
        ----------
        vertices : sequence of (float, float)
            The polygon's corners, m.
        cv : int, optional
            Certainty value of its cells (default `cv_max`).
        filled : bool
            Fill the inside too.
        """
        value = self._cv_value(cv)
        closed = list(vertices) + [vertices[0]]
        for p0, p1 in zip(closed[:-1], closed[1:]):
            self._mark(*self._segment_cells(p0, p1), value)
        if filled:
            vx = np.array([p[0] for p in vertices], dtype=float)
            vy = np.array([p[1] for p in vertices], dtype=float)
            i0, j0 = self.cell_index(vx.min(), vy.min())
            i1, j1 = self.cell_index(vx.max(), vy.max())
            ii, jj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1), indexing="ij")
            cx, cy = self.cell_center(ii, jj)
            inside = _inside_polygon(cx, cy, vx, vy)
            self._mark(ii[inside], jj[inside], value)
        return self

    def draw_rectangle(self, x0, y0, x1, y1, cv=None, filled=True) -> "HistogramGrid":
        """An axis-aligned rectangle with corners (x0, y0), (x1, y1), m.

        Parameters
        ----------
        x0, y0, x1, y1 : float
            Opposite corners, m.
        cv : int, optional
            Certainty value of its cells (default `cv_max`).
        filled : bool
            Fill the inside too.
        """
        return self.draw_polygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], cv, filled)

    def draw_protrusion(self, p0, p1, depth, cv=None, filled=False) -> "HistogramGrid":
        """A bump of `depth` m on the wall segment p0 → p1, towards its left (the +90° normal).

        Drawn as its outline (two flanks and the front face, like a wall that
        juts out) unless `filled`.

        Parameters
        ----------
        p0, p1 : (float, float)
            The wall segment's ends, m.
        depth : float
            How far the bump juts out, m.
        cv : int, optional
            Certainty value of its cells (default `cv_max`).
        filled : bool
            Fill the bump rather than draw its outline.
        """
        depth = check_number("depth", depth, 0.0, unit="m")
        (x0, y0), (x1, y1) = p0, p1
        length = math.hypot(x1 - x0, y1 - y0)
        if length == 0:
            raise ValueError("protrusion must have p0 != p1")
        nx_, ny_ = -(y1 - y0) / length * depth, (x1 - x0) / length * depth
        corners = [(x0, y0), (x0 + nx_, y0 + ny_), (x1 + nx_, y1 + ny_), (x1, y1)]
        if filled:
            return self.draw_polygon(corners, cv, filled=True)
        return self.draw_polyline(corners, cv)

    def draw_gap(self, p0, p1) -> "HistogramGrid":
        """Clear the cells the segment p0 → p1 passes through (an opening in a wall).

        Parameters
        ----------
        p0, p1 : (float, float)
            The segment's ends, m.
        """
        self._mark(*self._segment_cells(p0, p1), 0)
        return self

    def clear_rectangle(self, x0, y0, x1, y1) -> "HistogramGrid":
        """Clear every cell of an axis-aligned rectangle (a wide opening).

        Parameters
        ----------
        x0, y0, x1, y1 : float
            Opposite corners, m.
        """
        return self.draw_rectangle(x0, y0, x1, y1, cv=0, filled=True)

    def __repr__(self) -> str:
        nx, ny = self.shape
        return (
            f"HistogramGrid({nx}x{ny} cells of {self.cell_size:g} m at ({self.x_min:g}, {self.y_min:g}), "
            f"{int(np.count_nonzero(self.cv))} occupied)"
        )


def _inside_polygon(x, y, vx, vy) -> np.ndarray:
    """Even–odd rule: True where (x, y) is strictly inside the polygon (vx, vy)."""
    inside = np.zeros(np.shape(x), dtype=bool)
    n = len(vx)
    for a in range(n):
        b = (a + 1) % n
        crosses = (vy[a] > y) != (vy[b] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_cross = vx[a] + (y - vy[a]) * (vx[b] - vx[a]) / (vy[b] - vy[a])
        inside ^= crosses & (x < x_cross)
    return inside
