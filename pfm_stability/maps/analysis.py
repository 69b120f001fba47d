"""Stability along every corridor of a map: per-sample N and V*, per-segment verdicts, the `MapAnalysis`.

`analyze_map` runs the chain (docs/maps.md): the map onto the robot's histogram grid
(`field.histogram_of`), the routes (`routes.find_routes`), the lateral equilibrium
and N at samples every cell along each segment (`equilibria`), then the loop model.
NV* of a model depends only on (τ, T, k, c) and its structure (hold, compute delay),
so its `Boundary` is computed once per distinct heading gain c (c = 0 for the static
VFF field) and every sample is decided from it:

* N > 0: V* = NV*/N, stable when N·V lies in the stable set, margin
  `models.base.gain_margin` (NV*/NV − 1 for the usual set (0, NV*)), label
  `models.base.verdict_label`;
* N < 0 (the field pushes away from the equilibrium): unstable at any speed,
  V* = 0, margin −1 (`models.base.divergent_reason`);
* N = 0 (no restoring force): the model's own verdict at NV = 0, its heading
  loop (`is_stable(0, loop)`, asked once per analysis; docs/models.md "N = 0"):
  stable, V* = inf, margin inf, or unstable, V* = 0, margin −1, with
  `models.neutral_reason`.

A segment is decided by its mean growth rate (`verdicts`): over its judged part the
lateral deviation grows by exp(σ̄·duration), σ̄ the mean of the samples' σ(N_i·V)
(the model's rightmost-root real part, tabulated once per analysis: `verdicts.GrowthRate`);
stable when σ̄ < 0. Its N is N_eff, the uniform gain with the same growth
(σ(N_eff·V) = σ̄; negative, unstable at any speed, when the mean N is), its V* the
smallest V with σ̄(V) = 0, its margin NV*/(N_eff·V) − 1; a segment whose
lateral deviation changes by less than one e-fold over its judged part (|σ̄|·length/V < 1)
is "weak" (no verdict). Only the segment's judged part counts: its longest run of samples where the
repulsion along the travel direction is at most `verdicts.END_FRACTION` of the
attraction (near a wall ahead the robot turns instead of oscillating); a segment
with less than one wavelength λ = 2πV/ω* of it left gets no verdict ("end effect").
The per-sample worst is kept (`N_max`, `V_critical_local`) for the picture and
the CSV. A segment with no equilibrium at any sample gets no verdict: "open" when no
repulsion acts on its axis (an open area, wider than the window sees), "no
equilibrium" otherwise (a single wall, a dead end, a junction, an aisle whose middle
no wall reaches).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..laws.effective_force import GridWallLaw
from ..laws.force_law import ForceLaw, PowerLaw
from ..laws.registry import MAP_LAWS
from ..models import Loop, gain_margin, models_for, verdict_label
from ..models.verdicts import Judgement, inside, judge
from ..parameters import Controller, Robot
from ..io.serialize import json_number
from .deciding.equilibria import Samples, grid_equilibria, power_equilibria
from .reading.field import UNKNOWN_AS, HistogramMap, histogram_of
from .reading.occupancy import OccupancyMap
from .judging.driven import SampledTransition
from .deciding.paths import PathVerdicts, analyze_paths
from .reading.routes import Route, default_min_length, find_paths, find_routes
from .deciding.wobble_zones import SegmentWobble
from .deciding.verdicts import END_FRACTION, TAPER_SLOPE, GrowthRate, drift_slope, critical_speed, is_weak, judged_run, segment_gain, wavelength

__all__ = ["DIRECTIONS", "MAP_LAWS", "MAX_CORRIDOR_WIDTHS", "MAX_MAP_SIDE", "MAX_RESOLUTION", "NO_VERDICT", "TAKEN_SOURCES", "MapAnalysis", "MapSegment",
           "add_routes", "analyze_map", "corridor_warnings", "judge_routes", "sample_verdict", "scale_warnings"]

DIRECTIONS = ("forward", "reverse")
"""Travel directions of a segment: from (x0, y0) to (x1, y1), and back."""
MAX_MAP_SIDE = 1000.0
"""Longest side of a plausible map, m: the largest buildings are under 1 km long; a longer map is most often a
resolution typo (5.0 for 0.05 makes a map 100 times too large, and its analysis minutes long)."""
MAX_RESOLUTION = 0.5
"""Coarsest plausible resolution, in robot widths W (m/pixel): a pixel wider than W/2 cannot draw the clearance a
robot needs (a corridor the robot fits in is then at most a few pixels wide); Nav2's maps use 0.02–0.1 m."""
MAX_CORRIDOR_WIDTHS = 10.0
"""Narrowest corridor of a plausible map, in robot widths: when even the narrowest corridor (twice the clearance
along the route, the median over each segment) is wider than 10 W, the map's scale is most likely wrong (a
resolution 10 times too large makes 1 m corridors 10 m wide); building corridors are 2–5 robot widths."""
NO_VERDICT = ("open", "no equilibrium", "weak", "end effect", "tapering")
"""Verdicts of a segment without a verdict: no lateral equilibrium, a field too weak to show (`verdicts.is_weak`), or
too little of it where the corridor model holds (`verdicts.judged_run`: a wall ahead or behind), or an equilibrium
path turned from the segment (`verdicts.drift_slope` > `verdicts.TAPER_SLOPE`: a tapering space)."""


