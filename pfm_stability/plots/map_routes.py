"""A map with the verdict along every route, and what the drives found (`maps.deciding.paths.PathVerdicts`,
`validation.map_drives.DriveValidation`)."""

from __future__ import annotations

import math

import numpy as np

from .map import OCCUPIED_GREY, UNKNOWN_GREY, map_frame

__all__ = ["ROUTE_STYLES", "TRACKING_STYLES", "plot_route_verdicts", "plot_tracking_verdicts"]

ROUTE_STYLES = {
    "nothing grows": dict(color="#a6d96a", lw=1.6, label="stable: no field (calm at any speed)"),
    "stable": dict(color="#1a9641", lw=2.6, label="stable (< 1 e-fold over the window, no weave)"),
    "forced weave": dict(color="#fdae61", lw=3.2, label="unstable: forced weave (the field's ripple)"),
    "growth": dict(color="#d7191c", lw=3.6, label="unstable: a disturbance grows (>= 1 e-fold)"),
    "relay": dict(color="#7b3294", lw=3.6, label="unstable: window-edge relay (a jump of the window's force)"),
    "collision course": dict(color="#000000", lw=3.6, label="unstable: collision course (the path meets an obstacle)"),
    "wall ahead both ways": dict(color="0.45", lw=1.4, label="no verdict: wall ahead both ways", ls=(0, (1.5, 2.0))),
    "wall ahead": dict(color="0.45", lw=1.4, label="no verdict: wall ahead (a path driven one way)", ls=(0, (1.5, 2.0))),
    "inside an obstacle": dict(color="0.3", lw=1.4, label="no verdict: inside an obstacle", ls=(0, (4.0, 2.0))),
}
"""Style of a stretch by its kind: the cause of an unstable stretch, stable (with or without a field), else its
verdict (a reason)."""


def _kind(stretch) -> str:
    if stretch.verdict == "stable":
        return "nothing grows" if stretch.V_critical == math.inf else "stable"
    if stretch.verdict == "unstable":
        return stretch.cause
    return stretch.verdict if stretch.verdict in ROUTE_STYLES else "inside an obstacle"


def _stretch_lines(paths, stretch) -> np.ndarray:
    """The polyline of a stretch (m): its route's points between its start and stop arc positions."""
    points = paths[stretch.route].points
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    inner = (arc > stretch.start) & (arc < stretch.stop)
    ends = [np.array([np.interp(a, arc, points[:, 0]), np.interp(a, arc, points[:, 1])]) for a in (stretch.start, stretch.stop)]
    return np.vstack([ends[0], points[inner], ends[1]])


