"""The summary figure of ``pfm-stability sweep`` (data: `pfm_stability.sweeps.summary.SweepFigureData`).

A verdict map (colour: fraction of the models that call a point stable;
lines: each model's boundary; markers: the simulator's verdicts) or, for one
varying parameter, the models' pairwise agreement matrix. Draws only.
"""

from __future__ import annotations

import numpy as np

from .common import MODEL_STYLE, figure_and_axes

__all__ = ["plot_sweep_summary"]

_FRACTION_COLOURS = ("#a50026", "#e8a317", "#006837")
"""Red (no model says stable) through amber (half) to green (all): the middle stays visible on white,
where RdYlGn's pale yellow vanished among scattered points."""


def _fraction_colormap():
    from matplotlib.colors import LinearSegmentedColormap

    return LinearSegmentedColormap.from_list("stable_fraction", _FRACTION_COLOURS)


def plot_sweep_summary(data, ax=None):
    """Draw `data` (a `SweepFigureData`) and return the figure.

    Parameters
    ----------
    data : SweepFigureData
        The figure's data.
    ax : matplotlib Axes, optional
        Axes to draw on; None: a new figure.
    """
    if data.kind == "agreement":
        return _agreement(data, ax)
    return _map(data, ax)


def _map(data, ax):
    fig, ax = figure_and_axes(ax, size=(7.6, 5.4))
    levels = len(data.models)
    if data.gridded:
        mesh = ax.pcolormesh(data.x_values, data.y_values, data.fraction, cmap=_fraction_colormap(), vmin=0.0, vmax=1.0, shading="nearest")
        handles = []
        if data.x_values.size > 1 and data.y_values.size > 1:
            for model, share in data.model_fraction.items():
                style = MODEL_STYLE.get(model, {})
                ax.contour(data.x_values, data.y_values, share, levels=[0.5], colors=[style.get("color", "k")],
                           linestyles=[style.get("ls", "-")], linewidths=[style.get("lw", 1.5)])
                handles.append(ax.plot([], [], label=f"{model} boundary", **style)[0])
    else:
        size = float(np.clip(20000.0 / max(data.x_values.size, 1), 6.0, 70.0))  # few points: large dots
        mesh = ax.scatter(data.x_values, data.y_values, c=data.fraction, cmap=_fraction_colormap(), vmin=0.0, vmax=1.0, s=size, linewidths=0)
        handles = []
    if data.sim_x is not None and data.sim_x.size:
        ok = data.sim_stable
        mark = float(np.clip(40000.0 / data.sim_x.size, 10.0, 140.0))
        handles.append(ax.scatter(data.sim_x[ok], data.sim_y[ok], marker="o", s=mark, facecolors="none", edgecolors="k",
                                  linewidths=0.7, label="simulated: stable"))
        handles.append(ax.scatter(data.sim_x[~ok], data.sim_y[~ok], marker="x", s=mark, c="k", linewidths=0.8,
                                  label="simulated: oscillates"))
    if data.x_log:
        ax.set_xscale("log")
    if data.y_log:
        ax.set_yscale("log")
    ax.set_xlabel(data.x_label)
    ax.set_ylabel(data.y_label)
    ax.set_title(data.title, fontsize=9)
    bar = fig.colorbar(mesh, ax=ax, pad=0.02)
    bar.set_label(f"fraction of the {levels} model{'s' if levels > 1 else ''} that call it stable"
                  + (" (mean over the other parameters)" if data.averaged else ""), fontsize=8)
    if handles:
        ax.legend(handles=handles, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=min(3, len(handles)), framealpha=0.9)
    return fig


def _agreement(data, ax):
    n = len(data.labels)
    fig, ax = figure_and_axes(ax, size=(1.6 + 1.1 * n, 1.2 + 0.9 * n))
    image = ax.imshow(data.matrix, cmap="viridis", vmin=min(0.5, float(np.nanmin(data.matrix))), vmax=1.0)
    ax.set_xticks(range(n), data.labels, rotation=30, ha="right", fontsize=8)
    ax.set_yticks(range(n), data.labels, fontsize=8)
    for i in range(n):
        for j in range(n):
            value = data.matrix[i, j]
            ax.text(j, i, "-" if np.isnan(value) else f"{100 * value:.1f} %", ha="center", va="center", fontsize=8,
                    color="white" if value < 0.8 else "black")
    ax.set_title("agreement of the verdicts (fraction of points)\n" + data.title, fontsize=8)
    fig.colorbar(image, ax=ax, pad=0.02, fraction=0.05)
    return fig
