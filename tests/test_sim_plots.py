"""Plots: trajectories drawn like KB's figures, the grid's force law against KB's lumped law."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from pfm_stability.laws.effective_force import GridWallLaw, calibrate_cell_ratio  # noqa: E402
from pfm_stability.plots.force import plot_equivalent_f, plot_force_laws, plot_force_summary  # noqa: E402
from pfm_stability.plots.trajectory import plot_trajectory  # noqa: E402
from pfm_stability.sim import simulate  # noqa: E402


def test_trajectory_plot_like_kb():
    """Filled cells, one circle of diameter W per second, equal aspect, axes in metres (KB Figs 3, 5, 6)."""
    run = simulate("kb-fig6-narrow")
    fig, ax = plt.subplots()
    assert plot_trajectory(run, ax=ax) is fig
    circles = [p for p in ax.patches if type(p).__name__ == "Circle"]
    assert len(circles) == int(run.t_end) + 1
    assert circles[0].get_radius() == pytest.approx(run.scenario.robot.W / 2)
    assert ax.get_aspect() == 1.0 and "(m)" in ax.get_xlabel() and "(m)" in ax.get_ylabel()
    assert len(ax.collections) >= 1  # the occupied cells
    plt.close(fig)
    analytic = simulate("kb-fig6-wide", env="analytic")
    plt.close(plot_trajectory(analytic))
    with pytest.raises(ValueError, match="no trajectory"):
        plot_trajectory(simulate("straight", record="offset"))


def test_force_plots_return_figures():
    law = GridWallLaw(calibrate_cell_ratio(0.8, 2.0, 0.8), 2.0, 0.8)
    fig, ax = plt.subplots()
    assert plot_force_laws(law, ax=ax) is fig
    assert len(ax.get_lines()) >= 4
    assert plot_equivalent_f(law, ax=ax) is fig
    plt.close(fig)
    plt.close(plot_force_summary(law))
