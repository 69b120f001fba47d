"""Verdicts along every route: the lateral loop linearized about the path the VFF robot follows (docs/maps.md).

A route (`routes.RoutePath`: a skeleton branch through its junctions, or the user's own
route) is sampled every cell c along its arc. At each sample p with travel direction t
(the route's tangent) and left normal nrm the robot's path is

* its lateral equilibrium p + s0·nrm, the root of F_n nearest the route in the free band
  (`equilibria.equilibria_at`, the corridor analysis' search), where there is one;
* the route itself (s0 = 0) where there is none: a single wall, an open hall, a junction,
  a wall ahead. The lateral force is not zero there, so the path bends away, but the
  deviation between neighbouring paths obeys the same linear loop with the local gradient:
  the variational equation about any trajectory has the Jacobian at that trajectory.

At that point the lateral gain of each travel direction is
N = −(dF_n/ds)/(1 ± F_r·t) (1/m; `Samples.directional`), the heading gain c is 0 (the
static field), and the loop is KB's (`Loop.of` through `models.Loop`): σ(N·V), the real part of
the model's rightmost root (`verdicts.GrowthRate`), is how fast a lateral disturbance grows
there (1/s), and `models.verdicts.judge_arrays` gives the local verdict and margin.

**The verdict of a point** is the growth accumulated over a window of the route around it
(`WINDOW_PERIODS` oscillation wavelengths λ = 2πV/ω*, clipped at the route's ends). With the
`sampled` model (the default: the controller's own loop) it is exact for the loop whose gain varies
along the path: the product of the one-period transition matrices Φ(N(s_k)·V) of the robot's
steps s_k = s + k·V·T through the window (`SampledTransition`), σ̄_w = log ρ(product)/duration
(for a uniform N exactly σ(N·V)); a gain spike shorter than a period adds what it really adds,
not its frozen σ. With the other models, σ̄_w is the mean of σ(N·V) over the window,
exp(∫σ(s)/V ds). The point is unstable when a disturbance gains at least `verdicts.EFOLDS` (one)
e-fold in the worse travel direction over the window, σ̄_w·duration >= 1, or over the run of consecutive growing
windows around it (`decide.run_efolds`: a long corridor that grows slowly); stable otherwise. A
field too weak to move the robot, or none (an open hall: N = 0, σ = σ(0) = 0 when the
heading loop is stable), is a verdict: "nothing grows here", stable, margin inf or large.
**A wall ahead.** Where the repulsion along the route cancels more than `verdicts.END_FRACTION` of the
attraction (1 ± F_r·t < 1 − END_FRACTION) the forward force collapses and N = −F_n′/F_t grows without bound:
the robot turns there (its goal lies along the route, round the bend or at the dead end), it does not oscillate
about a line. That travel direction is not judged at those samples (left out of its window; the corridor
analysis' end rule, `verdicts.judged_run`), the other direction still is. What cannot be judged is named
(`UNJUDGED`): a wall ahead both ways (a narrow dead end), or a sample inside an obstacle.

**The window-edge relay** (`relay.window_relay`): where F_n jumps within a cell of the path (the window gaining or
losing a wall's column as the robot moves a cell sideways) by more than its smooth change over a cell, and the jump
restores (pushes the robot back across it), the robot holds a sustained oscillation of about a cell's amplitude
there, which the smooth linearization cannot see: such a sample is unstable, its cause "relay", where
the cycle reaches the episodes' threshold — by the describing function of the jump (`relay.relay_amplitude`) and,
with the sampled model, by the loop driven along the route there too (below: it runs the whole profile, the
sampling and the rate limit; the one jump's first harmonic runs high near the threshold): its lateral excursion
about its one-period average within half a period of the sample must reach the threshold as well.

**The loop driven along the route** (`driven_loops`): the sampled loop is also run along each route through the force
across it (`lateral_profile`, every quarter cell: the window sum's jumps, a rack's staircase, a one-sided field), with
the steering-rate limit on its command (`SampledTransition`, `models.sampled.command_form`); its episodes (the
drives' own definition, `maps.judging.episodes`) mark the route unstable (cause "forced weave"): a forced weave, or a cycle the
nonlinearity holds, that the window growth cannot see.

**Paths taken** (``taken``: the paths the simulated robot drove, between goals or in the validation,
`validation.map_drives`). Its goal, not only the field, holds the robot there: a lateral equilibrium farther than W/2
from the path is not the one it follows, so the loop is linearized at the path itself, and the line it is pulled to
is the path. The goal's pull balances the field's mean P there (over a wavelength along the path and a cell across
it, `_goal_pull`); the attraction has unit size, so its part along the path is A = √(1 − P²), and the lateral gain
is N = −(dF_n/ds − K)/(A ± F_r·t): a robot sliding along a wall towards a goal off to its side steers against a small
forward force, and its loop is that much stiffer. K = A²/D (`_aim_stiffness`) is the goal's own pull back to the
path: the point the robot steers at lies D ahead (a plan's carrot at its lookahead, or a point target), so a
lateral offset y turns the attraction by y/D — the whole lateral gain of a pure-pursuit robot in an open hall,
which oscillates once V/D passes NV*. Such a path is judged the way it was driven; where a wall is
ahead that way it is unjudged ("wall ahead").

**A drive's own path** (a path taken whose aims are known, `RoutePath.aims`: the point the robot steered at as it
passed each of its points) is driven as the robot drove it (`DrivenTrack`, `driven_loops`): the force at the loop's own
point p(s) + y·nrm is the window sum there, the attraction is the unit vector from there to the point steered at,
the loop moves along the path at its own pace, ds/dt = V·cos θ/(1 − κ·y) (`_TrackWalk`: a robot weaving about its path
covers less of it than V·t, and keeps its phase only at that pace), and the path's frame turns under it — its heading
loses the path's turn over each step (`SampledTransition.turn`), so a bend's onset kicks the loop as it kicks the
robot, and a steady bend is held where the carrot's lead asks for the turn. Its episodes and weave are judged on its
track in the plane by the drives' own judge (`episodes.episodes`, `episodes.swing`): the robot's weave is measured
about its own one-period average, and the path (that average) ripples about it too. The window growth and the
verdicts' N stay the linearization above.

**Stretches**: runs of consecutive samples with one verdict and cause (`PathStretch`), each with the
numbers of its worst window: σ̄_w, its e-folds, N_eff (`verdicts.effective_gain`: the uniform gain with that
growth); V* by the same rule at other speeds (`stretch_speed`: at or below it the stretch does not weave) and the
margin V*/V − 1, which has the verdict's sign (docs/maps.md, "One answer per stretch").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...io.serialize import json_number
from ...models.verdicts import inside as in_set, judge_arrays
from .decide import CAUSES, PATH_VERDICTS, UNJUDGED, DecisionRule, RouteGeometry, SampleDecision, decide, route_geometry
from ..reading.routes import polyline_arcs
from .stretch_speed import stretch_speeds
from .verdicts import END_FRACTION, GrowthRate, effective_gain

__all__ = ["PathStretch", "PathVerdicts", "RouteStretch", "analyze_paths", "routes_json", "verdict_lengths"]

@dataclass(frozen=True)
class RouteStretch:
    """A run of one verdict along one route: what a VFF stretch (`PathStretch`) and a Nav2 controller's
    (`tracking.TrackingStretch`) share.

    Attributes
    ----------
    route : int
        Index of the route in its result's ``paths``.
    start, stop : float
        Arc positions along the route, m.
    x0, y0, x1, y1 : float
        The end points on the route, m.
    length : float
        m.
    verdict : str
        "stable", "unstable", or why it is not decided.
    cause : str or None
        Why it is unstable; None when stable.
    """

    NUMBERS = ()
    """The fields that may be infinite, written "inf" in JSON (`to_dict`)."""

    route: int
    start: float
    stop: float
    x0: float
    y0: float
    x1: float
    y1: float
    length: float
    verdict: str
    cause: str | None = None

    @property
    def decided(self) -> bool:
        """True for "stable" and "unstable"."""
        return self.verdict in ("stable", "unstable")

    def to_dict(self) -> dict:
        """JSON-ready ("inf" for infinite values)."""
        out = dict(self.__dict__)
        for key in self.NUMBERS:
            out[key] = json_number(out[key]) if out[key] is not None else None
        return out


@dataclass(frozen=True)
class PathStretch(RouteStretch):
    """A run of one verdict along one route (`RouteStretch`).

    Attributes
    ----------
    route : int
        Index of the route in `PathVerdicts.paths`.
    start, stop : float
        Arc positions along the route, m.
    x0, y0, x1, y1 : float
        The end points on the route, m.
    length : float
        m.
    verdict : str
        "stable", "unstable", or a reason of `UNJUDGED`.
    cause : str or None
        Why it is unstable (`CAUSES`): "growth" (the linear loop), "forced weave" (the field's ripple drives a weave),
        "relay" (the window's edge), "collision course" (the driven loop meets an obstacle without a weave first);
        None when stable.
    growth_rate : float or None
        σ̄_w of the worst window at V, 1/s: the linear loop's (a forced weave or a relay weaves with it negative).
    efolds : float or None
        e-folds a disturbance gains (< 0: loses) over the worst window (σ̄_w times the window's time).
    N : float or None
        N_eff of the worst window, 1/m (the uniform gain with its growth, `verdicts.effective_gain`; 0: no field).
    margin : float or None
        V*/V − 1: how much faster (> 0) the robot may drive, or how much slower (< 0) it must (inf: no speed weaves).
        It is the report's NV*/NV − 1 where the gain is uniform.
    V_critical : float or None
        V*, m/s, the edge of the calm speeds nearest V (`stretch_speed`): for a stable stretch the first speed above V
        at which it weaves (inf: none), for an unstable one the fastest speed below V at which it does not (0: none
        down to `stretch_speed.SPEED_STEPS` steps). So V* >= V exactly when the verdict is stable.
    direction : str or None
        "forward" (along the route's order) or "reverse": the worse travel direction of the worst window.
    linearized_at_route : float
        Fraction of the stretch's samples without a lateral equilibrium (linearized about the route).
    oscillates : bool
        The loop driven along the route weaves over part of it (`maps.judging.episodes`).
    amplitude : float
        The weave's predicted size: the largest lateral oscillation the loop driven along the route holds on it, m
        (`maps.judging.episodes.lateral_extent`; `LEAVES` where it left the corridor: at least that; a relay's cycle where that
        is larger).
    """

    NUMBERS = ("growth_rate", "efolds", "N", "margin", "V_critical")

    growth_rate: float | None = None
    efolds: float | None = None
    N: float | None = None
    margin: float | None = None
    V_critical: float | None = None
    direction: str | None = None
    linearized_at_route: float = 0.0
    oscillates: bool = False
    amplitude: float = 0.0


@dataclass(frozen=True)
class PathVerdicts:
    """Every route's samples and stretches.

    Attributes
    ----------
    paths : tuple of RoutePath
    samples : equilibria.Samples
        The equilibria at the samples (`segment`: the route index; nan N without an equilibrium).
    arc : ndarray
        Arc position of each sample along its route, m.
    spacing : ndarray
        Route length per sample, m (each sample stands for that much route).
    px, py : ndarray
        The linearization point of each sample (the equilibrium, or the route point), m.
    N_forward, N_reverse : ndarray
        Lateral gain of each travel direction at that point, 1/m (nan: the robot is stopped that way).
    sigma_forward, sigma_reverse : ndarray
        σ(N·V) of each direction, 1/s.
    window_growth : ndarray
        σ̄_w of the worse direction, 1/s (nan: unjudged).
    code : ndarray of int
        Index into `PATH_VERDICTS` per sample.
    local_verdict, local_margin : ndarray
        `models.verdicts.judge_arrays` of the worse direction's own gain (no window).
    window : float
        Window length Λ, m.
    stretches : tuple of PathStretch
    oscillates : ndarray of bool
        The linear loop driven along the route weaves here (`maps.judging.episodes`: a forced or growing oscillation).
    amplitude : ndarray
        The predicted lateral oscillation at each sample, m (the largest of the runs passing it; as on `PathStretch`).
    cause : ndarray of int
        Index into `CAUSES` where unstable, −1 elsewhere (`relay`: where it is the window-edge relay).
    """

    paths: tuple
    samples: object
    arc: np.ndarray
    spacing: np.ndarray
    px: np.ndarray
    py: np.ndarray
    N_forward: np.ndarray
    N_reverse: np.ndarray
    sigma_forward: np.ndarray
    sigma_reverse: np.ndarray
    window_growth: np.ndarray
    code: np.ndarray
    local_verdict: np.ndarray
    local_margin: np.ndarray
    window: float
    stretches: tuple
    oscillates: np.ndarray = None
    amplitude: np.ndarray = None
    cause: np.ndarray = None

    @property
    def relay(self) -> np.ndarray:
        """Per sample: the window-edge relay holds the robot in a sustained oscillation here (`maps.deciding.relay`; cause
        "relay")."""
        return self.cause == CAUSES.index("relay")

    @property
    def route_length(self) -> float:
        """Total length of the routes, m."""
        return float(sum(p.length for p in self.paths))

    def length_of(self, verdict: str) -> float:
        """Route length with verdict `verdict` (m).

        Parameters
        ----------
        verdict : str
            One of `PATH_VERDICTS`.
        """
        return float(self.spacing[self.code == PATH_VERDICTS.index(verdict)].sum())

    def summary(self) -> dict:
        """``route_length_m``, ``decided_length_m``, ``decided_fraction``, ``unstable_length_m``, ``stable_length_m``,
        ``linearized_at_route_length_m``, ``unstable_length_by_cause_m`` (`CAUSES`), ``unjudged_length_m`` per reason,
        ``window_m``, ``V_critical_min`` (the smallest V* of a decided stretch, m/s)."""
        values = [s.V_critical for s in self.stretches if s.verdict == "unstable" and s.V_critical is not None]
        values += [s.V_critical for s in self.stretches if s.verdict == "stable" and s.V_critical is not None]
        return {
            **verdict_lengths(len(self.paths), float(self.spacing.sum()), self.length_of),
            "linearized_at_route_length_m": float(self.spacing[~np.isfinite(self.samples.offset)].sum()),
            "unstable_length_by_cause_m": {c: float(self.spacing[self.cause == k].sum()) if self.cause is not None else 0.0
                                           for k, c in enumerate(CAUSES)},
            "unjudged_length_m": {r: self.length_of(r) for r in UNJUDGED},
            "window_m": json_number(self.window),
            "V_critical_min": json_number(min(values)) if values else None,
        }

    def to_dict(self) -> dict:
        """``routes`` (source, length, points), ``stretches``, ``summary``."""
        return {
            "routes": routes_json(self.paths),
            "stretches": [s.to_dict() for s in self.stretches],
            "summary": self.summary(),
        }


def verdict_lengths(routes: int, total: float, length_of) -> dict:
    """The lengths a map's result set summarises (`PathVerdicts.summary`, `tracking.TrackingVerdicts.summary`):
    ``routes``, ``route_length_m``, ``decided_length_m``, ``decided_fraction`` (None without route),
    ``unstable_length_m``, ``stable_length_m``.

    Parameters
    ----------
    routes : int
        How many routes.
    total : float
        Their length, m.
    length_of : callable
        ``length_of(verdict)``: the route length with that verdict, m.
    """
    stable, unstable = length_of("stable"), length_of("unstable")
    return {"routes": routes, "route_length_m": total, "decided_length_m": stable + unstable,
            "decided_fraction": (stable + unstable) / total if total > 0 else None,
            "unstable_length_m": unstable, "stable_length_m": stable}


def routes_json(paths) -> list:
    """The routes, JSON-ready: each one's source, length (m) and points (m).

    Parameters
    ----------
    paths : sequence of RoutePath
    """
    return [{"source": p.source, "length": p.length, "points": [[float(a), float(b)] for a, b in p.points]} for p in paths]


def analyze_paths(grid, law, paths, clearance: np.ndarray, W: float, V: float, boundary, growth: GrowthRate,
                  heading_stable: bool, transition=None, end_fraction: float = END_FRACTION, taken=False,
                  speeds: bool = True) -> PathVerdicts:
    """The verdict at every point of every route, and each stretch's one answer (module docstring).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : GridWallLaw
        KB's grid law of the robot.
    paths : sequence of RoutePath
        The routes.
    clearance : ndarray, shape (nx, ny)
        Distance to the nearest occupied cell, m, per histogram cell.
    W : float
        Robot width, m.
    V : float
        Speed, m/s.
    boundary : Boundary
        The loop model's boundary (c = 0).
    growth : GrowthRate
        The model's σ(NV).
    heading_stable : bool
        The model's verdict at NV = 0 (its heading loop).
    transition : SampledTransition, optional
        The sampled loop's Φ(NV) (`SampledTransition`): the window's growth is then that of the product of the
        transition matrices along the window (the loop with a gain varying along the path, exactly), and the loop is
        driven along the routes (the forced weave, the relay's confirmation); without it, the mean of σ(N·V) over the
        window.
    end_fraction : float
        A travel direction is not judged where the repulsion ahead cancels more than this fraction of the attraction
        (1 ± F_r·t < 1 − end_fraction: `verdicts.END_FRACTION`): the robot turns there (module docstring).
    taken : bool or sequence of bool
        The routes (all, or each) are paths the simulated robot took (its goal holds it there, not only the field): a
        lateral equilibrium farther than W/2 from the path is not the robot's, the path itself is the line it follows
        (linearized there, no pull towards the equilibrium), judged the way it was driven (module docstring, "Paths
        taken").
    speeds : bool
        Find each stretch's V* (`stretch_speed`); False: the verdicts alone, V* and margin None (the validation's
        drives' own paths, whose samples' verdicts alone are scored: the V* search reruns the driven loop per speed).
    """
    rule = DecisionRule(grid, law, W, boundary, growth, heading_stable, transition, end_fraction)
    geometry = route_geometry(grid, law, tuple(paths), clearance, W, taken, drive=rule.drives)
    at = decide(geometry, rule, V)
    runs = _runs(geometry, at)
    speeds = stretch_speeds(geometry, rule, V, at, runs) if speeds else [None] * len(runs)
    stretches = tuple(_stretch(geometry, rule, V, at, run, speed) for run, speed in zip(runs, speeds))
    NV = np.nan_to_num(at.N_worse) * V
    local_stable = np.array([bool(heading_stable) if v == 0 else in_set(boundary, float(v)) for v in NV]) if NV.size else np.zeros(0, bool)
    local_verdict, local_margin = judge_arrays(NV, np.full(NV.shape, boundary.NV_critical), local_stable)
    return PathVerdicts(geometry.paths, geometry.samples, geometry.arc, geometry.ds, geometry.px, geometry.py, at.N_forward, at.N_reverse,
                        at.sigma[0], at.sigma[1], at.window_growth, at.code, local_verdict, local_margin, at.window, stretches,
                        at.oscillates, at.amplitude, at.cause)


@dataclass(frozen=True)
class _Run:
    """A run of samples with one verdict and cause along one route: its sample indices and its worst window's sample."""

    route: int
    samples: np.ndarray
    worst: int | None


def _runs(g: RouteGeometry, at: SampleDecision) -> list:
    """The runs of one verdict and cause along each route, with the sample of the worst window of each decided run."""
    out = []
    for r in range(len(g.paths)):
        idx = np.flatnonzero(g.route == r)
        if idx.size == 0:
            continue
        breaks = np.flatnonzero(np.diff(at.code[idx] * 10 + at.cause[idx]) != 0) + 1
        for run in np.split(idx, breaks):
            worst = int(run[int(np.nanargmax(at.window_growth[run]))]) if at.code[run[0]] < 2 else None
            out.append(_Run(r, run, worst))
    return out


def _stretch(g: RouteGeometry, rule: DecisionRule, V: float, at: SampleDecision, run: _Run, V_star) -> PathStretch:
    """A run's `PathStretch`: its ends, verdict and cause, V* (`stretch_speed.stretch_speeds`), the speed margin, the
    predicted weave, and the worst window's linear numbers."""
    r, idx = run.route, run.samples
    first, last = idx[0], idx[-1]
    start, stop = float(g.arc[first] - g.ds[first] / 2), float(g.arc[last] + g.ds[last] / 2)
    points = g.paths[r].points
    edges = polyline_arcs(points)
    ends = [float(np.interp(a, edges, points[:, k])) for a in (start, stop) for k in (0, 1)]
    base = dict(route=r, start=start, stop=stop, x0=ends[0], y0=ends[1], x1=ends[2], y1=ends[3], length=float(g.ds[idx].sum()),
                verdict=PATH_VERDICTS[at.code[first]], linearized_at_route=float(np.mean(~g.has[idx])))
    if run.worst is None:
        return PathStretch(**base)
    k = run.worst
    d = int(at.worse[k])
    near = np.flatnonzero((g.route == r) & (np.abs(g.arc - g.arc[k]) <= at.window / 2))
    N = np.stack([at.N_forward, at.N_reverse])[d, near]
    N_eff = _effective(float(at.window_growth[k]), float(at.mean_N[d, k]), N[np.isfinite(N)], V, rule)
    cause = CAUSES[at.cause[first]] if at.cause[first] >= 0 else None
    return PathStretch(**base, cause=cause, growth_rate=float(at.window_growth[k]), efolds=float(at.efolds[k]), N=N_eff,
                       margin=None if V_star is None else V_star / V - 1.0, V_critical=None if V_star is None else float(V_star),
                       direction=("forward", "reverse")[d],
                       oscillates=bool(at.oscillates[idx].any()), amplitude=float(at.amplitude[idx].max()))


def _effective(sigma: float, mean_N: float, N: np.ndarray, V: float, rule: DecisionRule) -> float:
    """N_eff of a window (`verdicts.effective_gain`; 0 for a window with no field), 1/m."""
    if N.size == 0 or not np.any(N != 0):
        return 0.0
    return float(effective_gain(sigma, mean_N, V, rule.growth, rule.boundary.NV_critical))


