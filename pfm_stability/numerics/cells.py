"""Square cells of a regular grid: which cell holds a point, and where a cell's centre is.

The one rule for every grid of the package (`CellGrid`: `maps.reading.field.HistogramMap`, `sim.grid.HistogramGrid`):
cell (i, j) covers [x_min + i·c, x_min + (i + 1)·c) × [y_min + j·c, y_min + (j + 1)·c), c the cell size.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cell_index", "cell_center", "CellGrid"]


def cell_index(x, y, x_min: float, y_min: float, cell_size: float):
    """(i, j) int64 arrays of the cells holding the points (x, y) (negative or past the grid's end outside it).

    Parameters
    ----------
    x, y : array_like
        Points, m.
    x_min, y_min : float
        Lower-left corner of cell (0, 0), m.
    cell_size : float
        Side of a cell, m.
    """
    return (np.floor((np.asarray(x, dtype=float) - x_min) / cell_size).astype(np.int64),
            np.floor((np.asarray(y, dtype=float) - y_min) / cell_size).astype(np.int64))


def cell_center(i, j, x_min: float, y_min: float, cell_size: float):
    """(x, y) of the centres of cells (i, j), m.

    Parameters
    ----------
    i, j : array_like of int
        Cell indices along x and y.
    x_min, y_min : float
        Lower-left corner of cell (0, 0), m.
    cell_size : float
        Side of a cell, m.
    """
    return x_min + (np.asarray(i) + 0.5) * cell_size, y_min + (np.asarray(j) + 0.5) * cell_size


class CellGrid:
    """The cell geometry of a grid with attributes ``x_min``, ``y_min`` (m, the corner of cell (0, 0)) and
    ``cell_size`` (m): mixed into the package's grids so that they share `cell_index` and `cell_center`."""

    x_min: float
    y_min: float
    cell_size: float

    def cell_index(self, x, y):
        """(i, j) int64 arrays of the cells holding the points (may lie outside the grid).

        Parameters
        ----------
        x, y : array_like
            Points, m.
        """
        return cell_index(x, y, self.x_min, self.y_min, self.cell_size)

    def cell_center(self, i, j):
        """(x, y) of cell centres, m.

        Parameters
        ----------
        i, j : array_like of int
            Cell indices along x and y.
        """
        return cell_center(i, j, self.x_min, self.y_min, self.cell_size)
