"""Stability-region plots: where the robot is safe near a wall and in a corridor.

Each panel shades one model's verdicts on a dense grid (green stable, red
unstable; `pfm_stability.analysis.regions`) and draws every model's boundary curve in
its own style (`plots.common.MODEL_STYLE`), with the operating points of KB's
CARMEL runs marked (Koren & Borenstein 1991 Figs 5 and 6). The shaded model
is by default the one the stability report's verdict uses (``sampled`` with
the controller's hold and compute delay, `regions.verdict_model`); the title
and the legend name it. Legends sit outside the axes, so they hide no curve,
operating point or label. Computation lives in `pfm_stability.analysis.regions`; these
functions only draw.

* `plot_wall_f_region`: (V, f) plane at one α; stable above f*(V) (KB eq 24).
* `plot_wall_alpha_critical`: α*(V); stable above (KB eq 21, 23).
* `plot_corridor_region`: (L, V) plane; stable below V*(L) (KB eq 25).
* `plot_corridor_L_critical`: L*(V); stable above (KB eq 25).
* `plot_wall_regions`, `plot_corridor_regions`: the panels above side by side
  with one legend (the figures of ``analyses/``).

Simulated boundary points go on top of any of these with
`pfm_stability.plots.validation.plot_simulated_boundary`.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from ..laws.force_law import ForceLaw, PowerLaw
from ..parameters import Controller, Robot
from ..analysis.curves import corridor_L_curves, corridor_V_curves, default_models, wall_alpha_curves, wall_f_curves
from ..analysis.regions import corridor_region, region_model, verdict_model, wall_alpha_region, wall_f_region
from .common import MODEL_STYLE, MODEL_ZORDER, figure_and_axes, model_description, model_label, outside_legend

__all__ = [
    "MARK_LABEL",
    "STABLE_COLOR",
    "UNSTABLE_COLOR",
    "plot_wall_f_region",
    "plot_wall_alpha_critical",
    "plot_corridor_region",
    "plot_corridor_L_critical",
    "plot_wall_regions",
    "plot_corridor_regions",
    "region_legend",
    "shading_text",
]

STABLE_COLOR = "#dcefd6"
UNSTABLE_COLOR = "#f7d9d6"
MARK_LABEL = "CARMEL operating point (KB §4–5)"
_MARK = dict(marker="*", ms=13, mfc="gold", mec="k", mew=1.0, ls="none", zorder=6)
_NOFIT = dict(facecolor="0.85", edgecolor="0.55", hatch="///", lw=0)
_SINGLE = (6.4, 4.8)
_WITH_LEGEND = (9.6, 4.8)
_SHADED = weakref.WeakKeyDictionary()
"""Axes → text of the model its shading shows (read by `region_legend`)."""

V_LABEL = "speed V (m/s)"
F_LABEL = "force ratio f = F_cr/F_ct (dimensionless, KB eq 13)"
ALPHA_LABEL = "target angle α (deg); curves: critical α*(V)"
L_LABEL = "corridor half-width L (m)"
L_STAR_LABEL = "corridor half-width L (m); curves: critical L*(V)"


# ------------------------------------------------------------------ pieces
def shading_text(model, controller: Controller) -> str:
    """What a shaded map shows, for titles and legends.

    E.g. ``sampled (command hold, compute delay 1) — the report's verdict``
    when `model` is the report's verdict model (`regions.verdict_model`),
    ``exact_delay (vectorized crossing count)`` for ``exact_delay``.

    Parameters
    ----------
    model : LoopModel
    controller : Controller
        Decides the report's verdict model (its hold and compute delay).

    Returns
    -------
    str
    """
    text = model_description(model)
    if model == verdict_model(controller):
        return f"{text} — the report's verdict"
    if model.name == "exact_delay":
        return f"{text} (vectorized crossing count)"
    return text


def _shade(ax, region, text: str, y_scale=1.0):
    """Shade the region's verdicts (green stable, red unstable); `text` names the shaded model."""
    from matplotlib.colors import ListedColormap

    ax.pcolormesh(
        region.x, region.y * y_scale, region.stable.astype(float), shading="nearest",
        cmap=ListedColormap([UNSTABLE_COLOR, STABLE_COLOR]), vmin=0, vmax=1, rasterized=True, zorder=0,
    )
    _SHADED[ax] = text


