"""Compute and draw apart: every result that has a picture draws itself with ``.plot()`` (the python-control way).

For each result class, ``result.plot()`` must return a figure and draw exactly what the plot
function of `pfm_stability.plots` draws from the same result: the same axes, and on each the
same number of lines, collections, patches, images and texts, the same axis labels and title,
and the same legend entries. The results are small (coarse grids, short runs) so the module
runs in seconds; the pictures themselves are checked in tests/test_plots_regions.py,
tests/test_validation.py, tests/test_maps.py and tests/test_sim_plots.py. The plot functions
take results and compute nothing (docs/architecture.md: `plots` imports nothing that computes).
"""

import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from pfm_stability.parameters import CARMEL  # noqa: E402

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
RES = 12


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def _content(fig) -> list:
    """What a figure holds, axes by axes: artist counts, labels, title and legend entries (no pixels)."""
    out = []
    for ax in fig.axes:
        legend = ax.get_legend()
        out.append((len(ax.get_lines()), len(ax.collections), len(ax.patches), len(ax.images), len(ax.texts), ax.get_xlabel(),
                    ax.get_ylabel(), ax.get_title(), [t.get_text() for t in legend.get_texts()] if legend else None, ax.get_visible()))
    out.append([[t.get_text() for t in legend.get_texts()] for legend in fig.legends])
    out.append(fig._suptitle.get_text() if fig._suptitle else None)
    return out


def _same_picture(method_figure, function_figure):
    assert isinstance(method_figure, matplotlib.figure.Figure) and method_figure is not function_figure
    assert _content(method_figure) == _content(function_figure)
    assert any(len(ax.get_lines()) + len(ax.collections) + len(ax.images) for ax in method_figure.axes)  # something is drawn


def _gain_curves():
    from pfm_stability.analysis.comparison import critical_gain_vs_delay, critical_gain_vs_k
    from pfm_stability.plots.comparison import plot_critical_gain_vs_delay
    from pfm_stability.plots.rlocus import plot_critical_gain_vs_k

    by_delay = critical_gain_vs_delay(ROBOT.tau, ROBOT.k, np.geomspace(0.05, 2, 5))
    by_k = critical_gain_vs_k(ROBOT.tau, CONTROLLER.T, np.geomspace(0.5, 10, 5))
    return [(by_delay, plot_critical_gain_vs_delay), (by_k, plot_critical_gain_vs_k)]


def _comparison():
    from pfm_stability.analysis.comparison import kb_error_map, root_locus
    from pfm_stability.analysis.criteria import loop_of
    from pfm_stability.models import Sampled
    from pfm_stability.plots.comparison import plot_kb_error_map
    from pfm_stability.plots.rlocus import plot_root_locus

    error_map = kb_error_map(np.geomspace(0.1, 10, 5), np.geomspace(0.02, 2, 5), Sampled("command", 1))
    locus = root_locus(loop_of(ROBOT, CONTROLLER), hold=CONTROLLER.hold, compute_delay=CONTROLLER.compute_delay, points=40)
    return [(error_map, plot_kb_error_map), (locus, plot_root_locus)]


def _region_panels():
    from pfm_stability.analysis.region_panels import corridor_L_panel, corridor_panels, corridor_V_panel, wall_alpha_panel, wall_f_panel, wall_panels
    from pfm_stability.plots.regions import (plot_corridor_L_critical, plot_corridor_region, plot_corridor_regions, plot_wall_alpha_critical,
                                             plot_wall_f_region, plot_wall_regions)

    return [
        (wall_f_panel(ROBOT, CONTROLLER, math.radians(30), resolution=RES), plot_wall_f_region),
        (wall_alpha_panel(ROBOT, CONTROLLER, resolution=RES), plot_wall_alpha_critical),
        (corridor_V_panel(ROBOT, CONTROLLER, resolution=RES), plot_corridor_region),
        (corridor_L_panel(ROBOT, CONTROLLER, resolution=RES, shade=False), plot_corridor_L_critical),
        (wall_panels(ROBOT, CONTROLLER, (20.0,), resolution=RES), plot_wall_regions),
        (corridor_panels(ROBOT, CONTROLLER, resolution=RES), plot_corridor_regions),
    ]