@dataclass(frozen=True)
class MapSegment:
    """One straight corridor segment and its verdict.

    Attributes
    ----------
    x0, y0, x1, y1 : float
        End points in map coordinates, m (travel from 0 to 1; the verdict holds both ways).
    length : float
        m.
    N : float or None
        Effective gain N_eff at the robot's V, 1/m: the uniform gain with the segment's mean growth rate
        (`verdicts.segment_gain`; None without an equilibrium).
    c : float
        Heading gain (0 for the VFF field).
    V_critical : float or None
        V* of the segment, m/s: the smallest V whose mean growth rate σ̄(V) is 0 (0: unstable at any speed;
        inf: stable at any speed; None: no verdict).
    margin : float or None
        Gain margin NV*/(N_eff·V) − 1 (−1 for N_eff < 0).
    stable : bool or None
        N_eff·V in the model's stable set (None: no verdict).
    verdict : str
        "stable", "unstable", "undecided", "weak", "end effect", "tapering", "open" or "no equilibrium".
    offset : float or None
        Mean lateral equilibrium offset s0, m, along the left normal of (x1 − x0, y1 − y0).
    samples : int
        Samples along the segment.
    analysed : int
        Samples with an equilibrium.
    roots : int
        Most roots of F_n found in one sample's band.
    samples_offset : tuple of float
        s0 of each sample with an equilibrium, m.
    reason : str or None
        Why it is unstable at any speed (N < 0), if so, or why N = 0 has its verdict (`models.neutral_reason`).
    N_max : float or None
        Largest N of a single sample, 1/m (the local worst; not the verdict's).
    V_critical_local : float or None
        NV*/N of the worst single sample, m/s (0 if a sample has N < 0): the old, local bound.
    wavelength : float or None
        λ = 2πV/ω* at the robot's V, m (inf: the model has no oscillation frequency).
    stretch : int
        Samples averaged into σ̄ (the judged part's samples with an equilibrium).
    direction : str or None
        The travel direction deciding the verdict ("forward": from (x0, y0) to (x1, y1); "reverse"):
        the one with the smaller V* (the forward force, and so N, differ between the two where a
        wall lies ahead). None without a verdict.
    judged_from, judged_to : float or None
        The judged part, m from (x0, y0) along the segment (`verdicts.judged_run`: where
        |F_r·t| <= `verdicts.END_FRACTION`); None without an equilibrium.
    growth_rate : float or None
        σ̄, the mean growth rate over the judged part at the robot's V, 1/s (`verdicts.mean_growth`).
    wobble : SegmentWobble or None
        The speed limit by wobble tolerance (`maps.deciding.wobble_zones.with_wobble`, ``map --wobble``); None: not asked.
    """

    x0: float
    y0: float
    x1: float
    y1: float
    length: float
    N: float | None
    c: float
    V_critical: float | None
    margin: float | None
    stable: bool | None
    verdict: str
    offset: float | None
    samples: int
    analysed: int
    roots: int
    samples_offset: tuple = ()
    reason: str | None = None
    N_max: float | None = None
    V_critical_local: float | None = None
    wavelength: float | None = None
    stretch: int = 0
    direction: str | None = None
    judged_from: float | None = None
    judged_to: float | None = None
    growth_rate: float | None = None
    wobble: SegmentWobble | None = None

    def to_dict(self) -> dict:
        """JSON-ready (infinities as "inf", undefined as null; ``wobble`` only when asked)."""
        out = {
            "x0": self.x0, "y0": self.y0, "x1": self.x1, "y1": self.y1, "length": self.length,
            "N": self.N, "c": self.c, "V_critical": json_number(self.V_critical) if self.V_critical is not None else None,
            "margin": json_number(self.margin) if self.margin is not None else None, "stable": self.stable,
            "verdict": self.verdict, "offset": self.offset, "samples": self.samples, "analysed": self.analysed,
            "roots": self.roots, "reason": self.reason, "N_max": self.N_max,
            "V_critical_local": json_number(self.V_critical_local) if self.V_critical_local is not None else None,
            "wavelength": json_number(self.wavelength) if self.wavelength is not None else None, "stretch": self.stretch,
            "direction": self.direction, "judged_from": self.judged_from, "judged_to": self.judged_to,
            "growth_rate": self.growth_rate,
        }
        if self.wobble is not None:
            out["wobble"] = self.wobble.to_dict()
        return out


