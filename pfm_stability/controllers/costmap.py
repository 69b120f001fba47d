"""The local costmap Nav2's critics feel: the inflation layer's cost around a straight corridor's walls.

**Inflation** (``nav2_costmap_2d/include/nav2_costmap_2d/inflation_layer.hpp`` ``InflationLayer::computeCost``):
a cell at distance d from the nearest lethal cell costs

* 254 (``LETHAL_OBSTACLE``) at d = 0,
* 253 (``INSCRIBED_INFLATED_OBSTACLE``) for 0 < d <= r (the robot's inscribed radius),
* ⌊252·exp(−cost_scaling_factor·(d − r))⌋ beyond (``(INSCRIBED_INFLATED_OBSTACLE − 1)·factor`` cast to
  ``unsigned char``: truncated),
* 0 (free) for cells farther than ``inflation_radius`` — in whole cells: ``plugins/inflation_layer.cpp``
  ``applyInflation`` skips cells whose distance in cells exceeds ⌈inflation_radius/resolution⌉
  (``Costmap2D::cellDistance``), so the cost drops from its value at that many cells straight to 0 (with
  Nav2's bringup values, 0.70 m and 3.0, from 59 to 0).

The distance is the Euclidean distance transform in cells between cell centres, and the cost of a distance is
read from a table at 1/100 of a cell (``COST_LUT_PRECISION``, rounded: ``distance·100 + 0.5`` truncated).

**The corridor** (`CorridorCostmap`): walls of lethal cells along x at y = ±half_width (none: a straight plan in
free space), on a world-fixed lattice of square cells whose centres lie on multiples of the resolution shifted by
``lattice`` (default none: the centre line y = 0 is a row of cell centres and the grid is symmetric about it; a
plan is rarely aligned with the costmap's cells, and a linearisation of a quantized controller draws the shift). A robot's local costmap is the
rolling window of ``width`` × ``height`` around it (Nav2's ``rolling_window``: the origin moves in whole cells,
``Costmap2D::updateOrigin``); a point outside it has no information (255), a pose of the plan outside it ends
the plan a controller sees (`controllers.plan.local_plan`). ``exact=True`` replaces each cell's cost by the
formula above at the point's own distance to the nearer wall, in floating point (no cells, no truncation, no
table): the smooth potential the grid approximates, for numeric derivatives.

Defaults are Nav2's bringup configuration (``nav2_bringup/params/nav2_params.yaml``, ``local_costmap``:
resolution 0.05 m, 3 m × 3 m, ``robot_radius`` 0.22 m, ``inflation_radius`` 0.70 m, ``cost_scaling_factor``
3.0); the source's declared defaults are 0.55 m and 10.0 (``inflation_layer.cpp``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..checks import check_number

__all__ = ["FREE_SPACE", "INSCRIBED_INFLATED_OBSTACLE", "LETHAL_OBSTACLE", "NO_INFORMATION", "COST_LUT_PRECISION",
           "Inflation", "Window", "CorridorCostmap"]

FREE_SPACE = 0
INSCRIBED_INFLATED_OBSTACLE = 253
LETHAL_OBSTACLE = 254
NO_INFORMATION = 255
COST_LUT_PRECISION = 100
"""Entries of the inflation layer's cost table per cell of distance (``InflationLayer::COST_LUT_PRECISION``)."""