def _curve_label(curve) -> str:
    return f"{model_label(curve.model)}: NV* = {curve.NV_critical:.3g} 1/s"


def _draw_curves(ax, curves, *, swap=False, y_scale=1.0):
    for c in curves:
        x, y = np.asarray(c.x, dtype=float), np.asarray(c.y, dtype=float) * y_scale
        y = np.where(np.isfinite(y), y, np.nan)
        if swap:
            x, y = y, x
        ax.plot(x, y, label=_curve_label(c), zorder=MODEL_ZORDER[c.model.name], **MODEL_STYLE[c.model.name])


def _mark(ax, x, y, text, *, label=None, offset=(7, 5)):
    """A star at (x, y) with `text` at `offset` (points; negative x: text left of the star)."""
    ax.plot([x], [y], label=label, **_MARK)
    if text:
        # below the curves (zorder 3.x): a label box must not hide a boundary
        ax.annotate(text, (x, y), xytext=offset, textcoords="offset points", fontsize=8, ha="right" if offset[0] < 0 else "left",
                    va="top" if offset[1] < 0 else "baseline",
                    bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.6), zorder=2.5)


def _marks(ax, marks, point, offsets):
    """Draw `marks` ((value, text) or (value, text, offset)); `point(value)` gives (x, y)."""
    for i, m in enumerate(marks or ()):
        offset = m[2] if len(m) > 2 else offsets.get(m[0], (7, 5))
        _mark(ax, *point(m[0]), m[1], label=MARK_LABEL if i == 0 else None, offset=offset)


def _shading_entries(texts):
    from matplotlib.patches import Patch

    handles, labels = [], []
    for text in texts:
        handles += [Patch(fc=STABLE_COLOR, ec="0.6"), Patch(fc=UNSTABLE_COLOR, ec="0.6")]
        model, _, why = text.partition(" — ")
        labels += [f"stable, shaded: {model}" + (f"\n— {why}" if why else ""), f"unstable (oscillates), shaded: {model}"]
    return handles, labels


def region_legend(ax=None, *, fig=None, ncol=1, loc=None, fontsize=8, **kwargs):
    """Legend with the model curves, the CARMEL mark and the shading (naming the shaded model).

    Draws into `fig` (a figure legend, default below the panels) when given,
    else into `ax` (default outside the axes, on the right): a legend inside
    the axes would hide curves or operating points.

    Parameters
    ----------
    ax : matplotlib Axes, optional
    fig : matplotlib Figure, optional
        Its axes' entries are merged (each label once).
    ncol : int
    loc : str, optional
        Legend location (default: outside, see above).
    fontsize : float
        Points.
    **kwargs
        Passed to ``legend``.

    Returns
    -------
    matplotlib.legend.Legend
    """
    sources = [ax] if ax is not None else [a for a in fig.axes if a.get_visible()]
    seen = {}
    for source in sources:
        for h, l in zip(*source.get_legend_handles_labels()):
            seen.setdefault(l, h)
    handles, labels = list(seen.values()), list(seen)
    shaded = list(dict.fromkeys(_SHADED[a] for a in sources if a in _SHADED))
    more_handles, more_labels = _shading_entries(shaded)
    handles, labels = handles + more_handles, labels + more_labels
    if fig is not None:
        return fig.legend(handles, labels, ncol=ncol, loc=loc or "outside lower center", fontsize=fontsize, frameon=False, **kwargs)
    if loc is None:
        return outside_legend(ax, handles, labels, ncol=ncol, fontsize=fontsize, **kwargs)
    return ax.legend(handles, labels, ncol=ncol, loc=loc, fontsize=fontsize, framealpha=0.9, **kwargs)


