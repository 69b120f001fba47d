"""Nav2's Regulated Pure Pursuit along a map's routes: each stretch's verdict, margin, V* and L* (docs/maps.md,
"Nav2's controllers along a map").

RPP tracks every route of the map (`routes.find_paths`, the skeleton's routes, and the user's ``--route`` files),
sampled every histogram cell as the VFF routes are (`decide.path_samples`). At each sample the analysis of
``report --controller rpp`` (`analysis.path_tracking`) is asked about the straight corridor the sample lies in:

* **the half-width** L_c is the sample's clearance on the map's own pixels (`HistogramMap.clearance` of the map at its
  resolution: the distance from the point to the nearest occupied pixel's face, bilinear between pixel centres; the
  routes come from the coarser histogram grid), the distance Nav2's inflation layer turns into the cost at the robot (`analysis.path_laws.corridor_pose_cost`), which the cost heuristic turns into a speed;
* **the curvature** the regulation reads is the carrot's (`controllers.rpp.curvature` of the route point at the
  lookahead ahead along the route, in the frame of the route's tangent: what RPP computes on the route), at the
  lookahead of the straight corridor's speed; the curvature heuristic scales V by R/R_min below R_min =
  ``regulated_linear_scaling_min_radius``. The factor R/R_min is rounded up to `CURVATURE_STEP` (the faster, less
  stable side) and the curvature reported is the rounded one.

The verdict then depends on (the cost at the robot, the rounded curvature) alone: each distinct pair is decided once
(`analysis.path_tracking.law_verdict`: the verdict by the one rule, margin ρ*/ρ − 1, V*, L*), with the one ρ* of the
model and plant (`analysis.path_tracking.ratio_critical`: it does not depend on the speed or the lookahead), so a
whole map costs a few hundred decisions of a few milliseconds. A sample where the robot does not fit (clearance at
most the costmap's inscribed radius) is not judged ("no room").

**Stretches** are runs of one verdict along a route (`TrackingStretch`); each gives the worst sample's numbers (the
smallest margin: the fastest regulated speed), the smallest V* and the largest L* of its samples, and, where it is
unstable and a lookahead L* <= ``max_lookahead_dist`` is stable, the lookahead a ZoneParameterFilter zone sets there
(`TrackingStretch.zone_lookahead`: L* rounded up to `LOOKAHEAD_STEP`). The masks are `maps.deciding.outputs`'.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ...analysis.path_laws import PurePursuit, corridor_pose_cost, path_law
from ...analysis.path_tracking import LawVerdict, PathTracking, analyze_path_tracking, check_tracking_point, law_verdict, ratio_critical, tracking_loop
from ...controllers.rpp import curvature as carrot_curvature
from ...io.serialize import json_number
from ...models import models_for
from .decide import path_samples
from ..reading.field import histogram_of
from .paths import RouteStretch, routes_json, verdict_lengths
from ..reading.routes import find_paths, find_routes, polyline_arcs

__all__ = ["CURVATURE_STEP", "LOOKAHEAD_STEP", "MAP_CONTROLLERS", "TRACKING_VERDICTS", "MapTracking", "TrackingStretch", "TrackingVerdicts",
           "analyze_map_tracking", "route_corridors"]

MAP_CONTROLLERS = ("rpp",)
"""The Nav2 controllers ``map --controller`` decides along a map's routes."""
CURVATURE_STEP = 0.02
"""Step to which the curvature heuristic's speed factor R/R_min is rounded up (the curvature reported is the rounded one)."""
LOOKAHEAD_STEP = 0.01
"""Step to which a zone's lookahead L* is rounded up, m (the ZoneParameterFilter's states: at most 100 distinct values)."""
TRACKING_VERDICTS = ("stable", "unstable", "undecided", "no room")
"""A sample's verdict: the model's (`models.verdicts.judge`), or "no room" where the clearance is at most the costmap's
inscribed radius (the robot does not fit; not judged)."""


@dataclass(frozen=True)
class CorridorSamples:
    """The routes' samples and the corridor each lies in (`route_corridors`).

    Attributes
    ----------
    x, y : ndarray
        Sample points, m.
    route, arc, ds : ndarray
        Route index, arc position along it (m), route length per sample (m).
    half_width : ndarray
        The clearance at the sample, m (the corridor's half-width on its centre line).
    curvature : ndarray
        The carrot's curvature on the route at the lookahead, 1/m (signed: > 0 turning left).
    """

    x: np.ndarray
    y: np.ndarray
    route: np.ndarray
    arc: np.ndarray
    ds: np.ndarray
    half_width: np.ndarray
    curvature: np.ndarray