def plot_route_verdicts(analysis, drives=None, ax=None, *, title: str | None = None, size=None):
    """The map with every route stretch drawn by its verdict, the unjudged ones by reason, and the drives' episodes.

    Parameters
    ----------
    analysis : MapAnalysis
        With its routes' verdicts (`MapAnalysis.paths`).
    drives : DriveValidation, optional
        Validation by driving: its episodes (magenta dots), recall and precision (in the title).
    ax : matplotlib Axes, optional
    title : str, optional
        Default: map name, V, the decided fraction, unstable length, and the validation's figures.
    size : (float, float), optional
        Figure size, inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D

    occupancy = analysis.occupancy
    pv = analysis.paths
    fig, ax, (x0, x1, y0, y1), _ = map_frame(occupancy, ax, size, (0.6, 3.0 if drives is None else 3.6))  # the validation's title lines
    kinds = []
    for kind, style in ROUTE_STYLES.items():
        lines = [_stretch_lines(pv.paths, s) for s in pv.stretches if _kind(s) == kind]
        if not lines:
            continue
        kinds.append(kind)
        ax.add_collection(LineCollection(lines, colors=style["color"], linewidths=style["lw"], linestyles=[style.get("ls", "-")],
                                         zorder=3 + list(ROUTE_STYLES).index(kind) / 10, capstyle="butt"))
    handles = [Line2D([], [], color=ROUTE_STYLES[k]["color"], lw=ROUTE_STYLES[k]["lw"], ls=ROUTE_STYLES[k].get("ls", "-"),
                      label=ROUTE_STYLES[k]["label"]) for k in kinds]
    validation = ""
    if drives is not None:
        dp = getattr(drives, "drive_paths", None)
        if dp is not None:  # the paths the drives between points took, and their unstable stretches (what they are scored on)
            ax.add_collection(LineCollection([p.points for p in dp.paths], colors="0.55", linewidths=0.7, linestyles=[(0, (2.0, 2.0))], zorder=2.5))
            handles.append(Line2D([], [], color="0.55", lw=0.7, ls=(0, (2.0, 2.0)), label="drives: the paths taken"))
            for s in dp.stretches:
                kind = _kind(s)
                if s.verdict == "unstable":
                    style = ROUTE_STYLES[kind]
                    ax.add_collection(LineCollection([_stretch_lines(dp.paths, s)], colors=style["color"], linewidths=1.6, zorder=3.5,
                                                     capstyle="butt"))
                    if kind not in kinds:
                        kinds.append(kind)
                        handles.append(Line2D([], [], color=style["color"], lw=style["lw"], label=style["label"]))
        if drives.episode_points.size:
            ax.scatter(drives.episode_points[:, 0], drives.episode_points[:, 1], s=3, color="#c51b7d", alpha=0.5, zorder=6, lw=0)
            handles.append(Line2D([], [], marker="o", ls="", color="#c51b7d", markersize=5, label="simulated oscillation episodes"))
        missed = [d for d in drives.disagreements if d.kind == "missed"]
        alarms = [d for d in drives.disagreements if d.kind == "false alarm"]
        for group, marker, colour, label in ((missed, "v", "#542788", "missed (episode, predicted stable)"),
                                             (alarms, "^", "#e66101", "false alarm (predicted unstable, no episode)")):
            if group:
                ax.scatter([(d.x0 + d.x1) / 2 for d in group], [(d.y0 + d.y1) / 2 for d in group], marker=marker, s=60, color=colour,
                           edgecolors="white", linewidths=0.8, zorder=7)
                handles.append(Line2D([], [], marker=marker, ls="", color=colour, markeredgecolor="white", markersize=8, label=label))

        collisions = getattr(drives, "collisions", None)
        for foreseen, colour, label in ((True, "#000000", "drive collided: a collision course was predicted there"),
                                        (False, "#d01c8b", "drive collided: no collision course predicted there")):
            group = [c for c in (collisions.collisions if collisions is not None else ()) if c.foreseen == foreseen]
            if group:
                ax.scatter([c.x for c in group], [c.y for c in group], marker="X", s=55, color=colour, edgecolors="white",
                           linewidths=0.7, zorder=7)
                handles.append(Line2D([], [], marker="X", ls="", color=colour, markeredgecolor="white", markersize=8, label=label))

        def pct(v):
            return "n/a" if v is None else f"{100 * v:.0f}%"

        L = drives.lengths
        kinds = "; ".join(f"{kind} drives {pct(v['recall'])} / {pct(v['precision'])} / {pct(v['specificity'])}"
                          for kind, v in drives.by_kind.items())
        def span(interval):
            return f" ({100 * interval[0]:.0f}–{100 * interval[1]:.0f}%)" if interval else ""

        validation = (f"\n{drives.counts['drives']} drives, {drives.counts['episodes']} episodes: recall {pct(drives.recall)}"
                      f"{span(drives.recall_interval)}, precision {pct(drives.precision)}{span(drives.precision_interval)}\n"
                      f"specificity {pct(drives.specificity)}{span(drives.specificity_interval)} along "
                      f"the paths driven (95% over the drives)\n{kinds}\n{L['drive_paths_driven']:.0f} m measured, "
                      f"{L['drive_paths_unmeasured']:.0f} m not (a drive's last 3 periods)")
    handles.append(Line2D([], [], marker="s", ls="", color=str(OCCUPIED_GREY), markersize=8, label="occupied"))
    if occupancy.unknown.any():
        handles.append(Line2D([], [], marker="s", ls="", color=str(UNKNOWN_GREY), markeredgecolor="0.6", markersize=8, label="unknown"))
    fig.legend(handles=handles, loc="outside lower center", ncol=2, fontsize=7.5, frameon=False)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    if title is None:
        s = pv.summary()
        title = (f"{occupancy.name}: will the robot oscillate at V = {analysis.robot.V:g} m/s?\n{analysis.model} model, "
                 f"unknown cells {analysis.unknown}\n{100 * (s['decided_fraction'] or 0):.0f}% of {s['route_length_m']:.0f} m of route "
                 f"decided; unstable {s['unstable_length_m']:.1f} m" + validation)
    ax.set_title(title, fontsize=9.5)
    return fig


TRACKING_STYLES = {
    "stable": dict(color="#1a9641", lw=2.6, label="stable at the file's lookahead"),
    "longer lookahead": dict(color="#fdae61", lw=3.4, label="unstable; a longer lookahead calms it (ZoneParameterFilter zone)"),
    "slower": dict(color="#d7191c", lw=3.6, label="unstable; only a lower speed calms it (speed mask zone)"),
    "undecided": dict(color="0.45", lw=1.4, label="undecided", ls=(0, (1.5, 2.0))),
    "no room": dict(color="0.3", lw=1.4, label="no room (the costmap's footprint does not fit)", ls=(0, (4.0, 2.0))),
}
"""Style of a Nav2 controller's stretch (`maps.deciding.tracking.TrackingStretch`) by its verdict and its remedy."""


