"""The total potential of a scene with its obstacles, goal and stationary points (`pfm_stability.analysis.traps`)."""

from __future__ import annotations

import numpy as np

from .common import figure_and_axes, outside_legend

__all__ = ["plot_traps", "KIND_STYLE"]

KIND_STYLE = {
    "minimum": dict(marker="o", color="#d62728", s=70, label="trap (local minimum)"),
    "saddle": dict(marker="X", color="#ff7f0e", s=80, label="saddle"),
    "maximum": dict(marker="^", color="#1f77b4", s=70, label="maximum"),
    "degenerate": dict(marker="D", color="#9467bd", s=60, label="degenerate"),
}
"""Marker per kind of stationary point; the goal is a gold star."""


def _draw_obstacles(ax, scene):
    from matplotlib.patches import Circle as CirclePatch
    from matplotlib.patches import Polygon as PolygonPatch

    style = dict(facecolor="0.35", edgecolor="black", lw=1.0, zorder=3)
    for i, o in enumerate(scene.obstacles):
        label = "obstacle" if i == 0 else None
        if o.kind == "circle":
            ax.add_patch(CirclePatch(o.center, o.radius, label=label, **style))
        elif o.kind == "polygon":
            ax.add_patch(PolygonPatch(np.asarray(o.vertices), closed=True, label=label, **style))
        else:
            (x0, y0), (x1, y1) = o.start, o.end
            ax.plot([x0, x1], [y0, y1], color="black", lw=3.0, solid_capstyle="round", zorder=3, label=label)


def plot_traps(analysis, ax=None, *, points: int = 301, title: str | None = None):
    """Filled contours of U over the region (bands of equal area), obstacles, influence limits ρ = ρ0, goal and stationary points.

    Parameters
    ----------
    analysis : pfm_stability.analysis.traps.TrapAnalysis
        What `find_stationary_points` returned.
    ax : matplotlib Axes, optional
        Draw here; default a new figure.
    points : int
        Grid points along the region's longer side for the contours.
    title : str, optional
        Default: the law and the conclusion.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.lines import Line2D

    from ..laws.scene import field

    scene = analysis.scene
    (x0, y0), (x1, y1) = scene.region
    own = ax is None
    fig, ax = figure_and_axes(ax, size=(8.4, min(9.0, max(4.5, 5.2 * (y1 - y0) / (x1 - x0) + 2.4))))  # little white above and below
    xs, ys, _ = scene.grid(points)
    X, Y = np.meshgrid(xs, ys)
    q = np.column_stack([X.ravel(), Y.ravel()])
    u, _, _, _, free = field(scene, q, hessian=False)
    free |= np.hypot(q[:, 0] - scene.goal[0], q[:, 1] - scene.goal[1]) == 0  # the goal node itself
    u = np.where(free, u, np.nan).reshape(X.shape)
    values = u[np.isfinite(u)]
    top = float(np.quantile(values, 0.95)) if values.size else 1.0
    levels = np.unique(np.quantile(values[values <= top], np.linspace(0.0, 1.0, 25))) if values.size else np.array([0.0, 1.0])
    if levels.size < 2:
        levels = np.array([levels[0], levels[0] + 1.0])
    filled = ax.contourf(X, Y, np.clip(u, levels[0], levels[-1]), levels=levels, cmap="viridis")
    bar = fig.colorbar(filled, ax=ax, location="bottom", shrink=0.9, aspect=35, format="%.3g")
    bar.set_label("U (bands of equal area; clipped at the 95th percentile)", fontsize=8)
    bar.ax.tick_params(labelsize=7, labelrotation=45)
    saddles = sorted({round(p.potential, 12) for p in analysis.stationary_points if p.kind == "saddle" and levels[0] < p.potential < levels[-1]})
    if saddles:  # the level sets through the saddles bound the basins
        ax.contour(X, Y, u, levels=saddles, colors="white", linewidths=0.9)

    handles = []
    if scene.obstacles:
        rho = np.min([o.geometry(q)[0] for o in scene.obstacles], axis=0).reshape(X.shape)
        ax.contour(X, Y, rho, levels=[scene.law.rho0], colors="white", linestyles="--", linewidths=1.0)
        handles.append(Line2D([], [], color="0.5", ls="--", label=f"influence limit rho = rho0 = {scene.law.rho0:g} m"))
    if saddles:
        handles.append(Line2D([], [], color="0.5", lw=0.9, label="U = U(saddle): basin boundaries"))
    _draw_obstacles(ax, scene)
    handles += [h for h in ax.get_legend_handles_labels()[0]]

    goal = next((p for p in analysis.stationary_points if p.goal), None)
    goal_label = "goal" + (" (global minimum)" if analysis.goal_is_global_minimum else " (not a minimum)" if goal is None else f" ({goal.kind})")
    handles.append(ax.scatter(*scene.goal, marker="*", s=260, color="gold", edgecolor="black", zorder=6, label=goal_label))
    for kind, style in KIND_STYLE.items():
        chosen = [p for p in analysis.stationary_points if p.kind == kind and not p.goal]
        if chosen:
            style = dict(style)
            label = style.pop("label") + f" ({len(chosen)})"
            handles.append(ax.scatter([p.x for p in chosen], [p.y for p in chosen], edgecolor="black", zorder=7, label=label, **style))
    for p in analysis.traps:
        ax.annotate(f"({p.x:.4g}, {p.y:.4g})", (p.x, p.y), xytext=(-8, 10), textcoords="offset points", ha="right", fontsize=8, color="white",
                    bbox=dict(boxstyle="round,pad=0.2", fc="black", alpha=0.6), zorder=8)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title if title is not None else f"{scene.law.describe()}\n{analysis.conclusion}", fontsize=9)
    labels = [h.get_label() for h in handles]
    if own:  # the layout engine reserves room for a figure legend, also with an equal aspect ratio
        fig.legend(handles, labels, loc="outside right upper", fontsize=8)
    else:
        outside_legend(ax, handles, labels, fontsize=8)
    return fig
