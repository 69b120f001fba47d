"""Region and model-comparison plots.

Checked on the figure objects (Agg backend, no pixels compared): every plot
returns its figure, draws into a given ``ax``, never calls ``plt.show()``,
labels its axes with units, names every model by its `pfm_stability.models`
name in the legend with the shared `MODEL_STYLE` colour, marks the CARMEL
operating point at its coordinates, names the shaded model (by default the
report's verdict model), keeps every legend outside the axes (window extents
after a draw: a legend may not overlap any axes), draws ``pade`` above
``exact_delay``, and says in the root locus's legend when a model has no
marker. Small grids keep the plot tests under a few seconds; the
notebooks of ``analyses/`` are executed by nbmake (``--nbmake`` in the pytest
configuration, ``analyses`` in ``testpaths``), so a notebook failure fails CI.
"""

import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_hex  # noqa: E402

from pfm_stability.models import MODEL_NAMES, ExactDelay, Loop, Sampled  # noqa: E402
from pfm_stability.parameters import CARMEL  # noqa: E402
from pfm_stability.plots.common import MODEL_STYLE  # noqa: E402
from pfm_stability.plots.comparison import (  # noqa: E402
    plot_critical_gain_vs_delay,
    plot_kb_error_map,
    plot_kb_error_maps,
    plot_model_comparison,
)
from pfm_stability.plots.regions import (  # noqa: E402
    MARK_LABEL,
    plot_corridor_L_critical,
    plot_corridor_region,
    plot_corridor_regions,
    plot_wall_alpha_critical,
    plot_wall_f_region,
    plot_wall_regions,
)
from pfm_stability.analysis.comparison import critical_gain_vs_delay, critical_gain_vs_k, kb_error_map, kb_relative_error, root_locus  # noqa: E402
from pfm_stability.analysis.region_panels import (  # noqa: E402
    corridor_L_panel,
    corridor_panels,
    corridor_V_panel,
    wall_alpha_panel,
    wall_f_panel,
    wall_panels,
)
from pfm_stability.plots.validation import plot_simulated_boundary  # noqa: E402
from pfm_stability.validation import SimulatedBoundary  # noqa: E402

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
RES = 40


@pytest.fixture(autouse=True)
def no_show(monkeypatch):
    """plt.show() must never be called; close figures after each test."""

    def fail(*a, **k):
        raise AssertionError("plt.show() called")

    monkeypatch.setattr(plt, "show", fail)
    yield
    plt.close("all")


def _legend_texts(ax):
    legend = ax.get_legend()
    return [t.get_text() for t in legend.get_texts()] if legend else []


def _model_lines(ax):
    """Legend label → line colour for the model curves."""
    return {l.get_label(): to_hex(l.get_color()) for l in ax.get_lines() if not l.get_label().startswith("_")}


def _assert_models_styled(ax):
    lines = _model_lines(ax)
    for name in MODEL_NAMES:
        labels = [lab for lab in lines if lab.startswith(name)]
        assert labels, f"no curve labelled {name}"
        assert lines[labels[0]] == to_hex(MODEL_STYLE[name]["color"])


def _has_mark(ax, x, y):
    return any(
        l.get_marker() == "*" and np.allclose(l.get_xdata(), [x]) and np.allclose(l.get_ydata(), [y]) for l in ax.get_lines()
    )


@pytest.mark.parametrize(
    "plot,xunit,yunit,mark",
    [
        (lambda ax: plot_wall_f_region(wall_f_panel(ROBOT, CONTROLLER, math.radians(30), resolution=RES), ax=ax), "(m/s)", "dimensionless", (0.8, 0.8)),
        (lambda ax: plot_wall_alpha_critical(wall_alpha_panel(ROBOT, CONTROLLER, resolution=RES), ax=ax), "(m/s)", "(deg)", (0.8, 20.0)),
        (lambda ax: plot_corridor_region(corridor_V_panel(ROBOT, CONTROLLER, resolution=RES), ax=ax), "(m)", "(m/s)", (0.9, 0.8)),
        (lambda ax: plot_corridor_L_critical(corridor_L_panel(ROBOT, CONTROLLER, resolution=RES), ax=ax), "(m/s)", "(m)", (0.8, 0.6)),
    ],
    ids=["wall_f", "wall_alpha", "corridor_LV", "corridor_Lstar"],
)
def test_region_plot_contract(plot, xunit, yunit, mark):
    """Draws into the given axes, returns its figure; units on both axes; five models in their style; CARMEL marked; legend."""
    fig, ax = plt.subplots()
    out = plot(ax)
    assert out is fig
    assert xunit in ax.get_xlabel() and yunit in ax.get_ylabel()
    _assert_models_styled(ax)
    assert _has_mark(ax, *mark)
    texts = _legend_texts(ax)
    assert MARK_LABEL in texts
    assert any(t.startswith("stable") for t in texts) and any(t.startswith("unstable") for t in texts)
    for name in MODEL_NAMES:
        assert any(t.startswith(name) for t in texts)


