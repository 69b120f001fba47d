"""Histogram grid, drawing helpers and the active-window tables (KB §2; docs/simulator.md)."""

import math

import numpy as np
import pytest

from pfm_stability.sim.grid import HistogramGrid
from pfm_stability.sim.vff import cell_repulsion, direction_of, steering_command, vff_speed, window_repulsion, wrap_angle
from pfm_stability.sim.window import compile_window_table, stack_tables


def _grid():
    g = HistogramGrid.centred(-3, 3, -3, 3)
    g.draw_segment((-1.0, -2.0), (-1.0, 2.0))
    g.draw_segment((0.5, -2.5), (2.5, 1.0))  # a diagonal wall
    g.draw_rectangle(0.0, 1.5, 0.3, 1.8)
    return g


def test_centred_grid_puts_cell_centres_on_multiples_of_c():
    g = HistogramGrid.centred(-1, 1, 0, 2)
    i, j = g.cell_index(0.0, 0.0)
    assert g.cell_center(i, j) == pytest.approx((0.0, 0.0), abs=1e-12)


def test_drawing_helpers():
    """Walls of any orientation, filled rectangles, gaps, protrusions (docs/simulator.md)."""
    g = HistogramGrid.centred(-2, 2, -2, 2)
    g.draw_segment((0.0, -1.0), (0.0, 1.0))
    assert np.count_nonzero(g.cv) == 21  # 2 m of cells on centres, both ends included
    g.draw_gap((0.0, -0.2), (0.0, 0.2))
    assert np.count_nonzero(g.cv) == 16
    g.draw_rectangle(0.5, 0.5, 0.8, 0.8)  # corners on cell centres: 4 x 4 cells
    assert np.count_nonzero(g.cv) == 32
    g.draw_protrusion((-1.0, -1.0), (-1.0, 0.0), 0.3)  # three sides of a bump
    assert np.count_nonzero(g.cv) > 32
    g.clear_rectangle(-2, -2, 2, 2)
    assert np.count_nonzero(g.cv) == 0
    diagonal = HistogramGrid.centred(-2, 2, -2, 2).draw_segment((-1, -1), (1, 1))
    assert np.count_nonzero(diagonal.cv) >= 21  # every cell the 45° line passes through
    assert np.all(diagonal.cv[diagonal.cv > 0] == 15)


def test_frozen_grid_refuses_drawing():
    g = HistogramGrid.centred(-1, 1, -1, 1).freeze()
    with pytest.raises(ValueError, match="frozen"):
        g.draw_segment((0, 0), (0, 1))
    assert not g.copy().frozen


def test_window_table_equals_brute_force_window_sum():
    """The compiled occupied-cell lists give exactly the sum of KB eq 1 over every cell of the 33 × 33 window.

    Brute force: slice the window around the robot's cell from the dense grid.
    Same terms, different summation order: 1e-13 relative.
    """
    g = _grid()
    rng = np.random.default_rng(1)
    px, py = rng.uniform(-2.9, 2.9, 200), rng.uniform(-2.9, 2.9, 200)
    fx, fy = window_repulsion(g, px, py, ratio=0.01, n=2.0, W=0.8, window_cells=33)
    for k in range(px.size):
        i, j = g.cell_index(px[k], py[k])
        ii, jj = np.meshgrid(np.arange(i - 16, i + 17), np.arange(j - 16, j + 17), indexing="ij")
        inside = (ii >= 0) & (ii < g.shape[0]) & (jj >= 0) & (jj < g.shape[1])
        ii, jj = ii[inside], jj[inside]
        cv = g.cv[ii, jj].astype(float)
        cx, cy = g.cell_center(ii, jj)
        d = np.hypot(px[k] - cx, py[k] - cy)
        keep = cv > 0
        ex = np.sum(0.01 * 0.64 * cv[keep] * (px[k] - cx[keep]) / d[keep] ** 3)
        ey = np.sum(0.01 * 0.64 * cv[keep] * (py[k] - cy[keep]) / d[keep] ** 3)
        assert fx[k] == pytest.approx(ex, rel=1e-12, abs=1e-14)
        assert fy[k] == pytest.approx(ey, rel=1e-12, abs=1e-14)