@dataclass(frozen=True)
class MapAnalysis:
    """The whole map's answer.

    Attributes
    ----------
    occupancy : OccupancyMap
    grid : HistogramMap
        The robot's histogram grid of the map.
    law : ForceLaw
    robot, controller : Robot, Controller
    model : str
        The loop model deciding the verdicts.
    NV_critical : float
        NV* of that model for c = 0, 1/s.
    segments : tuple of MapSegment
    samples : Samples
    skeleton, clearance : ndarray, shape (nx, ny)
        The medial axis where the robot fits, and each cell's clearance (m).
    unknown : str
        How unknown cells counted ("occupied" or "free").
    timing : dict
        Seconds per stage (read, grid, routes, equilibria, verdicts).
    warnings : tuple of str
        One line each: an implausible scale of the map (`scale_warnings`, `corridor_warnings`).
    paths : PathVerdicts or None
        The verdict along every route, linearized about the robot's path (`paths.analyze_paths`; grid law only).
    """

    occupancy: OccupancyMap
    grid: HistogramMap
    law: ForceLaw
    robot: Robot
    controller: Controller
    model: str
    NV_critical: float
    segments: tuple
    samples: Samples
    skeleton: np.ndarray
    clearance: np.ndarray
    unknown: str
    timing: dict = field(default_factory=dict)
    warnings: tuple = ()
    paths: PathVerdicts | None = None

    @property
    def unstable_length(self) -> float:
        """Total length of the unstable segments, m."""
        return float(sum(s.length for s in self.segments if s.stable is False))

    @property
    def V_critical_min(self) -> float | None:
        """Smallest V* of any segment, m/s (None when no segment has a verdict)."""
        values = [s.V_critical for s in self.segments if s.V_critical is not None]
        return min(values) if values else None

    def plot(self, ax=None, **kwargs):
        """`plots.map.plot_map_stability` of this analysis; returns the figure.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on; None: a new figure.
        **kwargs
            Passed on to `plots.map.plot_map_stability`.
        """
        from ..plots.map import plot_map_stability

        return plot_map_stability(self, ax=ax, **kwargs)

    def summary(self) -> dict:
        """``unstable_length_m``, ``V_critical_min``, segment counts by verdict, total length."""
        counts = {v: sum(s.verdict == v for s in self.segments) for v in ("stable", "unstable", "undecided", *NO_VERDICT)}
        return {
            "segments": len(self.segments),
            "route_length_m": float(sum(s.length for s in self.segments)),
            "unstable_length_m": self.unstable_length,
            "V_critical_min": json_number(self.V_critical_min) if self.V_critical_min is not None else None,
            "verdicts": counts,
        }

    def to_dict(self) -> dict:
        """``map``, ``inputs``, ``NV_critical``, ``segments``, ``summary``, ``warnings``, ``paths`` (the JSON of
        ``pfm-stability map``, without validation): one result set — the routes' stretches (``paths``, its summary
        the ``summary``) where the routes are judged, else the corridor segments (``segments``, their summary);
        ``segments`` is null when they were not decided (`analyze_map`'s ``corridors``)."""
        g = self.grid
        return {
            "map": self.occupancy.to_dict(),
            "inputs": {
                "V": self.robot.V, "tau": self.robot.tau, "k": self.robot.k, "W": self.robot.W,
                "T": self.controller.T, "f": self.controller.f, "n": self.controller.n,
                "hold": self.controller.hold, "compute_delay": self.controller.compute_delay,
                "law": getattr(self.law, "key", "power"), "law_parameters": _law_parameters(self.law),
                "model": self.model, "unknown": self.unknown, "cell_size": g.cell_size,
                "grid_cells": [int(g.shape[0]), int(g.shape[1])],
            },
            "NV_critical": json_number(self.NV_critical),
            "segments": [s.to_dict() for s in self.segments] if self.samples is not None else None,
            "summary": self.paths.summary() if self.paths is not None else self.summary(),
            "warnings": list(self.warnings),
            "paths": self.paths.to_dict() if self.paths is not None else None,
        }


