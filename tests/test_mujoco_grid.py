"""What the MuJoCo engine needs without MuJoCo: `HistogramGrid.add_readings`, the VFF update its range sensor uses
(KB §2; docs/mujoco.md), and the one-line refusal when the extra is missing."""

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


def test_without_the_extra_validate_engine_mujoco_exits_2_naming_it(monkeypatch):
    """Without MuJoCo installed (its import made to fail here) ``validate --engine mujoco`` exits 2 with one line that
    names the extra and how to install it, before any work; the default engine does not need it."""
    import importlib

    from cli_helpers import run

    real = importlib.import_module

    def no_mujoco(name, *args, **kwargs):
        if name == "mujoco":
            raise ImportError("No module named 'mujoco'")
        return real(name, *args, **kwargs)

    monkeypatch.setattr("pfm_stability.extras.importlib.import_module", no_mujoco)
    code, out, err = run(["validate", "--engine", "mujoco", "--scenario", "corridor", "--quiet"])
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "optional extra 'mujoco'" in err and "pip install 'pfm-stability[mujoco]'" in err