def route_corridors(grid, paths, clearance: np.ndarray, lookahead: float, spacing: float) -> CorridorSamples:
    """The samples of `paths` every `spacing` m (`decide.path_samples`), their clearance and the carrot's curvature at
    `lookahead`.

    Parameters
    ----------
    grid : HistogramMap
        The grid of `clearance` (the map's own pixels: the costmap's distances).
    paths : sequence of RoutePath
        The routes.
    clearance : ndarray, shape (nx, ny)
        Distance from each cell centre to the nearest occupied cell, m (`HistogramMap.clearance`).
    lookahead : float
        The carrot's distance along the route, m.
    spacing : float
        Largest distance between samples, m (the routes' grid cell).
    """
    from scipy.ndimage import map_coordinates

    x, y, tx, ty, route, arc, ds = path_samples(paths, spacing)
    c = grid.cell_size
    at = np.vstack([(x - grid.x_min) / c - 0.5, (y - grid.y_min) / c - 0.5])
    half_width = map_coordinates(clearance, at, order=1, mode="nearest") if x.size else np.zeros(0)
    kappa = np.zeros(x.size)
    for r, path in enumerate(paths):
        mine = np.flatnonzero(route == r)
        edges = polyline_arcs(path.points)
        ahead = np.minimum(arc[mine] + lookahead, edges[-1])  # past the route's end: its last point (the plan's last pose)
        dx = np.interp(ahead, edges, path.points[:, 0]) - x[mine]
        dy = np.interp(ahead, edges, path.points[:, 1]) - y[mine]
        along, across = dx * tx[mine] + dy * ty[mine], -dx * ty[mine] + dy * tx[mine]
        kappa[mine] = [carrot_curvature(float(a), float(b)) for a, b in zip(along, across)]
    return CorridorSamples(x, y, route, arc, ds, np.asarray(half_width, dtype=float), kappa)


@dataclass(frozen=True)
class TrackingStretch(RouteStretch):
    """A run of one verdict of the controller along one route (`paths.RouteStretch`).

    Attributes
    ----------
    route : int
        Index of the route in `TrackingVerdicts.paths`.
    start, stop : float
        Arc positions along the route, m.
    x0, y0, x1, y1 : float
        The end points on the route, m.
    length : float
        m.
    verdict : str
        One of `TRACKING_VERDICTS`.
    cause : str or None
        "growth" (the linear loop) where unstable, else None.
    margin : float or None
        ρ*/ρ − 1 of the worst sample (the smallest), as ``report --controller rpp`` computes it.
    V_critical : float or None
        V*, m/s: the fastest stable cruising speed (``max_linear_vel``), the smallest of the stretch's samples.
    lookahead_critical : float or None
        L*, m: the shortest stable lookahead at the robot's speed, the largest of the stretch's samples.
    V : float or None
        The regulated speed of the worst sample, m/s.
    L : float or None
        The lookahead that steers there, m.
    half_width : float or None
        The worst sample's corridor half-width (its clearance), m.
    pose_cost : int or None
        The costmap's cost there (the inflation of `half_width`).
    curvature : float or None
        The worst sample's regulation curvature, rounded (`CURVATURE_STEP`), 1/m.
    zone_lookahead : float or None
        Unstable, and some lookahead L* <= ``max_lookahead_dist`` stable: L* rounded up to `LOOKAHEAD_STEP`, m, the
        value the ZoneParameterFilter sets here; None otherwise.
    """

    NUMBERS = ("margin", "V_critical", "lookahead_critical")

    margin: float | None = None
    V_critical: float | None = None
    lookahead_critical: float | None = None
    V: float | None = None
    L: float | None = None
    half_width: float | None = None
    pose_cost: int | None = None
    curvature: float | None = None
    zone_lookahead: float | None = None


