"""`HistogramGrid.add_readings`, the VFF update the MuJoCo engine's range sensor uses (KB §2; docs/mujoco.md).
No MuJoCo needed."""

from __future__ import annotations

import numpy as np
import pytest

from pfm_stability.sim.grid import HistogramGrid


def test_readings_add_one_per_reading_up_to_cv_max():
    """Each reading adds 1 to its cell, several in one cell add up, the sum is capped at cv_max, readings outside the
    grid are ignored: checked against a plain loop over the readings (cell = floor((p − min)/c))."""
    rng = np.random.default_rng(3)
    grid = HistogramGrid(-1.0, -2.0, 2.0, 3.0, cell_size=0.1, cv_max=15)
    expected = np.zeros(grid.shape, dtype=int)
    for _ in range(4):
        x, y = rng.uniform(-1.3, 1.3, 400), rng.uniform(-2.3, 1.3, 400)
        x[:60], y[:60] = 0.05, 0.05  # many readings in one cell: capped
        grid.add_readings(x, y)
        for xi, yi in zip(x, y):
            i, j = int(np.floor((xi + 1.0) / 0.1)), int(np.floor((yi + 2.0) / 0.1))
            if 0 <= i < grid.shape[0] and 0 <= j < grid.shape[1]:
                expected[i, j] = min(expected[i, j] + 1, 15)
    assert np.array_equal(grid.cv, expected)
    assert grid.cv.max() == 15


def test_readings_on_a_frozen_grid_or_with_a_bad_increment_are_refused():
    """A frozen (shared) grid is not updated; the increment must be a whole number in [1, cv_max]."""
    grid = HistogramGrid(0.0, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="increment"):
        grid.add_readings([0.5], [0.5], increment=0)
    grid.freeze()
    with pytest.raises(ValueError, match="frozen"):
        grid.add_readings([0.5], [0.5])
