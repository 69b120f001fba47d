"""A map with its corridor segments coloured by V* (`pfm_stability.maps.analysis.MapAnalysis`)."""

from __future__ import annotations

import math

import numpy as np

from .common import figure_and_axes

__all__ = ["NO_VERDICT_LABELS", "NO_VERDICT_STYLES", "known_extent", "map_greys", "plot_map_stability"]

FREE_GREY, UNKNOWN_GREY, OCCUPIED_GREY = 1.0, 0.82, 0.15
"""Shades of free, unknown and occupied map cells (white, light grey, near black)."""
NO_VERDICT_STYLES = {
    "open": dict(color="0.45", lw=1.3, ls=(0, (1.5, 2.0))),
    "end effect": dict(color="0.35", lw=1.4, ls=(0, (6.0, 2.5, 1.5, 2.5))),
    "weak": dict(color="0.55", lw=0.8, ls="-"),
    "tapering": dict(color="0.4", lw=1.2, ls=(0, (4.0, 2.0))),
}
"""Quiet grey styles of the segments without a verdict (`maps.analysis.NO_VERDICT`), by kind; "no equilibrium" is drawn as "open"."""
NO_VERDICT_LABELS = {
    "open": "no verdict: open / no lateral equilibrium",
    "end effect": "no verdict: end effect (wall ahead)",
    "weak": "no verdict: weak field",
    "tapering": "no verdict: tapering (equilibrium path turns)",
}
"""Legend entries of `NO_VERDICT_STYLES`."""


def _no_verdict_kind(verdict: str) -> str:
    """The `NO_VERDICT_STYLES` key of a segment's verdict ("no equilibrium" and anything unforeseen draw as "open")."""
    return verdict if verdict in NO_VERDICT_STYLES else "open"


def map_greys(occupancy) -> np.ndarray:
    """RGB image (height, width, 3) of a map, row 0 at the top: free white, unknown light grey, occupied dark.

    Parameters
    ----------
    occupancy : OccupancyMap
        The map.
    """
    grey = np.full(occupancy.values.shape, UNKNOWN_GREY)
    grey[occupancy.free] = FREE_GREY
    grey[occupancy.occupied] = OCCUPIED_GREY
    return np.repeat(grey[::-1, :, None], 3, axis=2)


def known_extent(occupancy, margin: float = 1.0) -> tuple:
    """(x0, x1, y0, y1), m: the known (free or occupied) cells' bounding box plus `margin` m, within the map.

    A map recorded in a large unknown frame (tb3_sandbox: a 5 m room in a 19 m image) is
    drawn around what is known; the whole map when nothing is known.

    Parameters
    ----------
    occupancy : OccupancyMap
        The map.
    margin : float, optional
        Margin around the known cells, m.
    """
    x0, x1, y0, y1 = occupancy.extent
    known = occupancy.free | occupancy.occupied
    rows, cols = np.nonzero(known.any(axis=1))[0], np.nonzero(known.any(axis=0))[0]
    if rows.size == 0:
        return x0, x1, y0, y1
    r = occupancy.resolution
    return (max(x0, x0 + cols[0] * r - margin), min(x1, x0 + (cols[-1] + 1) * r + margin),
            max(y0, y0 + rows[0] * r - margin), min(y1, y0 + (rows[-1] + 1) * r + margin))


def _colour_limit(analysis) -> float:
    """Top of the V* colour scale, m/s: 2 V (so V sits mid-scale), or the largest finite V* below it."""
    return 2.0 * analysis.robot.V


