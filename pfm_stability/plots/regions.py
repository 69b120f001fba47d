"""Stability-region plots: where the robot is safe near a wall and in a corridor.

Each panel shades one model's verdicts on a dense grid (green stable, red
unstable; `pfm_stability.analysis.regions`) and draws every model's boundary curve in
its own style (`plots.common.MODEL_STYLE`), with the operating points of KB's
CARMEL runs marked (Koren & Borenstein 1991 Figs 5 and 6). The shaded model
is by default the one the stability report's verdict uses (``sampled`` with
the controller's hold and compute delay, `regions.verdict_model`); the title
and the legend name it. Legends sit outside the axes, so they hide no curve,
operating point or label. Computation lives in `pfm_stability.analysis.region_panels`
(one `RegionPanel` per panel, whose ``.plot()`` calls these); these functions only draw.

* `plot_wall_f_region`: (V, f) plane at one α; stable above f*(V) (KB eq 24).
* `plot_wall_alpha_critical`: α*(V); stable above (KB eq 21, 23).
* `plot_corridor_region`: (L, V) plane; stable below V*(L) (KB eq 25).
* `plot_corridor_L_critical`: L*(V); stable above (KB eq 25).
* `plot_wall_regions`, `plot_corridor_regions`: the panels above side by side
  with one legend (`region_panels.RegionPanels`: the figures of ``analyses/``).

Simulated boundary points go on top of any of these with
`pfm_stability.plots.validation.plot_simulated_boundary`.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from .common import MODEL_STYLE, MODEL_ZORDER, figure_and_axes, model_label, outside_legend

__all__ = [
    "MARK_LABEL",
    "PANELS",
    "STABLE_COLOR",
    "UNSTABLE_COLOR",
    "plot_wall_f_region",
    "plot_wall_alpha_critical",
    "plot_corridor_region",
    "plot_corridor_L_critical",
    "plot_wall_regions",
    "plot_corridor_regions",
    "region_legend",
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


def _panel(m, ax, legend: bool, y_scale: float = 1.0):
    """(figure, axes) of a panel with its shading (when the panel has one) and every model's curve drawn."""
    fig, ax = figure_and_axes(ax, _WITH_LEGEND if legend else _SINGLE)
    if m.region is not None:
        _shade(ax, m.region, m.shaded, y_scale=y_scale)
    _draw_curves(ax, m.curves, y_scale=y_scale)
    return fig, ax


def _finish(fig, ax, m, labels: tuple, title: str, stable: tuple, oscillates: tuple, legend: bool):
    """The axis `labels`, the title (the loop and the shaded model under it), the words "stable" and "oscillates" at
    (x, y, alignment) in axes fractions, the legend; returns the figure."""
    _style_axes(ax, *labels, _title(f"{title}\n{m.loop}", m.shaded))
    ax.text(stable[0], stable[1], "stable", transform=ax.transAxes, fontsize=10, color="#2a6a1f", weight="bold", **stable[2])
    ax.text(oscillates[0], oscillates[1], "oscillates", transform=ax.transAxes, fontsize=10, color="#9b2b22", weight="bold", **oscillates[2])
    if legend:
        region_legend(ax, fontsize=7)
    return fig