def _loop_text(robot: Robot, controller: Controller, law: ForceLaw | None = None) -> str:
    law_text = f"f = {controller.f:g}, n = {controller.n:g}" if law is None or isinstance(law, PowerLaw) else f"{law.name}"
    return f"τ = {robot.tau:g} s, T = {controller.T:g} s, k = {robot.k:g} 1/s, W = {robot.W:g} m, {law_text}"


def _title(text, shaded_text=None):
    return text if shaded_text is None else f"{text}\nshaded: {shaded_text}"


def _style_axes(ax, xlabel, ylabel, title):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="major", lw=0.4, alpha=0.5)


def _no_fit_band(ax, W, *, vertical=True):
    """Hatch L <= W/2, where the robot does not fit the corridor."""
    if vertical:
        lo = ax.get_xlim()[0]
        ax.axvspan(lo, W / 2, label=f"robot does not fit (L ≤ W/2 = {W / 2:g} m)", zorder=1, **_NOFIT)
    else:
        lo = ax.get_ylim()[0]
        ax.axhspan(lo, W / 2, label=f"robot does not fit (L ≤ W/2 = {W / 2:g} m)", zorder=1, **_NOFIT)


# ------------------------------------------------------------------ wall
def plot_wall_f_region(
    robot: Robot,
    controller: Controller,
    alpha: float,
    *,
    V=None,
    f=None,
    models=None,
    shaded=None,
    ax=None,
    legend: bool = True,
    mark: bool = True,
    resolution: int = 300,
):
    """Stable and unstable regions along a wall in the (V, f) plane at one target angle α.

    Shading: the verdicts of the `shaded` model (`regions.wall_f_region`);
    curves: f*(V) of every model (`curves.wall_f_curves`, KB eq 24 with the
    model's NV*); stable above the curves. KB's power law.

    Parameters
    ----------
    robot, controller : Robot, Controller
        The robot (τ, k, W) and controller (n, T, hold, compute delay); the
        operating point (V, f) is marked when `mark`.
    alpha : float
        Target angle from the wall normal, rad (KB eq 9).
    V : array_like, optional
        Speeds, m/s (default 300 points in [0.02, 2] m/s).
    f : array_like, optional
        Force ratios (default 300 log-spaced points in [0.01, 100]).
    models : list of LoopModel, optional
        Curves drawn; default `curves.default_models(controller)`.
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (`regions.region_model`); default
        the report's verdict model, ``sampled`` with the controller's hold
        and compute delay. Named in the title and the legend.
    ax : matplotlib Axes, optional
    legend : bool
        Draw the legend outside the axes, on the right.
    mark : bool
        Mark (robot.V, controller.f).
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, _WITH_LEGEND if legend else _SINGLE)
    V = np.linspace(0.02, 2.0, resolution) if V is None else np.asarray(V, dtype=float)
    f = np.geomspace(0.01, 100.0, resolution) if f is None else np.asarray(f, dtype=float)
    models = default_models(controller) if models is None else models
    shaded = region_model(controller, shaded)
    text = shading_text(shaded, controller)
    _shade(ax, wall_f_region(robot, controller, alpha, V, f, model=shaded), text)
    _draw_curves(ax, wall_f_curves(robot, controller, alpha, V, models))
    if mark:
        _mark(ax, robot.V, controller.f, "CARMEL", label=MARK_LABEL, offset=(-8, 6))
    ax.set_yscale("log")
    ax.set_xlim(V[0], V[-1])
    ax.set_ylim(f[0], f[-1])
    title = f"Wall, α = {math.degrees(alpha):.3g}°: stable above f*(V) (KB eq 24)\n{_loop_text(robot, controller)}"
    _style_axes(ax, V_LABEL, F_LABEL, _title(title, text))
    ax.text(0.03, 0.96, "stable", transform=ax.transAxes, va="top", fontsize=10, color="#2a6a1f", weight="bold")
    ax.text(0.97, 0.04, "oscillates", transform=ax.transAxes, ha="right", fontsize=10, color="#9b2b22", weight="bold")
    if legend:
        region_legend(ax, fontsize=7)
    return fig


def plot_wall_alpha_critical(
    robot: Robot,
    controller: Controller,
    *,
    V=None,
    models=None,
    law: ForceLaw | None = None,
    marks=((20.0, "KB Fig 5: α = 20°"), (50.0, "before the corner: α = 50°")),
    shaded=None,
    ax=None,
    legend: bool = True,
    shade: bool = True,
    resolution: int = 300,
):
    """Critical target angle α*(V) along a wall: stable above every model's curve (KB eq 21, 23).

    Parameters
    ----------
    robot, controller : Robot, Controller
    V : array_like, optional
        Speeds, m/s (default [0.02, 2]).
    models : list of LoopModel, optional
    law : ForceLaw, optional
        Default KB's power law with the controller's f; e.g. the grid's
        effective law to compare with the grid simulator.
    marks : sequence of (alpha_deg, text) or (…, text, (dx, dy))
        Operating points (robot.V, α) to mark (default KB Fig 5's corner run);
        an optional offset places the text, points from the star.
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict
        model, see `plot_wall_f_region`).
    ax : matplotlib Axes, optional
    legend : bool
        Draw the legend outside the axes, on the right.
    shade : bool
        Shade the `shaded` model's verdicts.
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, _WITH_LEGEND if legend else _SINGLE)
    V = np.linspace(0.02, 2.0, resolution) if V is None else np.asarray(V, dtype=float)
    models = default_models(controller) if models is None else models
    text = None
    if shade:
        shaded = region_model(controller, shaded)
        text = shading_text(shaded, controller)
        alpha = np.radians(np.linspace(0.2, 89.8, resolution))
        _shade(ax, wall_alpha_region(robot, controller, V, alpha, law=law, model=shaded), text, y_scale=180 / math.pi)
    _draw_curves(ax, wall_alpha_curves(robot, controller, V, models, law=law), y_scale=180 / math.pi)
    _marks(ax, marks, lambda a: (robot.V, a), {50.0: (-8, 6)})
    ax.set_xlim(V[0], V[-1])
    ax.set_ylim(0, 90)
    ax.set_yticks(range(0, 91, 15))
    title = f"Wall: stable above α*(V) (KB eq 21 with eq 23)\n{_loop_text(robot, controller, law)}"
    _style_axes(ax, V_LABEL, ALPHA_LABEL, _title(title, text))
    ax.text(0.03, 0.96, "stable", transform=ax.transAxes, va="top", fontsize=10, color="#2a6a1f", weight="bold")
    ax.text(0.97, 0.04, "oscillates", transform=ax.transAxes, ha="right", fontsize=10, color="#9b2b22", weight="bold")
    if legend:
        region_legend(ax, fontsize=7)
    return fig