def _law_parameters(law) -> dict:
    return {k: v for k, v in law.parameters().items()} if hasattr(law, "parameters") else {}


def check_map_law(law) -> None:
    """ValueError unless `law` is one a map analysis supports (`MAP_LAWS`): the grid's window sum or KB's power law."""
    if not isinstance(law, (GridWallLaw, PowerLaw)):
        name = getattr(law, "key", type(law).__name__)
        raise ValueError(f"law must be one of {', '.join(MAP_LAWS)} for a map (a distance-based goal-aware field needs the goal, "
                         f"which a map does not give); got {name!r}")


def scale_warnings(occupancy: OccupancyMap, W: float) -> tuple:
    """One line if the map's resolution looks wrong for a robot of width W (m): coarser than `MAX_RESOLUTION`·W per
    pixel, or a map side longer than `MAX_MAP_SIDE`; () otherwise (docs/maps.md, "Map files").

    Parameters
    ----------
    occupancy : OccupancyMap
        The map (resolution, size).
    W : float
        Robot width, m.
    """
    r = occupancy.resolution
    x0, x1, y0, y1 = occupancy.extent
    reasons = [f"a pixel is wider than {MAX_RESOLUTION:g} W = {MAX_RESOLUTION * W:g} m"] if r > MAX_RESOLUTION * W else []
    if max(x1 - x0, y1 - y0) > MAX_MAP_SIDE:
        reasons.append(f"the map is {x1 - x0:.0f} x {y1 - y0:.0f} m, larger than any building ({MAX_MAP_SIDE:g} m)")
    if not reasons:
        return ()
    return (f"map {occupancy.name!r}: resolution {r:g} m/pixel is implausible ({'; '.join(reasons)}): check the map's YAML file "
            f"(a typo such as 5.0 for 0.05?)",)


