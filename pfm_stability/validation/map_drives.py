"""Validation by driving: the simulated VFF robot driven along a map's routes and between random waypoints
(``pfm-stability map --validate N``; docs/maps.md, "Validation by driving").

**Drives** (batched, `sim.engine.run_batch`, the simulator's grid law on the map's histogram grid cropped
around each drive). Half of them follow the routes: a route (`routes.RoutePath`) drawn at random (seeded), driven
in a random direction from its first point plus a lateral offset δ = `START_OFFSET` (the disturbance) towards its
last (`Target.point`: the VFF robot finds its own path); the other half go between two random reachable points of
the routes (the same free component), following the global plan between them (`maps.reading.planner.SkeletonPlanner`: the
shortest path along the skeleton) as a navigation stack would hand it to the VFF controller: the robot is pulled
towards the plan's point `LOOKAHEAD` ahead of it (`Target.follow`, a pure-pursuit carrot), starting towards it. Every
drive runs until its target is reached, it collides or stalls, or `DRIVE_TIME_FACTOR` times its length's time.

**Episodes** (`maps.judging.episodes.episodes`, the one definition the map's prediction uses too): the robot's
lateral oscillation about its own path averaged over one period P = 2π/ω*; an episode is three periods of it
that grow by an e-fold or stay above `AMPLITUDE_THRESHOLD`. Every threshold of the judge and of the scoring below
is a field of `maps.judging.judge_thresholds.JudgeThresholds` (docs/judge.md: justifications, measured sensitivity);
`drive_map` is `judge_drives` (any table, ``thresholds=JUDGE``) of `simulate_drives` (the drives, simulated once).

**Each drive is judged along the path it took** (its positions averaged over one period, `maps.analysis.judge_routes`
with ``taken``: the prediction the map makes along any route — the loop driven through the force across the path,
`maps.deciding.paths` — made along that path, in the direction it was driven, as the robot drove it: the window sum at the
loop's own point, the attraction towards the point the robot steered at as it passed each point of the path (its
plan's carrot or its goal, `RoutePath.aims`), the path's frame turning under the loop at the loop's own pace along
it, and the loop's track judged in the plane by the drives' own judge; `maps.judging.driven.DrivenTrack`). The VFF robot aims at a
point, not along a route: it leaves the skeleton wherever the field bends it away (beside a rack it rides the
window's edge, metres from the route), so comparing the skeleton's verdicts with a robot that drove elsewhere would
compare two different paths.
The map's route samples within `MATCH_DISTANCE` of a drive are counted as covered (``lengths["driven"]``), not scored.

**Route length** (`_score`). Each trajectory point marks its nearest sample of its own path (within `MATCH_DISTANCE`
or the robot's width): those samples are driven; the points during an episode mark episode samples. Two kinds of
sample cannot show an episode and are not measured: those passed in the drive's first period (the start's
transient), and those passed only in its last `EPISODE_PERIODS` periods (an episode needs three periods after them:
the drive reached its goal, collided or stalled first — a stall when its progress stopped,
`validation.maps.stall_time` before the simulator calls it trapped; counted as ``drive_paths_unmeasured``, never as
agreement), and with them the end of a predicted-unstable stretch that reaches them, over three periods' travel less half a
window Λ before them (`_cut_short`: a weave arriving there, at most Λ/2 early, would have run into the drive's end
before three periods; matched or not, so that drives cut short count neither way). A driven sample predicted
unstable matches an episode when an episode sample of the same path lies within half the verdict's window Λ (the
point's verdict is the growth over the window centred there), and an episode sample is recalled when a
predicted-unstable sample lies within Λ/2. Recall = recalled episode length / episode length; precision = matched
predicted-unstable length / predicted-unstable length driven (None when a denominator is 0: nothing to measure,
never counted as agreement), each with its 95 % interval over the choice of drives (`_interval`). Every disagreement
is listed as a stretch (`Disagreement`: "missed" — an episode where stable was predicted; "false alarm" — predicted
unstable, driven, no episode). Route length never driven, and drives that stalled or collided, are counted as such.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from ..checks import check_integer
from ..io.serialize import json_number
from ..sim.engine import run_batch
from ..sim.scenario import Pose, Scenario, Target
from ..maps.judging.episodes import episodes, swing
from ..maps.judging.judge_thresholds import JUDGE, JudgeThresholds
from ..maps.reading.planner import SkeletonPlanner
from ..maps.reading.routes import polyline_arcs
from .map_collisions import locate_collisions
from .map_drive_results import Disagreement, Drive, DriveRuns, DriveValidation, SimulatedDrive, WobbleAgreement, wobble_agreement
from .maps import START_OFFSET, _batches, _table_size, crop_grid, simulator_grid, stall_time

__all__ = ["DRIVE_TIME_FACTOR", "MATCH_DISTANCE", "WOBBLE_FACTOR", "Disagreement", "Drive", "DriveRuns", "DriveValidation",
           "SimulatedDrive", "WobbleAgreement", "drive_map", "goal_routes", "judge_drives", "simulate_drives", "wobble_agreement"]

MATCH_DISTANCE = JUDGE.match_distance
"""Largest distance (m) from a trajectory point to the route sample it marks (at least the robot's width W):
`JudgeThresholds.match_distance` of `JUDGE` (docs/judge.md)."""
DRIVE_TIME_FACTOR = 2.5
"""A drive lasts at most this many times its length's time (the plan's, or the straight line's), plus 5 s."""
START_ROOM = 1e-3
"""Least room (m) beside the robot at a drive's start offset by δ; with less the drive starts on the route itself."""
INTERVAL_RESAMPLES = 2000
"""Resamples of the drives behind the 95 % intervals of recall and precision (`_interval`)."""
LOOKAHEAD = 2.0
"""How far ahead along its plan a waypoint drive's robot is pulled, m (`sim.follow`; docs/maps.md, "Validation by
driving": at 1 m and 3 m the figures were worse)."""
FIGURES = {"recall": ("episode_recalled", "episode"), "precision": ("predicted_unstable_matched", "predicted_unstable_driven"),
           "specificity": ("quiet_predicted_stable", "quiet_driven")}
"""Each figure of the validation: the (part, whole) of `_score`'s lengths whose ratio it is (module docstring)."""
CROP_SLACK = 3.0
"""How far (m) around a drive's straight line its cropped grid reaches beyond the window."""
WOBBLE_FACTOR = JUDGE.wobble_factor
"""A predicted weave agrees in size with the simulated one when their ratio lies within 1/this .. this
(`WobbleAgreement`): `JudgeThresholds.wobble_factor` of `JUDGE`."""


def _components(analysis):
    """Free-space component label of each route sample (the robot fits: clearance > W/2)."""
    from scipy.ndimage import label

    grid = analysis.grid
    labels, _ = label(analysis.clearance > analysis.robot.W / 2, structure=np.ones((3, 3), dtype=int))
    pv = analysis.paths
    i, j = grid.cell_index(pv.samples.x, pv.samples.y)
    i, j = np.clip(i, 0, grid.shape[0] - 1), np.clip(j, 0, grid.shape[1] - 1)
    return labels[i, j]


def _plan(analysis, count: int, rng) -> list:
    """The drives: (kind, path (its first point the start, its last the goal; m), start heading (rad), length (m)) for
    `count` drives (module docstring)."""
    pv = analysis.paths
    c = analysis.grid.cell_size
    pieces = [(path.points[0], path.points[-1]) for path in pv.paths if math.hypot(*(path.points[-1] - path.points[0])) >= 4 * c]
    component = _components(analysis)
    samples = np.column_stack([pv.samples.x, pv.samples.y])
    ok = component > 0
    plans = []
    route_drives = min(len(pieces), (count + 1) // 2)
    for k in (rng.permutation(len(pieces))[:route_drives] if pieces else []):
        p, q = pieces[k]
        if rng.random() < 0.5:
            p, q = q, p
        heading = math.atan2(q[0] - p[0], q[1] - p[1])
        plans.append(("route", np.array([p, q]), heading, float(math.hypot(*(q - p)))))
    candidates = np.flatnonzero(ok)
    planner = SkeletonPlanner(analysis.grid, analysis.skeleton)
    tries = 0
    while len(plans) < count and candidates.size >= 2 and tries < 50 * count:
        tries += 1
        a, b = rng.choice(candidates, 2, replace=False)
        if component[a] != component[b] or math.hypot(*(samples[b] - samples[a])) < 2.0:
            continue
        planned = _planned(planner, samples[a], samples[b])
        if planned is not None:
            plans.append(("waypoints", *planned))
    return plans


def _planned(planner, p, q) -> tuple | None:
    """(path, start heading (rad), length (m)) of the plan from `p` to `q` (m; `SkeletonPlanner.plan`), the robot
    starting towards its carrot; None when the skeleton does not join them."""
    path = planner.plan(p, q)
    if path is None:
        return None
    arc = polyline_arcs(path)
    ahead = [np.interp(min(LOOKAHEAD, arc[-1]), arc, path[:, k]) for k in (0, 1)]
    return path, math.atan2(ahead[0] - path[0, 0], ahead[1] - path[0, 1]), float(arc[-1])


def drive_map(analysis, count: int, *, seed: int = 0, progress=None, thresholds: JudgeThresholds = JUDGE) -> DriveValidation:
    """Drive the VFF robot `count` times over a map and score the map's unstable stretches (module docstring):
    `judge_drives` of `simulate_drives`.

    Parameters
    ----------
    analysis : MapAnalysis
        A grid-law analysis with its routes' verdicts (`MapAnalysis.paths`).
    count : int
        Drives, >= 1.
    seed : int
        Seed of the drives' choice.
    progress : callable, optional
        ``progress(line)`` after each batch.
    thresholds : JudgeThresholds
        The judge's and the scoring's thresholds (`maps.judging.judge_thresholds.JUDGE`: the package's; docs/judge.md).
    """
    return judge_drives(simulate_drives(analysis, count, seed=seed, progress=progress), thresholds)


def simulate_drives(analysis, count: int, *, seed: int = 0, progress=None) -> DriveRuns:
    """The drives of `drive_map`, simulated (module docstring, "Drives"), with the prediction along the paths they
    took: nothing judged yet.

    Parameters
    ----------
    analysis : MapAnalysis
        A grid-law analysis with its routes' verdicts (`MapAnalysis.paths`).
    count : int
        Drives, >= 1.
    seed : int
        Seed of the drives' choice.
    progress : callable, optional
        ``progress(line)`` after each batch.
    """
    from ..maps.analysis import judge_routes

    started = time.perf_counter()
    count = check_integer("count", count, 1, 100_000)
    seed = check_integer("seed", seed, 0, 2**63 - 1)
    if analysis.paths is None:
        raise ValueError("validation by driving needs --law grid: the simulator senses the map through its histogram grid")
    omega = _omega(analysis)
    period = 2 * math.pi / omega if omega else math.inf
    runs, skipped = _prepare(analysis, count, np.random.default_rng(seed))
    drives, batches = [], _batches(runs)
    for b, batch in enumerate(batches, 1):
        outcome = run_batch([r.scenario for r in batch], record="trajectory", metrics=False)
        for r, result in zip(batch, outcome.runs):
            tr = result.trajectory
            first = result.events[0] if result.events else None
            contact = (float(first.x), float(first.y)) if first is not None and first.type == "collision" else None
            drives.append((r, SimulatedDrive(len(drives), r.kind, r.ends, first.type if first is not None else None, tr.t, tr.x, tr.y,
                                             contact=contact)))
        if progress:
            progress(f"map drives: batch {b}/{len(batches)}: {len(batch)} drives")
    # every drive's own path (period-averaged), judged like any route: prediction and episode on one path
    taken, simulated = [], []
    for r, d in drives:
        try:
            route = _taken_path(d.x, d.y, period, analysis.controller.T, analysis.grid.cell_size, len(taken), "drive",
                                r.scenario.target, r.scenario.start)
        except ValueError:  # fewer than two distinct points: the drive did not move
            simulated.append(d)
            continue
        simulated.append(dataclasses.replace(d, path=len(taken)))
        taken.append(route)
    dp = judge_routes(analysis, taken, taken=True, speeds=False) if taken else None  # their samples' verdicts are scored
    return DriveRuns(analysis, count, seed, period, tuple(simulated), skipped, dp, time.perf_counter() - started)


def _prepare(analysis, count: int, rng) -> tuple:
    """(the drives' `_Prepared` scenarios, how many could not start) of `count` drives (`_plan`, `rng`)."""
    robot, controller, law = analysis.robot, analysis.controller, analysis.law
    grid = simulator_grid(analysis.grid)
    h = law.window_cells // 2
    reach = (h + 1) * grid.cell_size + CROP_SLACK
    runs, skipped = [], 0
    for kind, path, heading, length in _plan(analysis, count, rng):
        p, q = path[0], path[-1]
        ux, uy = math.sin(heading), math.cos(heading)
        delta = START_OFFSET if kind == "route" else 0.0
        sx, sy = p[0] + delta * uy, p[1] - delta * ux  # δ to the right of the travel direction
        (x_lo, y_lo), (x_hi, y_hi) = path.min(axis=0), path.max(axis=0)
        local = crop_grid(grid, x_lo - reach, x_hi + reach, y_lo - reach, y_hi + reach)
        target = (Target.point(float(q[0]), float(q[1]), radius=0.3) if kind == "route"
                  else Target.follow(path, LOOKAHEAD, radius=0.3))
        duration = DRIVE_TIME_FACTOR * length / robot.V + 5.0
        room = float(local.clearance([sx], [sy])[0]) - robot.W / 2
        if not room > START_ROOM:
            sx, sy = float(p[0]), float(p[1])
        try:
            scenario = Scenario(name=f"drive {len(runs)} ({kind})", robot=robot, controller=controller, environment=local,
                                start=Pose(float(sx), float(sy), heading), target=target, duration=duration,
                                cell_ratio=law.ratio, window_cells=law.window_cells, trap_time=stall_time(robot.V))
        except ValueError:  # the start or the goal touches an obstacle: a drive that cannot start
            skipped += 1
            continue
        runs.append(_Prepared(kind, (float(p[0]), float(p[1]), float(q[0]), float(q[1])), scenario,
                              _table_size(local, h)))
    return runs, skipped


def judge_drives(runs: DriveRuns, thresholds: JudgeThresholds = JUDGE) -> DriveValidation:
    """Judge and score simulated drives (module docstring, "Episodes", "Route length"): each drive's episodes
    (`maps.judging.episodes.episodes`), the samples of its own path it measured, and recall, precision and specificity with
    their intervals; with `JUDGE`, `drive_map`'s answer.

    Parameters
    ----------
    runs : DriveRuns
        The drives (`simulate_drives`).
    thresholds : JudgeThresholds
        The judge's and the scoring's thresholds (`maps.judging.judge_thresholds.JUDGE`: the package's; docs/judge.md).
    """
    from ..maps.deciding.decide import PATH_VERDICTS, UNJUDGED
    from ..maps.judging.driven import LEAVES

    started = time.perf_counter()
    analysis, period, dp = runs.analysis, runs.period, runs.drive_paths
    pv = analysis.paths
    drives = []
    for d in runs.drives:
        found, amplitude = episodes(d.t, d.x, d.y, period, thresholds)
        drives.append(Drive(d.index, d.kind, *d.ends, event=d.event, duration=d.duration, episodes=found,
                            max_amplitude=amplitude, contact=d.contact))
    sc = _Scored.of(pv, dp)
    verdict = _Verdicts(sc.code == PATH_VERDICTS.index("unstable"), sc.code == PATH_VERDICTS.index("stable"),
                        np.isin(sc.code, [PATH_VERDICTS.index(reason) for reason in UNJUDGED]),
                        pv.window * thresholds.match_window if math.isfinite(pv.window) else 0.0, pv.code.size)
    marks, points, swung = _mark_drives(runs, drives, sc, verdict, thresholds)
    near_unstable = _within(verdict.unstable, sc.route, sc.arc, verdict.half)
    lengths, driven, episode, near_episode = _score(sc, marks, range(len(drives)), verdict.unstable, verdict.stable,
                                                    near_unstable, verdict.half, verdict.base)
    by_kind = {}
    for kind in ("route", "waypoints"):
        chosen = [k for k, d in enumerate(drives) if d.kind == kind]
        kind_lengths = _score(sc, marks, chosen, verdict.unstable, verdict.stable, near_unstable, verdict.half, verdict.base)[0]
        by_kind[kind] = {**{name: json_number(v) if v is not None else None for name, v in _figures(kind_lengths).items()},
                         "lengths": kind_lengths}
    passed_by = [set() for _ in range(sc.code.size)]
    for d, mark in zip(drives, marks):
        for k in mark.scored:
            passed_by[k].add(d.index)
    disagreements = (_runs("missed", episode & ~near_unstable, sc, passed_by, swung)
                     + _runs("false alarm", verdict.unstable & driven & ~near_episode, sc, passed_by, swung))
    for key, kind, amplitude in (("false_alarm_swinging", "false alarm", "simulated_amplitude"),
                                 ("missed_predicted_swinging", "missed", "predicted_amplitude")):  # the side that wove
        lengths[key] = float(sum(d.length for d in disagreements
                                 if d.kind == kind and getattr(d, amplitude) >= thresholds.amplitude_threshold))
    per_drive = [_score(sc, marks, [k], verdict.unstable, verdict.stable, near_unstable, verdict.half, verdict.base)[0]
                 for k in range(len(drives))]
    figures, intervals = _figures(lengths), _intervals(per_drive, _figures(lengths), runs.seed)
    pts = np.vstack(points) if points else np.zeros((0, 2))
    measured = np.flatnonzero(driven)
    measured = measured[measured >= verdict.base]  # the drives' own paths' samples scored (`_score`)
    wobble = wobble_agreement(np.nan_to_num(sc.amplitude[measured]), swung[measured], sc.spacing[measured], LEAVES,
                              thresholds)
    return DriveValidation(figures["recall"], figures["precision"], tuple(drives), disagreements, lengths,
                           _counts(drives, runs.skipped), _inputs(runs, thresholds), runs.seconds + time.perf_counter() - started,
                           pts, by_kind, dp, intervals["recall"], intervals["precision"], figures["specificity"],
                           intervals["specificity"], wobble,
                           locate_collisions(pv, [(d.index, *d.contact) for d in drives if d.contact is not None],
                                             max(thresholds.match_distance, analysis.robot.W)))


def _counts(drives, skipped: int) -> dict:
    """`DriveValidation.counts`: the drives by how they ended, the episodes found."""
    events = [d.event or "time" for d in drives]
    return {"drives": len(drives), "not_started": skipped, "route_drives": sum(d.kind == "route" for d in drives),
            "waypoint_drives": sum(d.kind == "waypoints" for d in drives), "episodes": sum(len(d.episodes) for d in drives),
            **{f"ended_{e}": events.count(e) for e in sorted(set(events))}}


def _inputs(runs: DriveRuns, thresholds: JudgeThresholds) -> dict:
    """`DriveValidation.inputs`: what the drives and their judge were given."""
    return {"count": runs.count, "seed": runs.seed, "V": runs.analysis.robot.V, "period": json_number(runs.period),
            "window": json_number(runs.analysis.paths.window), "episode_periods": thresholds.episode_periods,
            "growth_efolds": thresholds.growth_efolds, "amplitude_threshold": thresholds.amplitude_threshold,
            "noise_floor": thresholds.noise_floor, "match_distance": max(thresholds.match_distance, runs.analysis.robot.W),
            "start_offset": START_OFFSET, "interval_resamples": INTERVAL_RESAMPLES}


def _intervals(per_drive: list, figures: dict, seed: int) -> dict:
    """Each of `FIGURES`' 95 % interval over the drives (`_interval`; `per_drive`: each drive's `_score` lengths; None
    where the figure is None), drawn in `FIGURES`' order from one generator seeded by the drives' `seed`."""
    resampled = np.random.default_rng([seed, 1])
    intervals = {}
    for name, (part, whole) in FIGURES.items():  # in this order: they draw on one generator
        shares = [np.array([L[key] for L in per_drive], dtype=float) for key in (part, whole)]
        intervals[name] = _interval(*shares, resampled) if figures[name] is not None else None
    return intervals


@dataclass(frozen=True)
class _Verdicts:
    """The scored samples' verdicts (`_Scored`): unstable, stable, unjudged (a wall ahead: no claim either way), the match's
    half window (m: `JudgeThresholds.match_window` of Λ) and the map's routes' sample count (the drives' paths' follow)."""

    unstable: np.ndarray
    stable: np.ndarray
    unjudged: np.ndarray
    half: float
    base: int


def _mark_drives(runs: DriveRuns, drives, sc, verdict: _Verdicts, thresholds: JudgeThresholds) -> tuple:
    """(marks, points, swung): each drive's `_Marks` (module docstring, "Route length"), its positions during its
    episodes (m), and the drives' largest lateral oscillation at each sample of their own paths (m)."""
    from scipy.spatial import cKDTree

    robot, pv, period = runs.analysis.robot, runs.analysis.paths, runs.period
    tree = cKDTree(np.column_stack([pv.samples.x, pv.samples.y]))
    limit = max(thresholds.match_distance, robot.W)
    reach_back = max(0.0, thresholds.end_exclusion * robot.V * period - verdict.half)  # m (`_cut_short`)
    swung = np.zeros(sc.code.size)
    marks, points = [], []
    for d, s in zip(drives, runs.drives):
        t, x, y = s.t, s.x, s.y
        if t.size == 0 or s.path is None:
            marks.append(_Marks.none())
            continue
        dist, near = tree.query(np.column_stack([x, y]), distance_upper_bound=limit)
        on_routes = np.unique(near[np.isfinite(dist)])
        mine = verdict.base + np.flatnonzero(runs.drive_paths.samples.segment == s.path)
        dist, nearest = cKDTree(np.column_stack([sc.x[mine], sc.y[mine]])).query(np.column_stack([x, y]), distance_upper_bound=limit)
        nearest = mine[np.minimum(nearest, mine.size - 1)]
        during = np.zeros(t.size, dtype=bool)
        for lo, hi in d.episodes:
            during |= (t >= lo) & (t <= hi)
        near_path = np.isfinite(dist)
        # the start's transient is not measured
        start = t - t[0] >= min(thresholds.start_periods * period, thresholds.start_share * d.duration)
        # an episode needs its periods after a sample to be found, before the drive ended: a stall ended it when its
        # progress stopped, `stall_time` before the stall was called
        stop = t[-1] - (stall_time(robot.V) if d.event == "trapped" else 0.0)
        end = stop - t >= thresholds.end_exclusion * period
        hit = near_path & start & (end | during)
        step = np.concatenate([[0.0], np.hypot(np.diff(x), np.diff(y))])
        off = float(step[during & ~near_path].sum())  # an episode away from its own path (a spin): measured, not scored
        unmeasured = np.setdiff1d(np.unique(nearest[near_path & start & ~end & ~during]), nearest[hit])
        np.maximum.at(swung, nearest[hit], swing(t, x, y, period, thresholds)[hit])
        scored = np.unique(nearest[hit])
        cut = _cut_short(mine, sc.arc, verdict.unstable, verdict.unjudged, unmeasured, reach_back)
        marks.append(_Marks(np.setdiff1d(scored, cut), np.unique(nearest[hit & during]), off,
                            np.union1d(unmeasured, np.intersect1d(scored, cut)), on_routes))
        points.append(np.column_stack([x[during], y[during]]))
    return marks, points, swung


@dataclass(frozen=True)
class _Scored:
    """The samples: the map's routes' (`PathVerdicts`; passed, not scored), then the drives' own paths' (scored; route
    index offset by the map's routes)."""

    code: np.ndarray
    route: np.ndarray
    arc: np.ndarray
    spacing: np.ndarray
    x: np.ndarray
    y: np.ndarray
    amplitude: np.ndarray

    @classmethod
    def of(cls, pv, dp=None) -> "_Scored":
        parts = [(pv.code, pv.samples.segment, pv.arc, pv.spacing, pv.samples.x, pv.samples.y, pv.amplitude)]
        if dp is not None:
            parts.append((dp.code, dp.samples.segment + len(pv.paths), dp.arc, dp.spacing, dp.samples.x, dp.samples.y, dp.amplitude))
        return cls(*(np.concatenate(a) for a in zip(*parts)))


@dataclass(frozen=True)
class _Marks:
    """What one drive marks: the samples of its own path it passed and that are measured (`scored`: after the start's
    first period, and three periods or more before it ended unless during an episode), those during its episodes,
    its episodes' path length away from its own path (m), the samples it passed only in its last three periods
    (`unmeasured`: no episode could have been found after them), and the map's route samples it passed."""

    scored: np.ndarray
    episode: np.ndarray
    off_path: float
    unmeasured: np.ndarray
    on_routes: np.ndarray

    @classmethod
    def none(cls) -> "_Marks":
        empty = np.zeros(0, dtype=int)
        return cls(empty, empty, 0.0, empty, empty)


def _score(sc, marks, chosen, unstable, stable, near_unstable, half, base):
    """(lengths, driven, episode, near_episode) of the drives `chosen` (module docstring); the
    first `base` samples are the map's routes' (passed: coverage only), the rest the drives' own paths' (scored)."""
    driven = np.zeros(sc.code.size, dtype=bool)
    episode = np.zeros(sc.code.size, dtype=bool)
    unmeasured = np.zeros(sc.code.size, dtype=bool)
    off_path = 0.0
    for k in chosen:
        mark = marks[k]
        driven[mark.scored] = True
        driven[mark.on_routes] = True
        episode[mark.episode] = True
        unmeasured[mark.unmeasured] = True
        off_path += mark.off_path
    unmeasured &= ~driven
    near_episode = _within(episode, sc.route, sc.arc, half)
    ds = sc.spacing
    on_map = np.arange(ds.size) < base
    scored = driven & ~on_map
    lengths = {
        "route": float(ds[on_map].sum()), "driven": float(ds[driven & on_map].sum()), "not_driven": float(ds[~driven & on_map].sum()),
        "drive_paths": float(ds[~on_map].sum()), "drive_paths_driven": float(ds[scored].sum()),
        "drive_paths_unmeasured": float(ds[unmeasured].sum()),
        "episode": float(ds[episode].sum()), "episode_recalled": float(ds[episode & near_unstable].sum()),
        "episode_off_route": off_path,
        "predicted_unstable_driven": float(ds[unstable & scored].sum()),
        "predicted_unstable_matched": float(ds[unstable & scored & near_episode].sum()),
        "predicted_unstable_unmeasured": float(ds[unstable & unmeasured].sum()),
        "predicted_unstable_not_driven": float(ds[unstable & ~driven & on_map].sum()),
        "quiet_driven": float(ds[scored & ~near_episode & (stable | unstable)].sum()),
        "quiet_predicted_stable": float(ds[scored & ~near_episode & stable].sum()),
    }
    return lengths, scored, episode, near_episode


@dataclass(frozen=True)
class _Prepared:
    kind: str
    ends: tuple
    scenario: Scenario
    table: tuple


def _omega(analysis) -> float | None:
    """ω* of the analysis' model (rad/s), from its routes' window (Λ = 3·2πV/ω*), or None."""
    from ..maps.deciding.decide import WINDOW_PERIODS

    w = analysis.paths.window
    if not math.isfinite(w) or w <= 0:
        return None
    return WINDOW_PERIODS * 2 * math.pi * analysis.robot.V / w


def _cut_short(path: np.ndarray, arc: np.ndarray, unstable: np.ndarray, unjudged: np.ndarray, unmeasured: np.ndarray,
               reach: float) -> np.ndarray:
    """The samples of a drive's own `path` (its sample indices in order; `arc`, m, along it) predicted unstable that the
    drive ended too soon to check: on a predicted-unstable stretch that reaches a sample passed only in the drive's
    last three periods (`unmeasured`), those within `reach` m before the first such sample — three periods' travel
    less half the match's window: an episode beginning no earlier than half a window before such a sample (a weave
    arriving where it was predicted) would have run into the drive's end. They are not measured, whether or not an
    episode lies on them (keeping those with one would count the drives cut short only when they agree). Samples
    without a verdict (`unjudged`: a wall ahead) do not end a stretch."""
    from scipy.ndimage import label

    u, s = unstable[path], arc[path]
    stretch, count = label(u | unjudged[path])  # 1.. per stretch, its unjudged samples joining it; 0 elsewhere
    ends = (stretch > 0) & np.isin(path, unmeasured)
    first = np.full(count + 1, np.inf)
    np.minimum.at(first, stretch[ends], s[ends])  # per stretch, where the drive's last three periods begin, m
    return path[u & np.isfinite(first[stretch]) & (s + reach >= first[stretch])]


def _figures(lengths: dict) -> dict:
    """Each of `FIGURES`: lengths[part] / lengths[whole] (None when the whole is 0: nothing to measure)."""
    return {name: lengths[part] / lengths[whole] if lengths[whole] > 0 else None for name, (part, whole) in FIGURES.items()}


def _interval(part: np.ndarray, whole: np.ndarray, rng) -> tuple | None:
    """The 95 % percentile interval of Σpart/Σwhole over the drives resampled with replacement (`part`, `whole`: each
    drive's lengths, m; a drive's own path is its own, so the figure over any choice of drives is their sums' ratio);
    resamples whose Σwhole is 0 (no drive with anything to measure) are left out. When every drive agrees the interval
    is a point: the resampling shows how the figure moves with the choice of drives, not how it would with others
    that meet a weave the chosen ones never met (the episodes' count says how many there were)."""
    n = part.size
    counts = rng.multinomial(n, np.full(n, 1.0 / n), size=INTERVAL_RESAMPLES)
    num, den = counts @ part, counts @ whole
    ratio = num[den > 0] / den[den > 0]
    if ratio.size == 0:
        return None
    return tuple(float(v) for v in np.percentile(ratio, [2.5, 97.5]))


def _within(mask: np.ndarray, route: np.ndarray, arc: np.ndarray, half: float) -> np.ndarray:
    """True at samples with a `mask` sample of the same route within `half` m of arc."""
    out = np.zeros(mask.shape, dtype=bool)
    for r in np.unique(route[mask]):
        idx = np.flatnonzero(route == r)
        marked = arc[idx][mask[idx]]
        pos = np.searchsorted(marked, arc[idx])
        before = np.abs(arc[idx] - marked[np.clip(pos - 1, 0, marked.size - 1)])
        after = np.abs(marked[np.clip(pos, 0, marked.size - 1)] - arc[idx])
        out[idx] = np.minimum(before, after) <= half + 1e-9
    return out


def _runs(kind: str, mask: np.ndarray, sc, passed_by, swung) -> tuple:
    """The stretches of consecutive `mask` samples of each route, as `Disagreement`s (`swung`: the drives' largest
    lateral oscillation per sample, m)."""
    out = []
    route = sc.route
    for r in np.unique(route[mask]):
        idx = np.flatnonzero(route == r)
        m = mask[idx]
        edges = np.flatnonzero(np.diff(np.concatenate([[0], m.astype(int), [0]])))
        for a, b in zip(edges[::2], edges[1::2]):
            run = idx[a:b]
            start, stop = float(sc.arc[run[0]] - sc.spacing[run[0]] / 2), float(sc.arc[run[-1]] + sc.spacing[run[-1]] / 2)
            drives = sorted(set().union(*(passed_by[k] for k in run)))
            out.append(Disagreement(kind, int(r), start, stop, float(sc.spacing[run].sum()), float(sc.x[run[0]]),
                                    float(sc.y[run[0]]), float(sc.x[run[-1]]), float(sc.y[run[-1]]), tuple(drives),
                                    float(np.nan_to_num(sc.amplitude[run]).max()), float(swung[run].max())))
    return tuple(out)


def _taken_path(x, y, period: float, T: float, cell: float, index: int, source: str, target, start=None):
    """The path a drive took: its positions (m) averaged over one period (s; `JudgeThresholds.average_periods` of
    `JUDGE`, the judge's; the controller's step T, s), a point
    every `cell` m of arc (`routes.path_of`, route `index`, `source`), with the point `target` (a `Target`) the robot
    steered at (`RoutePath.goal`, `RoutePath.lookahead`) and the `Pose` it started from, if given (`RoutePath.start`)."""
    from scipy.ndimage import uniform_filter1d

    from ..maps.reading.routes import path_of

    n = max(1, int(round(JUDGE.average_periods * period / T)))
    x, y = uniform_filter1d(x, n, mode="nearest"), uniform_filter1d(y, n, mode="nearest")
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])
    step = np.flatnonzero(np.diff(np.concatenate([[-1.0], arc // cell])) > 0)  # a point every cell
    points = np.column_stack([x[step], y[step]]) if step.size >= 2 else np.column_stack([x[[0, -1]], y[[0, -1]]])
    return path_of(points, index, source, goal=(target.x, target.y) if target.is_point else None,
                   lookahead=target.lookahead if target.is_path else math.inf, aims=_aims(points, target),
                   start=None if start is None else (start.x, start.y, start.theta))


def _aims(points, target) -> np.ndarray:
    """The point (m) a robot steering at `target` (a `Target`) aims at as it passes each of `points` (m) in order:
    its plan's carrot (`sim.follow.PathFollower`, the simulator's own), or its point target."""
    from ..sim.follow import PathFollower

    if not target.is_path:
        return np.tile([target.x, target.y], (len(points), 1))
    follower = PathFollower([target])
    aims = np.empty((len(points), 2))
    for k, (px, py) in enumerate(points):
        follower.advance(np.array([px]), np.array([py]))
        cx, cy = follower.carrot()
        aims[k] = cx[0], cy[0]
    return aims


def goal_routes(analysis, goals, progress=None) -> list:
    """The paths the simulated VFF robot takes between consecutive goals, as routes to judge (`maps.analysis.add_routes`):
    each drive (the simulator's grid law on the map's grid) follows the plan between the two goals as the validation's
    do (`SkeletonPlanner`, `Target.follow` with `LOOKAHEAD`; a point target straight at the goal where the skeleton
    does not join them), averaged over one oscillation period P = 2π/ω* — the path it follows, about which
    `maps.deciding.paths` linearizes — from its start to where it stopped (the goal, a collision or a stall).

    Parameters
    ----------
    analysis : MapAnalysis
        A grid-law analysis with its routes' verdicts.
    goals : array_like, shape (n, 2)
        Goals in map coordinates, m (n >= 2).
    progress : callable, optional
        ``progress(line)`` once the drives are done.
    """
    goals = np.asarray(goals, dtype=float).reshape(-1, 2)
    if len(goals) < 2:
        raise ValueError(f"goals must hold at least two points (m); got {len(goals)}")
    robot, controller, law = analysis.robot, analysis.controller, analysis.law
    grid = simulator_grid(analysis.grid)
    omega = _omega(analysis)
    period = 2 * math.pi / omega if omega else 1.0
    planner = SkeletonPlanner(analysis.grid, analysis.skeleton)
    scenarios = []
    for k, (p, q) in enumerate(zip(goals[:-1], goals[1:])):
        planned = _planned(planner, p, q)
        if planned is None:  # no plan: straight at the goal
            target = Target.point(float(q[0]), float(q[1]), radius=0.3)
            heading, length = math.atan2(q[0] - p[0], q[1] - p[1]), float(math.hypot(*(q - p)))
        else:
            path, heading, length = planned
            target = Target.follow(path, LOOKAHEAD, radius=0.3)
        try:
            scenarios.append(Scenario(name=f"goal {k + 1}", robot=robot, controller=controller, environment=grid,
                                      start=Pose(float(p[0]), float(p[1]), heading), target=target,
                                      duration=DRIVE_TIME_FACTOR * length / robot.V + 5.0, cell_ratio=law.ratio,
                                      window_cells=law.window_cells, trap_time=stall_time(robot.V)))
        except ValueError as exc:
            raise ValueError(f"goal {k + 1} -> {k + 2}: {exc}") from None
    outcome = run_batch(scenarios, record="trajectory", metrics=False)
    routes = [_taken_path(run.trajectory.x, run.trajectory.y, period, controller.T, analysis.grid.cell_size, k, "goals", s.target,
                          s.start)
              for k, (s, run) in enumerate(zip(scenarios, outcome.runs))]
    if progress:
        progress(f"goals: {len(routes)} drives between {len(goals)} goals")
    return routes