@dataclass(frozen=True)
class TrackingVerdicts:
    """Every route's samples and stretches for a Nav2 controller (the `paths.PathVerdicts` of ``map --controller``).

    Attributes
    ----------
    controller : str
        ``rpp``.
    paths : tuple of RoutePath
    corridors : CorridorSamples
    verdict : ndarray of int
        Index into `TRACKING_VERDICTS` per sample.
    stretches : tuple of TrackingStretch
    lookahead_parameter : str
        The Nav2 parameter a zone sets (`analysis.path_laws.PurePursuit.lookahead_parameter`).
    decisions : int
        Distinct (cost, curvature) pairs decided.
    """

    controller: str
    paths: tuple
    corridors: CorridorSamples
    verdict: np.ndarray
    stretches: tuple
    lookahead_parameter: str
    decisions: int = 0

    def length_of(self, verdict: str) -> float:
        """Route length with verdict `verdict`, m.

        Parameters
        ----------
        verdict : str
            One of `TRACKING_VERDICTS`.
        """
        return float(self.corridors.ds[self.verdict == TRACKING_VERDICTS.index(verdict)].sum())

    def summary(self) -> dict:
        """``routes``, ``route_length_m``, ``decided_fraction``, lengths by verdict (m), ``stretches`` by verdict,
        ``V_critical_min``, ``lookahead_zones`` (unstable stretches a lookahead zone fixes), ``decisions``."""
        values = [s.V_critical for s in self.stretches if s.V_critical is not None]
        return {
            **verdict_lengths(len(self.paths), float(self.corridors.ds.sum()), self.length_of),
            "unjudged_length_m": {"no room": self.length_of("no room")},
            "stretches": {v: sum(s.verdict == v for s in self.stretches) for v in TRACKING_VERDICTS},
            "V_critical_min": json_number(min(values)) if values else None,
            "lookahead_zones": sum(s.zone_lookahead is not None for s in self.stretches),
            "decisions": self.decisions,
        }

    def to_dict(self) -> dict:
        """``routes`` (source, length, points), ``stretches``, ``summary``, ``lookahead_parameter``."""
        return {
            "routes": routes_json(self.paths),
            "stretches": [s.to_dict() for s in self.stretches],
            "summary": self.summary(),
            "lookahead_parameter": self.lookahead_parameter,
        }


@dataclass(frozen=True)
class MapTracking:
    """A Nav2 controller along a whole map (`analyze_map_tracking`): what ``map --controller rpp`` prints and writes.

    Attributes
    ----------
    occupancy : OccupancyMap
    grid : HistogramMap
        The histogram grid the routes were found on.
    robot, controller : Robot, Controller
        The plant and period; ``robot.V`` is the cruising speed (``max_linear_vel``), ``robot.W`` twice the costmap's
        inscribed radius (the routes where the robot fits; the zones reach W/2 from a route).
    tracker : io.nav2.Nav2Tracker
        The controller and its Nav2 parameters.
    model : str
        The loop model deciding the verdicts.
    reference : PathTracking
        ``report --controller rpp`` on a straight path in free space (every critical value, D* and T* too).
    paths : TrackingVerdicts
    timing : dict
        Seconds per stage.
    warnings : tuple of str
    unknown : str
        How unknown map cells counted.
    segments : tuple
        Empty: the routes' stretches are the result set (`maps.deciding.outputs.speed_limits` reads them).
    """

    occupancy: object
    grid: object
    robot: object
    controller: object
    tracker: object
    model: str
    reference: PathTracking
    paths: TrackingVerdicts
    timing: dict = field(default_factory=dict)
    warnings: tuple = ()
    unknown: str = "occupied"
    segments: tuple = ()

    def to_dict(self) -> dict:
        """``map``, ``inputs``, ``controller``, ``tracking`` and ``tracking_verdict`` (the free-space reference: the law and the
        model's verdict with D* and T*), ``NV_critical``, ``segments`` (null),
        ``summary``, ``warnings``, ``paths`` (the JSON of ``map --controller``, without outputs and timing)."""
        ref = self.reference.models[self.model]
        return {
            "map": self.occupancy.to_dict(),
            "inputs": {"V": self.robot.V, "W": self.robot.W, "tau": self.robot.tau, "dead_time": self.robot.dead_time,
                       "plant_gain": self.robot.plant_gain, "actuator_lag": self.robot.actuator_lag, "T": self.controller.T,
                       "hold": self.controller.hold, "compute_delay": self.controller.compute_delay, "law": None, "model": self.model,
                       "unknown": self.unknown, "cell_size": self.grid.cell_size,
                       "grid_cells": [int(self.grid.shape[0]), int(self.grid.shape[1])], "parameters": self.tracker.values(),
                       "costmap": self.tracker.costmap_values()},
            "controller": self.tracker.controller,
            "tracking": {key: value for key, value in self.reference.to_dict().items() if key != "models"},
            "tracking_verdict": ref.to_dict(),
            "NV_critical": json_number(ref.NV_critical),
            "segments": None,
            "summary": self.paths.summary(),
            "warnings": list(self.warnings),
            "paths": self.paths.to_dict(),
        }


def _law(tracker, half_width: float | None, curvature: float) -> PurePursuit:
    """RPP's law in the corridor of `half_width` (m) along a path of `curvature` (1/m) (`analysis.path_laws.path_law`)."""
    return replace(path_law(tracker.controller, tracker.values(), costmap=tracker.costmap_values(), half_width=half_width),
                   curvature=float(curvature))