def _traps():
    from pfm_stability.analysis.traps import find_stationary_points
    from pfm_stability.cli.traps import scene_path
    from pfm_stability.laws.scene import Scene
    from pfm_stability.plots.traps import plot_traps

    return [(find_stationary_points(Scene.load(scene_path("gc2000_fig3")), 40), plot_traps)]


def _run():
    from pfm_stability.plots.trajectory import plot_trajectory
    from pfm_stability.sim import simulate

    return [(simulate("corridor", env="analytic", duration=2.0), plot_trajectory)]


def _sweep_figure():
    from pfm_stability.plots.sweep import plot_sweep_summary
    from pfm_stability.sweeps.summary import SweepFigureData

    x, y = np.linspace(0.2, 1.6, 4), np.linspace(0.02, 0.2, 3)
    share = np.outer(y / y.max(), x / x.max())
    grid = SweepFigureData("map", "corridor, L = 0.9 m", ("sampled", "exact_delay"), "V", "T", "V (m/s)", "T (s)", x_values=x, y_values=y,
                           fraction=share, model_fraction={"sampled": share, "exact_delay": share})
    agreement = SweepFigureData("agreement", "sampled vs exact_delay", ("sampled", "exact_delay"), labels=("sampled", "exact_delay"),
                                matrix=np.array([[1.0, 0.9], [0.9, 1.0]]))
    return [(grid, plot_sweep_summary), (agreement, plot_sweep_summary)]


def _simulated_boundary():
    from pfm_stability.plots.validation import plot_simulated_boundary
    from pfm_stability.validation import SimulatedBoundary

    sim = SimulatedBoundary("wall", "grid", "alpha", "V", np.array([0.4, 0.8]), np.radians([20.0, 33.0]), np.radians([19.9, 32.9]),
                            np.radians([20.1, 33.1]), np.array([True, True]), 72)
    return [(sim, plot_simulated_boundary)]


CASES = {"gain curves": _gain_curves, "comparison": _comparison, "region panels": _region_panels, "traps": _traps, "run": _run,
         "sweep figure": _sweep_figure, "simulated boundary": _simulated_boundary}


@pytest.mark.parametrize("case", CASES)
def test_plot_method_draws_what_the_plot_function_draws(case):
    """``result.plot()`` returns a figure with the content `plots.X.plot_…(result)` draws (module docstring)."""
    for result, function in CASES[case]():
        _same_picture(result.plot(), function(result))


@pytest.mark.xdist_group("map_depot_carmel")  # the depot's analysis once per suite (tests/map_helpers.py)
def test_plot_method_draws_into_a_given_axes():
    """``result.plot(ax=ax)`` draws into that axes and returns its figure, as the plot functions do (a map of the shipped depot
    and a region panel: one of each family of pictures that take ``ax``). The depot's analysis at CARMEL's preset is the
    one ``map depot`` makes in other tests, computed once per process (tests/map_helpers.py)."""
    from pfm_stability.analysis.region_panels import corridor_V_panel
    from pfm_stability.cli.map import map_path
    from pfm_stability.laws.fields import make_law
    import pfm_stability.maps.analysis as map_analysis
    from map_helpers import shared_map_analyses
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.plots.map import plot_map_stability

    panel = corridor_V_panel(ROBOT, CONTROLLER, resolution=RES)
    fig, ax = plt.subplots()
    assert panel.plot(ax=ax, legend=False) is fig and ax.get_lines()
    with shared_map_analyses():
        analysis = map_analysis.analyze_map(load_map(map_path("depot")), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER))
    fig, ax = plt.subplots()
    assert analysis.plot(ax=ax) is fig
    _same_picture(analysis.plot(), plot_map_stability(analysis))


def test_validation_results_plot_themselves():
    """A boundary validation (its overlay and σ) and the random sweep draw what `plots.validation` draws."""
    from pfm_stability.plots.validation import plot_sweep, plot_validation
    from pfm_stability.validation import validate_boundary, verdict_sweep

    v = validate_boundary("corridor", env="analytic", rtol=1e-2, stability_map=(2, 3))
    _same_picture(v.plot(), plot_validation(v))
    sweep = verdict_sweep(8, seed=1)
    _same_picture(sweep.plot(), plot_sweep(sweep))