def corridor_warnings(occupancy: OccupancyMap, grid: HistogramMap, routes, clearance: np.ndarray, W: float) -> tuple:
    """One line if even the narrowest corridor is wider than `MAX_CORRIDOR_WIDTHS` robot widths W (m): a corridor's
    width is twice the clearance (m, per histogram cell) along its segment, the median over the segment's cells.

    Parameters
    ----------
    occupancy : OccupancyMap
        The map (its name for the message).
    grid : HistogramMap
        Its histogram grid.
    routes : list of Route
        The segments found (`routes.find_routes`).
    clearance : ndarray, shape (nx, ny)
        Distance to the nearest occupied cell, m, per histogram cell.
    W : float
        Robot width, m.
    """
    widths = []
    for r in routes:
        count = max(2, int(math.ceil(r.length / grid.cell_size)))
        i, j = grid.cell_index(np.linspace(r.x0, r.x1, count), np.linspace(r.y0, r.y1, count))
        inside = (i >= 0) & (i < grid.shape[0]) & (j >= 0) & (j < grid.shape[1])
        if inside.any():
            widths.append(2.0 * float(np.median(clearance[i[inside], j[inside]])))
    if not widths or min(widths) <= MAX_CORRIDOR_WIDTHS * W:
        return ()
    return (f"map {occupancy.name!r}: its narrowest corridor is {min(widths):.3g} m wide, {min(widths) / W:.0f} robot widths "
            f"(W = {W:g} m; more than {MAX_CORRIDOR_WIDTHS:g} is implausible): check the resolution ({occupancy.resolution:g} m/pixel) "
            f"in the map's YAML file",)


