"""The simulated stability boundary in one parameter, by the package's batched bisection.

Both searches here are `pfm_stability.numerics.solve.bisect_batched` (docs/validation.md,
how a boundary is bisected): each round simulates `members` values of one
parameter spread over the current bracket in one batch (`simulate_batch`) and
keeps the cell where the verdict changes, so a round divides the bracket by
members − 1. The verdict is linear stability, what the models predict: the
sign of σ from the linear-prediction fit, a collision being unstable
(`pfm_stability.sim.verdict.simulated_verdict`; not the settled flag
`BatchResult.stable`).

* `boundary_by_bisection` — the bare search in `simulate_batch` units (α in
  rad) on a given bracket: a `BoundaryEstimate`.
* `bisect_boundary` — `validate_boundary`'s search in reported units (α in
  deg): a bracket is grown around a prediction until the verdicts at its ends
  differ, then bisected; every run is kept as a `SimulatedPoint`, and
  `crossing` interpolates σ to zero between the final bracket's ends.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_integer, check_number
from ..io.serialize import json_ready
from ..sim.api import simulate_batch
from ..sim.verdict import linearly_stable, simulated_verdict
from ..numerics.solve import spread_values
from ..numerics.solve import bisect_batched

__all__ = [
    "BoundaryEstimate",
    "ParameterRuns",
    "SimulatedPoint",
    "bisect_boundary",
    "boundary_by_bisection",
    "crossing",
    "run_value",
    "simulated_point",
]


@dataclass(frozen=True)
class BoundaryEstimate:
    """Where the simulated verdict changes.

    Attributes
    ----------
    parameter : str
    value : float
        Midpoint of the final bracket (same unit as the parameter).
    lo, hi : float
        Final bracket: the verdict differs at its ends.
    stable_above : bool
        True if runs are stable for values above the boundary.
    rounds : int
    runs : int
        Simulations run.
    """

    parameter: str
    value: float
    lo: float
    hi: float
    stable_above: bool
    rounds: int
    runs: int

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return dict(self.__dict__)


def boundary_by_bisection(
    scenario: str,
    parameter: str,
    lo: float,
    hi: float,
    *,
    env: str = "analytic",
    rtol: float = 1e-4,
    members: int = 9,
    max_rounds: int = 20,
    **fixed,
) -> BoundaryEstimate:
    """Bisect the simulated stability boundary in one parameter (`bisect_batched` on `linearly_stable`).

    The parameter must change the verdict once inside [lo, hi] (e.g. L:
    unstable below L*, stable above). The first round simulates `members`
    values including both ends; later rounds simulate the `members` − 2
    values inside the current bracket.

    Parameters
    ----------
    scenario : str
        Scenario name (``corridor``, ``wall``, …).
    parameter : str
        A `simulate_batch` parameter (``L``, ``alpha`` in rad, ``V``, ``f``, …).
    lo, hi : float
        Bracket; the verdict must differ at its ends.
    env : {"analytic", "grid"}
    rtol : float
        Stop when hi − lo <= rtol·|hi|.
    members : int
        Values per round (>= 3).
    max_rounds : int
    **fixed
        Other `simulate_batch` arguments (scalars), e.g. ``offset=1e-6``.

    Raises
    ------
    ValueError
        If the verdict is the same at both ends of the bracket, or the bracket
        is already narrower than `rtol`.
    """
    lo = check_number(f"{parameter} lo", lo)
    hi = check_number(f"{parameter} hi", hi, lo)
    rtol = check_number("rtol", rtol, 0.0)
    members = check_integer("members", members, 3, 10_000)
    if hi - lo <= rtol * abs(hi):
        raise ValueError(f"{parameter}: bracket [{lo:g}, {hi:g}] is already narrower than rtol")
    batches = []

    def stable(values):
        batches.append(linearly_stable(simulate_batch(scenario, env=env, metrics=True, **{parameter: values}, **fixed)))
        return batches[-1]

    try:
        b = bisect_batched(stable, lo, hi, members=members, rtol=rtol, max_rounds=max_rounds)
    except ValueError:
        if len(batches) == 1 and batches[0][0] == batches[0][-1]:  # bisect_batched's "same label at both ends"
            raise ValueError(
                f"{parameter}: the simulated verdict is {'stable' if batches[0][0] else 'not stable'} at both ends of "
                f"[{lo:g}, {hi:g}]; widen the bracket"
            ) from None
        raise
    return BoundaryEstimate(parameter, (b.lo + b.hi) / 2, b.lo, b.hi, bool(b.high_label), b.rounds, b.evaluations)


# ----------------------------------------------------- the validation's search
@dataclass(frozen=True)
class SimulatedPoint:
    """One simulated run of a bisection or a stability map.

    Attributes
    ----------
    value : float
        Parameter value (reported units: L m, α deg, V m/s, f).
    verdict : str
        "stable" or "unstable" (`pfm_stability.sim.verdict.simulated_verdict`).
    basis : str
        "growth_rate", "collision" or "metrics".
    growth_rate : float or None
        Measured σ, 1/s.
    x : float or None
        Second coordinate in a stability map (None in the bisection).
    """

    value: float
    verdict: str
    basis: str
    growth_rate: float | None
    x: float | None = None

    def to_dict(self) -> dict:
        """Plain JSON form (field name → value; numbers by `serialize.json_number`)."""
        return json_ready(dict(self.__dict__))


class ParameterRuns:
    """Runs batches of one scenario with one parameter varied (and optionally a second), in reported units.

    ``runs(name, values, second=(name2, values2))`` → the batch's `RunResult`s;
    α is given in degrees and simulated in radians. ``runs.runs`` counts the
    simulations.

    Parameters
    ----------
    scenario : str
        The scenario's name (`sim.presets.SCENARIO_NAMES`).
    env : {"grid", "analytic"}
        The environment's kind.
    robot, controller : Robot, Controller
        The robot and its controller.
    fixed : dict
        Parameters held fixed unless varied (simulator units: α in rad).
    common : dict
        Options of every batch (offset, duration, the grid's window and cells).
    """

    def __init__(self, scenario, env, robot, controller, fixed, common):
        self.scenario, self.env = scenario, env
        self.robot, self.controller = robot, controller
        self.fixed = fixed
        self.common = common
        self.runs = 0

    @staticmethod
    def _sim_values(name, values):
        return np.radians(values) if name == "alpha" else np.asarray(values, dtype=float)

    def __call__(self, name, values, second=None):
        arrays = {name: self._sim_values(name, values)}
        if second is not None:
            arrays[second[0]] = self._sim_values(second[0], second[1])
        fixed = {k: v for k, v in self.fixed.items() if k not in arrays}
        batch = simulate_batch(
            self.scenario, env=self.env, robot=self.robot, controller=self.controller, record="offset", metrics=True,
            **fixed, **self.common, **arrays,
        )
        self.runs += len(batch)
        return batch.runs


def run_value(run, name) -> float:
    """The parameter value a run really used (reported units): grid corridors snap L to c/2.

    Parameters
    ----------
    run : RunResult
        A simulated run.
    name : str
        A parameter (`V`, `L`, `alpha` in degrees, `f`).
    """
    s = run.scenario
    if name == "L":
        return float(s.analysis["L"])
    if name == "alpha":
        return math.degrees(s.analysis["alpha"])
    if name == "V":
        return s.robot.V
    return s.controller.f


def simulated_point(run, name, x_name=None) -> SimulatedPoint:
    """The `SimulatedPoint` of one run: its value of `name` (and `x_name`), verdict and σ.

    Parameters
    ----------
    run : RunResult
        A simulated run.
    name : str
        The varied parameter.
    x_name : str, optional
        A second varied parameter (a stability map's x).
    """
    verdict, basis = simulated_verdict(run)
    return SimulatedPoint(run_value(run, name), verdict, basis, run.metrics.growth_rate, run_value(run, x_name) if x_name else None)


def bisect_boundary(simulate, name, p, domain, *, stable_above, members, rtol, quantum, progress):
    """Bracket around the prediction p, then `bisect_batched`.

    The bracket [p/w, p·w] ∩ `domain` grows (w = 1.25, 1.56, 2.4, 5.96, 35.5)
    until the verdict at its low end is the one expected below the boundary
    and differs at its high end (only the two ends are simulated per try);
    then each round simulates `members` − 2 values inside the bracket. With
    `quantum` (grid corridor widths), only its multiples are simulated and the
    search stops at two neighbouring multiples; otherwise when
    hi − lo <= rtol·|hi|. The first inside round and the two ends together
    make the first round of `members` runs.

    Parameters
    ----------
    simulate : ParameterRuns
    name : str
        The parameter (reported units).
    p : float
        The sampled model's prediction.
    domain : (float, float)
        The values the scenario can be simulated with.
    stable_above : bool
    members : int
    rtol : float
    quantum : float or None
    progress : callable or None
        Called with one line per round.

    Returns
    -------
    (SimulatedPoint, SimulatedPoint, list, dict)
        The final bracket's low and high ends, every run, notes.
    """
    low_expected = "unstable" if stable_above else "stable"
    tried = []
    width = 1.25
    for _ in range(5):  # widen the bracket until the verdicts at its ends differ
        lo = max(domain[0], p / width)
        hi = min(domain[1], p * width)
        ends = spread_values(lo, hi, 2, quantum, False)  # with a quantum: the outermost multiples inside
        if ends.size < 2:
            raise ValueError(f"{name}: the bracket [{lo:g}, {hi:g}] holds fewer than two values the simulator can represent")
        ends = [float(v) for v in ends]
        lo_pt, hi_pt = (simulated_point(r, name) for r in simulate(name, np.array(ends)))
        tried += [lo_pt, hi_pt]
        if lo_pt.verdict == low_expected and hi_pt.verdict != low_expected:
            break
        if lo <= domain[0] and hi >= domain[1]:
            break
        width = width**2
    if lo_pt.verdict == hi_pt.verdict:
        raise ValueError(
            f"{name}: the simulated verdict is {lo_pt.verdict} at both ends of [{lo_pt.value:g}, {hi_pt.value:g}] "
            f"around the sampled model's prediction {p:g}; no boundary to bisect"
        )

    at = dict(zip(ends, (lo_pt, hi_pt)))  # simulated value → point
    rounds = []

    def verdicts(values):
        pts = [simulated_point(r, name) for r in simulate(name, values)]
        at.update(zip(values.tolist(), pts))
        rounds.append(pts)
        return [pt.verdict for pt in pts]

    def report(b):
        if progress:
            progress(f"round {b.rounds}: {name} in [{at[b.lo].value:.6g}, {at[b.hi].value:.6g}]")

    b = bisect_batched(
        verdicts, ends[0], ends[1], members=members, rtol=0.0 if quantum is not None else rtol, quantum=quantum,
        max_rounds=30, ends=(lo_pt.verdict, hi_pt.verdict), on_round=report,
    )
    notes = {}
    if b.most_changes > 1:
        notes["non_monotone"] = f"the verdict changed {b.most_changes} times inside one bracket; the change nearest the low end was kept"
    count = max(b.rounds, 1)  # the ends and the first inside values make round 1
    notes["rounds"] = "stopped after 30 rounds" if b.rounds >= 30 else f"{count} round{'s' if count > 1 else ''} of at most {members} runs"
    first = rounds[0] if rounds else []
    points = tried[:-2] + [lo_pt] + first + [hi_pt] + [pt for later in rounds[1:] for pt in later]
    return at[b.lo], at[b.hi], points, notes


def crossing(lo_pt: SimulatedPoint, hi_pt: SimulatedPoint) -> float:
    """Zero of σ by linear interpolation between the bracket's ends (midpoint when σ is not usable).

    Parameters
    ----------
    lo_pt, hi_pt : SimulatedPoint
        The bracket's ends.
    """
    a, b = lo_pt.growth_rate, hi_pt.growth_rate
    if lo_pt.basis == hi_pt.basis == "growth_rate" and a is not None and b is not None and a * b < 0:
        return lo_pt.value + (hi_pt.value - lo_pt.value) * a / (a - b)
    return (lo_pt.value + hi_pt.value) / 2