# ------------------------------------------------------------------ corridor
def plot_corridor_region(
    robot: Robot,
    controller: Controller,
    *,
    L=None,
    V=None,
    models=None,
    law: ForceLaw | None = None,
    marks=((0.9, "KB Fig 6a\n(wide)"), (0.6, "KB Fig 6b\n(narrow)")),
    shaded=None,
    ax=None,
    legend: bool = True,
    shade: bool = True,
    resolution: int = 300,
):
    """Stable and unstable regions in the middle of a corridor, (L, V) plane: stable below V*(L).

    Shading: the verdicts of the `shaded` model (`regions.corridor_region`);
    curves: V*(L) = NV*/N(L) of every model (`curves.corridor_V_curves`;
    KB eq 25).

    Parameters
    ----------
    robot, controller : Robot, Controller
    L : array_like, optional
        Half-widths, m (default (W/2, 2] m).
    V : array_like, optional
        Speeds, m/s (default [0.02, 2]).
    models : list of LoopModel, optional
    law : ForceLaw, optional
        Default KB's power law.
    marks : sequence of (L, text) or (…, text, (dx, dy))
        Operating points (L, robot.V) to mark (default KB Fig 6's corridors
        after the step, L = 0.9 m and 0.6 m); an optional offset places the
        text, points from the star.
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict
        model, see `plot_wall_f_region`).
    ax : matplotlib Axes, optional
    legend : bool
        Draw the legend outside the axes, on the right.
    shade : bool
        Shade the `shaded` model's verdicts.
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, _WITH_LEGEND if legend else _SINGLE)
    lo = robot.W / 2
    L = np.linspace(lo * 1.0005, 2.0, resolution) if L is None else np.asarray(L, dtype=float)
    V = np.linspace(0.02, 2.0, resolution) if V is None else np.asarray(V, dtype=float)
    models = default_models(controller) if models is None else models
    text = None
    if shade:
        shaded = region_model(controller, shaded)
        text = shading_text(shaded, controller)
        _shade(ax, corridor_region(robot, controller, L, V, law=law, model=shaded), text)
    _draw_curves(ax, corridor_V_curves(robot, controller, L, models, law=law))
    _marks(ax, marks, lambda Lm: (Lm, robot.V), {0.9: (8, -8), 0.6: (-8, 6)})
    ax.set_xlim(min(L[0], lo) - 0.1, L[-1])
    ax.set_ylim(V[0], V[-1])
    _no_fit_band(ax, robot.W, vertical=True)
    title = f"Corridor: stable below V*(L) = NV*/N(L) (KB eq 25)\n{_loop_text(robot, controller, law)}"
    _style_axes(ax, L_LABEL, V_LABEL, _title(title, text))
    ax.text(0.97, 0.04, "stable", transform=ax.transAxes, ha="right", fontsize=10, color="#2a6a1f", weight="bold")
    ax.text(0.25, 0.96, "oscillates", transform=ax.transAxes, va="top", fontsize=10, color="#9b2b22", weight="bold")
    if legend:
        region_legend(ax, fontsize=7)
    return fig


def plot_corridor_L_critical(
    robot: Robot,
    controller: Controller,
    *,
    V=None,
    models=None,
    law: ForceLaw | None = None,
    marks=((0.9, "KB Fig 6a\n(wide)"), (0.6, "KB Fig 6b\n(narrow)")),
    shaded=None,
    ax=None,
    legend: bool = True,
    shade: bool = True,
    resolution: int = 300,
):
    """Critical corridor half-width L*(V): stable above every model's curve (KB eq 25).

    Parameters
    ----------
    robot, controller : Robot, Controller
    V : array_like, optional
        Speeds, m/s (default [0.02, 2]).
    models : list of LoopModel, optional
    law : ForceLaw, optional
    marks : sequence of (L, text) or (…, text, (dx, dy))
        Operating points (robot.V, L); an optional offset places the text,
        points from the star.
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict
        model, see `plot_wall_f_region`).
    ax : matplotlib Axes, optional
    legend : bool
        Draw the legend outside the axes, on the right.
    shade : bool
        Shade the `shaded` model's verdicts.
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, _WITH_LEGEND if legend else _SINGLE)
    V = np.linspace(0.02, 2.0, resolution) if V is None else np.asarray(V, dtype=float)
    models = default_models(controller) if models is None else models
    curves = corridor_L_curves(robot, controller, V, models, law=law)
    top = max(1.6, 1.15 * max(float(np.nanmax(np.where(np.isfinite(c.y), c.y, np.nan))) for c in curves))
    text = None
    if shade:
        shaded = region_model(controller, shaded)
        text = shading_text(shaded, controller)
        L = np.linspace(robot.W / 2 * 1.0005, top, resolution)
        region = corridor_region(robot, controller, L, V, law=law, model=shaded)
        # the region grid is (V rows, L columns): transpose to (L rows, V columns)
        from dataclasses import replace

        _shade(ax, replace(region, x=region.y, y=region.x, stable=region.stable.T), text)
    _draw_curves(ax, curves)
    _marks(ax, marks, lambda Lm: (robot.V, Lm), {0.9: (-8, 6)})
    ax.set_xlim(V[0], V[-1])
    ax.set_ylim(0.0, top)
    _no_fit_band(ax, robot.W, vertical=False)
    title = f"Corridor: stable above L*(V) (KB eq 25)\n{_loop_text(robot, controller, law)}"
    _style_axes(ax, V_LABEL, L_STAR_LABEL, _title(title, text))
    ax.text(0.03, 0.96, "stable", transform=ax.transAxes, va="top", fontsize=10, color="#2a6a1f", weight="bold")
    ax.text(0.97, 0.3, "oscillates", transform=ax.transAxes, ha="right", fontsize=10, color="#9b2b22", weight="bold")
    if legend:
        region_legend(ax, fontsize=7)
    return fig


