"""Every sample of every route decided at one speed: the rule behind `maps.deciding.paths`' stretches (docs/maps.md,
"Verdicts along every route" and "One answer per stretch").

`route_geometry` computes what does not depend on the speed (samples, lateral equilibria, the field's gradient, the
lateral profile the loop is driven through, the window-edge jumps); `decide` applies the rule at a speed V — the
window's growth (`WINDOW_PERIODS` wavelengths, at least `verdicts.EFOLDS` e-folds: "growth"), the loop driven along the
route (`driven.driven_loops`: a "forced weave"), the window-edge relay (`relay`: "relay") — and gives each sample its verdict
and cause (`SampleDecision`). `maps.deciding.paths` makes the stretches and `maps.deciding.stretch_speed` their V* with the same rule.
The rule itself is described in `maps.deciding.paths`' module docstring.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from ..reading.contact import free_band
from ..judging.driven import LEAVES, DriveRequest, DrivenTrack, SampledTransition, driven_loops
from ..judging.episodes import AMPLITUDE_THRESHOLD
from .equilibria import equilibria_at, lateral_force
from .relay import relay_amplitude, window_relay
from .verdicts import EFOLDS, END_FRACTION, GrowthRate, wavelength

__all__ = ["CAUSES", "PATH_NEWTON_STEPS", "PATH_VERDICTS", "PROFILE_PHASE_NODES", "PROFILE_STEP", "RENORMALIZE", "ROUND_OFF_EFOLDS",
           "UNJUDGED", "WINDOW_PERIODS", "DecisionRule", "RouteGeometry", "SampleDecision", "SpeedQuery", "decide", "decide_speeds", "lateral_profile", "path_samples",
           "route_geometry", "run_efolds"]

WINDOW_PERIODS = 3.0
"""Length of the window whose accumulated growth decides a point, in oscillation wavelengths λ = 2πV/ω*: the
simulator's oscillation metrics need three periods to call a growth (`validation.map_selection.MIN_PERIODS`), and an
episode of the driving validation is a growth over at least three periods (`validation.map_drives`)."""
PATH_NEWTON_STEPS = 12
"""Newton steps per equilibrium along the routes (`equilibria.equilibria_at`): the corridor analysis' `NEWTON_STEPS`.
With 6 (a jump located to < 1 mm) the depot's north-wall weave at CARMEL's preset, predicted near the episode
threshold, was lost (recall 97 % -> 54 %): the forced weave is that sensitive to where the line is."""
UNJUDGED = ("wall ahead both ways", "inside an obstacle", "wall ahead")
"""Reasons a sample gets no verdict: a wall ahead in both travel directions (the repulsion along the route cancels more
than `verdicts.END_FRACTION` of the attraction either way: the robot turns there, a narrow dead end), or the sample
lies in an occupied cell (the field is not finite)."""
PATH_VERDICTS = ("stable", "unstable", *UNJUDGED)
"""Verdict codes of a sample, in this order (`PathVerdicts.code` indexes it)."""




def path_samples(paths, spacing: float):
    """(x, y, tx, ty, route, arc, ds): points every ~`spacing` m along each route (piece midpoints), their unit
    tangents, route index, arc position (m) and the route length each stands for (m).

    Parameters
    ----------
    paths : sequence of RoutePath
        The routes.
    spacing : float
        Largest distance between samples, m.
    """
    out = [[] for _ in range(7)]
    for k, path in enumerate(paths):
        p = path.points
        pieces = np.hypot(*np.diff(p, axis=0).T)
        total = float(pieces.sum())
        count = max(1, int(math.ceil(total / spacing - 1e-9)))
        arc = (np.arange(count) + 0.5) * total / count
        edges = np.concatenate([[0.0], np.cumsum(pieces)])
        piece = np.clip(np.searchsorted(edges, arc, side="right") - 1, 0, len(pieces) - 1)
        u = (arc - edges[piece]) / np.where(pieces[piece] > 0, pieces[piece], 1.0)
        d = p[piece + 1] - p[piece]
        length = np.where(pieces[piece] > 0, pieces[piece], 1.0)
        for target, value in zip(out, (p[piece, 0] + u * d[:, 0], p[piece, 1] + u * d[:, 1], d[:, 0] / length, d[:, 1] / length,
                                       np.full(count, k), arc, np.full(count, total / count))):
            target.append(value)
    if not out[0]:
        empty = np.zeros(0)
        return empty, empty, empty, empty, np.zeros(0, dtype=int), empty, empty
    return tuple(np.concatenate(a) for a in out)


def _window_mean(values: np.ndarray, route: np.ndarray, arc: np.ndarray, ds: np.ndarray, half: float) -> np.ndarray:
    """Mean of the finite `values` over the samples of the same route within `half` m of arc (nan: none finite)."""
    out = np.full(values.shape, np.nan)
    for r in np.unique(route):
        idx = np.flatnonzero(route == r)
        v, a, w = values[idx], arc[idx], ds[idx]
        ok = np.isfinite(v)
        csum = np.concatenate([[0.0], np.cumsum(np.where(ok, v * w, 0.0))])
        cw = np.concatenate([[0.0], np.cumsum(np.where(ok, w, 0.0))])
        lo = np.searchsorted(a, a - half, side="left")
        hi = np.searchsorted(a, a + half, side="right")
        weight = cw[hi] - cw[lo]
        with np.errstate(invalid="ignore", divide="ignore"):
            out[idx] = np.where(weight > 0, (csum[hi] - csum[lo]) / np.where(weight > 0, weight, 1.0), np.nan)
    return out


def _between(values: np.ndarray, route: np.ndarray, arc: np.ndarray, centres: np.ndarray, N: np.ndarray) -> np.ndarray:
    """`values` at the `centres` (finite there), linearly interpolated along each route at its other samples whose
    direction moves (finite N); nan on a route with no finite centre and where N is nan."""
    out = np.array(values, dtype=float)
    for r in np.unique(route[centres]):
        on = route == r
        known = on & centres & np.isfinite(values)
        fill = on & ~centres & np.isfinite(N)
        if known.any() and fill.any():
            out[fill] = np.interp(arc[fill], arc[known], values[known])
    return out


def run_efolds(rate: np.ndarray, route: np.ndarray, ds: np.ndarray, V: float) -> np.ndarray:
    """e-folds a disturbance gains over the run of consecutive samples of one route whose window grows, ∫σ̄_w ds/V over
    the run, at each of its samples (nan elsewhere): a corridor longer than the window whose loop grows slowly still
    weaves by its end (docs/maps.md, "One answer per stretch").

    Parameters
    ----------
    rate : ndarray
        σ̄_w per sample, 1/s (nan: not judged; samples of a route consecutive, in arc order).
    route : ndarray of int
    ds : ndarray
        Route length per sample, m.
    V : float
        m/s.
    """
    grows = np.isfinite(rate) & (rate > 0)
    if not grows.any():
        return np.full(rate.shape, np.nan)
    start = grows & ~np.concatenate([[False], grows[:-1] & (route[1:] == route[:-1])])  # a run begins here
    run = np.cumsum(start) - 1
    total = np.bincount(run[grows], weights=(rate * ds)[grows] / V, minlength=int(run.max()) + 1)
    return np.where(grows, total[np.maximum(run, 0)], np.nan)


def _aim_stiffness(paths, route, x, y, attraction, W: float) -> np.ndarray:
    """K per sample, F_ct/m: how much the goal's pull across the path grows per metre of lateral offset on a path
    taken towards a point at distance D, K = A²/D, the derivative of the unit attraction's lateral part at the path
    (A its part along the path, `_goal_pull`). D is the plan's lookahead (`RoutePath.lookahead`: its carrot) or the
    point target's distance (`RoutePath.goal`), whichever is nearer, the target's at least W (within W of its goal
    the robot arrives); 0 on a route, whose goal lies along it at infinity (module docstring, "Paths taken")."""
    stiffness = np.zeros(np.size(x))
    for r, path in enumerate(paths):
        if path.goal is None and not math.isfinite(path.lookahead):
            continue  # a goal at infinity: K = 0 (every skeleton route)
        on = route == r
        D = np.full(int(on.sum()), path.lookahead)
        if path.goal is not None:
            D = np.minimum(D, np.maximum(np.hypot(path.goal[0] - x[on], path.goal[1] - y[on]), W))
        stiffness[on] = attraction[on] ** 2 / D
    return stiffness


def _cell_mean(grid, law, x, y, tx, ty) -> np.ndarray:
    """F_n at the points averaged across the path over one cell, s in [−c/2, c/2] (F_ct units; the trapezoid rule on
    `lateral_profile`'s nodes within half a cell)."""
    _, fn, _ = lateral_profile(grid, law, x, y, tx, ty, grid.cell_size / 2)
    weights = np.full(fn.shape[1], 1.0)
    weights[[0, -1]] = 0.5
    return fn @ (weights / weights.sum())




@dataclass(frozen=True)
class DecisionRule:
    """What decides a sample at a speed, besides the routes (`decide`): the map's field, the robot's width, the loop
    model's boundary and growth rate, the sampled loop's transition (None: another model) and the end rule.

    Attributes
    ----------
    grid : HistogramMap
    law : GridWallLaw
    W : float
        Robot width, m.
    boundary : Boundary
    growth : GrowthRate
    heading_stable : bool
    transition : SampledTransition or None
    end_fraction : float
    """

    grid: object
    law: object
    W: float
    boundary: object
    growth: GrowthRate
    heading_stable: bool
    transition: object = None
    end_fraction: float = END_FRACTION

    @property
    def drives(self) -> bool:
        """The loop is driven along the routes (`driven.driven_loops`): the sampled model with an oscillation frequency."""
        omega = self.boundary.omega_critical
        return self.transition is not None and bool(omega) and omega > 0


@dataclass(frozen=True)
class RouteGeometry:
    """Everything about the routes' samples that does not depend on the speed (`route_geometry`).

    Attributes
    ----------
    paths : tuple of RoutePath
    x, y, tx, ty : ndarray
        Samples (m) and unit tangents (`path_samples`).
    route, arc, ds : ndarray
        Route index, arc position (m), length per sample (m).
    driven : ndarray of bool
        Per route: a path the robot took.
    taken : ndarray of bool
        Per sample: on a path the robot took.
    samples : Samples or None
        The equilibria (None on a subset, `RouteGeometry.subset`).
    has : ndarray of bool
        The sample's path is its lateral equilibrium (within W/2 of a path taken).
    offset, px, py : ndarray
        The linearization point's offset along the left normal (0: the route itself) and position, m.
    along, slope : ndarray
        F_r·t and −dF_n/ds there (F_ct units, 1/m), before the goal's pull.
    inside : ndarray of bool
        The sample lies in an obstacle (the field is not finite).
    cell_force : ndarray
        F_n averaged across one cell on paths taken (`_cell_mean`; nan elsewhere).
    profile : tuple or None
        `lateral_profile` within `driven.LEAVES` (where the loop is driven) and the free band across each sample
        (`contact.free_band`, shape (samples, 2): where the robot's disc meets an obstacle).
    track : DrivenTrack or None
        A drive's own paths' track.
    relay_found, relay_jump : ndarray
        `relay.window_relay` at the samples whose path is known (False, 0 elsewhere).
    """

    paths: tuple
    x: np.ndarray
    y: np.ndarray
    tx: np.ndarray
    ty: np.ndarray
    route: np.ndarray
    arc: np.ndarray
    ds: np.ndarray
    driven: np.ndarray
    taken: np.ndarray
    samples: object
    has: np.ndarray
    offset: np.ndarray
    px: np.ndarray
    py: np.ndarray
    along: np.ndarray
    slope: np.ndarray
    inside: np.ndarray
    cell_force: np.ndarray
    profile: tuple | None
    track: object
    relay_found: np.ndarray
    relay_jump: np.ndarray

    def subset(self, keep: np.ndarray, grid, law) -> "RouteGeometry":
        """The same geometry at the samples `keep` (bool, whole routes), its own driven track rebuilt.

        Parameters
        ----------
        keep : ndarray of bool
            Per sample; whole routes only (the window and the driven loop run along a route).
        grid, law : HistogramMap, GridWallLaw
            For the drives' own track.
        """
        cut = {f: getattr(self, f)[keep] for f in _PER_SAMPLE}
        profile = tuple(a if a.ndim == 1 else a[keep] for a in self.profile) if self.profile is not None else None
        track = (DrivenTrack.of(grid, law, self.paths, cut["x"], cut["y"], cut["tx"], cut["ty"], cut["route"], cut["arc"])
                 if self.track is not None else None)
        return replace(self, samples=None, profile=profile, track=track, **cut)


_PER_SAMPLE = ("x", "y", "tx", "ty", "route", "arc", "ds", "taken", "has", "offset", "px", "py", "along", "slope", "inside", "cell_force",
               "relay_found", "relay_jump")
"""`RouteGeometry`'s fields with a value per sample (what a subset cuts)."""


def route_geometry(grid, law, paths: tuple, clearance: np.ndarray, W: float, taken=False, drive: bool = True) -> RouteGeometry:
    """The speed-independent part of `analyze_paths` (`RouteGeometry`): samples, equilibria, the field's gradient,
    the lateral profile for the driven loop (`drive`) and the window-edge jumps.

    Parameters
    ----------
    grid : HistogramMap
    law : GridWallLaw
    paths : tuple of RoutePath
    clearance : ndarray
        Per histogram cell, m.
    W : float
        Robot width, m.
    taken : bool or sequence of bool
        As `analyze_paths`.
    drive : bool
        Sample the lateral profile and the drives' own track (the sampled loop is driven).
    """
    x, y, tx, ty, route, arc, ds = path_samples(paths, grid.cell_size)
    driven = np.array(np.broadcast_to(np.asarray(taken, dtype=bool), (len(paths),)))  # per route
    taken = driven[route] if route.size else np.zeros(0, dtype=bool)  # per sample
    samples = equilibria_at(grid, law, x, y, tx, ty, route, clearance, W, newton_steps=PATH_NEWTON_STEPS)
    has = np.isfinite(samples.offset)
    along, slope = np.array(samples.along, dtype=float), samples.N * samples.forward  # −dF_n/ds at the equilibrium
    if taken.any():  # an equilibrium the robot's own path keeps away from is not the one it follows
        far = has & taken & (np.abs(np.nan_to_num(samples.offset)) > W / 2)
        has = has & ~far
        slope = np.where(far, np.nan, slope)
    offset = np.where(has, samples.offset, 0.0)
    px, py = x - ty * offset, y + tx * offset
    # the gradient at the route's own point where there is no equilibrium (and at an equilibrium the repulsion stops
    # the robot at in one direction, where the corridor search keeps no N)
    redo = np.flatnonzero(~np.isfinite(slope))
    if redo.size:
        _, ft0, df0 = lateral_force(grid, law, x[redo], y[redo], tx[redo], ty[redo], offset[redo], jacobian=True)
        along[redo], slope[redo] = ft0, -df0
    inside = ~(np.isfinite(along) & np.isfinite(slope))
    cell_force = np.full(x.size, np.nan)
    if taken.any():
        cell_force[taken] = _cell_mean(grid, law, x[taken], y[taken], tx[taken], ty[taken])
    profile = None
    if drive and x.size:
        offsets, fn, ft = lateral_profile(grid, law, x, y, tx, ty, LEAVES)
        profile = (offsets, fn, ft, free_band(grid, clearance, x, y, tx, ty, W, offsets).T)
    track = DrivenTrack.of(grid, law, paths, x, y, tx, ty, route, arc) if drive and taken.any() else None
    found, jump = np.zeros(x.size, dtype=bool), np.zeros(x.size)
    check = np.flatnonzero((has | taken) & ~inside)  # where the robot's path is known: its equilibrium, or driven
    if check.size:
        found[check], jump[check] = window_relay(grid, law, x[check], y[check], tx[check], ty[check], offset[check], reference=~has[check])
    return RouteGeometry(paths, x, y, tx, ty, route, arc, ds, driven, taken, samples, has, offset, px, py, along, slope, inside,
                         cell_force, profile, track, found, jump)


CAUSES = ("growth", "forced weave", "relay", "collision course")
"""Why a sample is unstable (`SampleDecision.cause` indexes it; −1: stable or unjudged), tried in the order: the
linear loop grows at least `verdicts.EFOLDS` e-folds over the window or the run of growing windows ("growth"); the
loop driven along the route through the field weaves though the linear loop is damped (the field's ripple forcing
it, `maps.judging.episodes`: "forced weave"); the driven loop's disc meets an obstacle within one period after the sample
without a weave first ("collision course", `contact.free_band`); the window-edge relay holds a cycle of at least the
episodes' amplitude (`maps.deciding.relay`: "relay")."""


@dataclass(frozen=True)
class SampleDecision:
    """Every sample decided at one speed (`decide`).

    Attributes
    ----------
    V : float
        m/s.
    window : float
        Window length Λ, m.
    N_forward, N_reverse : ndarray
        Lateral gain per travel direction, 1/m (nan: stopped that way).
    sigma : ndarray, shape (2, samples)
        σ(N·V) of each direction, 1/s.
    forward : ndarray, shape (2, samples)
        The forward force of each direction, F_ct units.
    worse : ndarray of int
        The worse direction (0 forward, 1 reverse).
    N_worse : ndarray
        Its gain, 1/m.
    window_growth, efolds : ndarray
        σ̄_w of the worse direction (1/s; nan unjudged) and the e-folds over its window.
    mean_N : ndarray, shape (2, samples)
        Mean gain over each direction's window, 1/m.
    code : ndarray of int
        Index into `PATH_VERDICTS`.
    cause : ndarray of int
        Index into `CAUSES` where unstable, else −1.
    oscillates : ndarray of bool
        The driven loop weaves here.
    amplitude : ndarray
        The predicted lateral oscillation, m (`PathStretch.amplitude`).
    """

    V: float
    window: float
    N_forward: np.ndarray
    N_reverse: np.ndarray
    sigma: np.ndarray
    forward: np.ndarray
    worse: np.ndarray
    N_worse: np.ndarray
    window_growth: np.ndarray
    efolds: np.ndarray
    mean_N: np.ndarray
    code: np.ndarray
    cause: np.ndarray
    oscillates: np.ndarray
    amplitude: np.ndarray


def _gains(g: RouteGeometry, rule: DecisionRule, V: float, lam: float) -> tuple:
    """(N_forward, N_reverse, forward, pull, attraction, aim): each direction's lateral gain (1/m) with the goal's pull
    on paths taken (`_goal_pull`, `_aim_stiffness`) and the wall-ahead rule (module docstring)."""
    pull = np.zeros(g.x.size)
    if g.taken.any() and math.isfinite(lam):
        pull = np.where(g.taken, np.nan_to_num(_window_mean(g.cell_force, g.route, g.arc, g.ds, lam / 2)), 0.0)
    attraction = np.sqrt(np.clip(1.0 - pull ** 2, 0.0, None))
    aim = _aim_stiffness(g.paths, g.route, g.x, g.y, attraction, rule.W)
    slope = g.slope + aim
    forward = np.stack([attraction + g.along, attraction - g.along])  # the forward force of each travel direction
    f = rule.end_fraction
    with np.errstate(divide="ignore", invalid="ignore"):  # a wall ahead (the repulsion along the path) stops the robot
        N_forward = np.where((1 + g.along >= 1 - f) & (forward[0] > 0), slope / forward[0], np.nan)
        N_reverse = np.where((1 - g.along >= 1 - f) & (forward[1] > 0), slope / forward[1], np.nan)
    N_forward[g.inside], N_reverse[g.inside] = np.nan, np.nan
    N_reverse[g.taken] = np.nan  # the robot drove a path taken one way, from its start: the reverse is not its path
    return N_forward, N_reverse, forward, pull, attraction, aim


def decide(g: RouteGeometry, rule: DecisionRule, V: float, centres: np.ndarray | None = None, drive: bool = True) -> SampleDecision:
    """Every sample's verdict and cause at speed V (module docstring): the growth over the window or over the run of
    growing windows around it (`run_efolds`), then the loop driven along the route (a forced weave), then the
    window-edge relay (`decide_speeds` at one speed).

    Parameters
    ----------
    g : RouteGeometry
    rule : DecisionRule
    V : float
        m/s.
    centres : ndarray of bool, optional
        Multiply out only these samples' windows; the others' growth is interpolated along the route between them
        (`_between`; unjudged on a route with none). The loop is still driven along the whole routes. Default all.
    drive : bool
        Drive the loop along the routes (where the rule does); False: the growth and the relay's describing function
        alone (`stretch_speed` above V).
    """
    return decide_speeds(g, rule, [SpeedQuery(V, centres)], drive)[0]


@dataclass(frozen=True)
class SpeedQuery:
    """One speed `decide_speeds` decides the samples at.

    Attributes
    ----------
    V : float
        m/s.
    centres : ndarray of bool or None
        As `decide`'s.
    routes : ndarray of bool or None
        Per route index: drive the loop along these routes only (None: all); the other routes' samples are decided
        without a forced weave (a caller reads only its routes' samples).
    """

    V: float
    centres: np.ndarray | None = None
    routes: np.ndarray | None = None


def decide_speeds(g: RouteGeometry, rule: DecisionRule, queries, drive: bool = True) -> list:
    """`decide` at several speeds (one `SampleDecision` each): the loop driven along the routes at all of them in one
    run (`driven.driven_loops`), each speed's samples decided by the same rule as `decide` alone.

    Parameters
    ----------
    g : RouteGeometry
    rule : DecisionRule
    queries : sequence of SpeedQuery
        The speeds, each with its centres and the routes it drives.
    drive : bool
        As `decide`'s.
    """
    linear = [_linear_decision(g, rule, q.V, q.centres) if q.routes is None else _on_routes(g, rule, q) for q in queries]
    loops = [None] * len(queries)
    if drive and rule.drives and g.profile is not None and g.x.size:
        requests = [DriveRequest(d.V, np.stack([~np.isfinite(d.N_forward), ~np.isfinite(d.N_reverse)]), *goal, q.routes)
                    for q, (d, goal) in zip(queries, linear)]
        loops = driven_loops(g.route, g.arc, g.profile, requests, rule.transition, 2 * math.pi / rule.boundary.omega_critical,
                             g.driven[: int(g.route.max()) + 1], g.track)
    return [_with_the_drive(g, rule, d, loop) for (d, _), loop in zip(linear, loops)]


def _linear_decision(g: RouteGeometry, rule: DecisionRule, V: float, centres) -> tuple:
    """(decision, (pull, attraction, aim)): the samples decided at V by the window's growth alone (`decide`), and the
    goal's terms the driven loop needs (`_gains`)."""
    boundary = rule.boundary
    lam = wavelength(V, boundary.omega_critical)
    N_forward, N_reverse, forward, pull, attraction, aim = _gains(g, rule, V, lam)
    sig = np.stack([np.where(np.isfinite(n), rule.growth(np.nan_to_num(n) * V), np.nan) for n in (N_forward, N_reverse)])
    window = WINDOW_PERIODS * lam if math.isfinite(lam) else math.inf
    half = window / 2
    if rule.transition is not None and math.isfinite(window):
        means, seconds = _window_products((N_forward, N_reverse), g.route, g.arc, half, V, rule.transition, centres)
        if centres is not None:
            means = [_between(m, g.route, g.arc, centres, n) for m, n in zip(means, (N_forward, N_reverse))]
            seconds = [_between(t, g.route, g.arc, centres, n) for t, n in zip(seconds, (N_forward, N_reverse))]
    else:
        means = [_window_mean(s, g.route, g.arc, g.ds, half) for s in sig]
        seconds = [np.full(g.x.size, min(window, 1e9) / V)] * 2
    mean_N = np.stack([_window_mean(n, g.route, g.arc, g.ds, half) for n in (N_forward, N_reverse)])
    gained = np.stack([np.fmax(m * t, run_efolds(m, g.route, g.ds, V)) for m, t in zip(means, seconds)])
    with np.errstate(invalid="ignore"):
        worse = np.where(np.nan_to_num(gained[1], nan=-np.inf) > np.nan_to_num(gained[0], nan=-np.inf), 1, 0)
    rows = np.arange(g.x.size)
    window_growth = np.stack(means)[worse, rows]
    efolds = np.where(np.isfinite(window_growth), gained[worse, rows], np.nan)
    code = np.where(efolds >= EFOLDS, 1, 0)  # a disturbance grows by at least one e-fold over the window
    stopped = ~np.isfinite(N_forward) & ~np.isfinite(N_reverse)
    wall = np.where(g.taken, PATH_VERDICTS.index("wall ahead"), PATH_VERDICTS.index("wall ahead both ways"))
    code = np.where(stopped, wall, code)
    code = np.where(g.inside, PATH_VERDICTS.index("inside an obstacle"), code)
    code = np.where(~np.isfinite(window_growth) & (code < 2), wall, code)
    cause = np.where(code == 1, CAUSES.index("growth"), -1)
    N_worse = np.stack([N_forward, N_reverse])[worse, rows]
    decision = SampleDecision(V, window, N_forward, N_reverse, sig, forward, worse, N_worse, window_growth, efolds, mean_N, code, cause,
                              np.zeros(g.x.size, dtype=bool), np.zeros(g.x.size))
    return decision, (pull, attraction, aim)


_OUTSIDE = {"code": PATH_VERDICTS.index("wall ahead both ways"), "worse": 0, "cause": -1, "oscillates": False, "amplitude": 0.0}
"""What a sample off a query's routes holds in its `SampleDecision` (`_on_routes`; nan where not named): unjudged."""


def _on_routes(g: RouteGeometry, rule: DecisionRule, query: SpeedQuery) -> tuple:
    """`_linear_decision` of the query's routes' samples alone (each route is decided on its own), spread back over
    every sample of `g` (off its routes: `_OUTSIDE`, and no goal's terms: P = K = 0, A = 1)."""
    keep = query.routes[g.route]
    part = replace(g, profile=None, track=None, **{f: getattr(g, f)[keep] for f in _PER_SAMPLE})
    d, goal = _linear_decision(part, rule, query.V, None if query.centres is None else query.centres[keep])
    spread = {f.name: _spread(value, keep, _OUTSIDE.get(f.name, np.nan)) for f in fields(SampleDecision)
              if isinstance(value := getattr(d, f.name), np.ndarray)}
    return replace(d, **spread), tuple(_spread(value, keep, fill) for value, fill in zip(goal, (0.0, 1.0, 0.0)))


def _spread(value: np.ndarray, keep: np.ndarray, fill) -> np.ndarray:
    """`value` (per sample of `keep`'s True ones, last axis) at those samples of all, `fill` elsewhere."""
    full = np.full(value.shape[:-1] + keep.shape, fill, dtype=value.dtype)
    full[..., keep] = value
    return full



def _with_the_drive(g: RouteGeometry, rule: DecisionRule, d: SampleDecision, loop) -> SampleDecision:
    """The linear decision `d` with the driven loop's forced weave (`loop`: a `driven.DrivenLoop`, None: not driven)
    and the window-edge relay (module docstring)."""
    code, cause, excursion = d.code, d.cause, None
    oscillates, amplitude = d.oscillates, d.amplitude
    if loop is not None:
        oscillates, amplitude, excursion = loop.oscillates, loop.amplitude, loop.excursion
        weave = (code == 0) & oscillates
        code, cause = np.where(weave, 1, code), np.where(weave, CAUSES.index("forced weave"), cause)
        course = (code == 0) & loop.collides
        code, cause = np.where(course, 1, code), np.where(course, CAUSES.index("collision course"), cause)
    relay, cycle = _relay(g, rule, d.V, code, d.worse, d.forward, d.N_forward, d.N_reverse, excursion)
    amplitude = np.where(relay, np.maximum(amplitude, cycle), amplitude)
    code, cause = np.where(relay, 1, code), np.where(relay, CAUSES.index("relay"), cause)
    return replace(d, code=code, cause=cause, oscillates=oscillates, amplitude=amplitude)


def _relay_cycle(jump, ahead, N_smooth, NV_critical: float, V):
    """The window-edge relay's cycle (m) by the describing function of one jump beside the smooth slope, per unit
    forward force (`relay.relay_amplitude`; capped at `driven.LEAVES`, 0 where not finite).

    Parameters
    ----------
    jump : ndarray
        The jump of F_n, F_ct units.
    ahead : ndarray
        The forward force of the travel direction, F_ct units.
    N_smooth : ndarray
        The smooth gain there, 1/m.
    NV_critical : float
        The loop's NV*, 1/s.
    V : float or ndarray
        Speed, m/s.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        cycle = np.minimum(relay_amplitude(jump / np.where(ahead > 0, ahead, np.nan), NV_critical / V, N_smooth), LEAVES)
    return np.nan_to_num(cycle)


def _relay(g: RouteGeometry, rule: DecisionRule, V: float, code, worse, forward, N_forward, N_reverse, excursion) -> tuple:
    """(relay, cycle) per sample: the window-edge relay holds a cycle of at least the episodes' amplitude where the
    sample is otherwise stable (module docstring) — by the describing function of its jump and, where the loop is
    driven, by the driven loop's excursion too."""
    relay, cycle = np.zeros(g.x.size, dtype=bool), np.zeros(g.x.size)
    NV_star = rule.boundary.NV_critical
    check = np.flatnonzero((code == 0) & g.relay_found)
    if not (check.size and NV_star and math.isfinite(NV_star) and NV_star > 0):
        return relay, cycle
    d = worse[check]
    N_smooth = np.nan_to_num(np.where(d == 0, N_forward[check], N_reverse[check]))
    cycle[check] = _relay_cycle(g.relay_jump[check], forward[d, check], N_smooth, NV_star, V)
    if excursion is not None:  # the loop driven through the whole profile must stray as far there (docstring)
        cycle[check] = np.minimum(cycle[check], excursion[check])
    relay[check] = cycle[check] >= AMPLITUDE_THRESHOLD  # a limit cycle the episodes' judge would see
    return relay, cycle




RENORMALIZE = 8
"""Steps between renormalizations of the window products (their scale is kept as a logarithm)."""
ROUND_OFF_EFOLDS = 1e-9
"""|e-folds| over a window below which a window product's growth is round-off (the neutral lateral mode, z = 1,
of a window with no field): 0."""


def _window_products(Ns: tuple, route: np.ndarray, arc: np.ndarray, half: float, V: float, transition: SampledTransition,
                     centres: np.ndarray | None = None) -> tuple:
    """(rates, seconds), one array each per travel direction of `Ns` (forward, reverse): the growth rate (1/s) over the
    window around each sample of the sampled loop driven along the route at V, log ρ(Φ(N_M·V)···Φ(N_1·V)) / (M·T), the
    robot at arc V·T apart taking the N of its nearest sample (nan N: the robot is stopped there that way; those steps
    are left out), and the window's time M·T (s); nan for a window with no step, and for the samples not among
    `centres` (bool, default all). Every route's windows in both directions have the same M steps: they are multiplied
    out together (`_product_efolds`)."""
    step = V * transition.T
    steps = int(math.ceil(2 * half / step))
    offsets = (np.arange(steps) + 0.5) * step - half
    where, gains, valid = [], [], []
    for k, N in enumerate(Ns):
        for r in np.unique(route):
            on = np.flatnonzero(route == r)
            idx = on if centres is None else on[centres[on]]
            if idx.size:
                rows, ok = _window_gains(N[on], arc[on], arc[idx], offsets[::-1] if k == 1 else offsets, step)
                where.append((k, idx))
                gains.append(rows)
                valid.append(ok)
    rates, seconds = [np.full(route.shape, np.nan) for _ in Ns], [np.zeros(route.shape) for _ in Ns]
    if not where:
        return rates, seconds
    gains, valid = np.concatenate(gains), np.concatenate(valid)
    log_rho = _product_efolds(np.where(valid, gains, 0.0) * V, valid, transition)
    duration = valid.sum(axis=1) * transition.T
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = np.where(duration > 0, log_rho / np.where(duration > 0, duration, 1.0), np.nan)
    rate = np.where((duration > 0) & (np.abs(log_rho) < ROUND_OFF_EFOLDS), 0.0, rate)  # a window with no step stays nan
    first = 0
    for k, idx in where:
        rates[k][idx], seconds[k][idx] = rate[first:first + idx.size], duration[first:first + idx.size]
        first += idx.size
    return rates, seconds


def _window_gains(N: np.ndarray, a: np.ndarray, centre: np.ndarray, offsets: np.ndarray, step: float) -> tuple:
    """(gains, valid), shape (windows, steps): the N (1/m) of the sample nearest each step of the windows centred at
    arc positions `centre` (m) of one route (samples at arcs `a` with gains `N`), the steps `offsets` (m) from the
    centre in the order driven, V·T = `step` (m) apart; valid where the step lies on the route (within half a sample
    spacing of its ends) and N is finite."""
    edges = (a[:-1] + a[1:]) / 2
    positions = centre[:, None] + offsets[None, :]
    first_gap, last_gap = (a[1] - a[0], a[-1] - a[-2]) if a.size > 1 else (step, step)
    inside = (positions >= a[0] - first_gap / 2) & (positions <= a[-1] + last_gap / 2)
    gains = N[np.searchsorted(edges, np.clip(positions, a[0], a[-1]))]
    return gains, inside & np.isfinite(gains)


def _product_efolds(NV: np.ndarray, valid: np.ndarray, transition: SampledTransition) -> np.ndarray:
    """log ρ(Φ(NV_M)···Φ(NV_1)) of each row: the e-folds of the sampled loop over a window of M steps with gains
    NV (1/s, shape (windows, M)); a step not `valid` (the robot stopped there) is left out (the identity).

    Parameters
    ----------
    NV : ndarray, shape (windows, M)
        N·V at each step, 1/s.
    valid : ndarray of bool, same shape
    transition : SampledTransition
    """
    n = transition.Phi0.shape[0]
    identity = np.eye(n)
    P = np.broadcast_to(identity, (NV.shape[0], n, n)).copy()
    log_scale = np.zeros(NV.shape[0])
    for m in range(NV.shape[1]):
        Phi = transition.Phi0[None] + NV[:, m][:, None, None] * transition.Phi1[None]
        Phi[~valid[:, m]] = identity  # the robot stopped at this step: left out
        P = Phi @ P
        if (m + 1) % RENORMALIZE == 0 or m == NV.shape[1] - 1:
            scale = np.abs(P).max(axis=(1, 2))
            scale[scale == 0] = 1.0
            P /= scale[:, None, None]
            log_scale += np.log(scale)
    with np.errstate(divide="ignore"):
        return np.log(np.abs(np.linalg.eigvals(P)).max(axis=1)) + log_scale


PROFILE_STEP = 0.25
"""Spacing of the lateral force profile across the route, histogram cells: a quarter cell, so that each jump of the
window sum (at the cell boundaries) lies between two nodes a quarter cell apart, as in `relay.window_relay`."""
PROFILE_PHASE_NODES = 1
"""Positions along the route within a cell over which the profile's force is averaged (`equilibria.lateral_force`'s
phase average; one: the cell's middle — the robot's run crosses every along-track position of the cell anyway)."""


def lateral_profile(grid, law, x, y, tx, ty, reach: float):
    """(offsets, F_n, F_r·t): the VFF force across each route point p, at p + s·nrm for the offsets s (m, every
    `PROFILE_STEP` cells within ±`reach`), in F_ct units, shape (points, offsets); nan inside an obstacle.

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : GridWallLaw
        KB's grid law.
    x, y : ndarray
        Route points, m.
    tx, ty : ndarray
        Unit travel directions.
    reach : float
        Largest |s|, m.
    """
    step = PROFILE_STEP * grid.cell_size
    half = int(math.ceil(reach / step))
    offsets = np.arange(-half, half + 1) * step
    S = offsets.size
    rep = lambda v: np.repeat(np.asarray(v, dtype=float), S)  # noqa: E731
    fn, ft = lateral_force(grid, law, rep(x), rep(y), rep(tx), rep(ty), np.tile(offsets, np.size(x)), phase_nodes=PROFILE_PHASE_NODES)
    return offsets, fn.reshape(-1, S), ft.reshape(-1, S)
