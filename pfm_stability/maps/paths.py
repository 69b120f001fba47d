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
there, which the smooth linearization cannot see: such a sample is unstable, its stretch labelled "relay".

**Paths taken** (``taken``: the paths the simulated robot drove between goals, `validation.map_drives`). Its goal,
not only the field, holds the robot there: a lateral equilibrium farther than W/2 from the path is not the one it
follows, so the loop is linearized at the path itself, and the line it is pulled to is the path.

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
from .relay import relay_amplitude, window_relay
from .routes import RoutePath  # noqa: F401 (named in the docstrings and annotations)
from .verdicts import EFOLDS, END_FRACTION, GrowthRate, critical_speed, effective_gain, wavelength

__all__ = ["PATH_VERDICTS", "RENORMALIZE", "ROUND_OFF_EFOLDS", "UNJUDGED", "WINDOW_PERIODS", "PathStretch", "PathVerdicts", "SampledTransition",
           "analyze_paths", "path_samples"]

WINDOW_PERIODS = 3.0
"""Length of the window whose accumulated growth decides a point, in oscillation wavelengths λ = 2πV/ω*: the
simulator's oscillation metrics need three periods to call a growth (`validation.map_selection.MIN_PERIODS`), and an
episode of the driving validation is a growth over at least three periods (`validation.map_drives`)."""
PATH_NEWTON_STEPS = 12
"""Newton steps per equilibrium along the routes (`equilibria.equilibria_at`): the corridor analysis' `NEWTON_STEPS`.
With 6 (a jump located to < 1 mm) the depot's north-wall weave at CARMEL's preset, predicted near the episode
threshold, was lost (recall 97 % -> 54 %): the forced weave is that sensitive to where the line is."""
UNJUDGED = ("wall ahead both ways", "inside an obstacle")
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
        The largest lateral amplitude the linear loop predicts for the runs through it, m.
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
        The largest predicted lateral amplitude of the run through each sample, m.
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


