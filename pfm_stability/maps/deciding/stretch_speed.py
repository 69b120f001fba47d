"""V* of a route stretch: the edge of the calm speeds nearest the robot's V, by the one rule that decides it
(docs/maps.md, "One answer per stretch").

A stretch's verdict at V comes from `decide.decide` (the window's growth, the loop driven along the route, the
window-edge relay). Its V* must say "at or below this speed it does not weave" and agree with that verdict, so it is
found with the same rule at other speeds, never with a second criterion:

* **unstable at V**: the rule is run again on the stretch's routes at V·(1 − k·`SPEED_STEP`), k = 1, 2, … up to
  `SPEED_STEPS`; the first of these speeds at which none of the stretch's samples is unstable and the rung above it
  (unstable) bracket the edge, which `BISECT_STEPS` halvings narrow; V* is the bracket's calm end: the speed to slow
  down to (a speed mask's zone). A ladder first, because the driven loop's weave (forced by the field's ripple) and
  the relay's cycle need not change monotonically with V: the ladder finds the fastest calm rung, the halvings the
  edge above it; V* lies within 2.5 % of V below the edge, on the slow side. None calm down to
  V·(1 − SPEED_STEPS·SPEED_STEP): V* = 0.
* **stable at V**: V* is the first speed above V at which one of the stretch's samples is unstable by the same rule
  without the driven loop — its growth (`verdicts.EFOLDS` over the window or over the run of growing windows,
  `decide.run_efolds`) or its window-edge relay's describing-function cycle — bracketed by factors
  `HEADROOM_GROWTH` and bisected to `HEADROOM_RTOL`. Above V the loop driven along the route is not run (its cost
  is a whole run per speed): a forced weave that appears only faster than V is not in V*, which is then an upper
  bound. None unstable below `HEADROOM_MAX`·V (a stretch with no field): V* = inf.

Each speed tried decides only the stretches' own samples (`decide.decide`'s ``centres``) on their routes alone, and the
stretches that share a bracket are decided together. On a long straight corridor the run of growing windows is the
corridor, so V* tends to the report's V* (zero growth) as the corridor lengthens; on a short one a slow growth does
not reach an e-fold before the corridor ends and V* lies above it.

So V* >= V exactly when the verdict is stable, and the margin V*/V − 1 has the verdict's sign.
"""

from __future__ import annotations

import math

import numpy as np

from .decide import WINDOW_PERIODS, SpeedQuery, decide_speeds
from .verdicts import wavelength

__all__ = ["BISECT_STEPS", "CENTRES_PER_WINDOW", "HEADROOM_GROWTH", "HEADROOM_MAX", "HEADROOM_RTOL", "SPEED_STEP", "SPEED_STEPS", "stretch_speeds"]

SPEED_STEP = 0.1
"""Step of the ladder of slower speeds an unstable stretch is decided at, in units of V (each rung costs a run of the
driven loop, longer the slower: 5 % rungs doubled the warehouse's time; `BISECT_STEPS` then narrows the step)."""
SPEED_STEPS = 9
"""Rungs of that ladder: down to V·(1 − 9·0.1) = 0.1 V; a stretch still unstable there gets V* = 0."""
CENTRES_PER_WINDOW = 8
"""Samples of a stretch whose windows are multiplied out per window length at each speed tried (with its ends and its
worst window; the growth between them interpolated, `decide.decide`'s ``centres``): a window shifted by an eighth of
its length shares 7/8 of its steps, so the growth between two centres changes little."""
BISECT_STEPS = 2
"""Halvings of the ladder's step between the rung found calm and the one above it (unstable): V* lies within
0.1·V/2² = 2.5 % of V below the rule's edge (each halving is one batched run of the driven loop for every bracket, about 0.4 s on the warehouse: with four, 0.625 %,
the warehouse took 8.2–8.8 s against 7.2–7.8 s, too near its 10 s bar)."""
HEADROOM_GROWTH = 1.25
"""Ratio of the speeds tried above V before the bisection of a stable stretch's V* (its bracket)."""
HEADROOM_MAX = 1e3
"""Largest V*/V searched for a stable stretch; none weaves below it: V* = inf."""
HEADROOM_RTOL = 1e-3
"""Relative width to which a stable stretch's V* is bisected (each halving decides the stretch's routes once more)."""


def stretch_speeds(geometry, rule, V: float, at, runs) -> list:
    """V* (m/s) of each run of `paths._runs` (None for an unjudged run; module docstring).

    Parameters
    ----------
    geometry : decide.RouteGeometry
    rule : decide.DecisionRule
    V : float
        The robot's speed, m/s.
    at : decide.SampleDecision
        The decision at V.
    runs : list of paths._Run
    """
    out = [None] * len(runs)
    unstable = [i for i, r in enumerate(runs) if r.worst is not None and at.code[r.samples[0]] == 1]
    stable = [i for i, r in enumerate(runs) if r.worst is not None and at.code[r.samples[0]] == 0]
    for i, v in zip(unstable, _slower(geometry, rule, V, [runs[i] for i in unstable])):
        out[i] = v
    for i, v in zip(stable, _faster(geometry, rule, V, [runs[i] for i in stable])):
        out[i] = v
    return out