# ------------------------------------------------------------------ summaries
def _suptitle(fig, where: str, section: str, shaded, controller: Controller):
    for ax in fig.axes:  # the shaded model is named once, in the figure title
        ax.set_title(ax.get_title().split("\nshaded: ")[0], fontsize=9)
    fig.suptitle(
        f"Where CARMEL is safe {where}: every model's boundary (lines), KB's runs (stars) (Koren & Borenstein 1991 {section})\n"
        f"shaded: {shading_text(shaded, controller)}",
        fontsize=11,
    )


def plot_wall_regions(robot: Robot, controller: Controller, alphas_deg=(20.0, 45.0, 70.0), *, models=None, shaded=None, resolution: int = 300):
    """(V, f) regions at each α and α*(V), in a 2 × 2 grid with one legend below (KB §5.3).

    Parameters
    ----------
    robot, controller : Robot, Controller
    alphas_deg : sequence of float
        Target angles of the (V, f) panels, deg.
    models : list of LoopModel, optional
        Curves drawn (default every model).
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict
        model, ``sampled`` with the controller's structure).
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    shaded = region_model(controller, shaded)
    panels = len(alphas_deg) + 1
    cols = 2
    rows = math.ceil(panels / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(11.5, 4.3 * rows + 1.6), layout="constrained")
    axes = np.ravel(axes)
    for ax, a in zip(axes, alphas_deg):
        plot_wall_f_region(robot, controller, math.radians(a), models=models, shaded=shaded, ax=ax, legend=False, resolution=resolution)
    plot_wall_alpha_critical(robot, controller, models=models, shaded=shaded, ax=axes[len(alphas_deg)], legend=False, resolution=resolution)
    for ax in axes[panels:]:
        ax.set_visible(False)
    region_legend(fig=fig, ncol=3)
    _suptitle(fig, "along a wall", "§5.3", shaded, controller)
    return fig


def plot_corridor_regions(robot: Robot, controller: Controller, *, models=None, shaded=None, resolution: int = 300):
    """(L, V) regions and L*(V) side by side with one legend below (KB §5.4).

    Parameters
    ----------
    robot, controller : Robot, Controller
    models : list of LoopModel, optional
        Curves drawn (default every model).
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict
        model, ``sampled`` with the controller's structure).
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    shaded = region_model(controller, shaded)
    fig, (a, b) = plt.subplots(1, 2, figsize=(11.5, 6.0), layout="constrained")
    plot_corridor_region(robot, controller, models=models, shaded=shaded, ax=a, legend=False, resolution=resolution)
    plot_corridor_L_critical(robot, controller, models=models, shaded=shaded, ax=b, legend=False, resolution=resolution)
    region_legend(fig=fig, ncol=3)
    _suptitle(fig, "in a corridor", "§5.4", shaded, controller)
    return fig
