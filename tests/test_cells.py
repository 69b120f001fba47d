"""`numerics.cells`: the one cell rule of every grid (the map's histogram field and the simulator's grid).

Checked against the definition itself, on random points, with numbers computed here: a point lies
inside the square of the cell it is given (x_min + i·c <= x < x_min + (i + 1)·c), and a cell's centre
maps back to that cell. Exact comparisons where the arithmetic is exact (centres of cells of a
power-of-two size); the containment test allows one ulp-scale slack (1e-12 m) for the division.
"""

from __future__ import annotations

import numpy as np

from pfm_stability.maps.reading.field import HistogramMap
from pfm_stability.numerics.cells import cell_center, cell_index
from pfm_stability.sim.grid import HistogramGrid


def test_points_lie_in_their_cells_and_centres_map_back():
    """Random points (some outside the grid, negative indices) lie in the square of their cell; centres map back."""
    rng = np.random.default_rng(3)
    for x_min, y_min, c in [(0.0, 0.0, 0.1), (-3.7, 2.25, 0.05), (1e3, -1e3, 0.125)]:
        x = x_min + rng.uniform(-5, 50, 500) * c
        y = y_min + rng.uniform(-5, 50, 500) * c
        i, j = cell_index(x, y, x_min, y_min, c)
        assert i.dtype == np.int64 and j.dtype == np.int64
        assert np.all(x_min + i * c <= x + 1e-12) and np.all(x < x_min + (i + 1) * c + 1e-12)
        assert np.all(y_min + j * c <= y + 1e-12) and np.all(y < y_min + (j + 1) * c + 1e-12)
        cx, cy = cell_center(i, j, x_min, y_min, c)
        np.testing.assert_array_equal(cell_index(cx, cy, x_min, y_min, c), (i, j))
    np.testing.assert_array_equal(cell_center([0, 3], [1, -2], 0.5, -1.0, 0.25), ([0.625, 1.375], [-0.625, -1.375]))


def test_both_grids_use_the_rule():
    """The map's field and the simulator's grid give the module's answers (one rule, two grids)."""
    cv = np.zeros((40, 30))
    field = HistogramMap(-1.5, 0.5, 0.1, cv)
    grid = HistogramGrid(-1.5, 0.5, 4.0, 3.0, cell_size=0.1)
    x, y = np.linspace(-2.0, 3.0, 17), np.linspace(0.0, 4.0, 17)
    for g in (field, grid):
        np.testing.assert_array_equal(g.cell_index(x, y), cell_index(x, y, -1.5, 0.5, 0.1))
        np.testing.assert_array_equal(g.cell_center([0, 5], [2, 7]), cell_center([0, 5], [2, 7], -1.5, 0.5, 0.1))
