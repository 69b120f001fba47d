"""The files of ``pfm-stability map --out-dir``: segments.csv and a Nav2 Speed Filter mask (their contents; the CLI writes them atomically with `files.atomic_directory`).

The speed mask (docs/maps.md, "The speed mask") has the input map's size, resolution
and origin. Each cell holds a speed limit as a percentage of the robot's V, for the
Nav2 speed filter with ``type: 1`` (percentage), ``base: 0``, ``multiplier: 1``:

* cells within W/2 of every unstable route stretch (`maps.deciding.paths`; with the power law, of every unstable segment whose
  V* is below V): 100·V*/V rounded down (never above what is stable), at least 1 (the filter reads 0 as
  "no limit"); with a braking deceleration a_max (``--dilate-upstream``) each route
  stretch's zone reaches (V² − V*²)/(2·a_max) further along its route at both ends
  (`upstream_distance`: Nav2's filter slows the robot only once it is inside a zone);
* with a wobble tolerance (``map --wobble TOL``, `maps.deciding.wobble_zones`) a segment's or route stretch's zone holds
  100·V_limit/V instead: V_tolerance, the fastest speed whose wobble stays under TOL, where the describing function
  is trusted, else V* (`ZoneWobble.V_limit`); a zone only where the verdict is unstable, none where V_limit >= V; a stretch's upstream dilation brakes to
  V_limit;
* every other cell — free, occupied or unknown — 100: the robot may drive at V.
  Occupied cells are never driven through, and 100 % is the filter's "no
  reduction"; no cell is written as unknown (−1), which the filter ignores
  without resetting a previous limit.

The PGM is read in ``mode: scale`` with ``negate: 0``, ``free_thresh: 0``,
``occupied_thresh: 1``: Nav2 turns a pixel value v into
rint(100·(255 − v)/255). Writing v = 255 − round(2.55·q) for a percentage q gives
back q exactly (the rounding error 0.5/2.55 ≈ 0.2 % stays below the 0.5 of rint):
`percent_to_pixel` and `pixel_to_percent`.
"""

from __future__ import annotations

import math

import numpy as np

from ..reading.routes import polyline_arcs

__all__ = [
    "has_zone",
    "MASK_FILES",
    "SEGMENT_FILES",
    "ROUTE_COLUMNS",
    "ROUTE_FILES",
    "routes_csv",
    "percent_to_pixel",
    "route_piece",
    "pixel_to_percent",
    "segments_csv",
    "speed_limits",
    "speed_mask_yaml",
    "speed_mask_pgm",
    "stamp_stretch",
    "tracking_csv",
    "TRACKING_COLUMNS",
    "upstream_distance",
]

ROUTE_FILES = ("routes.png", "routes.csv")
"""Written with the routes' verdicts (`MapAnalysis.paths`, the grid law: the map's result set): their picture and
their stretches."""
SEGMENT_FILES = ("stability.png", "segments.csv")
"""Written instead with the power law (no routes' verdicts): the corridor segments' picture and table."""
MASK_FILES = ("speed_mask.pgm", "speed_mask.yaml")
"""The Nav2 speed filter mask, always."""
ROUTE_COLUMNS = ("route", "start", "stop", "x0", "y0", "x1", "y1", "length", "verdict", "cause", "growth_rate", "efolds", "N", "margin",
                 "V_critical", "direction", "oscillates", "amplitude", "linearized_at_route")
"""What ``--out-dir`` receives."""
TRACKING_COLUMNS = ("route", "start", "stop", "x0", "y0", "x1", "y1", "length", "verdict", "cause", "margin", "V_critical",
                    "lookahead_critical", "V", "L", "half_width", "pose_cost", "curvature", "zone_lookahead")
"""``routes.csv`` of ``map --controller rpp`` (`maps.deciding.tracking.TrackingStretch`)."""
CSV_COLUMNS = ("x0", "y0", "x1", "y1", "length", "N", "c", "V_critical", "margin", "stable", "verdict", "offset", "samples", "analysed",
               "N_max", "V_critical_local", "wavelength")