def _rounded_curvature(kappa: np.ndarray, law: PurePursuit) -> np.ndarray:
    """|κ| rounded so that the curvature heuristic's speed factor R/R_min is rounded up to `CURVATURE_STEP` (0 where the
    heuristic is off or R >= R_min), 1/m."""
    v = law.values
    if not v["use_regulated_linear_velocity_scaling"]:
        return np.zeros(kappa.shape)
    R_min = v["regulated_linear_scaling_min_radius"]
    with np.errstate(divide="ignore"):
        factor = np.where(kappa != 0, 1.0 / (np.abs(kappa) * R_min), np.inf)
    stepped = np.ceil(np.round(factor / CURVATURE_STEP, 9)) * CURVATURE_STEP
    return np.where(stepped < 1.0, 1.0 / (np.maximum(stepped, CURVATURE_STEP) * R_min), 0.0)


def _decide(tracker, robot, controller, model, corridors: CorridorSamples, progress) -> tuple:
    """(verdict codes, per-sample keys, {key: (LawVerdict, TrackingPoint)}) of every sample: each distinct (cost,
    rounded curvature) decided once by `law_verdict` with the one ρ*."""
    base = _law(tracker, None, 0.0)
    costmap = tracker.costmap_values()
    room = corridors.half_width > costmap["inscribed_radius"]
    costs = np.array([corridor_pose_cost(float(h), costmap) if ok else -1 for h, ok in zip(corridors.half_width, room)], dtype=int)
    kappa = _rounded_curvature(corridors.curvature, base)
    reference_point = base.point(robot.V)
    rho_star = ratio_critical(model, tracking_loop(robot, controller, reference_point), base.shape)
    keys = list(zip(costs.tolist(), kappa.tolist()))
    decided, width_of = {}, {}
    for k, key in enumerate(keys):
        if key[0] >= 0 and key not in width_of:
            width_of[key] = float(corridors.half_width[k])
    for key, half_width in width_of.items():
        law = _law(tracker, half_width, key[1])
        point = law.point(robot.V)
        check_tracking_point(point)
        decided[key] = (law_verdict(model, law, point, tracking_loop(robot, controller, point), rho_star), point)
    if progress is not None:
        progress(f"{len(decided)} corridors decided")
    code = np.array([TRACKING_VERDICTS.index(decided[key][0].verdict) if key in decided else TRACKING_VERDICTS.index("no room")
                     for key in keys], dtype=int)
    return code, keys, decided


def _stretches(paths, corridors: CorridorSamples, code: np.ndarray, keys: list, decided: dict, max_lookahead: float) -> tuple:
    """The runs of one verdict along each route (`TrackingStretch`): the worst sample's numbers, the smallest V*, the
    largest L*, and the zone's lookahead."""
    out = []
    for r, path in enumerate(paths):
        idx = np.flatnonzero(corridors.route == r)
        if idx.size == 0:
            continue
        edges = polyline_arcs(path.points)
        for run in np.split(idx, np.flatnonzero(np.diff(code[idx]) != 0) + 1):
            first, last = run[0], run[-1]
            start = float(corridors.arc[first] - corridors.ds[first] / 2)
            stop = float(corridors.arc[last] + corridors.ds[last] / 2)
            ends = [float(np.interp(a, edges, path.points[:, k])) for a in (start, stop) for k in (0, 1)]
            base = dict(route=r, start=start, stop=stop, x0=ends[0], y0=ends[1], x1=ends[2], y1=ends[3],
                        length=float(corridors.ds[run].sum()), verdict=TRACKING_VERDICTS[code[first]])
            if keys[first] not in decided:
                out.append(TrackingStretch(**base))
                continue
            out.append(_decided_stretch(base, run, corridors, keys, decided, max_lookahead))
    return tuple(out)


def _decided_stretch(base: dict, run: np.ndarray, corridors: CorridorSamples, keys: list, decided: dict, max_lookahead: float) -> TrackingStretch:
    """A decided run's `TrackingStretch` (`_stretches`)."""
    verdicts = {keys[k]: decided[keys[k]] for k in run}
    worst_key = min(verdicts, key=lambda key: verdicts[key][0].margin)
    worst = next(k for k in run if keys[k] == worst_key)
    verdict, point = verdicts[worst_key]
    L_star = max(v.lookahead_critical for v, _ in verdicts.values())
    zone = None
    if base["verdict"] == "unstable" and L_star <= max_lookahead:
        zone = min(math.ceil(round(L_star / LOOKAHEAD_STEP, 9)) * LOOKAHEAD_STEP, max_lookahead)
        zone = zone if zone >= L_star else None
    return TrackingStretch(**base, cause="growth" if base["verdict"] == "unstable" else None, margin=float(verdict.margin),
                           V_critical=float(min(v.V_critical for v, _ in verdicts.values())), lookahead_critical=float(L_star),
                           V=float(point.V), L=float(point.L), half_width=float(corridors.half_width[worst]), pose_cost=int(worst_key[0]),
                           curvature=float(worst_key[1]), zone_lookahead=None if zone is None else round(zone, 9))