def analyze_paths(grid, law, paths, clearance: np.ndarray, W: float, V: float, boundary, growth: GrowthRate,
                  heading_stable: bool, transition=None, end_fraction: float = END_FRACTION, taken: bool = False) -> PathVerdicts:
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
    taken : bool
        The routes are paths the simulated robot took (its goal holds it there, not only the field): a lateral
        equilibrium farther than W/2 from the path is not the robot's, and the path itself is the line it follows
        (linearized there, no pull towards the equilibrium; module docstring, "Paths taken").
    """
    paths = tuple(paths)
    x, y, tx, ty, route, arc, ds = path_samples(paths, grid.cell_size)
    samples = equilibria_at(grid, law, x, y, tx, ty, route, clearance, W, newton_steps=PATH_NEWTON_STEPS)
    has = np.isfinite(samples.offset)
    along, slope = np.array(samples.along, dtype=float), samples.N * samples.forward  # −dF_n/ds at the equilibrium
    if taken:  # an equilibrium the robot's own path keeps away from is not the one it follows
        far = has & (np.abs(np.nan_to_num(samples.offset)) > W / 2)
        has = has & ~far
        slope = np.where(far, np.nan, slope)
    offset = np.where(has, samples.offset, 0.0)
    px, py = x - ty * offset, y + tx * offset
    # the gradient at the route's own point where there is no equilibrium (and at an equilibrium the repulsion stops
    # the robot at in one direction, where the corridor search keeps no N)
    redo = np.flatnonzero(~np.isfinite(slope))
    pull = np.zeros(x.size)  # F_n at the linearization point (0 at an equilibrium)
    if redo.size:
        fn0, ft0, df0 = lateral_force(grid, law, x[redo], y[redo], tx[redo], ty[redo], offset[redo], jacobian=True)
        along[redo], slope[redo], pull[redo] = ft0, -df0, np.where(has[redo] | taken, 0.0, fn0)
    inside = ~(np.isfinite(along) & np.isfinite(slope))
    with np.errstate(divide="ignore", invalid="ignore"):
        N_forward = np.where(1 + along >= 1 - end_fraction, slope / (1 + along), np.nan)
        N_reverse = np.where(1 - along >= 1 - end_fraction, slope / (1 - along), np.nan)
    N_forward[inside], N_reverse[inside] = np.nan, np.nan
    sig = [np.where(np.isfinite(n), growth(np.nan_to_num(n) * V), np.nan) for n in (N_forward, N_reverse)]
    lam = wavelength(V, boundary.omega_critical)
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
    code = np.where(stopped, 2, code)
    code = np.where(inside, 3, code)
    code = np.where(~np.isfinite(window_growth) & (code < 2), 2, code)
    # the equilibrium line the loop is pulled to: s0, or without one the linear extrapolation F_n/(−dF_n/ds) from the
    # route point (a virtual equilibrium), within the room the robot has there
    i, j = grid.cell_index(x, y)
    room = np.maximum(clearance[np.clip(i, 0, clearance.shape[0] - 1), np.clip(j, 0, clearance.shape[1] - 1)] - W / 2, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        virtual = np.where(slope > 0, pull / slope, 0.0)
    line = np.where(has, offset, np.clip(np.nan_to_num(virtual), -room, room))
    oscillates = np.zeros(x.size, dtype=bool)
    amplitude = np.zeros(x.size)
    if transition is not None and boundary.omega_critical and boundary.omega_critical > 0:
        oscillates, amplitude = _forced(route, arc, (N_forward, N_reverse), line, V, transition, 2 * math.pi / boundary.omega_critical)
        code = np.where((code == 0) & oscillates, 1, code)
    # the window-edge relay (`relay`): a restoring jump of F_n within a cell of the path, larger than its smooth change
    relay = np.zeros(x.size, dtype=bool)
    check = np.flatnonzero((code == 0) & (has | taken))  # where the robot's path is known: its equilibrium, or driven
    if check.size and boundary.NV_critical and math.isfinite(boundary.NV_critical) and boundary.NV_critical > 0:
        found, jump = window_relay(grid, law, x[check], y[check], tx[check], ty[check], offset[check], reference=~has[check])
        cycle = relay_amplitude(jump, boundary.NV_critical / V)
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


@dataclass(frozen=True)
class SampledTransition:
    """The sampled loop's one-period transition matrix Φ(NV) = Φ0 + NV·Φ1 (`models.sampled.closed_loop_matrix` is
    affine in the loop gain: only the feedback row depends on it).

    Attributes
    ----------
    Phi0, Phi1 : ndarray, shape (n, n)
        Φ at NV = 0 and its derivative in NV (s).
    T : float
        The period, s.
    """

    Phi0: np.ndarray
    Phi1: np.ndarray
    T: float

    @classmethod
    def of(cls, model, loop) -> "SampledTransition":
        """From a `models.Sampled` model and its loop (c = 0).

        Parameters
        ----------
        model : Sampled
            The loop model.
        loop : Loop
            KB's loop (τ, T, k, c).
        """
        from ..models.sampled import closed_loop_matrix

        def at(NV):  # Φ_cl at the loop gain NV (1/s)
            return np.asarray(closed_loop_matrix(loop, loop.loop_gain(NV), model.hold, model.compute_delay), dtype=float)

        Phi0 = at(0.0)
        return cls(Phi0, at(1.0) - Phi0, float(loop.T))


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


PREDICTION_OFFSET = 0.03
"""Lateral offset (m) of the linear loop's start from the equilibrium line in `_forced` (the drives' start offset,
`validation.maps.START_OFFSET`): the disturbance whose growth shows where the loop is unstable."""


LEAVES = 1.0
"""Lateral distance (m) from the route at which the linear loop's run stops: it has left any corridor (its amplitude
is then "at least this")."""


def _forced(route, arc, gains, line, V: float, transition: SampledTransition, period: float):
    """(oscillates, amplitude) per sample: the sampled loop driven along each route in both directions at V, pulled
    to the equilibrium line (x_{k+1} = Φ(N_k V)·x_k − N_k V·Φ1·s0_k e_y), started `PREDICTION_OFFSET` off it; its
    lateral position's episodes (`episodes.lateral_episodes`) mark the samples the robot passes meanwhile."""
    from .episodes import lateral_episodes

    y_index = int(np.flatnonzero(np.abs(transition.Phi1).sum(axis=0))[0])
    forcing = transition.Phi1[:, y_index]
    step = V * transition.T
    oscillates, amplitude = np.zeros(arc.size, dtype=bool), np.zeros(arc.size)
    runs = []  # (samples passed at each step, K, s0) of each route and direction
    for r in np.unique(route):
        idx = np.flatnonzero(route == r)
        a = arc[idx]
        if a.size < 2:
            continue
        positions = (np.arange(int((a[-1] + (a[1] - a[0]) / 2) / step)) + 0.5) * step
        if positions.size < 8:
            continue
        for d, N in enumerate(gains):
            pos = positions if d == 0 else positions[::-1]
            nearest = idx[np.clip(np.searchsorted((a[:-1] + a[1:]) / 2, pos), 0, a.size - 1)]
            runs.append((nearest, np.nan_to_num(N[nearest]) * V, line[nearest] if d == 0 else -line[nearest]))  # the normal flips
    if not runs:
        return oscillates, amplitude
    steps = max(r[0].size for r in runs)
    K, s0 = np.zeros((len(runs), steps)), np.zeros((len(runs), steps))
    for i, (nearest, k, line_k) in enumerate(runs):
        K[i, :k.size], s0[i, :k.size] = k, line_k
    state = np.zeros((len(runs), transition.Phi0.shape[0]))
    state[:, y_index] = s0[:, 0] + PREDICTION_OFFSET
    lateral = np.full((len(runs), steps), np.nan)
    alive = np.ones(len(runs), dtype=bool)
    for k in range(steps):
        lateral[alive, k] = state[alive, y_index]
        state = state @ transition.Phi0.T + K[:, k, None] * (state @ transition.Phi1.T - forcing[None, :] * s0[:, k, None])
        alive &= np.isfinite(state).all(axis=1) & (np.abs(state[:, y_index]) <= LEAVES)
        state[~alive] = 0.0
    t = np.arange(steps) * transition.T
    for i, (nearest, _, _) in enumerate(runs):
        m = nearest.size
        ok = np.isfinite(lateral[i, :m])
        found, peak = lateral_episodes(t[:m][ok], lateral[i, :m][ok], period)
        for lo, hi in found:
            oscillates[nearest[(t[:m] >= lo) & (t[:m] <= hi)]] = True
        amplitude[nearest] = np.maximum(amplitude[nearest], peak if ok.all() else max(peak, LEAVES))
    return oscillates, amplitude


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
            edges = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
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