MIN_PERCENT = 1
"""Lowest limit written (the speed filter reads a mask value of 0 as "no limit")."""


def _csv_value(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "inf" if v == math.inf else f"{v:.6g}"
    return str(v)


def routes_csv(analysis) -> str:
    """One row per stretch of a route (`maps.deciding.paths.PathStretch`): route, arc positions and ends (m), length, verdict or
    the reason without one, label, the worst window's growth rate (1/s), e-folds, N_eff (1/m), margin, V* (m/s),
    direction, whether the linear loop weaves there and its amplitude (m), the share linearized about the route.

    Parameters
    ----------
    analysis : MapAnalysis
        With `MapAnalysis.paths`.
    """
    return _stretches_csv(analysis.paths.stretches, ROUTE_COLUMNS)


def tracking_csv(analysis) -> str:
    """One row per stretch of a Nav2 controller along the routes (`maps.deciding.tracking.TrackingStretch`): route, arc positions
    and ends (m), length, verdict, cause, margin, V* (m/s), L* (m), the regulated speed (m/s) and lookahead (m), the
    half-width (m), cost and curvature (1/m) of the worst sample, the zone's lookahead (m).

    Parameters
    ----------
    analysis : MapTracking
        With `maps.deciding.tracking.TrackingVerdicts` as ``paths``.
    """
    return _stretches_csv(analysis.paths.stretches, TRACKING_COLUMNS)


def _stretches_csv(stretches, columns) -> str:
    """A header of `columns` and one row per stretch."""
    lines = [",".join(columns)]
    for stretch in stretches:
        lines.append(",".join(_csv_value(getattr(stretch, key)) for key in columns))
    return "\n".join(lines) + "\n"


def segments_csv(analysis) -> str:
    """One row per segment: end points (m, map coordinates), length, N (N_eff), c, V*, margin, stable, verdict, offset,
    samples, and the local worst (N_max, V_critical_local) with the averaging wavelength (m).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis whose segments are written.
    """
    lines = [",".join(CSV_COLUMNS)]
    for s in analysis.segments:
        lines.append(",".join(_csv_value(getattr(s, k)) for k in CSV_COLUMNS))
    return "\n".join(lines) + "\n"


def percent_to_pixel(percent) -> np.ndarray:
    """PGM value (uint8) of a percentage 0 … 100 in the mask's scale mode (module docstring).

    Parameters
    ----------
    percent : array_like
        Speed limits, % of V (0 … 100).
    """
    q = np.asarray(percent, dtype=float)
    return (255 - np.round(2.55 * q)).astype(np.uint8)


def pixel_to_percent(value) -> np.ndarray:
    """Nav2's reading of a PGM value in the mask's scale mode: rint(100·(255 − v)/255).

    Parameters
    ----------
    value : array_like of int
        PGM values (0 … 255).
    """
    return np.rint(100.0 * (255.0 - np.asarray(value, dtype=float)) / 255.0).astype(np.int64)


def speed_limits(analysis, a_max: float | None = None) -> np.ndarray:
    """Speed limit per map cell, % of V (int, shape (height, width), row 0 at y = origin): within W/2 of each segment
    and of each route stretch whose V* is below V (module docstring), each route stretch optionally dilated upstream
    by the braking distance (V² − V*²)/(2·a_max) along its route, both travel directions (`upstream_distance`).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (map, segments and their verdicts; the routes' stretches when it has them).
    a_max : float, optional
        The robot's braking deceleration, m/s² (> 0): dilate each route stretch's slow zone upstream so the robot,
        slowed by Nav2's speed filter only once it is inside the zone, has braked to its limit (V*, or V_limit with
        ``map --wobble``) where the stretch begins.
        None: no dilation.
    """
    occupancy = analysis.occupancy
    V, half = analysis.robot.V, analysis.robot.W / 2
    limits = np.full(occupancy.values.shape, 100, dtype=np.int64)
    pv = getattr(analysis, "paths", None)
    for s in (analysis.segments if pv is None else ()):  # the result set: the routes' stretches, else the segments
        limit = _limit(s, V)
        if limit is None:
            continue
        _stamp(limits, occupancy, s.x0, s.y0, s.x1, s.y1, half, _percent(limit, V))
    for s in (pv.stretches if pv is not None else ()):
        limit = _limit(s, V)
        if limit is None:
            continue
        reach = upstream_distance(V, limit, a_max) if a_max is not None else 0.0
        stamp_stretch(limits, occupancy, pv.paths[s.route].points, s, reach, half, _percent(limit, V))
    return limits


def stamp_stretch(values: np.ndarray, occupancy, points, stretch, reach: float, half: float, value: int, combine=np.minimum) -> None:
    """`_stamp` `value` within `half` m of a route stretch extended by `reach` m along its route at both ends.

    Parameters
    ----------
    values : ndarray of int, shape (height, width)
        Per map cell, changed in place.
    occupancy : OccupancyMap
        The map (its cells).
    points : ndarray, shape (n, 2)
        The stretch's route, m.
    stretch : PathStretch or TrackingStretch
        With ``start`` and ``stop`` (m along the route).
    reach : float
        m added at both ends.
    half : float
        m either side of the route.
    value : int
        What the cells receive.
    combine : callable
        Of a cell's value and `value` (`np.minimum`: the lower limit).
    """
    piece = route_piece(points, stretch.start - reach, stretch.stop + reach)
    for (x0, y0), (x1, y1) in zip(piece[:-1], piece[1:]):
        _stamp(values, occupancy, x0, y0, x1, y1, half, value, combine)


def has_zone(zone, V: float) -> bool:
    """Whether the speed mask draws a zone for a route stretch (or, with the power law, a segment) at speed V (m/s):
    wherever its verdict is unstable. A stretch's V* is below V exactly then (`maps.deciding.stretch_speed`); a V* of 0 (no
    speed down to a tenth of V calms it) is drawn at the filter's slowest, `MIN_PERCENT`. A segment's V* can lie above V
    with an unstable verdict (its mean growth changes sign more than once): no zone, nothing to slow to.

    Parameters
    ----------
    zone : MapSegment or PathStretch
        With ``verdict`` and ``V_critical`` (m/s).
    V : float
        The robot's speed, m/s.
    """
    V_star = zone.V_critical
    return zone.verdict == "unstable" and V_star is not None and V_star < V


def _limit(zone, V: float) -> float | None:
    """The speed limit of a zone, m/s (`has_zone`): its wobble's V_limit when it has one (``map --wobble``), else V*;
    None: no zone, or V_limit >= V."""
    if not has_zone(zone, V):
        return None
    limit = zone.wobble.V_limit if getattr(zone, "wobble", None) is not None else zone.V_critical
    return limit if limit < V else None


def upstream_distance(V: float, V_limit: float, a_max: float) -> float:
    """How far before a slow zone the robot must start braking, m: (V² − V_limit²)/(2·a_max) (0 if V_limit >= V).

    Nav2's speed filter lowers the speed limit only once the robot's position is inside a mask zone (without a
    look-ahead), so a zone drawn exactly over the unstable stretch is entered at full speed; dilating it upstream by
    the braking distance at `a_max` makes the robot arrive at the stretch at V_limit.

    Parameters
    ----------
    V : float
        The robot's speed, m/s.
    V_limit : float
        The zone's speed limit, m/s.
    a_max : float
        Braking deceleration, m/s² (> 0).
    """
    if not a_max > 0:
        raise ValueError(f"a_max must be > 0 m/s^2; got {a_max!r}")
    return max(V * V - V_limit * V_limit, 0.0) / (2.0 * a_max)


def route_piece(points, start: float, stop: float) -> np.ndarray:
    """The polyline of a route between arc positions `start` and `stop` (m, clipped to the route), shape (k, 2).

    Parameters
    ----------
    points : array_like, shape (n, 2)
        The route's points, m.
    start, stop : float
        Arc positions along the route, m (start <= stop).
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    edges = polyline_arcs(p)
    a, b = max(float(start), 0.0), min(float(stop), float(edges[-1]))
    if b < a:
        return np.zeros((0, 2))
    inner = (edges > a) & (edges < b)
    arcs = np.concatenate([[a], edges[inner], [b]])
    return np.column_stack([np.interp(arcs, edges, p[:, 0]), np.interp(arcs, edges, p[:, 1])])


def _percent(V_limit: float, V: float) -> int:
    return max(MIN_PERCENT, min(100, math.floor(100.0 * V_limit / V)))


def _stamp(limits: np.ndarray, occupancy, x0: float, y0: float, x1: float, y1: float, half: float, percent: int,
           combine=np.minimum) -> None:
    """Lower `limits` to `percent` in the cells whose centres lie within `half` m of the segment (x0, y0)–(x1, y1)
    (`combine` of the two: the lower limit; `np.maximum` for the zone mask's states, the longest lookahead)."""
    r = occupancy.resolution
    ox, oy = occupancy.origin[0], occupancy.origin[1]
    i0, j0 = occupancy.cell_of(min(x0, x1) - half, min(y0, y1) - half)
    i1, j1 = occupancy.cell_of(max(x0, x1) + half, max(y0, y1) + half)
    i0, j0 = max(int(i0), 0), max(int(j0), 0)
    i1, j1 = min(int(i1), occupancy.width - 1), min(int(j1), occupancy.height - 1)
    if i1 < i0 or j1 < j0:
        return
    jj, ii = np.mgrid[j0:j1 + 1, i0:i1 + 1]
    px, py = ox + (ii + 0.5) * r, oy + (jj + 0.5) * r
    near = _distance_to_segment(px, py, x0, y0, x1, y1) <= half
    block = limits[j0:j1 + 1, i0:i1 + 1]
    block[near] = combine(block[near], percent)


def _distance_to_segment(px, py, x0, y0, x1, y1):
    dx, dy = x1 - x0, y1 - y0
    length2 = dx * dx + dy * dy
    t = np.clip(((px - x0) * dx + (py - y0) * dy) / length2, 0.0, 1.0) if length2 > 0 else 0.0
    return np.hypot(px - x0 - t * dx, py - y0 - t * dy)


def speed_mask_yaml(occupancy, image: str = "speed_mask.pgm") -> str:
    """The mask's map_server YAML: the map's resolution and origin, scale mode, thresholds that make the mapping exact.

    Parameters
    ----------
    occupancy : OccupancyMap
        The map (resolution, origin).
    image : str
        The PGM file's name, relative to the YAML file.
    """
    origin = ", ".join(f"{v:.12g}" for v in occupancy.origin)
    return (f"image: {image}\nmode: scale\nresolution: {occupancy.resolution:.12g}\norigin: [{origin}]\nnegate: 0\n"
            "occupied_thresh: 1.0\nfree_thresh: 0.0\n")


def speed_mask_pgm(analysis, a_max: float | None = None) -> bytes:
    """The mask image as a binary PGM (P5, 8 bits, row 0 at the top, as map_server reads it).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (`speed_limits`).
    a_max : float, optional
        Braking deceleration, m/s², of the upstream dilation (`speed_limits`); None: none.
    """
    pixels = percent_to_pixel(speed_limits(analysis, a_max))[::-1]
    height, width = pixels.shape
    return f"P5\n{width} {height}\n255\n".encode("ascii") + np.ascontiguousarray(pixels).tobytes()