def plot_map_stability(analysis, ax=None, *, title: str | None = None, size=None):
    """The map, and every segment coloured by V* with unstable ones marked.

    Segments are coloured by V* on a red–yellow–green scale centred on the robot's V
    (red: V* well below V, the robot oscillates; green: V* well above V); unstable
    segments get a thick black outline and a red ✕ at their midpoint; segments
    without a verdict are quiet grey lines, one style per kind (`NO_VERDICT_STYLES`:
    open or no equilibrium, end effect, weak field, tapering). The legend lists only the kinds
    the map has (no "unstable" entry without an unstable segment, no grey style not drawn).
    The colour bar marks V on itself.

    Parameters
    ----------
    analysis : MapAnalysis
    ax : matplotlib Axes, optional
    title : str, optional
        Default: map name, V, model and the unstable length.
    size : (float, float), optional
        Figure size, inches (default from the map's aspect ratio).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib import colormaps
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D

    occupancy = analysis.occupancy
    full = occupancy.extent
    x0, x1, y0, y1 = known_extent(occupancy)
    aspect = (y1 - y0) / max(x1 - x0, 1e-9)
    if size is None:
        w_map, h_map = (9.5, 9.5 * aspect) if aspect <= 1.2 else (10.5 / aspect, 10.5)
        size = (max(w_map + 1.6, 7.0), max(h_map + 2.2, 4.5))
    fig, ax = figure_and_axes(ax, size)
    ax.imshow(map_greys(occupancy), extent=full, origin="upper", interpolation="nearest", zorder=0)
    V = analysis.robot.V
    top = _colour_limit(analysis)
    cmap = colormaps["RdYlGn"]
    norm = Normalize(0.0, top)
    decided = [s for s in analysis.segments if s.V_critical is not None]
    undecided = [s for s in analysis.segments if s.V_critical is None]
    width = max(2.0, min(5.0, 600.0 / max(x1 - x0, y1 - y0)))
    kinds = sorted({_no_verdict_kind(s.verdict) for s in undecided}, key=list(NO_VERDICT_STYLES).index)
    for kind in kinds:
        style = NO_VERDICT_STYLES[kind]
        lines = [[(s.x0, s.y0), (s.x1, s.y1)] for s in undecided if _no_verdict_kind(s.verdict) == kind]
        ax.add_collection(LineCollection(lines, colors=style["color"], linewidths=style["lw"], linestyles=[style["ls"]], zorder=2))
    unstable = [s for s in decided if s.stable is False]
    if unstable:
        ax.add_collection(LineCollection([[(s.x0, s.y0), (s.x1, s.y1)] for s in unstable], colors="black", linewidths=width + 3.0,
                                         zorder=3, capstyle="round"))
    if decided:
        values = np.array([min(s.V_critical, top) if math.isfinite(s.V_critical) else top for s in decided])
        lines = LineCollection([[(s.x0, s.y0), (s.x1, s.y1)] for s in decided], cmap=cmap, norm=norm, linewidths=width, zorder=4,
                               capstyle="round")
        lines.set_array(values)
        ax.add_collection(lines)
    if unstable:
        mx = [(s.x0 + s.x1) / 2 for s in unstable]
        my = [(s.y0 + s.y1) / 2 for s in unstable]
        ax.scatter(mx, my, marker="X", s=90, color="#b2182b", edgecolors="white", linewidths=1.0, zorder=5)
    from matplotlib.cm import ScalarMappable

    tall = aspect > 1.2
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, fraction=0.05 if tall else 0.035, pad=0.01,
                       aspect=30 if tall else 20, extend="max", shrink=0.9 if tall else 1.0)
    bar.set_label("fastest stable speed V* (m/s)")
    _mark_speed(bar, V)
    handles = [
        *([Line2D([], [], color=cmap(norm(1.6 * V)), lw=width, label="stable at V (colour: V*)")] if any(s.stable for s in decided) else []),
        *([Line2D([], [], color=cmap(norm(0.4 * V)), lw=width, label="oscillates at V (V* < V)"),
           Line2D([], [], marker="X", ls="", color="#b2182b", markeredgecolor="white", markersize=9, label="unstable segment")]
          if unstable else []),
        *[Line2D([], [], color=NO_VERDICT_STYLES[k]["color"], lw=NO_VERDICT_STYLES[k]["lw"] + 0.4,
                 ls=NO_VERDICT_STYLES[k]["ls"], label=NO_VERDICT_LABELS[k]) for k in kinds],
        Line2D([], [], marker="s", ls="", color=str(OCCUPIED_GREY), markersize=8, label="occupied"),
        *([Line2D([], [], marker="s", ls="", color=str(UNKNOWN_GREY), markeredgecolor="0.6", markersize=8, label="unknown")]
          if occupancy.unknown.any() else []),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=3 if not tall else 2, fontsize=8.5, frameon=False)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    if title is None:
        s = analysis.summary()
        worst = s["V_critical_min"]
        title = (f"{occupancy.name}: will the robot oscillate at V = {V:g} m/s? ({analysis.model} model)\n"
                 f"{s['verdicts']['unstable']} of {s['segments']} segments unstable, {s['unstable_length_m']:.1f} m; "
                 f"slowest V* = {worst if isinstance(worst, str) else f'{worst:.3g}' if worst is not None else 'none'} m/s")
    ax.set_title(title, fontsize=11)
    return fig


def _mark_speed(bar, V: float) -> None:
    """A black line across the colour bar at the robot's speed V (m/s), labelled on the bar itself."""
    bar.ax.axhline(V, color="black", lw=2.0)
    bar.ax.text(0.5, V, f"V = {V:g}", transform=bar.ax.get_yaxis_transform(), va="bottom", ha="center", rotation=90,
                fontsize=8, fontweight="bold", clip_on=False,
                bbox=dict(boxstyle="round,pad=0.15", facecolor="white", edgecolor="none", alpha=0.85))