def test_region_plot_creates_figure_without_ax():
    """Without ax= a new figure is created and returned."""
    fig = plot_corridor_region(corridor_V_panel(ROBOT, CONTROLLER, resolution=RES))
    assert fig.axes and fig.axes[0].get_xlabel().endswith("(m)")


def test_summary_figures_have_one_shared_legend():
    """plot_wall_regions (3 angles + α*) and plot_corridor_regions: one figure legend naming every model."""
    for fig, panels in ((plot_wall_regions(wall_panels(ROBOT, CONTROLLER, resolution=RES)), 4),
                        (plot_corridor_regions(corridor_panels(ROBOT, CONTROLLER, resolution=RES)), 2)):
        visible = [a for a in fig.axes if a.get_visible()]
        assert len(visible) == panels
        assert all(a.get_legend() is None for a in visible)
        (legend,) = fig.legends
        texts = [t.get_text() for t in legend.get_texts()]
        for name in MODEL_NAMES:
            assert any(t.startswith(name) for t in texts)


def test_grid_law_curves_without_shading():
    """A non-power law (the grid's) draws curves; shading through the general-law verdicts also works."""
    from pfm_stability.laws.effective_force import GridWallLaw, calibrate_cell_ratio

    law = GridWallLaw(calibrate_cell_ratio(0.8, 2.0, 0.8), 2.0, 0.8)
    fig = plot_corridor_region(corridor_V_panel(ROBOT, CONTROLLER, law=law, shade=False, resolution=RES))
    _assert_models_styled(fig.axes[0])
    fig = plot_wall_alpha_critical(wall_alpha_panel(ROBOT, CONTROLLER, law=law, resolution=RES))
    assert "grid wall" in fig.axes[0].get_title()


def test_simulated_points_drawn_in_degrees():
    """Simulated α* (rad) is drawn in degrees at the values of `over`, with its bracket as error bars."""
    sim = SimulatedBoundary("wall", "grid", "alpha", "V", np.array([0.4, 0.8]), np.radians([20.0, 33.0]),
                            np.radians([19.9, 32.9]), np.radians([20.1, 33.1]), np.array([True, True]), 72)
    fig, ax = plt.subplots()
    assert plot_simulated_boundary(sim, ax=ax) is fig
    (line,) = [l for l in ax.get_lines() if l.get_marker() == "o"]
    np.testing.assert_allclose(line.get_xdata(), [0.4, 0.8])
    np.testing.assert_allclose(line.get_ydata(), [20.0, 33.0])


def test_comparison_plots_contract():
    """NV* vs T/τ and vs k: units, every model named, sampled structures told apart; returns the figure."""
    fig, ax = plt.subplots()
    assert plot_critical_gain_vs_delay(critical_gain_vs_delay(0.3, 2.0, np.geomspace(0.05, 2, 8)), mark=0.065 / 0.3, ax=ax) is fig
    assert "(1/s)" in ax.get_ylabel() and "T/τ" in ax.get_xlabel()
    texts = _legend_texts(ax)
    for name in MODEL_NAMES:
        assert any(t.startswith(name) for t in texts)
    assert sum(t.startswith("sampled") for t in texts) == 4
    fig = plot_model_comparison(critical_gain_vs_k(0.3, 0.065, np.geomspace(0.5, 10, 6)), critical_gain_vs_delay(0.3, 2.0, np.geomspace(0.05, 2, 6)))
    assert len(fig.axes) == 2 and "(1/s)" in fig.axes[0].get_xlabel()


