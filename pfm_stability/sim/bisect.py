"""The simulated stability boundary, by batched bisection (DESIGN §6).

Each round simulates `members` values of one parameter spread evenly over the
current bracket in a single batch (`simulate_batch`), finds where the verdict
changes, and shrinks the bracket to the two neighbouring values, so one round
divides the bracket by members − 1. The verdict is linear stability, what
the models predict: σ < 0 (σ from the linear-prediction fit, exact in the
linear regime) and no collision; where σ is undefined, the run's
`OscillationMetrics.stable`. (`stable` alone would also call a slowly decaying
run with a limit-cycle-like envelope "not stable", biasing grid boundaries.)
The parameter must change the verdict once inside [lo, hi] (e.g. L: unstable
below L*, stable above).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_integer, check_number
from .api import simulate_batch

__all__ = ["BoundaryEstimate", "boundary_by_bisection", "linearly_stable", "simulated_verdict"]


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


def simulated_verdict(run) -> tuple[str, str]:
    """(verdict, basis) of one simulated run: "stable" or "unstable", and why.

    A collision is unstable; otherwise the sign of the measured growth rate σ
    (linear stability, what the loop models predict); when σ is undefined (too
    few turning points and a rejected linear fit) the run's own
    `OscillationMetrics.stable` decides.

    Returns
    -------
    (str, str)
        Verdict, and its basis: ``"collision"``, ``"growth_rate"`` or ``"metrics"``.
    """
    if run.collided:
        return "unstable", "collision"
    m = run.metrics
    if m is None:
        raise ValueError("run has no metrics: simulate with metrics=True")
    if m.growth_rate is not None:
        return ("stable" if m.growth_rate < 0 else "unstable"), "growth_rate"
    return ("stable" if m.stable else "unstable"), "metrics"


def linearly_stable(result) -> np.ndarray:
    """`simulated_verdict` == "stable" for every member of a `BatchResult` (bool array)."""
    return np.array([simulated_verdict(run)[0] == "stable" for run in result.runs], dtype=bool)


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
    """Bisect the simulated stability boundary in one parameter.

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
        Stop when (hi − lo) <= rtol·|midpoint|.
    members : int
        Values per round (>= 3).
    max_rounds : int
    **fixed
        Other `simulate_batch` arguments (scalars), e.g. ``offset=1e-6``.

    Raises
    ------
    ValueError
        If the verdict is the same at both ends of the bracket.
    """
    lo = check_number(f"{parameter} lo", lo)
    hi = check_number(f"{parameter} hi", hi, lo)
    rtol = check_number("rtol", rtol, 0.0)
    members = check_integer("members", members, 3, 10_000)
    runs = rounds = 0
    stable_above = None
    while rounds < max_rounds and hi - lo > rtol * abs(lo + hi) / 2:
        values = np.linspace(lo, hi, members)
        result = simulate_batch(scenario, env=env, metrics=True, **{parameter: values}, **fixed)
        stable = linearly_stable(result)
        runs += members
        rounds += 1
        if stable[0] == stable[-1]:
            raise ValueError(
                f"{parameter}: the simulated verdict is {'stable' if stable[0] else 'not stable'} at both ends of "
                f"[{lo:g}, {hi:g}]; widen the bracket"
            )
        stable_above = bool(stable[-1])
        change = int(np.argmax(stable != stable[0]))
        lo, hi = float(values[change - 1]), float(values[change])
    if stable_above is None:
        raise ValueError(f"{parameter}: bracket [{lo:g}, {hi:g}] is already narrower than rtol")
    return BoundaryEstimate(parameter, (lo + hi) / 2, lo, hi, stable_above, rounds, runs)
