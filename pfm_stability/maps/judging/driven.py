"""The sampled loop driven along a route through the force across it (docs/maps.md, "The loop driven along the
route", "A drive's own path is driven as the robot drove it"; `maps.deciding.paths` judges with it).

`SampledTransition` is the sampled loop's one-period map with its command apart (the window growth's Φ(NV) and the
driven loop's step); `driven_loops` runs the loop along every route through the lateral force tabulated across it
(`paths.lateral_profile`), and along a drive's own path as the robot drove it (`DrivenTrack`: the window sum at the
loop's own point, the attraction towards the point the robot steered at, the path's frame turning under the loop at
the loop's own pace, `_TrackWalk`; its track judged in the plane by the drives' own judge, `maps.judging.episodes`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..reading.field import window_force
from ..reading.routes import polyline_arcs

__all__ = ["LEAVES", "OWN_STEPS", "PREDICTION_OFFSET", "DriveRequest", "DrivenLoop", "DrivenTrack", "SampledTransition", "driven_loops"]


@dataclass(frozen=True)
class SampledTransition:
    """The sampled loop's one-period transition matrix Φ(NV) = Φ0 + NV·Φ1 (`models.sampled.closed_loop_matrix` is
    affine in the loop gain: only the feedback row depends on it), and the same loop with its command apart
    (`models.sampled.command_form`): x_(k+1) = M·x_k + n·sat(v_k), v_k = −F0·x_k − gk·δ_k with δ_k the heading the
    lateral force asks for (−N·x to first order), sat the steering-rate limit.

    Attributes
    ----------
    Phi0, Phi1 : ndarray, shape (n, n)
        Φ at NV = 0 and its derivative in NV (s).
    T : float
        The period, s.
    M : ndarray, shape (n, n)
        The loop without the command.
    command : ndarray, shape (n,)
        Where the command v enters.
    F0 : ndarray, shape (n,)
        The command's feedback from the state at NV = 0 (the heading's).
    steering_gain : float
        g·k, 1/s: the command per radian of heading error, in motor units.
    rate_limit : float
        The largest |v|, rad/s: g·max_steering_rate with the command held (the simulator clips the held command);
        inf with the reference held (the servo's limit acts inside the period, which the one-period map does not see).
    lateral_index : int
        The state that holds the lateral position, as x/V (s).
    turn : ndarray, shape (n,)
        The state's change per radian the path's frame turns through during one period at a steady rate (the frame's
        rotation V·κ subtracted from the heading's rate: −turn·Δφ, Δφ the path's change of heading over the step; the
        heading's column of ∫₀ᵀ e^(As) ds / T, padded with zeros for the commands on their way).
    """

    Phi0: np.ndarray
    Phi1: np.ndarray
    T: float
    M: np.ndarray
    command: np.ndarray
    F0: np.ndarray
    steering_gain: float
    rate_limit: float
    lateral_index: int
    turn: np.ndarray

    @classmethod
    def of(cls, model, loop, max_steering_rate: float = math.inf) -> "SampledTransition":
        """From a `models.Sampled` model and its loop (c = 0).

        Parameters
        ----------
        model : Sampled
            The loop model.
        loop : Loop
            KB's loop (τ, T, k, g, D, c).
        max_steering_rate : float
            The robot's limit on its steering command, rad/s (`Robot.max_steering_rate`; inf: none).
        """
        from ...models.sampled import closed_loop_matrix, command_form, continuous_plant
        from ...numerics.matrix_exponential import zoh_blocks

        def at(NV):  # Φ_cl at the loop gain NV (1/s)
            return np.asarray(closed_loop_matrix(loop, loop.loop_gain(NV), model.hold, model.compute_delay), dtype=float)

        Phi0 = at(0.0)
        M, command, F0, F1 = command_form(loop, model.hold, model.compute_delay)
        limit = loop.plant_gain * max_steering_rate if model.hold == "command" else math.inf
        lateral = int(np.flatnonzero(F1)[0])
        A = continuous_plant(loop, model.hold)[0]
        turn = np.zeros(M.shape[0])
        turn[:A.shape[0]] = zoh_blocks(A, loop.T)[1][:, lateral - 1] / loop.T  # the heading precedes the lateral state
        return cls(Phi0, at(1.0) - Phi0, float(loop.T), M, command, F0, float(loop.steering_gain), float(limit), lateral, turn)


PREDICTION_OFFSET = 0.03
"""Lateral offset (m) of the loop's start from the route or path in `driven_loops` (the drives' start offset,
`validation.maps.START_OFFSET`): the disturbance whose growth shows where the loop is unstable. On a path taken too,
unless the pose the robot started from is known (a drive's own path: the loop starts there, `DrivenTrack.start`):
the loop's cycle is reached from above as from below (a rate-limited cycle at 1.7 cm, approached from 5 mm,
overshoots and dips under the episodes' threshold for periods on its way)."""


LEAVES = 1.0
"""Lateral distance (m) from the route at which the loop's run stops: it has left any corridor (its amplitude
is then "at least this")."""
def _path_heading(tx, ty, route) -> np.ndarray:
    """φ per sample, rad: the direction of each route's tangent, unwrapped along the route (continuous through its
    bends, so that its change over a stretch is the angle the path turns through there)."""
    heading = np.arctan2(ty, tx)
    for r in np.unique(route):
        on = route == r
        heading[on] = np.unwrap(heading[on])
    return heading


@dataclass(frozen=True)
class DrivenTrack:
    """What the loop driven along a drive's own path knows besides the force across it (`driven_loops`): the path's
    samples and direction, the point the robot steered at, and the field itself.

    Attributes
    ----------
    x, y : ndarray
        The samples, m.
    heading : ndarray
        φ per sample, rad (`_path_heading`).
    aims : ndarray, shape (2, samples)
        The point the robot steered at as it passed each sample, m (`RoutePath.aims`); nan where not known.
    force : callable
        ``force(x, y) -> (F_x, F_y)``: the VFF window sum at points (m), F_ct units (`field.window_force`).
    start : ndarray, shape (2, routes)
        Per route, where the robot started from its path's first sample: its offset to the left of the path (m) and
        its heading from the path's (rad, anticlockwise) (`RoutePath.start`); nan where not known.
    """

    x: np.ndarray
    y: np.ndarray
    heading: np.ndarray
    aims: np.ndarray
    force: object
    start: np.ndarray

    @classmethod
    def of(cls, grid, law, paths, x, y, tx, ty, route, arc) -> "DrivenTrack":
        """The track of the samples of `paths` on the map's histogram grid under KB's grid law.

        Parameters
        ----------
        grid : HistogramMap
            The map's histogram grid.
        law : GridWallLaw
            KB's grid law.
        paths : sequence of RoutePath
            The routes (`RoutePath.aims`: a drive's own path's).
        x, y, tx, ty : ndarray
            The samples (m) and unit tangents (`paths.path_samples`).
        route, arc : ndarray
            Route index and arc position (m) of each sample.
        """
        aims = np.full((2, np.size(x)), np.nan)
        heading = _path_heading(tx, ty, route)
        start = np.full((2, len(paths)), np.nan)
        for r, path in enumerate(paths):
            on = route == r
            if path.start is not None and on.any():
                first = np.flatnonzero(on)[0]
                dx, dy = path.start[0] - x[first], path.start[1] - y[first]
                phi = heading[first]
                start[:, r] = (math.cos(phi) * dy - math.sin(phi) * dx,
                               math.remainder(math.pi / 2 - path.start[2] - phi, 2 * math.pi))
            if path.aims is None:
                continue
            vertices = polyline_arcs(path.points)
            aims[0, on], aims[1, on] = (np.interp(arc[on], vertices, path.aims[:, k]) for k in (0, 1))
        return cls(np.asarray(x, dtype=float), np.asarray(y, dtype=float), heading, aims,
                   lambda px, py: window_force(grid, law, px, py), start)


@dataclass(frozen=True)
class DriveRequest:
    """One speed the loop is driven at (`driven_loops`), with what the rule at that speed says of each sample.

    Attributes
    ----------
    V : float
        Speed, m/s.
    stopped : ndarray of bool, shape (2, samples)
        Forward and reverse: the direction is not judged there (a wall ahead, `verdicts.END_FRACTION`): no lateral force.
    pull, attraction : ndarray
        The goal's pull across the path (P) and along it (A) per sample, F_ct units (0 and 1 on a route).
    aim : ndarray
        K per sample, F_ct/m (`decide._aim_stiffness`; 0 on a route).
    routes : ndarray of bool or None
        Per route index: drive the loop along these routes only (None: every route with samples).
    """

    V: float
    stopped: np.ndarray
    pull: np.ndarray
    attraction: np.ndarray
    aim: np.ndarray
    routes: np.ndarray | None = None


@dataclass(frozen=True)
class DrivenLoop:
    """What the loop driven at one speed shows at each sample (`driven_loops`).

    Attributes
    ----------
    oscillates : ndarray of bool
        An episode (`maps.judging.episodes`) of the loop's lateral motion passes the sample.
    collides : ndarray of bool
        The loop meets an obstacle within one period P after passing the sample (its disc leaves the free band,
        `contact.free_band`): the robot is on a collision course there.
    amplitude : ndarray
        The largest weave held there, m (`episodes.lateral_extent`; `LEAVES` where the run left the corridor).
    excursion : ndarray
        The farthest the loop strays from its one-period average within half a period, m (`LEAVES` likewise).
    """

    oscillates: np.ndarray
    collides: np.ndarray
    amplitude: np.ndarray
    excursion: np.ndarray


def driven_loops(route, arc, profile, requests, transition: SampledTransition, period: float, taken,
                 track: DrivenTrack | None = None) -> list:
    """The sampled loop driven along the routes at each requested speed (`DrivenLoop` per `DriveRequest`), all speeds'
    runs stepped together (one step of every run per period T).

    The loop is driven along each route at V through the real lateral force across it (`maps.deciding.paths` module docstring,
    "The loop driven along the route"), in both directions (a path taken: the way it was driven), started
    `PREDICTION_OFFSET` off it (a drive's own path: where the robot started, `DrivenTrack.start`); its lateral
    position's episodes (`episodes.lateral_episodes`, the drives' judge) mark the samples the robot passes meanwhile;
    amplitude is the largest weave held there and excursion the farthest it strays from its one-period average within
    half a period (`episodes.lateral_extent`, m); both `LEAVES` where the run left the corridor.

    ``x_{k+1} = M·x_k + n·sat(v_k)``, ``v_k = −F0·x_k − gk·g_k(y_k)`` (`SampledTransition`),
    g(y) = −atan2(F_n(y) − P − K·y, A ± F_r·t): the direction of the resultant the robot steers to (KB eq 4; the
    linear loop's N·y for small y) with the lateral force itself (interpolated in `profile` between its quarter
    cells), P and A what the goal balances across the path and its attraction along it, K the goal's pull back to
    the path, sat the steering-rate limit (`DriveRequest`). The run stops where it leaves the profile or `LEAVES`.

    **A drive's own path** (a path taken whose aims are known, `track`) is driven as the robot drove it (`maps.deciding.paths`
    module docstring, "A drive's own path"): at the loop's own point q = p(s) + y·nrm(s) the force is the window sum there
    (`DrivenTrack.force`, not the profile's value at the sample's cell middle), the attraction is the unit vector from q
    to the point the robot steered at (`RoutePath.aims`: its carrot, whose pull back to the path is the K·y above
    exactly), the loop moves along the path at its own pace (`_TrackWalk`), and it runs in the path's frame, which
    turns under it: each step subtracts the path's change of direction over the step from the heading
    (`SampledTransition.turn`); its episodes and weave are judged on its track q in the plane by the drives' own judge
    (`episodes.episodes`, `episodes.swing`), which measures the path's own ripple about its one-period average with it,
    as it does for the robot. It runs until it has come to the path's end (at most `OWN_STEPS` times the steps at V).

    Parameters
    ----------
    route, arc : ndarray
        Route index and arc position (m) of each sample.
    profile : tuple
        `decide.lateral_profile`'s (offsets, F_n, F_r·t), and optionally the free band across each sample
        (`contact.free_band`, shape (samples, 2); without it the loop meets no obstacle).
    requests : sequence of DriveRequest
        The speeds.
    transition : SampledTransition
        The loop.
    period : float
        The episodes' period P = 2π/ω*, s.
    taken : bool or ndarray of bool
        Per route (or all): a path the robot took.
    track : DrivenTrack, optional
        The drives' own paths' track (a path taken with its aims known is driven as the robot drove it).
    """
    taken = np.broadcast_to(np.asarray(taken, dtype=bool), (int(route.max()) + 1 if route.size else 0,))  # per route
    plan = _RunPlan.of(route, arc, requests, transition.T, taken, track)
    loops = [DrivenLoop(np.zeros(arc.size, dtype=bool), np.zeros(arc.size, dtype=bool), np.zeros(arc.size), np.zeros(arc.size))
             for _ in requests]
    if plan is None:
        return loops
    lateral, track_at, ended, contact = _step_loops(plan, route, arc, profile, requests, transition, period, track)
    _judge_runs(plan, lateral, track_at, ended, contact, transition.T, period, loops)
    return loops


@dataclass(frozen=True)
class _RunPlan:
    """The runs of `driven_loops`: each route at each requested speed, in each direction driven.

    Attributes
    ----------
    rows : ndarray of int, shape (runs, steps)
        The sample each run passes at each step (a drive's own path's: filled in as it goes, `_TrackWalk`).
    length : ndarray of int
        Steps of each run.
    sign : ndarray
        +1 along the route's order, −1 against it.
    V : ndarray
        Each run's speed, m/s.
    request : ndarray of int
        Each run's `DriveRequest`.
    own : ndarray of int
        The runs along a drive's own path.
    """

    rows: np.ndarray
    length: np.ndarray
    sign: np.ndarray
    V: np.ndarray
    request: np.ndarray
    own: np.ndarray

    @classmethod
    def of(cls, route, arc, requests, T: float, taken, track) -> "_RunPlan | None":
        """The runs (None: none long enough, 8 steps, to judge)."""
        runs = []  # (samples passed at each step, sign of travel, a drive's own path, request)
        samples_of = {int(r): np.flatnonzero(route == r) for r in np.unique(route)}  # the same at every speed
        for q, request in enumerate(requests):
            step = request.V * T
            for r, idx in samples_of.items():
                if (request.routes is not None and not request.routes[r]) or idx.size < 2:
                    continue
                a = arc[idx]
                positions = (np.arange(int((a[-1] + (a[1] - a[0]) / 2) / step)) + 0.5) * step
                if positions.size < 8:
                    continue
                mine = bool(taken[r] and track is not None and np.isfinite(track.aims[:, idx]).all())
                for d in ((0,) if taken[r] else (0, 1)):  # a path taken was driven one way, from its start
                    pos = positions if d == 0 else positions[::-1]
                    runs.append((idx[np.clip(np.searchsorted((a[:-1] + a[1:]) / 2, pos), 0, a.size - 1)], d, mine, q))
        if not runs:
            return None
        own = np.flatnonzero([mine for _, _, mine, _ in runs])
        length = np.array([n.size for n, _, _, _ in runs])
        steps = int(max(length.max(), math.ceil(OWN_STEPS * length[own].max()) if own.size else 0))
        length[own] = steps  # a drive's own path's loop runs until it has come to the path's end (`_TrackWalk`)
        rows = np.zeros((len(runs), steps), dtype=int)
        for i, (nearest, _, _, _) in enumerate(runs):
            rows[i, :nearest.size] = nearest
        request = np.array([q for _, _, _, q in runs])
        V = np.array([requests[q].V for q in request], dtype=float)
        return cls(rows, length, np.array([1.0 if d == 0 else -1.0 for _, d, _, _ in runs]), V, request, own)


def _step_loops(plan: _RunPlan, route, arc, profile, requests, transition: SampledTransition, period: float, track) -> tuple:
    """(lateral, track_at, ended, contact): every run stepped together (`driven_loops`): its lateral offset at each
    step (m; nan after it stopped), a drive's own path's point (m) and direction (rad) at each step (shape (3, own
    runs, steps)), the steps each run spent on its path, and the step at which its disc met an obstacle after its
    first period P (the start's transient from its offset start; −1: never; the run stops there)."""
    offsets, fn, ft = profile[:3]
    band = profile[3] if len(profile) > 3 else np.tile([-np.inf, np.inf], (arc.size, 1))
    y_index = transition.lateral_index
    M, command, F0, gk, limit = transition.M, transition.command, transition.F0, transition.steering_gain, transition.rate_limit
    runs, steps = plan.rows.shape
    own, V, sign = plan.own, plan.V, plan.sign
    h, centre, samples = offsets[1] - offsets[0], offsets.size // 2, arc.size
    pull, attraction, aim = (np.concatenate([getattr(r, f) for r in requests]) for f in ("pull", "attraction", "aim"))
    stopped = np.concatenate([r.stopped[:, None, :] for r in requests], axis=1)  # (direction, request, sample)
    base, direction = plan.request * samples, (sign < 0).astype(int)
    walk = _TrackWalk(track, route, arc, [plan.rows[i, 0] for i in own], V[own] * transition.T) if own.size else None
    track_at = np.full((3, own.size, steps), np.nan)
    state = np.zeros((runs, M.shape[0]))
    state[:, y_index] = sign * PREDICTION_OFFSET / V  # to the left of the travel direction (the state is x/V, s)
    for n, i in enumerate(own):  # a drive's own path: from where the robot started, its offset and heading off the path
        y0, theta0 = track.start[:, route[plan.rows[i, 0]]]
        if np.isfinite(y0):
            state[i, y_index], state[i, y_index - 1] = y0 / V[i], theta0
    lateral = np.full((runs, steps), np.nan)
    alive = np.ones(runs, dtype=bool)
    contact = np.full(runs, -1)
    transient = int(round(period / transition.T))  # the start's transient (the drives' judge leaves it out too)
    rows = plan.rows
    with np.errstate(invalid="ignore"):
        for k in range(steps):
            alive &= k < plan.length
            turn = np.zeros(runs)
            if own.size:  # a drive's own path: where the loop has got to along it (its own progress, `_TrackWalk`)
                alive[own] &= walk.going(k)
                rows[own, k] = walk.rows()
            row = rows[:, k]
            at = base + row
            judged = k >= transient
            yk = V * state[:, y_index]  # m
            u = (yk - offsets[0]) / h
            i0 = np.minimum(np.maximum(np.floor(u).astype(int), 0), offsets.size - 2)  # np.clip's overhead is a step's
            frac = u - i0
            f = fn[row, i0] * (1 - frac) + fn[row, i0 + 1] * frac
            g = -np.arctan2(f - pull[at] - aim[at] * yk, attraction[at] + sign * ft[row, centre])  # KB eq 4, ~ N·y
            if own.size:
                point = walk.here()
                track_at[:, :, k] = point[:3]
                g[own] = _steered(track, point, yk[own])
            g = np.where(stopped[direction, plan.request, row], 0.0, g)
            inside = (u >= 0) & (u <= offsets.size - 1) & (np.abs(yk) <= LEAVES) & np.isfinite(g)
            touching = alive & judged & ((yk <= band[row, 0]) | (yk >= band[row, 1]))  # the disc meets an obstacle: it stops
            contact[touching] = k
            alive &= inside & ~touching & np.isfinite(state).all(axis=1)
            lateral[alive, k] = yk[alive]
            if own.size:
                turn[own] = walk.advance(state[own, y_index - 1], yk[own])
            v = np.minimum(np.maximum(-(state @ F0) - gk * np.where(alive, g, 0.0), -limit), limit)  # the command, rate-limited
            state = state @ M.T + v[:, None] * command[None, :] - turn[:, None] * transition.turn[None, :]
            state[~alive] = 0.0
    ended = np.array(plan.length)
    if own.size:
        ended[own] = walk.ended_at(steps)
    return lateral, track_at, ended, contact


def _judge_runs(plan: _RunPlan, lateral, track_at, ended, contact, T: float, period: float, loops: list) -> None:
    """Each run's episodes, collision course (the samples passed within one period before its disc met an obstacle),
    weave and excursion marked on the samples it passed, in its request's `DrivenLoop` (`driven_loops`; a drive's own
    path's judged on its track in the plane)."""
    from .episodes import episodes, lateral_episodes, lateral_extent, swing

    t = np.arange(plan.rows.shape[1]) * T
    mine = {i: n for n, i in enumerate(plan.own)}
    for i in range(plan.rows.shape[0]):
        m = int(ended[i])
        nearest = plan.rows[i, :m]
        ok = np.isfinite(lateral[i, :m])
        tk, yk = t[:m][ok], lateral[i, :m][ok]
        swung, strays = lateral_extent(tk, yk, period)
        if i in mine:  # the drives' own judge on the loop's track in the plane
            x0, y0, phi = track_at[:, mine[i], :m][:, ok]
            px, py = x0 - np.sin(phi) * yk, y0 + np.cos(phi) * yk
            found, _ = episodes(tk, px, py, period)
            swung = swing(tk, px, py, period)
        else:
            found, _ = lateral_episodes(tk, plan.sign[i] * yk, period)
        loop = loops[plan.request[i]]
        for lo, hi in found:
            loop.oscillates[nearest[(t[:m] >= lo) & (t[:m] <= hi)]] = True
        if contact[i] >= 0:
            hit = int(contact[i])
            loop.collides[plan.rows[i, max(0, hit - int(round(period / T))):hit + 1]] = True
        np.maximum.at(loop.amplitude, nearest[ok], swung)
        np.maximum.at(loop.excursion, nearest[ok], strays)
        loop.amplitude[nearest[~ok]] = np.maximum(loop.amplitude[nearest[~ok]], LEAVES)  # it left the corridor: at least that
        loop.excursion[nearest[~ok]] = LEAVES


OWN_STEPS = 1.5
"""A loop along a drive's own path is run for at most this many times the steps its path's length takes at V: it
progresses along the path at V·cos θ/(1 − κ·y) (`_TrackWalk`), slower only by its heading off the path's."""


class _TrackWalk:
    """The loops along drives' own paths (`driven_loops`), each at its own progress s along its path: ds/dt = V·cos θ/(1 − κ·y)
    (θ its heading from the path's, y its offset to the left, κ the path's curvature): a robot weaving about its path
    covers less of it than V·t, and the loop must keep the robot's pace to keep its phase.

    Parameters
    ----------
    track : DrivenTrack
    route, arc : ndarray
        Route index and arc position (m) of each sample.
    first : sequence of int
        Per loop, a sample of its path.
    step : float or ndarray
        V·T per loop, m.
    """

    GAP = 1.0
    """m between consecutive routes on the walk's one arc axis (more than a sample's spacing: no interpolation across)."""

    def __init__(self, track: DrivenTrack, route, arc, first, step: float):
        lengths = np.zeros(int(route.max()) + 1)  # per route; 0 for a route without samples (a subset's)
        np.maximum.at(lengths, route, arc)
        offset = np.concatenate([[0.0], np.cumsum(lengths + self.GAP)])[:-1]
        self.axis = arc + offset[route]  # increasing: the samples are in route order, each route's by arc
        self.middles = (self.axis[:-1] + self.axis[1:]) / 2
        curvature = np.zeros(arc.size)
        for r in np.unique(route):
            on = np.flatnonzero(route == r)
            if on.size >= 2:
                curvature[on] = np.gradient(track.heading[on], arc[on])
        self.values = np.stack([track.x, track.y, track.heading, track.aims[0], track.aims[1], curvature])
        mine = route[np.asarray(first)]
        ends = [np.flatnonzero(route == r)[[0, -1]] for r in mine]
        self.lo = np.array([self.axis[i] for i, _ in ends])
        self.hi = np.array([self.axis[j] for _, j in ends])
        spacing = np.array([arc[j] - arc[j - 1] if j > i else 0.0 for i, j in ends])
        self.stop = offset[mine] + np.array([arc[j] for _, j in ends]) + spacing / 2  # the static positions' end
        self.s = offset[mine] + step / 2
        self.step = step
        self.ended = np.full(mine.size, -1)
        self.now = self._at(self.s)  # the path where each loop is: kept from one step to the next

    def _at(self, s) -> np.ndarray:
        return np.stack([np.interp(np.clip(s, self.lo, self.hi), self.axis, v) for v in self.values])

    def going(self, k: int) -> np.ndarray:
        """Whether each loop is still on its path at step `k` (recording the step it left it at)."""
        on = self.s < self.stop
        self.ended = np.where((self.ended < 0) & ~on, k, self.ended)
        return on

    def rows(self) -> np.ndarray:
        """The sample each loop is passing."""
        return np.searchsorted(self.middles, np.clip(self.s, self.lo, self.hi))

    def here(self) -> np.ndarray:
        """Shape (5, loops): the path's point (m), its direction φ (rad) and the point steered at (m) where each loop is."""
        return self.now[:5]

    def advance(self, theta: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Move each loop on by one step (heading θ from the path's, rad; offset y, m); the path's turn over it, rad."""
        now = self.now
        ahead = self.step * np.cos(np.nan_to_num(theta)) / np.maximum(1.0 - now[5] * np.nan_to_num(y), 0.1)
        self.s = self.s + ahead
        self.now = self._at(self.s)
        return self.now[2] - now[2]

    def ended_at(self, steps: int) -> np.ndarray:
        """Per loop, the steps it spent on its path."""
        return np.where(self.ended < 0, steps, self.ended)


def _steered(track: DrivenTrack, at: np.ndarray, y: np.ndarray) -> np.ndarray:
    """g (rad, `driven_loops`'s sign) of loops at lateral offsets `y` (m) from their path's points: the direction of the
    resultant of the window sum at q = p + y·nrm and the unit attraction from q to the point steered at, from the
    path's tangent (KB eq 4). `at`: `_TrackWalk.here` at the loops' step, shape (5, loops)."""
    px, py, phi, ax, ay = at
    tx, ty = np.cos(phi), np.sin(phi)
    qx, qy = px - ty * y, py + tx * y
    fx, fy = track.force(qx, qy)
    dx, dy = ax - qx, ay - qy
    reach = np.hypot(dx, dy)
    safe = np.where(reach > 0, reach, 1.0)
    gx, gy = np.where(reach > 0, dx / safe, tx), np.where(reach > 0, dy / safe, ty)  # at the point itself: straight on
    rx, ry = fx + gx, fy + gy
    return -np.arctan2(-ty * rx + tx * ry, tx * rx + ty * ry)