def test_kb_error_map_plot_marks_exact_value():
    """The error map's star is annotated with the exact KB error at that point (not the interpolated map)."""
    m = kb_error_map(np.geomspace(0.1, 10, 6), np.geomspace(0.02, 2, 6), Sampled("command", 1))
    fig, ax = plt.subplots()
    assert plot_kb_error_map(m, ax=ax, mark=(0.6, 0.065 / 0.3)) is fig
    expected = kb_relative_error(Loop(0.3, 0.065, 2.0), Sampled("command", 1))
    assert any(t.get_text() == f"CARMEL: {100 * expected:+.0f} %" for t in ax.texts)
    assert "kτ" in ax.get_xlabel() and "T/τ" in ax.get_ylabel()
    fig = plot_kb_error_maps([m, kb_error_map(m.k_tau, m.T_over_tau, ExactDelay())], mark=(0.6, 0.2))
    assert fig.legends


# ------------------------------------------------------------------ shaded model, legends, root locus
SHADED_TEXT = "sampled (command hold, compute delay 1)"


def _overlaps(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def _assert_legends_outside(fig):
    """No legend (axes or figure) overlaps any visible axes, in display coordinates after a draw (at a low dpi: faster, same geometry)."""
    fig.set_dpi(40)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legends = [a.get_legend() for a in fig.axes if a.get_legend()] + list(fig.legends)
    assert legends
    for legend in legends:
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            if ax.get_visible():
                assert not _overlaps(box, ax.get_window_extent(renderer)), (ax.get_title(), [t.get_text() for t in legend.get_texts()][:3])


@pytest.mark.parametrize(
    "plot",
    [
        lambda: plot_wall_f_region(wall_f_panel(ROBOT, CONTROLLER, math.radians(30), resolution=RES)),
        lambda: plot_wall_alpha_critical(wall_alpha_panel(ROBOT, CONTROLLER, resolution=RES)),
        lambda: plot_corridor_region(corridor_V_panel(ROBOT, CONTROLLER, resolution=RES)),
        lambda: plot_corridor_L_critical(corridor_L_panel(ROBOT, CONTROLLER, resolution=RES)),
        lambda: plot_corridor_regions(corridor_panels(ROBOT, CONTROLLER, resolution=RES)),
        lambda: plot_wall_regions(wall_panels(ROBOT, CONTROLLER, resolution=RES)),
    ],
    ids=["wall_f", "wall_alpha", "corridor_LV", "corridor_Lstar", "corridor_summary", "wall_summary"],
)
def test_region_plots_name_the_shaded_model_and_keep_legends_outside(plot):
    """Default shading = the report's verdict model, named in the legend (stable and unstable entries) and
    in a title; legends hide no curve or star; pade is drawn above exact_delay (they coincide for CARMEL)."""
    fig = plot()
    legend = fig.legends[0] if fig.legends else fig.axes[0].get_legend()
    texts = [t.get_text() for t in legend.get_texts()]
    assert any(t.startswith("stable") and SHADED_TEXT in t and "the report's verdict" in t for t in texts)
    assert any(t.startswith("unstable") and SHADED_TEXT in t for t in texts)
    titles = [a.get_title() for a in fig.axes] + ([fig._suptitle.get_text()] if fig._suptitle else [])
    assert any(f"shaded: {SHADED_TEXT} — the report's verdict" in t for t in titles)
    _assert_legends_outside(fig)
    for ax in fig.axes:
        z = {l.get_label().split(":")[0].split(" ")[0]: l.get_zorder() for l in ax.get_lines() if not l.get_label().startswith("_")}
        if "pade" in z:
            assert z["pade"] > z["exact_delay"] and z["kb_first_order"] > z["exact_delay"]


def test_region_plot_shades_the_model_asked_for():
    """shaded="exact_delay": the mesh is the exact_delay map (crossing count) and the legend says so."""
    from matplotlib.collections import QuadMesh

    from pfm_stability.analysis.regions import corridor_region

    L, V = np.linspace(0.45, 2.0, 12), np.linspace(0.05, 2.0, 10)
    fig, ax = plt.subplots()
    plot_corridor_region(corridor_V_panel(ROBOT, CONTROLLER, L=L, V=V, shaded="exact_delay"), ax=ax)
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    expected = corridor_region(ROBOT, CONTROLLER, L, V, model="exact_delay").stable
    assert np.array_equal(np.asarray(mesh.get_array()).reshape(expected.shape), expected.astype(float))
    assert any("shaded: exact_delay (vectorized crossing count)" in t for t in _legend_texts(ax))
    assert "the report's verdict" not in ax.get_title()


def test_other_legends_sit_outside_the_axes():
    """Root locus, NV* vs k, NV* vs T/τ, the model comparison and a trajectory (target arrow): legend outside."""
    from pfm_stability.plots.rlocus import plot_critical_gain_vs_k, plot_root_locus
    from pfm_stability.plots.trajectory import plot_trajectory

    loop = Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)
    by_k, by_delay = critical_gain_vs_k(0.3, 0.065, np.geomspace(0.5, 10, 5)), critical_gain_vs_delay(0.3, 2.0, np.geomspace(0.05, 2, 5))
    for fig in (
        plot_root_locus(root_locus(loop, hold="command", compute_delay=1)),
        plot_critical_gain_vs_k(by_k),
        plot_critical_gain_vs_delay(by_delay),
        plot_model_comparison(by_k, by_delay),
        plot_trajectory(_straight_run(), title="a run with a target at infinity (arrow)"),
    ):
        _assert_legends_outside(fig)
        plt.close(fig)