def analyze_map_tracking(occupancy, robot, controller, tracker, *, model: str = "sampled", unknown: str = "occupied",
                         cell_size: float = 0.1, routes=(), progress=None, warn=None) -> MapTracking:
    """A Nav2 controller (`tracker`) along every route of a map, decided stretch by stretch (module docstring).

    Parameters
    ----------
    occupancy : OccupancyMap
    robot : parameters.Robot
        The plant (τ, D, g, τ_a); V is the cruising speed (``max_linear_vel``). Its width W is replaced by twice the
        costmap's inscribed radius (the footprint Nav2 plans with): the routes where it fits, the zones' width.
    controller : parameters.Controller
        T, hold and compute delay.
    tracker : io.nav2.Nav2Tracker
        The controller (`MAP_CONTROLLERS`) and its Nav2 parameters.
    model : str
        Loop model name (`parameters.MODEL_NAMES`).
    unknown : {"occupied", "free"}
        How unknown map cells count.
    cell_size : float
        The histogram grid's cell, m: the routes' grid and sample spacing (the VFF map's 0.1 m by default).
    routes : sequence of RoutePath
        The user's own routes, judged after the skeleton's.
    progress : callable, optional
        ``progress(line)`` after each stage.
    warn : callable, optional
        ``warn(line)`` for each warning (`analysis.scale_warnings`).

    Raises
    ------
    ValueError
        A controller other than `MAP_CONTROLLERS`, a map with no free space or no route, an operating point outside the
        loop's range (`analysis.path_tracking.check_tracking_point`).
    """
    from ..analysis import scale_warnings

    if tracker.controller not in MAP_CONTROLLERS:
        raise ValueError(f"controller must be one of {', '.join(MAP_CONTROLLERS)} along a map's routes; got {tracker.controller!r}")
    say = progress or (lambda line: None)
    robot = robot.replace(W=2.0 * tracker.costmap_values()["inscribed_radius"])  # the costmap's footprint: where the robot fits
    warnings = scale_warnings(occupancy, robot.W)
    for line in warnings:
        (warn or (lambda text: None))(line)
    timing, clock = {}, time.perf_counter()
    (loop_model,) = models_for(controller, [model])
    reference = analyze_path_tracking(robot, controller, _law(tracker, None, 0.0), [loop_model], V_set=robot.V)
    grid = histogram_of(occupancy, cell_size, unknown)
    if not (~grid.occupied).any():
        raise ValueError(f"map {occupancy.name!r} has no free space (every cell is occupied{'' if unknown == 'free' else ' or unknown'})")
    _, skeleton, clearance = find_routes(grid, robot.W)
    paths = find_paths(grid, skeleton, clearance)
    paths = paths + [replace(r, branch=len(paths) + k) for k, r in enumerate(routes)]
    if not paths:
        raise ValueError(f"map {occupancy.name!r} has no route: no free space where a robot of width W = {robot.W:g} m fits")
    timing["routes"], clock = time.perf_counter() - clock, time.perf_counter()
    say(f"routes done ({timing['routes']:.2f} s)")
    base = _law(tracker, None, 0.0)
    pixels = histogram_of(occupancy, occupancy.resolution, unknown)  # the clearance at the map's own resolution, as the costmap sees it
    corridors = route_corridors(pixels, paths, pixels.clearance(), base.lookahead(base.speed(robot.V)), grid.cell_size)
    code, keys, decided = _decide(tracker, robot, controller, loop_model, corridors, progress)
    stretches = _stretches(paths, corridors, code, keys, decided, base.values["max_lookahead_dist"])
    timing["verdicts"] = time.perf_counter() - clock
    say(f"verdicts done ({timing['verdicts']:.2f} s)")
    verdicts = TrackingVerdicts(tracker.controller, tuple(paths), corridors, code, stretches, base.lookahead_parameter, len(decided))
    return MapTracking(occupancy, grid, robot, controller, tracker, loop_model.name, reference, verdicts, timing, tuple(warnings),
                       unknown=unknown)