def _tracking_kind(stretch) -> str:
    if stretch.verdict == "unstable":
        return "longer lookahead" if stretch.zone_lookahead is not None else "slower"
    return stretch.verdict if stretch.verdict in TRACKING_STYLES else "undecided"


def plot_tracking_verdicts(analysis, ax=None, *, size=None):
    """The map with every route stretch of a Nav2 controller (``map --controller rpp``) drawn by its verdict and the
    remedy its masks apply: a longer lookahead (the ZoneParameterFilter's zone), or a lower speed (the speed mask's).

    Parameters
    ----------
    analysis : MapTracking
        `maps.deciding.tracking.analyze_map_tracking`'s result.
    ax : matplotlib Axes, optional
    size : (float, float), optional
        Figure size, inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D

    occupancy, tv = analysis.occupancy, analysis.paths
    fig, ax, (x0, x1, y0, y1), _ = map_frame(occupancy, ax, size, (0.6, 2.2))
    handles = []
    for kind, style in TRACKING_STYLES.items():
        lines = [_stretch_lines(tv.paths, s) for s in tv.stretches if _tracking_kind(s) == kind]
        if lines:
            ax.add_collection(LineCollection(lines, colors=style["color"], linewidths=style["lw"], linestyles=[style.get("ls", "-")],
                                             zorder=3, capstyle="butt"))
            handles.append(Line2D([], [], color=style["color"], lw=style["lw"], ls=style.get("ls", "-"), label=style["label"]))
    handles.append(Line2D([], [], marker="s", ls="", color=str(OCCUPIED_GREY), markersize=8, label="occupied"))
    fig.legend(handles=handles, loc="outside lower center", ncol=2, fontsize=7.5, frameon=False)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    unstable = sum(s.length for s in tv.stretches if s.verdict == "unstable")
    zoned = sum(s.length for s in tv.stretches if _tracking_kind(s) == "longer lookahead")
    ax.set_title(f"{occupancy.name}: {tv.controller} along every route at V = {analysis.robot.V:g} m/s ({analysis.model} model)\n"
                 f"unstable {unstable:.1f} m of {sum(s.length for s in tv.stretches):.0f} m; a longer lookahead calms {zoned:.1f} m of it",
                 fontsize=9.5)
    return fig