def _straight_run():
    """A minimal recorded run (what `plot_trajectory` reads): 4 s straight up an analytic corridor, target at infinity.

    Built by hand so that this legend test does not depend on the simulator.
    """
    from types import SimpleNamespace

    t = np.linspace(0.0, 4.0, 41)
    trajectory = SimpleNamespace(x=np.zeros_like(t), y=0.8 * t, t=t, at_times=lambda ts: (np.zeros(len(ts)), 0.8 * np.asarray(ts)))
    walls = [SimpleNamespace(p0=(x, -1.0), p1=(x, 5.0)) for x in (-0.9, 0.9)]
    scenario = SimpleNamespace(env="analytic", environment=SimpleNamespace(walls=walls), robot=ROBOT, name="straight",
                               start=SimpleNamespace(x=0.0, y=0.0), target=SimpleNamespace(is_point=False, is_path=False, angle=0.0))
    return SimpleNamespace(trajectory=trajectory, scenario=scenario, events=[])


def test_root_locus_says_when_a_model_has_no_marker():
    """NV* = 0 (command hold, kT = 2.6): "unstable at any NV … no marker" and nothing drawn; a stable set that
    does not start at 0 is listed; a crossing outside the view and NV* = ∞ are named too."""
    from pfm_stability.models import Boundary
    from pfm_stability.plots.common import MODEL_STYLE
    from pfm_stability.plots.rlocus import crossing_text, plot_root_locus

    fig = plot_root_locus(root_locus(Loop(0.3, 0.065, 40.0), hold="command", compute_delay=0))
    ax = fig.axes[0]
    (entry,) = [l for l in ax.get_lines() if l.get_label().startswith("sampled")]
    assert "unstable at any NV" in entry.get_label() and "no marker" in entry.get_label()
    assert len(entry.get_xdata()) == 0
    green = to_hex(MODEL_STYLE["sampled"]["color"])
    assert not any(len(l.get_xdata()) and to_hex(l.get_markeredgecolor()) == green for l in ax.get_lines())
    for name in ("pade", "exact_delay", "kb_first_order"):  # these do cross: markers at ±jω*
        (line,) = [l for l in ax.get_lines() if l.get_label().startswith(name)]
        assert len(line.get_xdata()) == 2 and "ω* =" in line.get_label()

    gap = Sampled("command", 0)
    text, marked = crossing_text(gap, gap.boundary(Loop(0.03, 0.2, 15.0)))
    assert not marked and "stable only for NV in (1.622, 3.823) 1/s (no marker)" in text
    carmel = Sampled("command", 1)
    text, marked = crossing_text(carmel, carmel.boundary(Loop(0.3, 0.065, 2.0)), omega_max=1.0)
    assert not marked and "outside the view: no marker" in text
    text, marked = crossing_text(carmel, Boundary("sampled", math.inf, None, math.inf, ((0.0, math.inf),)))
    assert not marked and "stable at every NV" in text