def analyze_map(occupancy: OccupancyMap, robot: Robot, controller: Controller, law: ForceLaw, *, model: str = "sampled",
                unknown: str = "occupied", cell_size: float | None = None, min_length: float | None = None,
                progress=None, end_fraction: float = END_FRACTION, taper_slope: float = TAPER_SLOPE, warn=None,
                routes=(), along_routes: bool = True, corridors: bool = True) -> MapAnalysis:
    """Every corridor segment of a map, decided (module docstring).

    Parameters
    ----------
    occupancy : OccupancyMap
    robot, controller : Robot, Controller
        The robot's V is the speed judged; W its width.
    law : GridWallLaw or PowerLaw
        The field (`fields.make_law("grid" | "power", ...)`); the grid law's cell size
        and window are the histogram grid's.
    model : str
        Loop model name (`parameters.MODEL_NAMES`); ``sampled`` takes the controller's structure.
    unknown : {"occupied", "free"}
        How unknown map cells count.
    cell_size : float, optional
        Histogram cell size for the power law's routes, m (default 0.1; the grid law uses its own).
    min_length : float, optional
        Shortest segment, m (default `routes.default_min_length`).
    progress : callable, optional
        ``progress(line)`` after each stage.
    end_fraction : float
        Largest |F_r·t| (units of F_ct) of a judged sample, in (0, 1] (`verdicts.END_FRACTION`).
    taper_slope : float
        Largest |ds0/ds| of the judged part's equilibrium offset with a verdict, > 0 (`verdicts.TAPER_SLOPE`;
        inf: no tapering rule).
    warn : callable, optional
        ``warn(line)`` for each warning as soon as it is known (`scale_warnings` before any work,
        `corridor_warnings` once the routes are found); the warnings are also in `MapAnalysis.warnings`.
    routes : sequence of RoutePath
        The user's own routes (`user_routes.read_routes`), judged after the skeleton's (`MapAnalysis.paths`; grid law).
    along_routes : bool
        Judge every route (`MapAnalysis.paths`, the grid law's); False: the straight segments alone (``paths`` None,
        the user's routes refused), for work that reads only the segments (their validation by simulation).
    corridors : bool
        Decide the straight corridor segments too (`MapSegment`; the corridor model `report` checks against). False
        with the grid law: only the routes' stretches, the map's one result set (``pfm-stability map``), and no
        segments (``segments`` empty, ``samples`` None). The power law has no routes' verdicts: always True there.

    Raises
    ------
    ValueError
        A law other than grid or power, an unknown model, or a map with no free
        space or no route long enough.
    """
    check_map_law(law)
    own_routes = tuple(routes)  # `routes` is the segments' below
    if not (isinstance(end_fraction, (int, float)) and 0 < end_fraction <= 1):
        raise ValueError(f"end_fraction must be a number in (0, 1] (of the attraction); got {end_fraction!r}")
    if not (isinstance(taper_slope, (int, float)) and not isinstance(taper_slope, bool) and taper_slope > 0):
        raise ValueError(f"taper_slope must be a number > 0 (|ds0/ds|; inf: no tapering rule); got {taper_slope!r}")
    if unknown not in UNKNOWN_AS:
        raise ValueError(f"unknown must be one of {', '.join(UNKNOWN_AS)}; got {unknown!r}")
    say = progress or (lambda line: None)
    warnings = []

    def caution(lines):
        warnings.extend(lines)
        for line in lines:
            (warn or (lambda text: None))(line)

    caution(scale_warnings(occupancy, robot.W))
    timing, clock = {}, time.perf_counter()

    def stage(name):
        nonlocal clock
        now = time.perf_counter()
        timing[name] = now - clock
        clock = now
        say(f"{name} done ({timing[name]:.2f} s)")

    (loop_model,) = models_for(controller, [model])
    is_grid = isinstance(law, GridWallLaw)
    grid = histogram_of(occupancy, law.cell_size if is_grid else (cell_size or 0.1), unknown)
    if not (~grid.occupied).any():
        raise ValueError(f"map {occupancy.name!r} has no free space (every cell is occupied{'' if unknown == 'free' else ' or unknown'})")
    stage("grid")
    routes, skeleton, clearance = find_routes(grid, robot.W, min_length)
    paths = find_paths(grid, skeleton, clearance) if is_grid and along_routes else []
    if own_routes and not (is_grid and along_routes):
        raise ValueError("routes need --law grid: a route is judged with the histogram grid's field")
    paths = paths + [replace(r, branch=len(paths) + k) for k, r in enumerate(own_routes)]
    shortest = min_length if min_length is not None else default_min_length(robot.W)
    if not routes and not any(p.length >= shortest for p in paths):
        raise ValueError(f"map {occupancy.name!r} has no route long enough: no corridor of at least "
                         f"{min_length if min_length is not None else default_min_length(robot.W):g} m where a robot of width W = {robot.W:g} m fits")
    if not warnings and routes:  # one cause, one line: a resolution already flagged makes the corridors wide too
        caution(corridor_warnings(occupancy, grid, routes, clearance, robot.W))
    stage("routes")
    corridors = corridors or not (is_grid and along_routes)
    if not corridors:
        samples, routes = None, []
    elif is_grid:
        samples = grid_equilibria(grid, law, routes, clearance, robot.W)
    else:
        blocked = occupancy.occupied | (occupancy.unknown if unknown == "occupied" else False)
        samples = power_equilibria(grid, law, routes, clearance, robot.W, blocked, occupancy.resolution, occupancy.origin)
    stage("equilibria")
    c = 0.0  # the static VFF field and KB's law have no goal part
    loop = Loop.of(robot, controller, c=c)
    boundary = loop_model.boundary(loop)
    growth = GrowthRate(lambda NV: loop_model.rightmost_root(NV, loop), boundary.NV_critical)
    heading_stable = loop_model.is_stable(0.0, loop)  # decides the samples with N = 0
    segments = tuple(_segment(r, samples, k, boundary, robot, c, growth, heading_stable, end_fraction, taper_slope)
                     for k, r in enumerate(routes))
    stage("verdicts")
    transition = SampledTransition.of(loop_model, loop, robot.max_steering_rate) if loop_model.name == "sampled" else None
    along = analyze_paths(grid, law, paths, clearance, robot.W, robot.V, boundary, growth, heading_stable, transition,
                          end_fraction) if paths else None
    if is_grid and along_routes:
        stage("paths")
    return MapAnalysis(occupancy, grid, law, robot, controller, loop_model.name, boundary.NV_critical, segments, samples,
                       skeleton, clearance, unknown, timing, tuple(warnings), along)