# ------------------------------------------------------------------ wall
def plot_wall_f_region(m, ax=None, *, legend: bool = True, mark: bool = True):
    """Stable and unstable regions along a wall in the (V, f) plane at one target angle α (`region_panels.wall_f_panel`).

    Parameters
    ----------
    m : region_panels.RegionPanel
        ``kind="wall_f"``.
    ax : matplotlib Axes, optional
    legend : bool
        Draw the legend outside the axes, on the right.
    mark : bool
        Mark the operating point (robot.V, controller.f).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _panel(m, ax, legend)
    if mark:
        _mark(ax, m.robot.V, m.controller.f, "CARMEL", label=MARK_LABEL, offset=(-8, 6))
    ax.set_yscale("log")
    ax.set_xlim(m.x[0], m.x[-1])
    ax.set_ylim(m.y[0], m.y[-1])
    return _finish(fig, ax, m, (V_LABEL, F_LABEL), f"Wall, α = {math.degrees(m.alpha):.3g}°: stable above f*(V) (KB eq 24)",
                   (0.03, 0.96, {"va": "top"}), (0.97, 0.04, {"ha": "right"}), legend)


def plot_wall_alpha_critical(m, ax=None, *, marks=((20.0, "KB Fig 5: α = 20°"), (50.0, "before the corner: α = 50°")), legend: bool = True):
    """Critical target angle α*(V) along a wall: stable above every model's curve (`region_panels.wall_alpha_panel`).

    Parameters
    ----------
    m : region_panels.RegionPanel
        ``kind="wall_alpha"``.
    ax : matplotlib Axes, optional
    marks : sequence of (alpha_deg, text) or (…, text, (dx, dy))
        Operating points (robot.V, α) to mark (default KB Fig 5's corner run);
        an optional offset places the text, points from the star.
    legend : bool
        Draw the legend outside the axes, on the right.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _panel(m, ax, legend, y_scale=180 / math.pi)
    _marks(ax, marks, lambda a: (m.robot.V, a), {50.0: (-8, 6)})
    ax.set_xlim(m.x[0], m.x[-1])
    ax.set_ylim(0, 90)
    ax.set_yticks(range(0, 91, 15))
    return _finish(fig, ax, m, (V_LABEL, ALPHA_LABEL), "Wall: stable above α*(V) (KB eq 21 with eq 23)",
                   (0.03, 0.96, {"va": "top"}), (0.97, 0.04, {"ha": "right"}), legend)


# ------------------------------------------------------------------ corridor
def plot_corridor_region(m, ax=None, *, marks=((0.9, "KB Fig 6a\n(wide)"), (0.6, "KB Fig 6b\n(narrow)")), legend: bool = True):
    """Stable and unstable regions in the middle of a corridor, (L, V) plane: stable below V*(L) (`region_panels.corridor_V_panel`).

    Parameters
    ----------
    m : region_panels.RegionPanel
        ``kind="corridor_V"``.
    ax : matplotlib Axes, optional
    marks : sequence of (L, text) or (…, text, (dx, dy))
        Operating points (L, robot.V) to mark (default KB Fig 6's corridors
        after the step, L = 0.9 m and 0.6 m); an optional offset places the
        text, points from the star.
    legend : bool
        Draw the legend outside the axes, on the right.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _panel(m, ax, legend)
    _marks(ax, marks, lambda Lm: (Lm, m.robot.V), {0.9: (8, -8), 0.6: (-8, 6)})
    ax.set_xlim(min(m.x[0], m.robot.W / 2) - 0.1, m.x[-1])
    ax.set_ylim(m.y[0], m.y[-1])
    _no_fit_band(ax, m.robot.W, vertical=True)
    return _finish(fig, ax, m, (L_LABEL, V_LABEL), "Corridor: stable below V*(L) = NV*/N(L) (KB eq 25)",
                   (0.97, 0.04, {"ha": "right"}), (0.25, 0.96, {"va": "top"}), legend)


def plot_corridor_L_critical(m, ax=None, *, marks=((0.9, "KB Fig 6a\n(wide)"), (0.6, "KB Fig 6b\n(narrow)")), legend: bool = True):
    """Critical corridor half-width L*(V): stable above every model's curve (`region_panels.corridor_L_panel`).

    Parameters
    ----------
    m : region_panels.RegionPanel
        ``kind="corridor_L"``.
    ax : matplotlib Axes, optional
    marks : sequence of (L, text) or (…, text, (dx, dy))
        Operating points (robot.V, L); an optional offset places the text,
        points from the star.
    legend : bool
        Draw the legend outside the axes, on the right.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _panel(m, ax, legend)
    _marks(ax, marks, lambda Lm: (m.robot.V, Lm), {0.9: (-8, 6)})
    ax.set_xlim(m.x[0], m.x[-1])
    ax.set_ylim(0.0, m.y[-1])
    _no_fit_band(ax, m.robot.W, vertical=False)
    return _finish(fig, ax, m, (V_LABEL, L_STAR_LABEL), "Corridor: stable above L*(V) (KB eq 25)",
                   (0.03, 0.96, {"va": "top"}), (0.97, 0.3, {"ha": "right"}), legend)


PANELS = {"wall_f": plot_wall_f_region, "wall_alpha": plot_wall_alpha_critical, "corridor_V": plot_corridor_region,
          "corridor_L": plot_corridor_L_critical}
"""The panel of each kind of `region_panels.RegionPanel` (its ``.plot()``)."""


# ------------------------------------------------------------------ summaries
def _suptitle(fig, where: str, section: str, shaded: str):
    for ax in fig.axes:  # the shaded model is named once, in the figure title
        ax.set_title(ax.get_title().split("\nshaded: ")[0], fontsize=9)
    fig.suptitle(
        f"Where CARMEL is safe {where}: every model's boundary (lines), KB's runs (stars) (Koren & Borenstein 1991 {section})\n"
        f"shaded: {shaded}",
        fontsize=11,
    )


def plot_wall_regions(panels):
    """(V, f) regions at each α and α*(V), in a 2 × 2 grid with one legend below (KB §5.3).

    Parameters
    ----------
    panels : region_panels.RegionPanels
        `region_panels.wall_panels`: the (V, f) panels, then α*(V) (also its ``.plot()``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    cols = 2
    rows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(11.5, 4.3 * rows + 1.6), layout="constrained")
    axes = np.ravel(axes)
    for ax, m in zip(axes, panels):
        PANELS[m.kind](m, ax=ax, legend=False)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    region_legend(fig=fig, ncol=3)
    _suptitle(fig, "along a wall", "§5.3", panels[0].shaded)
    return fig


def plot_corridor_regions(panels):
    """(L, V) regions and L*(V) side by side with one legend below (KB §5.4).

    Parameters
    ----------
    panels : region_panels.RegionPanels
        `region_panels.corridor_panels`: (L, V), then L*(V) (also its ``.plot()``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(11.5, 6.0), layout="constrained")
    for ax, m in zip(np.ravel(axes), panels):
        PANELS[m.kind](m, ax=ax, legend=False)
    region_legend(fig=fig, ncol=3)
    _suptitle(fig, "in a corridor", "§5.4", panels[0].shaded)
    return fig