@dataclass(frozen=True)
class Inflation:
    """The inflation layer's parameters and its cost of a distance (module docstring).

    Attributes
    ----------
    inflation_radius : float
        m (bringup 0.70; source default 0.55).
    cost_scaling_factor : float
        1/m (bringup 3.0; source default 10.0).
    inscribed_radius : float
        The robot's inscribed radius, m (bringup ``robot_radius`` 0.22).
    """

    inflation_radius: float = 0.70
    cost_scaling_factor: float = 3.0
    inscribed_radius: float = 0.22

    def __post_init__(self):
        object.__setattr__(self, "inflation_radius", check_number("inflation_radius", self.inflation_radius, 0.0, 100.0, low_open=False, unit="m"))
        object.__setattr__(self, "cost_scaling_factor", check_number("cost_scaling_factor", self.cost_scaling_factor, 0.0, 1e4, unit="1/m"))
        object.__setattr__(self, "inscribed_radius", check_number("inscribed_radius", self.inscribed_radius, 0.0, 100.0, low_open=False, unit="m"))

    def cost(self, distance):
        """The inflation cost at a distance from the nearest lethal point, in floating point (no truncation, no cells).

        Parameters
        ----------
        distance : float or ndarray
            m (<= 0: lethal).
        """
        d = np.asarray(distance, dtype=float)
        decay = 252.0 * np.exp(-self.cost_scaling_factor * np.maximum(d - self.inscribed_radius, 0.0))
        out = np.where(d <= 0.0, 254.0, np.where(d <= self.inscribed_radius, 253.0, np.where(d <= self.inflation_radius, decay, 0.0)))
        return float(out) if out.ndim == 0 else out

    def cell_radius(self, resolution: float) -> int:
        """⌈inflation_radius/resolution⌉, cells (``Costmap2D::cellDistance``).

        Parameters
        ----------
        resolution : float
            m per cell.
        """
        return int(max(0.0, math.ceil(self.inflation_radius / resolution)))

    def cell_cost(self, distance_cells, resolution: float):
        """The cost Nav2 writes into a cell at `distance_cells` from the nearest lethal cell (module docstring).

        Parameters
        ----------
        distance_cells : float or ndarray
            Distance between cell centres, cells.
        resolution : float
            m per cell.

        Returns
        -------
        ndarray of uint8
        """
        d = np.asarray(distance_cells, dtype=float)
        radius = self.cell_radius(resolution)
        lut_max = radius * COST_LUT_PRECISION + 1
        scaled = np.minimum(lut_max, np.floor(d * COST_LUT_PRECISION + 0.5)) / COST_LUT_PRECISION  # the table's distance
        metres = scaled * resolution
        decay = np.floor(252.0 * np.exp(-self.cost_scaling_factor * (metres - self.inscribed_radius)))
        cost = np.where(scaled == 0.0, 254, np.where(metres <= self.inscribed_radius, 253, decay))
        return np.where(d > radius, 0, cost).astype(np.uint8)


@dataclass(frozen=True)
class Window:
    """A local costmap's bounds: cells [0, nx) × [0, ny) from the origin (x0, y0), m.

    Attributes
    ----------
    x0, y0 : float
        Origin (the lower corner of cell (0, 0)), m.
    nx, ny : int
        Cells along x and y.
    resolution : float
        m per cell.
    """

    x0: float
    y0: float
    nx: int
    ny: int
    resolution: float

    def contains(self, x, y):
        """Whether points lie on the window (``Costmap2D::worldToMap`` succeeds), element-wise.

        Parameters
        ----------
        x, y : float or ndarray
            m.
        """
        x, y = np.asarray(x), np.asarray(y)
        return (x >= self.x0) & (y >= self.y0) & (x < self.x0 + self.nx * self.resolution) & (y < self.y0 + self.ny * self.resolution)