def _slower(geometry, rule, V: float, runs: list) -> list:
    """Each unstable run's V*: the fastest rung of the ladder below V where none of its samples is unstable, then
    `BISECT_STEPS` halvings of the step above it (module docstring). Every rung is decided at once (`_Calm.at`: the
    loop driven at all of them in one run), for every run: a run calm at a rung is not decided again below it in
    effect, as its fastest calm rung is kept."""
    if not runs:
        return []
    calm = _Calm(geometry, rule, runs, drive=True)
    everyone = list(range(len(runs)))
    rungs = [V * (1.0 - k * SPEED_STEP) for k in range(1, SPEED_STEPS + 1)]
    quiet = calm.at([(v, everyone) for v in rungs])
    found = [next((v for v, q in zip(rungs, quiet) if q[i]), None) for i in everyone]
    brackets = {i: (f, f + V * SPEED_STEP) for i, f in enumerate(found) if f is not None}  # (calm, unstable)
    for _ in range(BISECT_STEPS):
        brackets = _halve(calm, brackets)
    return [brackets[i][0] if i in brackets else 0.0 for i in everyone]


def _faster(geometry, rule, V: float, runs: list) -> list:
    """Each stable run's V*: the first speed above V at which one of its samples is unstable by the growth or the
    relay's describing function (the loop not driven; module docstring), bracketed by factors `HEADROOM_GROWTH` and
    halved to `HEADROOM_RTOL`."""
    if not runs:
        return []
    calm = _Calm(geometry, rule, runs, drive=False)
    brackets, v = {}, V
    while v < HEADROOM_MAX * V and len(brackets) < len(runs):
        pending = [i for i in range(len(runs)) if i not in brackets]
        faster = v * HEADROOM_GROWTH
        for i, quiet in zip(pending, calm.at([(faster, pending)])[0]):
            if not quiet:
                brackets[i] = (v, faster)
        v = faster
    while any(hi - lo > HEADROOM_RTOL * hi for lo, hi in brackets.values()):
        brackets = _halve(calm, brackets)
    return [brackets[i][0] if i in brackets else math.inf for i in range(len(runs))]


def _halve(calm, brackets: dict) -> dict:
    """Each run's bracket (calm speed, unstable speed) halved: every bracket's middle decided at once, the runs
    sharing a bracket together."""
    shared = sorted(set(brackets.values()))
    chosen = [[i for i, b in brackets.items() if b == bracket] for bracket in shared]
    middles = [0.5 * (lo + hi) for lo, hi in shared]
    out = dict(brackets)
    for (lo, hi), mid, runs, quiet in zip(shared, middles, chosen, calm.at(list(zip(middles, chosen)))):
        for i, q in zip(runs, quiet):
            out[i] = (mid, hi) if q else (lo, mid)
    return out


class _Calm:
    """Whether runs have no unstable sample at speeds: `decide.decide_speeds` on their own routes alone (each set of
    routes' geometry cut once, `RouteGeometry.subset`), deciding only their samples, every speed asked at once."""

    def __init__(self, geometry, rule, runs: list, drive: bool):
        self.geometry, self.rule, self.runs, self.drive = geometry, rule, runs, drive
        self._parts = {}

    def at(self, asked: list) -> list:
        """Per (v, chosen) of `asked` (m/s; indices into the runs), per run of chosen: calm at v."""
        routes = tuple(sorted({self.runs[i].route for _, chosen in asked for i in chosen}))
        if routes not in self._parts:
            keep = np.isin(self.geometry.route, routes)
            self._parts[routes] = (self.geometry.subset(keep, self.rule.grid, self.rule.law), np.cumsum(keep) - 1)
        part, where = self._parts[routes]
        queries, members = [], []
        for v, chosen in asked:
            mine = [where[self.runs[i].samples] for i in chosen]
            driven = np.zeros(len(self.geometry.paths), dtype=bool)
            driven[[self.runs[i].route for i in chosen]] = True
            queries.append(SpeedQuery(v, self._centres(part, where, v, chosen, mine), driven))
            members.append(mine)
        decisions = decide_speeds(part, self.rule, queries, self.drive)
        return [[not (d.code[m] == 1).any() for m in mine] for d, mine in zip(decisions, members)]

    def _centres(self, part, where: np.ndarray, v: float, chosen: list, members: list) -> np.ndarray:
        """The samples whose windows are multiplied out at v: every `CENTRES_PER_WINDOW`-th of a window of each run,
        its ends and its worst window (`where`: a sample's index in `part`)."""
        omega = self.rule.boundary.omega_critical
        centres = np.zeros(part.x.size, dtype=bool)
        for i, m in zip(chosen, members):
            ds = float(np.median(part.ds[m]))
            stride = max(1, int(WINDOW_PERIODS * wavelength(v, omega) / CENTRES_PER_WINDOW / ds)) if omega and omega > 0 else 1
            centres[m[::stride]] = centres[m[-1]] = True
            if self.runs[i].worst is not None:
                centres[where[self.runs[i].worst]] = True
        return centres
