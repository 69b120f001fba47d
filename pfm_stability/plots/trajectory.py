"""Simulated runs drawn like Koren & Borenstein 1991's Figs 3, 5 and 6.

Obstacles are the histogram grid's filled cells (squares of the cell size) or
the analytic walls (thick lines); the robot is drawn every second as a circle
of its diameter W, to scale (KB: "circles which are plotted to scale
according to the 0.8 m diameter of CARMEL's sensor ring"), on equal axes in
metres, with the path, start, target and the event that ended the run. The
legend sits outside the axes, so it never hides the target arrow, the path
or an obstacle.
"""

from __future__ import annotations

import math

import numpy as np

from .common import figure_and_axes, outside_legend

__all__ = ["plot_trajectory"]

_PAD = 1.2
"""Margin around the path, m."""


def _figure_axes(ax, width, height, legend=True):
    scale = 7.5 / max(height, width)
    extra = 1.6 if legend else 0.0  # the legend, right of the axes
    return figure_and_axes(ax, (max(4.6, width * scale + 1.6) + extra, max(3.8, height * scale + 1.2)))


def _draw_grid(ax, grid, bounds):
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    x0, x1, y0, y1 = bounds
    ox, oy, _ = grid.occupied()
    c = grid.cell_size
    keep = (ox > x0 - c) & (ox < x1 + c) & (oy > y0 - c) & (oy < y1 + c)
    cells = [Rectangle((x - c / 2, y - c / 2), c, c) for x, y in zip(ox[keep], oy[keep])]
    ax.add_collection(PatchCollection(cells, facecolor="0.15", edgecolor="none", label="occupied cells"))


def _draw_walls(ax, environment):
    for i, w in enumerate(environment.walls):
        ax.plot([w.p0[0], w.p1[0]], [w.p0[1], w.p1[1]], color="0.15", lw=3, solid_capstyle="butt", label="wall" if i == 0 else None)


def _bounds(result):
    tr = result.trajectory
    xs = list(tr.x) + [result.scenario.start.x]
    ys = list(tr.y) + [result.scenario.start.y]
    t = result.scenario.target
    if t.is_point:
        xs.append(t.x)
        ys.append(t.y)
    pad = _PAD + result.scenario.robot.W / 2
    return min(xs) - pad, max(xs) + pad, min(ys) - pad, max(ys) + pad


def plot_trajectory(result, ax=None, *, every: float = 1.0, title: str | None = None, legend: bool = True):
    """Draw a simulated run like KB's figures.

    Parameters
    ----------
    result : RunResult
        A run with its trajectory recorded (``record="trajectory"``).
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.
    every : float
        Interval between the robot circles, s (KB: 1 s).
    title : str, optional
        Default: scenario, environment and outcome.
    legend : bool
        Draw the legend outside the axes, on the right (a figure with several
        runs can draw one figure legend of the axes' labelled artists instead).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.patches import Circle

    tr = result.trajectory
    if tr is None:
        raise ValueError("result has no trajectory: simulate with record='trajectory'")
    s = result.scenario
    bounds = _bounds(result)
    fig, ax = _figure_axes(ax, bounds[1] - bounds[0], bounds[3] - bounds[2], legend)
    if s.env == "grid":
        _draw_grid(ax, s.environment, bounds)
    else:
        _draw_walls(ax, s.environment)
    ax.plot(tr.x, tr.y, color="C0", lw=1.0, label="path")
    times = np.arange(0.0, tr.t[-1] + 1e-9, every)
    cx, cy = tr.at_times(times)
    for i, (x, y) in enumerate(zip(cx, cy)):
        ax.add_patch(Circle((x, y), s.robot.W / 2, fill=False, color="C0", lw=0.8, label=f"robot every {every:g} s" if i == 0 else None))
    ax.plot([s.start.x], [s.start.y], "o", color="C2", ms=5)
    ax.annotate("Start", (s.start.x, s.start.y), xytext=(6, -12), textcoords="offset points", color="C2")
    _draw_target(ax, s, tr)
    for e in result.events:
        marker = {"collision": ("x", "C3"), "target_reached": ("*", "C2"), "trapped": ("s", "C1")}[e.type]
        ax.plot([e.x], [e.y], marker[0], color=marker[1], ms=11, mew=2, label=f"{e.type.replace('_', ' ')} at {e.t:.1f} s")
    ax.set_xlim(bounds[0], bounds[1])
    ax.set_ylim(bounds[2], bounds[3])
    ax.set_aspect("equal")
    ax.set_xlabel("X (m)")
    ax.set_ylabel("Y (m)")
    ax.set_title(title if title is not None else _title(result), fontsize=10)
    if legend:
        outside_legend(ax, framealpha=0.85)
    ax.grid(True, lw=0.3, alpha=0.5)
    return fig


def _draw_target(ax, s, tr):
    t = s.target
    if t.is_path:  # the path it follows
        px, py = zip(*t.path)
        ax.plot(px, py, "--", color="C3", lw=1, label="path followed")
    if t.is_point:
        ax.plot([t.x], [t.y], "D", color="C3", ms=6)
        ax.annotate("Target", (t.x, t.y), xytext=(6, 4), textcoords="offset points", color="C3")
        return
    # an arrow in the target direction beside the end of the path
    dx, dy = math.sin(t.angle), math.cos(t.angle)
    x, y = tr.x[-1] + 0.8 * s.robot.W * dx, tr.y[-1] + 0.8 * s.robot.W * dy
    ax.annotate("", xy=(x + 0.8 * dx, y + 0.8 * dy), xytext=(x, y), arrowprops=dict(arrowstyle="-|>", color="C3", lw=1.5))
    ax.annotate("target\n(at infinity)", (x, y), xytext=(0, -4), textcoords="offset points", color="C3", fontsize=8, ha="center", va="top")


def _title(result) -> str:
    s, m = result.scenario, result.metrics
    parts = [f"{s.name} ({s.env})"]
    if s.analysis and m is not None:
        verdict = "oscillating" if m.oscillating else ("stable" if m.stable else "not stable")
        sigma = f", σ = {m.growth_rate:+.3f} 1/s" if m.growth_rate is not None else ""
        parts.append(f"{verdict}{sigma}")
    outcome = ", ".join(f"{e.type.replace('_', ' ')} at {e.t:.1f} s" for e in result.events) or f"ran {result.t_end:.1f} s"
    if result.min_clearance is not None and not result.collided:
        outcome += f", closest {result.min_clearance * 100:.2g} cm"
    parts.append(outcome)
    return parts[0] + "\n" + "; ".join(parts[1:])