def add_routes(analysis: MapAnalysis, routes) -> MapAnalysis:
    """The analysis with `routes` (RoutePath) judged too, after its own (`paths.analyze_paths`; grid law only).

    Parameters
    ----------
    analysis : MapAnalysis
        A grid-law analysis.
    routes : sequence of RoutePath
        More routes, in map coordinates (m): the user's, or the paths the simulated robot took between goals.
    """
    if analysis.paths is None:
        raise ValueError("routes need --law grid: a route is judged with the histogram grid's field")
    paths = list(analysis.paths.paths)
    paths += [replace(r, branch=len(paths) + k) for k, r in enumerate(routes)]
    return replace(analysis, paths=judge_routes(analysis, paths, taken=[r.source in TAKEN_SOURCES for r in paths]))


TAKEN_SOURCES = ("goals", "drive")
"""Route sources that are paths the simulated robot took (`validation.map_drives`): judged as taken."""


def judge_routes(analysis: MapAnalysis, routes, taken=False, speeds: bool = True) -> PathVerdicts:
    """The verdicts along `routes` alone (`paths.analyze_paths` with the analysis' grid, law, robot and loop model;
    grid law only): e.g. the paths the simulated robot took (`validation.map_drives`).

    Parameters
    ----------
    analysis : MapAnalysis
        A grid-law analysis.
    routes : sequence of RoutePath
        The routes, in map coordinates (m).
    taken : bool or sequence of bool
        The routes (all, or each) are paths the simulated robot took (`paths.analyze_paths`' ``taken``).
    speeds : bool
        Each stretch's V* too (`paths.analyze_paths`' ``speeds``).
    """
    if analysis.paths is None:
        raise ValueError("routes need --law grid: a route is judged with the histogram grid's field")
    (loop_model,) = models_for(analysis.controller, [analysis.model])
    loop = Loop.of(analysis.robot, analysis.controller, c=0.0)  # the plant's gain and dead time too
    boundary = loop_model.boundary(loop)
    growth = GrowthRate(lambda NV: loop_model.rightmost_root(NV, loop), boundary.NV_critical)
    transition = SampledTransition.of(loop_model, loop, analysis.robot.max_steering_rate) if loop_model.name == "sampled" else None
    return analyze_paths(analysis.grid, analysis.law, list(routes), analysis.clearance, analysis.robot.W, analysis.robot.V, boundary, growth,
                         loop_model.is_stable(0.0, loop), transition, taken=taken, speeds=speeds)


def sample_verdict(N: float, V: float, boundary, heading_stable: bool) -> Judgement:
    """The verdict of one sample with gain N (1/m) at speed V (m/s): `models.verdicts.judge`, stable inside the
    model's stable set, or at N = 0 by `heading_stable`, the model's verdict at NV = 0 (``model.is_stable(0.0, loop)``:
    its heading loop; module docstring).

    Parameters
    ----------
    N : float
        Environment gain, 1/m.
    V : float
        Speed, m/s.
    boundary : Boundary
        The model's boundary for the loop (`LoopModel.boundary`).
    heading_stable : bool
        The model's verdict at NV = 0 (its heading loop).
    """
    return judge(N * V, N, boundary, bool(heading_stable) if N == 0 else (lambda NV: inside(boundary, NV)))


def _direction(N: np.ndarray, length: float, boundary, V: float, growth: GrowthRate, heading_stable: bool) -> dict | None:
    """The verdict of one travel direction from the N (1/m) of its judged samples, `length` m: None without an
    equilibrium (`verdicts`: the sign of the mean growth rate σ̄; N_eff = 0: `sample_verdict`'s N = 0)."""
    gain = segment_gain(N, V, boundary.omega_critical, growth, boundary.NV_critical)
    if gain.N_eff is None:
        return None
    out = dict(N=gain.N_eff, wavelength=gain.wavelength, stretch=gain.stretch, growth_rate=gain.sigma)
    if is_weak(gain.sigma, length, V):
        return dict(out, V_critical=None, margin=None, stable=None, verdict="weak", reason=None)
    if gain.N_eff <= 0:  # the mean N is negative and σ̄ > 0: unstable at any speed; or no restoring force
        j = sample_verdict(gain.N_eff, V, boundary, heading_stable)
        return dict(out, V_critical=j.V_critical, margin=j.margin, stable=j.stable, verdict=j.verdict, reason=j.reason)
    stable = bool(gain.sigma < 0)
    NV = gain.N_eff * V
    V_star = critical_speed(N, growth, boundary.NV_critical)
    return dict(out, V_critical=float(V_star), margin=float(gain_margin(NV, boundary, stable)), stable=stable,
                verdict=verdict_label(NV, boundary, stable), reason=None)