def test_repulsion_points_away_from_the_cell():
    """KB eq 1 implemented as repulsion: a cell at +X pushes the robot towards −X (module docstring of vff)."""
    fx, fy = cell_repulsion(np.zeros((1, 1)), np.zeros((1, 1)), np.array([[0.5]]), np.array([[0.0]]), np.array([[1.0]]), 2.0)
    assert fx[0] == pytest.approx(-1 / 0.25) and fy[0] == 0.0
    general = cell_repulsion(np.zeros((1, 1)), np.zeros((1, 1)), np.array([[0.5]]), np.array([[0.0]]), np.array([[1.0]]), np.array([[2.0]]))
    assert general[0][0] == pytest.approx(fx[0], rel=1e-14)


def test_unreachable_cells_and_near_lists():
    """Cells where a robot cannot fit map to −1; collision lists hold every cell within W/2 of the robot cell."""
    g = _grid()
    t = compile_window_table(g, 33, W_min=0.8, W_max=0.8)
    geo = t.grids[0]
    i, j = g.cell_index(-1.0, 0.0)  # on the wall
    assert t.row_of_cell[(i + geo.pad) * geo.ny_padded + j + geo.pad] == -1
    # a point 0.6 m from the wall cells' faces: nothing within W/2 of its cell, so no collision candidates
    i, j = g.cell_index(-0.3, 0.0)
    assert t.near_count[t.row_of_cell[(i + geo.pad) * geo.ny_padded + j + geo.pad]] == 0
    # a reachable point near the wall: the near list finds the true clearance (brute force over all cells)
    x, y = -0.52, 0.03
    i, j = g.cell_index(x, y)
    row = t.row_of_cell[(i + geo.pad) * geo.ny_padded + j + geo.pad]
    cells = t.near[row][: t.near_count[row]]
    assert cells.size > 0
    gap = np.min(np.hypot(np.maximum(np.abs(x - t.ox[cells]) - 0.05, 0), np.maximum(np.abs(y - t.oy[cells]) - 0.05, 0)))
    assert gap == pytest.approx(float(g.clearance(x, y)[0]), abs=1e-12)


def test_stacked_tables_keep_each_grid():
    """Concatenating two grids' tables changes no window sum (rows and indices offset correctly)."""
    a, b = _grid(), HistogramGrid.centred(-2, 2, -2, 2).draw_segment((1.0, -2), (1.0, 2))
    ta, tb = compile_window_table(a, 33, 0.8, 0.8), compile_window_table(b, 33, 0.8, 0.8)
    s = stack_tables([ta, tb])
    for table, stacked_geo in ((ta, s.grids[0]), (tb, s.grids[1])):
        geo = table.grids[0]
        cells = np.flatnonzero(table.row_of_cell > 0)
        rows = table.row_of_cell[cells]
        rows_s = s.row_of_cell[stacked_geo.cell_offset + cells]
        own = np.sort(np.where(table.wcv[rows] > 0, table.wx[rows], np.inf), axis=1)
        theirs = np.sort(np.where(s.wcv[rows_s] > 0, s.wx[rows_s], np.inf), axis=1)[:, : own.shape[1]]
        assert np.array_equal(own, theirs)  # bit for bit is legitimate: stacking copies the same coordinates, no arithmetic
        assert geo.nx_padded == stacked_geo.nx_padded


def test_angles_and_commands():
    """wrap gives the shortest rotation; δ is measured from +Y towards +X; u = k·wrap(δ − θ) saturates (KB eq 5)."""
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(-math.pi) == pytest.approx(-math.pi)
    assert direction_of(1.0, 0.0) == pytest.approx(math.pi / 2)
    assert direction_of(0.0, 0.0) == 0.0
    u = steering_command(np.array([0.1, 3.0, 1.5]), np.array([0.0, -3.0, 0.0]), 2.0, math.radians(120))
    assert u[0] == pytest.approx(0.2)
    assert u[1] == pytest.approx(2.0 * (6.0 - 2 * math.pi))  # δ − θ = 6 rad is −0.28 rad the short way
    assert u[2] == pytest.approx(math.radians(120))  # 2 × 1.5 = 3 rad/s saturates at 120°/s
    speed = vff_speed(0.8, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, -1.0]), np.zeros(3))
    assert speed == pytest.approx([0.8, 0.8, 0.0])
