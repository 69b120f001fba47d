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
e-fold over the window, σ̄_w·duration >= 1, in the worse travel direction; stable otherwise. A
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
there, which the smooth linearization cannot see: such a sample is unstable, its stretch labelled "relay", where
the cycle reaches the episodes' threshold — by the describing function of the jump (`relay.relay_amplitude`) and,
with the sampled model, by the loop driven along the route there too (below: it runs the whole profile, the
sampling and the rate limit; the one jump's first harmonic runs high near the threshold): its lateral excursion
about its one-period average within half a period of the sample must reach the threshold as well.

**The loop driven along the route** (`_driven`): the sampled loop is also run along each route through the force
across it (`lateral_profile`, every quarter cell: the window sum's jumps, a rack's staircase, a one-sided field), with
the steering-rate limit on its command (`SampledTransition`, `models.sampled.command_form`); its episodes (the
drives' own definition, `maps.episodes`) mark the route unstable ("oscillates"): a forced weave, or a cycle the
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
passed each of its points) is driven as the robot drove it (`DrivenTrack`, `_driven`): the force at the loop's own
point p(s) + y·nrm is the window sum there, the attraction is the unit vector from there to the point steered at,
the loop moves along the path at its own pace, ds/dt = V·cos θ/(1 − κ·y) (`_TrackWalk`: a robot weaving about its path
covers less of it than V·t, and keeps its phase only at that pace), and the path's frame turns under it — its heading
loses the path's turn over each step (`SampledTransition.turn`), so a bend's onset kicks the loop as it kicks the
robot, and a steady bend is held where the carrot's lead asks for the turn. Its episodes and weave are judged on its
track in the plane by the drives' own judge (`episodes.episodes`, `episodes.swing`): the robot's weave is measured
about its own one-period average, and the path (that average) ripples about it too. The window growth and the
verdicts' N stay the linearization above.

**Stretches**: runs of consecutive samples with one verdict (`PathStretch`), each with the
numbers of its worst window: σ̄_w, e-folds σ̄_w·Λ/V, N_eff (`verdicts.effective_gain`:
the uniform gain with that growth), margin NV*/(N_eff·V) − 1, and V* (the speed at which that
window's mean growth crosses 0, `verdicts.critical_speed`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..io.serialize import json_number
from ..models import gain_margin, verdict_label
from ..models.verdicts import inside as in_set, judge_arrays
from .equilibria import Samples, equilibria_at, lateral_force
from .episodes import AMPLITUDE_THRESHOLD
from .driven import LEAVES, DrivenTrack, SampledTransition, _driven
from .relay import relay_amplitude, window_relay
from .routes import RoutePath, polyline_arcs  # noqa: F401 (RoutePath: named in the docstrings and annotations)
from .verdicts import EFOLDS, END_FRACTION, GrowthRate, critical_speed, effective_gain, wavelength

__all__ = ["PATH_VERDICTS", "RENORMALIZE", "ROUND_OFF_EFOLDS", "UNJUDGED", "WINDOW_PERIODS", "PathStretch", "PathVerdicts",
           "SampledTransition", "analyze_paths", "path_samples"]

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


@dataclass(frozen=True)
class PathStretch:
    """A run of one verdict along one route.

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
    label : str or None
        The worst window's label (`models.verdict_label`; "nothing grows" for a window with no field).
    growth_rate : float or None
        σ̄_w of the worst window, 1/s.
    efolds : float or None
        e-folds a disturbance gains (< 0: loses) over the worst window of the stretch (σ̄_w times the window's time).
    N : float or None
        N_eff of the worst window, 1/m.
    margin : float or None
        NV*/(N_eff·V) − 1 (inf: no field).
    V_critical : float or None
        V* of the worst window, m/s.
    direction : str or None
        "forward" (along the route's order) or "reverse": the worse travel direction of the worst window.
    linearized_at_route : float
        Fraction of the stretch's samples without a lateral equilibrium (linearized about the route).
    oscillates : bool
        The linear loop driven along the route weaves over part of it (`maps.episodes`).
    amplitude : float
        The largest lateral oscillation the loop driven along the route predicts on it, m (`maps.episodes.lateral_extent`;
        `LEAVES` where it left the corridor: at least that; a relay's cycle where that is larger).
    """

    route: int
    start: float
    stop: float
    x0: float
    y0: float
    x1: float
    y1: float
    length: float
    verdict: str
    label: str | None = None
    growth_rate: float | None = None
    efolds: float | None = None
    N: float | None = None
    margin: float | None = None
    V_critical: float | None = None
    direction: str | None = None
    linearized_at_route: float = 0.0
    oscillates: bool = False
    amplitude: float = 0.0

    @property
    def decided(self) -> bool:
        """True for "stable" and "unstable"."""
        return self.verdict in ("stable", "unstable")

    def to_dict(self) -> dict:
        """JSON-ready ("inf" for infinite values)."""
        out = dict(self.__dict__)
        for key in ("growth_rate", "efolds", "N", "margin", "V_critical"):
            out[key] = json_number(out[key]) if out[key] is not None else None
        return out


@dataclass(frozen=True)
class PathVerdicts:
    """Every route's samples and stretches.

    Attributes
    ----------
    paths : tuple of RoutePath
    samples : Samples
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
        The linear loop driven along the route weaves here (`maps.episodes`: a forced or growing oscillation).
    amplitude : ndarray
        The predicted lateral oscillation at each sample, m (the largest of the runs passing it; as on `PathStretch`).
    relay : ndarray of bool
        The window-edge relay holds the robot in a sustained oscillation here (`maps.relay`): unstable ("relay").
    """

    paths: tuple
    samples: Samples
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
    relay: np.ndarray = None

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
        ``no_equilibrium_length_m`` (linearized about the route), ``unjudged_length_m`` per reason, ``V_critical_min``."""
        total = float(self.spacing.sum())
        decided = self.length_of("stable") + self.length_of("unstable")
        values = [s.V_critical for s in self.stretches if s.verdict == "unstable" and s.V_critical is not None]
        values += [s.V_critical for s in self.stretches if s.verdict == "stable" and s.V_critical is not None]
        return {
            "routes": len(self.paths),
            "route_length_m": total,
            "decided_length_m": decided,
            "decided_fraction": decided / total if total > 0 else None,
            "unstable_length_m": self.length_of("unstable"),
            "stable_length_m": self.length_of("stable"),
            "linearized_at_route_length_m": float(self.spacing[~np.isfinite(self.samples.offset)].sum()),
            "relay_length_m": float(self.spacing[self.relay].sum()) if self.relay is not None else 0.0,
            "unjudged_length_m": {r: self.length_of(r) for r in UNJUDGED},
            "window_m": json_number(self.window),
            "V_critical_min": json_number(min(values)) if values else None,
        }

    def to_dict(self) -> dict:
        """``routes`` (source, length, points), ``stretches``, ``summary``."""
        return {
            "routes": [{"source": p.source, "length": p.length, "points": [[float(a), float(b)] for a, b in p.points]} for p in self.paths],
            "stretches": [s.to_dict() for s in self.stretches],
            "summary": self.summary(),
        }


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


def _goal_pull(grid, law, x, y, tx, ty, route, arc, ds, taken, wavelength_m: float):
    """(P, A) per sample, F_ct units: the lateral force F_n that the goal's pull balances where the robot holds its
    path, and the goal's attraction along the path (module docstring, "Paths taken"; P = 0, A = 1 on a route,
    whose goal lies along it).

    On a path the robot took, P is the field's mean over one wavelength λ of travel (the path is the robot's position
    averaged over a period: the goal and the path's curvature balance that mean, its ripple forces the loop) and
    across one cell (`_cell_mean`: where the path runs along a jump of the window sum, the robot holds the jump's
    middle, not the value on one side of it). The attraction has unit size, so its part along the path is
    A = √(1 − P²): the forward force the robot steers against is A ± F_r·t, not 1 ± F_r·t, when the goal lies off to
    the side (a robot sliding along a wall towards a goal behind it).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : GridWallLaw
        KB's grid law.
    x, y, tx, ty : ndarray
        Samples (m) and unit tangents.
    route, arc, ds : ndarray
        Route index, arc position (m) and length (m) of each sample.
    taken : ndarray of bool
        Per sample: on a path the robot took.
    wavelength_m : float
        λ = 2πV/ω*, m.
    """
    pull = np.zeros(np.size(x))
    on = np.flatnonzero(taken)
    if on.size and math.isfinite(wavelength_m):
        fn = np.full(np.size(x), np.nan)
        fn[on] = _cell_mean(grid, law, x[on], y[on], tx[on], ty[on])
        pull = np.where(taken, np.nan_to_num(_window_mean(fn, route, arc, ds, wavelength_m / 2)), 0.0)
    return pull, np.sqrt(np.clip(1.0 - pull ** 2, 0.0, None))


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


def analyze_paths(grid, law, paths, clearance: np.ndarray, W: float, V: float, boundary, growth: GrowthRate,
                  heading_stable: bool, transition=None, end_fraction: float = END_FRACTION, taken=False) -> PathVerdicts:
    """The verdict at every point of every route (module docstring).

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
        transition matrices along the window (the loop with a gain varying along the path, exactly); without it,
        the mean of σ(N·V) over the window.
    end_fraction : float
        A travel direction is not judged where the repulsion ahead cancels more than this fraction of the attraction
        (1 ± F_r·t < 1 − end_fraction: `verdicts.END_FRACTION`): the robot turns there (module docstring).
    taken : bool or sequence of bool
        The routes (all, or each) are paths the simulated robot took (its goal holds it there, not only the field): a
        lateral equilibrium farther than W/2 from the path is not the robot's, the path itself is the line it follows
        (linearized there, no pull towards the equilibrium), judged the way it was driven (module docstring, "Paths
        taken").
    """
    paths = tuple(paths)
    x, y, tx, ty, route, arc, ds = path_samples(paths, grid.cell_size)
    driven = np.broadcast_to(np.asarray(taken, dtype=bool), (len(paths),))  # per route
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
    lam = wavelength(V, boundary.omega_critical)
    pull, attraction = _goal_pull(grid, law, x, y, tx, ty, route, arc, ds, taken, lam)
    aim = _aim_stiffness(paths, route, x, y, attraction, W)
    slope = slope + aim
    forward = np.stack([attraction + along, attraction - along])  # the forward force of each travel direction
    with np.errstate(divide="ignore", invalid="ignore"):  # a wall ahead (the repulsion along the path) stops the robot
        N_forward = np.where((1 + along >= 1 - end_fraction) & (forward[0] > 0), slope / forward[0], np.nan)
        N_reverse = np.where((1 - along >= 1 - end_fraction) & (forward[1] > 0), slope / forward[1], np.nan)
    N_forward[inside], N_reverse[inside] = np.nan, np.nan
    N_reverse[taken] = np.nan  # the robot drove a path taken one way, from its start: the reverse is not its path
    sig = [np.where(np.isfinite(n), growth(np.nan_to_num(n) * V), np.nan) for n in (N_forward, N_reverse)]
    window = WINDOW_PERIODS * lam if math.isfinite(lam) else math.inf
    half = window / 2
    if transition is not None and math.isfinite(window):
        pairs = [_window_product(n, route, arc, half, V, transition, reverse=k == 1) for k, n in enumerate((N_forward, N_reverse))]
        means, seconds = [m for m, _ in pairs], [t for _, t in pairs]
    else:
        means = [_window_mean(s, route, arc, ds, half) for s in sig]
        seconds = [_window_mean(np.where(np.isfinite(s), 1.0, np.nan), route, arc, ds, half) * 0 + min(window, 1e9) / V for s in sig]
    mean_N = [_window_mean(n, route, arc, ds, half) for n in (N_forward, N_reverse)]
    with np.errstate(invalid="ignore"):
        worse = np.where(np.nan_to_num(means[1], nan=-np.inf) > np.nan_to_num(means[0], nan=-np.inf), 1, 0)
    rows = np.arange(x.size)
    window_growth = np.stack(means)[worse, rows]
    efolds = window_growth * np.stack(seconds)[worse, rows]
    code = np.where(efolds >= EFOLDS, 1, 0)  # a disturbance grows by at least one e-fold over the window
    stopped = ~np.isfinite(N_forward) & ~np.isfinite(N_reverse)
    wall = np.where(taken, PATH_VERDICTS.index("wall ahead"), PATH_VERDICTS.index("wall ahead both ways"))
    code = np.where(stopped, wall, code)
    code = np.where(inside, PATH_VERDICTS.index("inside an obstacle"), code)
    code = np.where(~np.isfinite(window_growth) & (code < 2), wall, code)
    oscillates = np.zeros(x.size, dtype=bool)
    amplitude = np.zeros(x.size)
    excursion = None  # the driven loop's, where it ran
    if transition is not None and boundary.omega_critical and boundary.omega_critical > 0:
        profile = lateral_profile(grid, law, x, y, tx, ty, LEAVES)
        stopped = np.stack([~np.isfinite(N_forward), ~np.isfinite(N_reverse)])
        track = DrivenTrack.of(grid, law, paths, x, y, tx, ty, route, arc) if taken.any() else None
        oscillates, amplitude, excursion = _driven(route, arc, stopped, profile, pull, attraction, aim, V, transition,
                                                   2 * math.pi / boundary.omega_critical, driven, track)
        code = np.where((code == 0) & oscillates, 1, code)
    # the window-edge relay (`relay`): a restoring jump of F_n within a cell of the path, larger than its smooth change
    relay = np.zeros(x.size, dtype=bool)
    check = np.flatnonzero((code == 0) & (has | taken))  # where the robot's path is known: its equilibrium, or driven
    if check.size and boundary.NV_critical and math.isfinite(boundary.NV_critical) and boundary.NV_critical > 0:
        found, jump = window_relay(grid, law, x[check], y[check], tx[check], ty[check], offset[check], reference=~has[check])
        # the describing function of one jump beside the smooth slope, per unit forward force, in the worse direction
        # (`relay.relay_amplitude`; the whole profile's, `relay.window_cycle`, is what the driven loop above runs through)
        d = worse[check]
        ahead = forward[d, check]
        N_smooth = np.nan_to_num(np.where(d == 0, N_forward[check], N_reverse[check]))
        with np.errstate(invalid="ignore", divide="ignore"):
            cycle = np.minimum(relay_amplitude(jump / np.where(ahead > 0, ahead, np.nan), boundary.NV_critical / V, N_smooth), LEAVES)
        cycle = np.nan_to_num(cycle)
        if excursion is not None:  # the loop driven through the whole profile must stray as far there (docstring)
            cycle = np.minimum(cycle, excursion[check])
        relay[check] = found & (cycle >= AMPLITUDE_THRESHOLD)  # a limit cycle the episodes' judge would see
        amplitude[check] = np.where(relay[check], np.maximum(amplitude[check], cycle), amplitude[check])
    code = np.where(relay, 1, code)
    N_worse = np.stack([N_forward, N_reverse])[worse, rows]
    NV = np.nan_to_num(N_worse) * V
    local_stable = np.array([bool(heading_stable) if v == 0 else in_set(boundary, float(v)) for v in NV]) if NV.size else np.zeros(0, bool)
    local_verdict, local_margin = judge_arrays(NV, np.full(NV.shape, boundary.NV_critical), local_stable)
    stretches = _stretches(paths, route, arc, ds, x, y, code, window_growth, worse, np.stack(mean_N), np.stack([N_forward, N_reverse]),
                           has, boundary, growth, heading_stable, V, window, efolds, oscillates, amplitude, relay)
    return PathVerdicts(paths, samples, arc, ds, px, py, N_forward, N_reverse, sig[0], sig[1], window_growth, code, local_verdict,
                        local_margin, window, stretches, oscillates, amplitude, relay)


RENORMALIZE = 8
"""Steps between renormalizations of the window products (their scale is kept as a logarithm)."""
ROUND_OFF_EFOLDS = 1e-9
"""|e-folds| over a window below which a window product's growth is round-off (the neutral lateral mode, z = 1,
of a window with no field): 0."""


def _window_product(N: np.ndarray, route: np.ndarray, arc: np.ndarray, half: float, V: float, transition: SampledTransition,
                    reverse: bool = False) -> np.ndarray:
    """The growth rate (1/s) over the window around each sample of the sampled loop driven along the route at V:
    log ρ(Φ(N_M·V)···Φ(N_1·V)) / (M·T), the robot at arc V·T apart taking the N of its nearest sample (nan N: the
    robot is stopped there that way; those steps are left out); nan for a window with no step."""
    out, seconds = np.full(N.shape, np.nan), np.zeros(N.shape)
    step = V * transition.T
    n = transition.Phi0.shape[0]
    for r in np.unique(route):
        idx = np.flatnonzero(route == r)
        a, g = arc[idx], N[idx]
        edges = (a[:-1] + a[1:]) / 2
        centre = a
        steps = int(math.ceil(2 * half / step))
        offsets = (np.arange(steps) + 0.5) * step - half
        if reverse:
            offsets = offsets[::-1]
        positions = centre[:, None] + offsets[None, :]
        inside = (positions >= a[0] - (a[1] - a[0] if a.size > 1 else step) / 2) & (positions <= a[-1] + (a[-1] - a[-2] if a.size > 1 else step) / 2)
        gains = g[np.searchsorted(edges, np.clip(positions, a[0], a[-1]))]
        valid = inside & np.isfinite(gains)
        P = np.broadcast_to(np.eye(n), (idx.size, n, n)).copy()
        log_scale = np.zeros(idx.size)
        for m in range(steps):
            Phi = transition.Phi0[None] + (np.where(valid[:, m], gains[:, m], 0.0) * V)[:, None, None] * transition.Phi1[None]
            Phi = np.where(valid[:, m][:, None, None], Phi, np.eye(n)[None])
            P = Phi @ P
            if (m + 1) % RENORMALIZE == 0 or m == steps - 1:
                scale = np.abs(P).max(axis=(1, 2))
                scale[scale == 0] = 1.0
                P /= scale[:, None, None]
                log_scale += np.log(scale)
        rho = np.abs(np.linalg.eigvals(P)).max(axis=1)
        with np.errstate(divide="ignore"):
            log_rho = np.log(rho) + log_scale
        count = valid.sum(axis=1)
        duration = count * transition.T
        with np.errstate(invalid="ignore", divide="ignore"):
            rate = np.where(count > 0, log_rho / np.where(duration > 0, duration, 1.0), np.nan)
        efolds = rate * duration
        out[idx] = np.where(np.abs(efolds) < ROUND_OFF_EFOLDS, 0.0, rate)
        seconds[idx] = duration
    return out, seconds


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


def _stretches(paths, route, arc, ds, x, y, code, window_growth, worse, mean_N, N, has, boundary, growth, heading_stable, V, window,
               efolds, oscillates, amplitude, relay):
    """The runs of one verdict along each route, with their worst window's numbers (module docstring)."""
    out = []
    for r in range(len(paths)):
        idx = np.flatnonzero(route == r)
        if idx.size == 0:
            continue
        breaks = np.flatnonzero(np.diff(code[idx] + 10 * relay[idx]) != 0) + 1
        for run in np.split(idx, breaks):
            first, last = run[0], run[-1]
            start, stop = float(arc[first] - ds[first] / 2), float(arc[last] + ds[last] / 2)
            points = paths[r].points
            edges = polyline_arcs(points)
            ends = [float(np.interp(a, edges, points[:, k])) for a in (start, stop) for k in (0, 1)]
            base = dict(route=r, start=start, stop=stop, x0=ends[0], y0=ends[1], x1=ends[2], y1=ends[3], length=float(ds[run].sum()),
                        verdict=PATH_VERDICTS[code[first]], linearized_at_route=float(np.mean(~has[run])))
            if code[first] >= 2:
                out.append(PathStretch(**base))
                continue
            k = run[int(np.nanargmax(window_growth[run]))]
            d = int(worse[k])
            sigma = float(window_growth[k])
            near = np.flatnonzero((route == r) & (np.abs(arc - arc[k]) <= window / 2))
            Nw = N[d, near]
            Nw = Nw[np.isfinite(Nw)]
            numbers = _window_numbers(sigma, float(mean_N[d, k]), Nw, V, float(efolds[k]), code[first] == 0, boundary, growth, heading_stable)
            numbers["efolds"] = float(efolds[k])
            if relay[first]:
                numbers["label"] = "relay"  # the window-edge relay (`maps.relay`): a sustained oscillation of ~ a cell
            elif code[first] == 1 and not numbers["efolds"] >= EFOLDS:
                numbers["label"] = "oscillates"  # a forced weave (`_forced`), the loop itself damped
            out.append(PathStretch(**base, **numbers, direction=("forward", "reverse")[d], oscillates=bool(oscillates[run].any()),
                                   amplitude=float(amplitude[run].max())))
    return tuple(out)


def _window_numbers(sigma, mean_N, N, V, efolds, verdict_stable, boundary, growth, heading_stable) -> dict:
    """label, growth_rate, N, margin, V_critical of one window with mean growth `sigma` (1/s), gains `N` (1/m) and
    `efolds` over it; `verdict_stable` is the point's verdict (less than one e-fold of growth: stable, "nothing grows")."""
    grows = sigma > 0
    if N.size == 0 or not np.any(N != 0):  # no field: the heading loop's verdict at NV = 0
        return dict(label="nothing grows" if heading_stable else "unstable", growth_rate=sigma, N=0.0,
                    margin=math.inf if heading_stable else -1.0, V_critical=math.inf if heading_stable else 0.0)
    N_eff = effective_gain(sigma, mean_N, V, growth, boundary.NV_critical)
    V_star = critical_speed(N, growth, boundary.NV_critical)
    if N_eff <= 0 or not math.isfinite(N_eff):
        margin = -1.0 if N_eff < 0 or grows else math.inf
        label = "unstable" if grows else "nothing grows"
    else:
        NV = N_eff * V
        margin = float(gain_margin(NV, boundary, not grows))
        label = verdict_label(NV, boundary, not grows)
    if verdict_stable and (grows or abs(efolds) < EFOLDS):
        label = "nothing grows"  # less than one e-fold either way over the window
    return dict(label=label, growth_rate=sigma, N=float(N_eff), margin=margin, V_critical=float(V_star))