def _segment(route: Route, samples: Samples, k: int, boundary, robot: Robot, c: float, growth: GrowthRate, heading_stable: bool,
             end_fraction: float = END_FRACTION, taper_slope: float = TAPER_SLOPE) -> MapSegment:
    """The verdict of one segment: the worse of its two travel directions, each from its mean growth rate over the
    judged part (`verdicts`)."""
    V = robot.V
    mine = np.flatnonzero(samples.segment == k)
    ok = mine[np.isfinite(samples.N[mine])]
    base = dict(x0=route.x0, y0=route.y0, x1=route.x1, y1=route.y1, length=route.length, c=c, samples=int(mine.size),
                analysed=int(ok.size), roots=int(samples.roots[mine].max()) if mine.size else 0)
    spacing = route.length / max(mine.size, 1)
    if ok.size == 0:
        verdict = "no equilibrium" if samples.field[mine].any() else "open"
        return MapSegment(N=None, V_critical=None, margin=None, stable=None, verdict=verdict, offset=None, **base)
    first, stop = judged_run(samples.along[mine], end_fraction) if samples.along is not None else (0, mine.size)
    judged = (stop - first) * spacing
    local = [sample_verdict(float(n), V, boundary, heading_stable) for n in samples.N[ok]]
    detail = dict(offset=float(np.mean(samples.offset[ok])), samples_offset=tuple(float(v) for v in samples.offset[ok]),
                  N_max=float(np.max(samples.N[ok])), V_critical_local=float(min(j.V_critical for j in local)),
                  judged_from=float(first * spacing), judged_to=float(stop * spacing), **base)
    lam = wavelength(V, boundary.omega_critical)
    if stop - first < mine.size and judged < (lam if math.isfinite(lam) else route.length / 2):
        return MapSegment(N=None, V_critical=None, margin=None, stable=None, verdict="end effect", wavelength=lam,
                          reason=f"the corridor model holds over {judged:.2f} m only (|F_r.t| > {end_fraction:g} F_ct elsewhere), "
                          f"less than one wavelength {lam:.2f} m", **detail)
    part = mine[first:stop]
    slope = drift_slope((np.arange(first, stop) + 0.5) * spacing, samples.offset[part])
    if slope > taper_slope:
        return MapSegment(N=None, V_critical=None, margin=None, stable=None, verdict="tapering", wavelength=lam,
                          reason=f"the equilibrium path turns from the segment: |ds0/ds| = {slope:.2f} over the judged part "
                          f"(> {taper_slope:g}, {math.degrees(math.atan(taper_slope)):.0f} deg)", **detail)
    ways = {name: _direction(N, judged, boundary, V, growth, heading_stable) for name, N in zip(DIRECTIONS, samples.directional(part))}
    ways = {name: w for name, w in ways.items() if w is not None}
    if not ways:
        verdict = "no equilibrium" if samples.field[mine].any() else "open"
        return MapSegment(N=None, V_critical=None, margin=None, stable=None, verdict=verdict, offset=None, **base)
    decided = [name for name in ways if ways[name]["margin"] is not None]
    name = min(decided, key=lambda d: (ways[d]["V_critical"], ways[d]["margin"])) if decided else DIRECTIONS[0] if DIRECTIONS[0] in ways else DIRECTIONS[1]
    return MapSegment(direction=name if decided else None, **ways[name], **detail)
