"""The speed mask by wobble tolerance: each straight segment's and route stretch's V_tolerance (``map --wobble TOL``; docs/maps.md).

Past V* a supercritical corridor settles on a small limit cycle whose amplitude grows from 0
(docs/wobble.md). A user who accepts a wobble of TOL metres may drive a zone up to
V_tolerance, the fastest speed whose cycle stays under TOL (`analysis.wobble.corridor_branch`,
`WobbleBranch.tolerance_speed`), instead of V*. A zone is a straight segment (`MapAnalysis.segments`) or a route
stretch (`MapAnalysis.paths`, the grid law's verdicts along every route); each is read as the straight corridor
of the map's law (`MapAnalysis.law`) whose half-width L is measured across it (`corridor_half_width`): from
sample points a ray along the corridor's normal, either way, finds the first occupied cell — its centre for the
``grid`` law (the law's walls are rows of cells, `laws.effective_force.GridWallLaw`), the point where the ray enters
it for the ``power`` law (whose L runs to the wall's face, as in `equilibria.power_equilibria`, there on the map's
pixels); a straight line fitted to each side's hits is the wall, and L is half the distance between the two lines at
the zone's point (exact for straight parallel walls, also when the zone lies at a small angle to them). A segment's
points are its samples with an equilibrium in its judged part, L taken at the judged part's middle
(`segment_half_width`); a route stretch's are its samples with an equilibrium within its worst window (the window
whose V* the stretch reports), the normal the route's at the window's centre, L taken there (`stretch_half_width`).

The speed written in the mask (`ZoneWobble.V_limit`) is V_tolerance only where the method
can be trusted: a supercritical branch whose cycle at V_tolerance passes the describing
function's trust test (`analysis.wobble.trusted_cycle`), and whose V* agrees with the zone's
own to `V_CRITICAL_AGREEMENT` (otherwise the zone is not the straight corridor the wobble
models: walls thicker than a cell, one-sided, bent; a route stretch's own speed of zero growth, NV*/N of its worst
window, is compared, since its V* lies above it where the stretch is too short for a slow growth to reach an e-fold),
and which is faster than the zone's V* (the tolerance only relaxes the mask). Everywhere else the mask keeps V*, and
`ZoneWobble.reason` says why (`ZoneWobble.kept` its short name). One rule for both kinds of zone, except that an
unstable route stretch whose cause is "relay" (the window-edge relay, `maps.deciding.relay`) or "forced weave" (a forced weave along the
route) is not a Hopf cycle of the straight corridor: it keeps V*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from ...analysis.wobble import WOBBLE_MODELS, corridor_branch, trusted_cycle
from ...io.serialize import json_number
from ...laws.effective_force import GridWallLaw
from ...checks import check_number
from .equilibria import RAY_LENGTH
from .outputs import has_zone
from .decide import path_samples
from .paths import PathStretch

__all__ = ["KEPT", "V_CRITICAL_AGREEMENT", "SegmentWobble", "WobbleStretch", "WobbleSummary", "ZoneWobble", "corridor_half_width",
           "segment_half_width", "stretch_half_width", "wobble_summary", "with_wobble"]

V_CRITICAL_AGREEMENT = 0.02
"""Largest |V*_wobble/V*_segment − 1| for which a segment counts as the straight corridor the wobble models (the
map's straight corridors agree with the grid law's to 0.7 %, tests/test_map_corridors.py)."""
KEPT = ("no verdict", "V* = 0", "stable at any speed", "no half-width", "no wobble branch", "not a straight corridor",
        "subcritical", "not trusted", "V* above V_tolerance", "relay", "forced weave", "collision course", "no zone")
"""Short names of the reasons a zone keeps V* (`ZoneWobble.kept`; the text output counts them)."""
_RAY_STEP = 0.125
"""Step of a ray across the segment, histogram cells."""


@dataclass(frozen=True)
class ZoneWobble:
    """One zone's speed limit by wobble tolerance: a segment's or a route stretch's (module docstring; JSON
    ``segments[i].wobble``, ``paths.stretches[i].wobble``).

    Attributes
    ----------
    tolerance : float
        The largest acceptable lateral amplitude, m.
    L : float or None
        Half-width of the straight corridor the zone is read as, m (None: not measured, see `reason`).
    V_tolerance : float or None
        The fastest speed whose wobble stays under `tolerance`, m/s (`WobbleBranch.tolerance_speed`; None: no branch).
    criticality : str or None
        ``"supercritical"`` or ``"subcritical"`` (None: no branch).
    V_limit : float or None
        The speed the mask uses, m/s: `V_tolerance` when trusted, else the zone's V* (None: no verdict).
    reason : str or None
        Why `V_limit` is V* rather than `V_tolerance` (None when it is `V_tolerance`).
    kept : str or None
        The reason's short name, one of `KEPT` (None when `V_limit` is `V_tolerance`).
    """

    tolerance: float
    L: float | None
    V_tolerance: float | None
    criticality: str | None
    V_limit: float | None
    reason: str | None = None
    kept: str | None = None

    def to_dict(self) -> dict:
        """JSON: every field (infinities as "inf", undefined as null)."""
        number = lambda x: None if x is None or (isinstance(x, float) and math.isnan(x)) else json_number(x)
        return {"tolerance": self.tolerance, "L": number(self.L), "V_tolerance": number(self.V_tolerance),
                "criticality": self.criticality, "V_limit": number(self.V_limit), "reason": self.reason, "kept": self.kept}


SegmentWobble = ZoneWobble
"""The former name of `ZoneWobble` (``MapSegment.wobble``)."""


def segment_half_width(analysis, index: int) -> float | None:
    """Half-width L of the straight corridor segment `index` is read as, m (module docstring; None: no sample with an
    equilibrium in its judged part, or a side with no wall within `equilibria.RAY_LENGTH`).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (its grid, samples and segments).
    index : int
        The segment's index in `analysis.segments`.
    """
    s = analysis.segments[index]
    samples = analysis.samples
    if s.judged_from is None:
        return None
    tx, ty = (s.x1 - s.x0) / s.length, (s.y1 - s.y0) / s.length
    mine = np.flatnonzero((samples.segment == index) & np.isfinite(samples.N))
    at = (samples.x[mine] - s.x0) * tx + (samples.y[mine] - s.y0) * ty
    mine = mine[(at >= s.judged_from) & (at <= s.judged_to)]
    return corridor_half_width(analysis, samples.x[mine], samples.y[mine], (s.x0, s.y0), (tx, ty),
                               (s.judged_from + s.judged_to) / 2)


def stretch_half_width(analysis, index: int) -> float | None:
    """Half-width L of the straight corridor route stretch `index` is read as, m (module docstring: measured across the
    route at the stretch's worst-window point, from the stretch's samples with an equilibrium within that window; None:
    no such sample, or a side with no wall within `equilibria.RAY_LENGTH`).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (its grid and `paths`).
    index : int
        The stretch's index in `analysis.paths.stretches`.
    """
    pv = analysis.paths
    s = pv.stretches[index]
    k = _worst_sample(pv, s)
    if k is None:
        return None
    samples, arc = pv.samples, pv.arc
    _, _, tangent_x, tangent_y, _, _, _ = path_samples(pv.paths, analysis.grid.cell_size)  # the samples of `analyze_paths`, in order
    tx, ty = float(tangent_x[k]), float(tangent_y[k])
    mine = np.flatnonzero((samples.segment == s.route) & (arc >= s.start) & (arc <= s.stop) & (np.abs(arc - arc[k]) <= pv.window / 2)
                          & np.isfinite(samples.offset))
    return corridor_half_width(analysis, samples.x[mine], samples.y[mine], (float(samples.x[k]), float(samples.y[k])), (tx, ty), 0.0)


def _worst_sample(pv, stretch) -> int | None:
    """Index (into `pv`'s samples) of the stretch's worst window: its largest σ̄_w, as `paths.PathStretch` reports it."""
    run = np.flatnonzero((pv.samples.segment == stretch.route) & (pv.arc >= stretch.start) & (pv.arc <= stretch.stop))
    growth = pv.window_growth[run]
    if run.size == 0 or not np.isfinite(growth).any():
        return None
    return int(run[int(np.nanargmax(growth))])


def corridor_half_width(analysis, x, y, origin, tangent, middle: float) -> float | None:
    """Half-width L, m, of the straight corridor across which rays from the points (x, y) find the walls (module
    docstring): from each point a ray along the normal (−ty, tx) of `tangent`, either way, finds the first occupied
    histogram cell; a straight line fitted to each side's hits in the frame of `origin` and `tangent` is the wall, and
    L is half the distance between the two lines at arc `middle` of that frame (None: no point, or a side with no wall
    within `equilibria.RAY_LENGTH`).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (its histogram grid and law: the hit is the cell's centre for the grid law, where the ray enters
        the cell for the power law).
    x, y : ndarray
        The ray origins, m (points inside the corridor).
    origin : tuple of float
        (x, y) of the frame's origin, m.
    tangent : tuple of float
        Unit vector (tx, ty) along the corridor.
    middle : float
        Arc position in the frame at which L is measured, m.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.size == 0:
        return None
    (x0, y0), (tx, ty) = origin, tangent
    centre = isinstance(analysis.law, GridWallLaw)
    nx_, ny_ = -ty, tx
    lines = []
    for sign in (1.0, -1.0):
        hx, hy = _wall_hits(analysis.grid, x, y, sign * nx_, sign * ny_, centre)
        if not np.isfinite(hx).all():
            return None
        # the wall a straight line in the corridor's frame (the route or segment may lie at a small angle to its walls)
        along, across = (hx - x0) * tx + (hy - y0) * ty, (hx - x0) * nx_ + (hy - y0) * ny_
        lines.append(np.polyfit(along, across, 1) if np.ptp(along) > 0 else np.array([0.0, float(np.mean(across))]))
    (b_left, a_left), (b_right, a_right) = lines
    gap = (a_left + b_left * middle) - (a_right + b_right * middle)
    return float(gap / 2 * math.cos(math.atan((b_left + b_right) / 2)))


def _wall_hits(grid, x, y, nx_, ny_, centre: bool) -> tuple:
    """(x, y) where a ray from each point along the unit vector (nx_, ny_) meets the first occupied histogram cell, m:
    that cell's centre (`centre`) or where the ray enters it (to half a step); nan if none within `RAY_LENGTH`."""
    c = grid.cell_size
    step = c * _RAY_STEP
    occupied = grid.occupied
    cells_x, cells_y = occupied.shape
    hx, hy = np.full(x.shape, np.nan), np.full(x.shape, np.nan)
    todo = np.arange(x.size)
    for k in range(1, int(math.ceil(RAY_LENGTH / step)) + 1):
        if todo.size == 0:
            break
        d = k * step
        i = np.floor((x[todo] + d * nx_ - grid.x_min) / c).astype(np.int64)
        j = np.floor((y[todo] + d * ny_ - grid.y_min) / c).astype(np.int64)
        inside = (i >= 0) & (i < cells_x) & (j >= 0) & (j < cells_y)
        hit = np.zeros(todo.size, dtype=bool)
        hit[inside] = occupied[i[inside], j[inside]]
        done = todo[hit]
        if centre:
            hx[done], hy[done] = grid.x_min + (i[hit] + 0.5) * c, grid.y_min + (j[hit] + 0.5) * c
        else:
            hx[done], hy[done] = x[done] + (d - step / 2) * nx_, y[done] + (d - step / 2) * ny_
        todo = todo[~hit & inside]
    return hx, hy


def with_wobble(analysis, tolerance: float):
    """The analysis with each segment's and each route stretch's `ZoneWobble` for `tolerance` (module docstring).

    Parameters
    ----------
    analysis : MapAnalysis
        A map analysis (`analyze_map`).
    tolerance : float
        Largest acceptable lateral amplitude, m, > 0.

    Returns
    -------
    MapAnalysis
        The same analysis, its segments (``MapSegment.wobble``) and route stretches (`WobbleStretch`) carrying their
        wobble; the verdicts and V* unchanged.

    Raises
    ------
    ValueError
        For a tolerance that is not a number > 0.
    """
    tolerance = check_number("tolerance", tolerance, 0.0, math.inf, unit="m")
    segments = tuple(replace(s, wobble=_zone_wobble(analysis, s.V_critical, lambda k=k: segment_half_width(analysis, k), tolerance))
                     for k, s in enumerate(analysis.segments))
    pv = analysis.paths
    if pv is not None:
        stretches = tuple(WobbleStretch(**{f.name: getattr(s, f.name) for f in fields(PathStretch)},
                                        wobble=_stretch_wobble(analysis, k, tolerance)) for k, s in enumerate(pv.stretches))
        pv = replace(pv, stretches=stretches)
    return replace(analysis, segments=segments, paths=pv)


def _stretch_wobble(analysis, index: int, tolerance: float) -> ZoneWobble:
    """A route stretch's wobble: the segments' rule (`_zone_wobble`) on the half-width across its worst window, except
    for what is not a Hopf cycle of the straight corridor (a window-edge relay, a forced weave: V* kept)."""
    s = analysis.paths.stretches[index]
    if s.verdict == "unstable" and s.cause in _NOT_A_HOPF_CYCLE:
        return ZoneWobble(tolerance, None, None, None, s.V_critical, _NOT_A_HOPF_CYCLE[s.cause], s.cause)
    if s.verdict == "stable" and s.V_critical is not None and not s.V_critical < analysis.robot.V:
        return ZoneWobble(tolerance, None, None, None, s.V_critical, "stable, V* at or above V: no slow zone", "no zone")
    V_linear = analysis.NV_critical / s.N if s.N and s.N > 0 else math.inf  # its worst window's zero growth
    return _zone_wobble(analysis, s.V_critical, lambda: stretch_half_width(analysis, index), tolerance, V_linear)


_NOT_A_HOPF_CYCLE = {
    "relay": "a window-edge relay (a sustained oscillation of about a cell), not a Hopf cycle of the straight corridor: V* kept",
    "forced weave": "a forced weave along the route, not a Hopf cycle of the straight corridor: V* kept",
    "collision course": "a collision course, not a Hopf cycle of the straight corridor: V* kept",
}


def _zone_wobble(analysis, V_star, half_width, tolerance: float, V_linear: float | None = None) -> ZoneWobble:
    """The one rule of a zone (segment or route stretch) with V* `V_star` whose corridor half-width `half_width()`
    measures (module docstring): V_tolerance where trusted and faster than V*, else V* and the reason. `V_linear`
    (default V*) is the zone's speed of zero linear growth, compared with the straight corridor's V*."""
    V_linear = V_star if V_linear is None else V_linear

    def keep(kept, reason, L=None, V_tol=None, criticality=None):
        return ZoneWobble(tolerance, L, V_tol, criticality, V_star, reason, kept)

    if V_star is None:
        return keep("no verdict", "no verdict: no speed limit")
    if not (0.0 < V_star < math.inf):
        return (keep("V* = 0", "V* = 0 (the loop grows at any speed): no limit cycle to tolerate") if V_star == 0
                else keep("stable at any speed", "stable at any speed: no wobble"))
    model = analysis.model if analysis.model in WOBBLE_MODELS else "sampled"
    L = half_width()
    if L is None:
        return keep("no half-width", "no corridor half-width: a side without a wall")
    try:
        branch = corridor_branch(analysis.robot, analysis.controller, analysis.law, L, model=model)
    except ValueError as error:
        return keep("no wobble branch", f"no wobble branch: {error}", L)
    V_tol = branch.tolerance_speed(tolerance)
    common = dict(L=L, V_tol=V_tol, criticality=branch.criticality)
    if not abs(branch.V_critical / V_linear - 1.0) <= V_CRITICAL_AGREEMENT:
        return keep("not a straight corridor",
                    f"not the straight corridor of half-width {L:.3g} m the wobble models (its V* {branch.V_critical:.4g} m/s, "
                    f"the zone's {V_linear:.4g} m/s): V* kept", **common)
    if branch.criticality != "supercritical":
        return keep("subcritical", "subcritical: past V* the wobble jumps to a large cycle; V* kept", **common)
    cycles = [c for c in branch.cycles_at(V_tol) if c.stable]
    if not math.isfinite(V_tol) or (V_tol > branch.V_critical and not (cycles and trusted_cycle(cycles[0]))):
        return keep("not trusted", "the describing function is not trusted at V_tolerance (strong harmonics or the steering-rate "
                    "limit): V* kept", **common)
    if not V_tol > V_star:
        return keep("V* above V_tolerance", f"V* {V_star:.4g} m/s is above V_tolerance (the zone ends before its weave grows an e-fold): "
                    "V* kept", **common)
    return ZoneWobble(tolerance, L, V_tol, branch.criticality, V_tol)


@dataclass(frozen=True)
class WobbleStretch(PathStretch):
    """A route stretch (`paths.PathStretch`, every field) with its speed limit by wobble tolerance (JSON
    ``paths.stretches[i].wobble``).

    Attributes
    ----------
    route, start, stop, x0, y0, x1, y1, length, verdict, cause, growth_rate, efolds, N, margin, V_critical, direction, linearized_at_route, oscillates, amplitude
        As `paths.PathStretch`.
    wobble : ZoneWobble or None
        The stretch's wobble (`with_wobble`).
    """

    wobble: ZoneWobble | None = None

    def to_dict(self) -> dict:
        """`PathStretch.to_dict` and ``wobble`` (`ZoneWobble.to_dict`)."""
        out = super().to_dict()
        out.pop("wobble", None)
        if self.wobble is not None:
            out["wobble"] = self.wobble.to_dict()
        return out


@dataclass(frozen=True)
class WobbleSummary:
    """What ``map --wobble TOL`` changed (JSON ``wobble``; the text output's block).

    Attributes
    ----------
    tolerance : float
        The tolerance, m.
    segments : dict
        Segments whose zone the mask draws (V* < V): ``{"V_tolerance": count, "kept": {reason code: count}}``.
    stretches : dict
        Route stretches whose zone the mask draws: the same counts.
    route_length_m : dict
        Their route length, m: ``{"V_tolerance": m, "kept": {reason code: m}}``.
    unstable_length_m : float
        Route length of every unstable stretch, m (also those whose V* >= V, which the mask does not slow).
    unstable_fraction : float or None
        The share of it whose zone got V_tolerance (None: no unstable route).
    V_limit_min, V_limit_max : float or None
        The slowest and fastest limit of the mask's zones, m/s (None: no zone).
    V_critical_min, V_critical_max : float or None
        The same without the wobble (every zone at V*), m/s.
    """

    tolerance: float
    segments: dict
    stretches: dict
    route_length_m: dict
    unstable_length_m: float
    unstable_fraction: float | None
    V_limit_min: float | None
    V_limit_max: float | None
    V_critical_min: float | None
    V_critical_max: float | None

    def to_dict(self) -> dict:
        """JSON: every field."""
        return dict(self.__dict__)


def wobble_summary(analysis, tolerance: float) -> WobbleSummary:
    """The counts of `WobbleSummary` of an analysis with its wobble (`with_wobble`).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis after `with_wobble`.
    tolerance : float
        The tolerance it was given, m.

    Raises
    ------
    ValueError
        For an analysis without the wobble.
    """
    V = analysis.robot.V
    segments = [s for s in analysis.segments if has_zone(s, V)]  # the zones the mask draws (`outputs.speed_limits`)
    stretches = [s for s in (analysis.paths.stretches if analysis.paths is not None else ()) if has_zone(s, V)]
    if any(getattr(s, "wobble", None) is None for s in segments + stretches):
        raise ValueError("the analysis has no wobble: call with_wobble first")

    def counts(zones, weight):
        out = {"V_tolerance": 0.0 if weight else 0, "kept": {}}
        for s in zones:
            w = weight(s) if weight else 1
            if s.wobble.kept is None:
                out["V_tolerance"] += w
            else:
                out["kept"][s.wobble.kept] = out["kept"].get(s.wobble.kept, 0) + w
        return out

    unstable = [s for s in (analysis.paths.stretches if analysis.paths is not None else ()) if s.verdict == "unstable"]
    unstable_length = float(sum(s.length for s in unstable))
    relaxed = float(sum(s.length for s in unstable if has_zone(s, V) and s.wobble.kept is None))
    limits = [s.wobble.V_limit for s in segments + stretches if s.wobble.V_limit < V]
    stars = [s.V_critical for s in segments + stretches]
    return WobbleSummary(tolerance, counts(segments, None), counts(stretches, None), counts(stretches, lambda s: float(s.length)),
                         unstable_length, relaxed / unstable_length if unstable_length > 0 else None,
                         min(limits) if limits else None, max(limits) if limits else None,
                         min(stars) if stars else None, max(stars) if stars else None)
