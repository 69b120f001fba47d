"""The simulated boundary for a start of a given size, beside its prediction (docs/wobble.md, "A disturbance of a given size").

`disturbance_boundary` bisects in V the speed V*(D) at or below which a corridor robot started D m off the centre
line settles — with the drive's yaw acceleration limit a large start can grow where a small one settles — and sets
`analysis.disturbance.disturbance_speed` (the describing-function branch read for that start) and the linear V*
beside it. The runs come from the package's simulator or, through ``runner`` (`validation.bisection.ParameterRuns`'s
interface, as `validate_boundary` takes it), from another engine, e.g. a MuJoCo robot with a velocity smoother
(`engines.mujoco.MujocoRuns.factory`, env ``grid``).

A run **settles** (`settled`) when it ends without an event (collision, trapped) and its lateral swing over the last
fifth of the run is below `DECAY` times the swing over the fifth before: still shrinking at the end. A run that grows
into a cycle, or onto a wall, does not; nor one that shrinks onto a cycle (its swing then stops changing). The
bisection (`numerics.solve.bisect_batched`, one batch of `members` speeds a round) narrows the speed where the
label changes to `rtol`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.disturbance import disturbance_speed
from ..analysis.wobble import corridor_branch, corridor_steering
from ..checks import check_number
from ..io.serialize import json_ready
from ..numerics.solve import bisect_batched
from ..parameters import CARMEL, Controller, Robot
from .bisection import ParameterRuns
from .wobble import WobbleCase, case_law

__all__ = ["DECAY", "DisturbanceBoundary", "settled", "disturbance_boundary"]

DECAY = 0.99
"""A run settles when its swing over the last fifth is below this fraction of the swing over the fifth before (module
docstring): at the default duration a decay rate of −0.005 1/s (a speed within ~0.5 % of V* for CARMEL) still passes."""


@dataclass(frozen=True)
class DisturbanceBoundary:
    """The simulated V*(D) of one start size beside its prediction.

    Attributes
    ----------
    disturbance : float
        D, the start's offset from the centre line, m.
    simulated : float
        The middle of the final bracket, m/s.
    lo, hi : float
        The final bracket: the start settles at lo and does not at hi, m/s.
    predicted : float
        V*(D) of the describing-function branch (`analysis.disturbance.disturbance_speed`), m/s.
    V_critical : float
        The linear V* (the `sampled` model's), m/s.
    runs : int
        Simulations run.
    notes : dict
        The runner's notes (e.g. the engine), if any.
    """

    disturbance: float
    simulated: float
    lo: float
    hi: float
    predicted: float
    V_critical: float
    runs: int
    notes: dict

    @property
    def error(self) -> float:
        """predicted / simulated − 1."""
        return self.predicted / self.simulated - 1.0

    def to_dict(self) -> dict:
        """The fields and the error, JSON-ready (SI units)."""
        return json_ready({**self.__dict__, "error": self.error})


def settled(run) -> bool:
    """Whether a run settles (module docstring): no event, and its swing still shrinking at the end by `DECAY`.

    Parameters
    ----------
    run : sim.results.RunResult
        A run with its lateral offset recorded.
    """
    if run.events:
        return False
    x = np.asarray(run.offset, dtype=float)
    n = x.size
    if n < 10:
        return False
    before, last = np.ptp(x[3 * n // 5: 4 * n // 5]), np.ptp(x[4 * n // 5:])
    return bool(last < DECAY * before or last <= 1e-9 * max(float(np.max(np.abs(x))), 1e-300))


def disturbance_boundary(
    disturbance: float,
    *,
    robot: Robot | None = None,
    controller: Controller | None = None,
    L: float = 0.9,
    env: str = "analytic",
    law: str = "power",
    members: int = 7,
    rtol: float = 0.01,
    duration: float | None = None,
    runner=None,
) -> DisturbanceBoundary:
    """Bisect the simulated V*(D) of a corridor start D m off the centre line, beside the prediction (module docstring).

    Parameters
    ----------
    disturbance : float
        D, m, in (0, L − W/2).
    robot, controller : Robot, Controller
        Default CARMEL (with its `yaw_accel_limit`, if any).
    L : float
        Corridor half-width, m.
    env : {"analytic", "grid"}
        Continuous walls with `law`, or the histogram grid (its averaged law for the prediction).
    law : {"power", "grid"}
        The analytic walls' law.
    members : int
        Speeds per round (>= 3).
    rtol : float
        Relative width of the final bracket.
    duration : float, optional
        Simulated time per run, s (default 40 periods of the sampled boundary's oscillation, within [60, 300] s).
    runner : callable, optional
        ``runner(scenario, env, robot, controller, fixed, common)`` building what simulates the runs (default the
        package's simulator, `bisection.ParameterRuns`).

    Returns
    -------
    DisturbanceBoundary

    Raises
    ------
    ValueError
        A start that does not fit, or a bracket from 0.3·V*(D) to 1.3·V* whose ends the simulation does not tell apart.
    """
    robot = robot or CARMEL.robot
    controller = controller or CARMEL.controller
    disturbance = check_number("disturbance", disturbance, 0.0, L - robot.W / 2, unit="m")
    probe = WobbleCase(robot, controller, L, 0.0, 1.0, env=env, law=law)
    force_law = case_law(probe)
    branch = corridor_branch(robot, controller, force_law, L)
    predicted, _ = disturbance_speed(branch, robot, controller, disturbance, corridor_steering(force_law, L))
    if duration is None:
        duration = float(np.clip(40 * 2 * math.pi / branch.omega_critical, 60.0, 300.0))
    common = {"offset": disturbance, "duration": duration, "L": L, **({"law": law} if env == "analytic" else {})}
    simulate = (runner or ParameterRuns)("corridor", env, robot, controller, {}, common)

    def grows(speeds):
        return [not settled(run) for run in simulate("V", np.asarray(speeds, dtype=float))]

    bracket = bisect_batched(grows, 0.3 * predicted, 1.3 * branch.V_critical, members=members, rtol=rtol)
    notes = dict(getattr(simulate, "notes", {}) or {})
    return DisturbanceBoundary(disturbance, 0.5 * (bracket.lo + bracket.hi), bracket.lo, bracket.hi, predicted, branch.V_critical,
                               int(getattr(simulate, "runs", bracket.evaluations)), notes)