@dataclass(frozen=True)
class CorridorCostmap:
    """A straight corridor along x (or free space) as Nav2's local costmap sees it (module docstring).

    Attributes
    ----------
    half_width : float or None
        Centre line to each wall's cells, m (None: no walls). The grid puts the walls on the nearest row of cell
        centres (`wall_rows`); ``exact`` keeps them where given.
    inflation : Inflation
        The inflation layer.
    resolution : float
        m per cell.
    width, height : float
        The rolling window's size, m.
    exact : bool
        The cost at a point's own distance to the wall, in floating point, instead of its cell's (module docstring).
    lattice : (float, float)
        Where the cell centres are: (i·resolution + lattice[0], j·resolution + lattice[1]), m.
    """

    half_width: float | None = None
    inflation: Inflation = field(default_factory=Inflation)
    resolution: float = 0.05
    width: float = 3.0
    height: float = 3.0
    exact: bool = False
    lattice: tuple = (0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "resolution", check_number("resolution", self.resolution, 0.0, 10.0, unit="m"))
        for name in ("width", "height"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), self.resolution, 1e4, low_open=False, unit="m"))
        object.__setattr__(self, "lattice", tuple(check_number("lattice", float(v), -self.resolution, self.resolution, unit="m") for v in self.lattice))
        if len(self.lattice) != 2:
            raise ValueError(f"lattice must be two offsets (x, y), m; got {self.lattice}")
        if self.half_width is not None:
            object.__setattr__(self, "half_width", check_number("half_width", self.half_width, self.resolution, 1e4, unit="m"))
            low, high = self.wall_rows
            j = np.arange(low, high + 1)
            table = self.inflation.cell_cost(np.minimum(high - j, j - low), self.resolution).astype(np.float32)
            object.__setattr__(self, "_rows", np.concatenate([table, [np.float32(LETHAL_OBSTACLE)]]))  # rows low … high, then beyond

    @property
    def wall_rows(self) -> tuple | None:
        """The walls' rows of cells (low, high): the rows whose centres are nearest y = ∓half_width (None: no walls)."""
        if self.half_width is None:
            return None
        r, oy = self.resolution, self.lattice[1]
        return int(round((-self.half_width - oy) / r)), int(round((self.half_width - oy) / r))

    @property
    def walls(self) -> tuple | None:
        """Where the walls are, (y_low, y_high), m: the rows of cell centres in the grid, as given if exact (None: no walls)."""
        if self.half_width is None:
            return None
        if self.exact:
            return -self.half_width, self.half_width
        low, high = self.wall_rows
        return low * self.resolution + self.lattice[1], high * self.resolution + self.lattice[1]

    @property
    def wall_offset(self) -> float | None:
        """The nearer wall's distance from the centre line, m (None: no walls)."""
        return None if self.half_width is None else min(-self.walls[0], self.walls[1])

    def replace(self, **changes) -> "CorridorCostmap":
        """A copy with some fields changed (validated again).

        Parameters
        ----------
        **changes
            Field values.
        """
        return replace(self, **changes)

    def window(self, x: float, y: float) -> Window:
        """The rolling window centred on a robot at (x, y): origin on the lattice, in whole cells (``updateOrigin``).

        Parameters
        ----------
        x, y : float
            The robot's position, m.
        """
        r = self.resolution
        nx, ny = int(round(self.width / r)), int(round(self.height / r))
        lx, ly = self.lattice[0] - 0.5 * r, self.lattice[1] - 0.5 * r  # cell corners
        ox = lx + math.trunc((x - 0.5 * nx * r - lx) / r) * r
        oy = ly + math.trunc((y - 0.5 * ny * r - ly) / r) * r
        return Window(ox, oy, nx, ny, r)

    def rows(self, y):
        """The lattice row of each point (row j holds the centres at y = j·resolution + lattice[1]).

        Parameters
        ----------
        y : float or ndarray
            m.
        """
        return np.floor((np.asarray(y, dtype=float) - self.lattice[1]) / self.resolution + 0.5).astype(np.int64)

    def columns(self, x):
        """The lattice column of each point (column i holds the centres at x = i·resolution + lattice[0]).

        Parameters
        ----------
        x : float or ndarray
            m.
        """
        return np.floor((np.asarray(x, dtype=float) - self.lattice[0]) / self.resolution + 0.5).astype(np.int64)

    def row_cost(self, rows):
        """The grid's cost of whole rows (uint8): the inflation of the nearer wall's row; lethal on and beyond it.

        Parameters
        ----------
        rows : ndarray of int
            Lattice rows.
        """
        rows = np.asarray(rows)
        if self.half_width is None:
            return np.zeros(rows.shape, dtype=np.uint8)
        low, high = self.wall_rows
        return self.inflation.cell_cost(np.maximum(np.minimum(high - rows, rows - low), 0), self.resolution)

    def cost(self, x, y, window: Window | None = None):
        """The costmap's cost at points (float32: 0 free … 254 lethal, 255 off the window).

        Parameters
        ----------
        x, y : float or ndarray
            m.
        window : Window, optional
            The local costmap's bounds (None: unbounded).
        """
        x, y = np.broadcast_arrays(np.asarray(x), np.asarray(y))
        if self.half_width is None:
            cost = np.zeros(y.shape, dtype=np.float32)
        elif self.exact:
            cost = np.asarray(self.inflation.cost(self.half_width - np.abs(y.astype(float))), dtype=np.float32)
        else:
            low, high = self.wall_rows
            index = self.rows(y) - low
            cost = self._rows[np.where((index < 0) | (index > high - low), high - low + 1, index)]
        if window is not None:
            cost = np.where(window.contains(x, y), cost, np.float32(NO_INFORMATION))
        return np.asarray(cost, dtype=np.float32)
