"""A Nav2 controller's stability boundary, simulated and predicted (docs/controllers.md, "The proof").

The only place where the controllers' linearisation meets the loop models and the simulator:

* **simulated** (`simulated_boundary`): the verdict of `sim.tracking` runs of the real algorithm
  (`sim.verdict.simulated_verdict`: the sign of the measured growth rate, a collision unstable), bisected in the
  robot's speed V or in a controller parameter (RPP's ``lookahead_dist``) by the package's one batched bisection
  (`numerics.solve.bisect_batched`), `members` runs per round in one batch;
* **predicted** (`predicted_boundary`): at each value the controller is linearised (`controllers.linearize`:
  k_θ, k_y at that value), and the `sampled` loop model with the command hold and the scenario's compute delay
  judges KB's loop `Loop(τ, T, k = k_θ, plant_gain = g, dead_time = D)` at NV = k_y·V/k_θ; the same bisection
  finds where the verdict changes.

`boundary_check` runs both and returns a `ControllerBoundary`. The linearisation's sampling uncertainty
(MPPI's noise, DWB's quantization) carries into the prediction: `prediction_spread` bisects the boundary with the
gains at their mean ± one standard error. What the static gains leave out — the measured yaw rate's share k_ω
(DWB) and a controller's memory between cycles (MPPI's control sequence) — the loop models do not represent;
their effect is what the simulated boundary measures against the prediction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_integer, check_number
from ..controllers import linearize
from ..models import Loop, make_model
from ..numerics.solve import bisect_batched
from ..sim.tracking import TrackingScenario, simulate_tracking
from ..sim.verdict import simulated_verdict

__all__ = ["ControllerBoundary", "BOUNDARY_PARAMETERS", "scenario_at", "simulated_boundary", "predicted_boundary",
           "loop_of", "boundary_check"]

BOUNDARY_PARAMETERS = ("V", "lookahead_dist")
"""What a boundary is bisected in: the robot's cruising speed V (m/s), or RPP's ``lookahead_dist`` (m)."""

_STABLE_ABOVE = {"V": False, "lookahead_dist": True}


@dataclass(frozen=True)
class ControllerBoundary:
    """A controller's simulated and predicted boundary in one parameter (module docstring).

    Attributes
    ----------
    controller : str
    parameter : str
        ``V`` (m/s) or ``lookahead_dist`` (m).
    predicted : float
        Where the sampled model's verdict changes, with the linearised gains.
    simulated : float
        The middle of the simulated bracket.
    simulated_lo, simulated_hi : float
        The simulated bracket: the verdict differs at its ends.
    relative_error : float
        (simulated − predicted)/predicted.
    stable_above : bool
        Runs are stable above the boundary (lookahead) or below it (speed).
    runs : int
        Simulations run.
    """

    controller: str
    parameter: str
    predicted: float
    simulated: float
    simulated_lo: float
    simulated_hi: float
    relative_error: float
    stable_above: bool
    runs: int

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return dict(self.__dict__)


def scenario_at(template: TrackingScenario, parameter: str, value: float) -> TrackingScenario:
    """The template with one parameter set: the robot's V, or a field of the controller's parameters.

    Parameters
    ----------
    template : TrackingScenario
    parameter : str
        One of `BOUNDARY_PARAMETERS`.
    value : float
        Its value (m/s or m).
    """
    check_choice("parameter", parameter, BOUNDARY_PARAMETERS)
    if parameter == "V":
        return template.replace(robot=template.robot.replace(V=float(value)))
    return template.replace(params=template.params.replace(**{parameter: float(value)}))


def simulated_boundary(template: TrackingScenario, parameter: str, lo: float, hi: float, *, members: int = 5,
                       rtol: float = 2e-3, max_rounds: int = 12):
    """Bisect the simulated verdict of the real algorithm in one parameter (module docstring).

    Parameters
    ----------
    template : TrackingScenario
        Everything but the parameter.
    parameter : str
        One of `BOUNDARY_PARAMETERS`.
    lo, hi : float
        The bracket; the simulated verdict must differ at its ends.
    members : int
        Runs per round (>= 3).
    rtol : float
        Stop when hi − lo <= rtol·hi.
    max_rounds : int

    Returns
    -------
    (numpy.solve.Bracket, int)
        The final bracket and the runs simulated.
    """
    members = check_integer("members", members, 3, 1000)
    runs = []

    def stable(values):
        batch = simulate_tracking([scenario_at(template, parameter, v) for v in values])
        runs.append(len(batch))
        return [simulated_verdict(r)[0] == "stable" for r in batch.runs]

    bracket = bisect_batched(stable, lo, hi, members=members, rtol=rtol, max_rounds=max_rounds)
    return bracket, sum(runs)


def loop_of(gains, scenario: TrackingScenario) -> Loop:
    """KB's steering loop of a linearised controller on the scenario's robot: k = k_θ, the plant's g and D.

    Parameters
    ----------
    gains : controllers.LateralGains
    scenario : TrackingScenario
    """
    r = scenario.robot
    return Loop(r.tau, scenario.T, gains.k_theta, plant_gain=r.plant_gain, dead_time=r.dead_time)


def _gains(scenario: TrackingScenario, draws: int, seed: int):
    return linearize(scenario.controller, scenario.controller_params(), scenario.costmap, T=scenario.T, draws=draws,
                     seed=seed, spacing=scenario.spacing)


def predicted_boundary(template: TrackingScenario, parameter: str, lo: float, hi: float, *, draws: int = 1, seed: int = 0,
                       rtol: float = 1e-6, shift: float = 0.0):
    """Bisect the sampled model's verdict with the linearised gains at each value (module docstring).

    Parameters
    ----------
    template : TrackingScenario
    parameter : str
        One of `BOUNDARY_PARAMETERS`.
    lo, hi : float
        The bracket; the predicted verdict must differ at its ends.
    draws : int
        Draws of the linearisation at each value (`controllers.linearize`).
    seed : int
        Its first seed.
    rtol : float
        Stop when hi − lo <= rtol·hi.
    shift : float
        The gains are taken at their mean + `shift` standard errors (k_y and k_θ together): the prediction's spread.

    Returns
    -------
    float
        The boundary (the middle of the final bracket).
    """
    model = make_model("sampled", hold="command", compute_delay=template.compute_delay)

    def stable(values):
        out = []
        for v in values:
            s = scenario_at(template, parameter, v)
            g = _gains(s, draws, seed)
            k_theta, k_y = g.k_theta + shift * g.k_theta_se, g.k_y + shift * g.k_y_se
            if k_theta <= 0.0 or k_y <= 0.0:
                out.append(False)
                continue
            loop = Loop(s.robot.tau, s.T, k_theta, plant_gain=s.robot.plant_gain, dead_time=s.robot.dead_time)
            out.append(bool(model.is_stable(k_y * g.V / k_theta, loop)))
        return out

    b = bisect_batched(stable, lo, hi, members=5, rtol=rtol, max_rounds=60)
    return 0.5 * (b.lo + b.hi)


def boundary_check(template: TrackingScenario, parameter: str, lo: float, hi: float, *, members: int = 5,
                   rtol: float = 2e-3, draws: int = 1, seed: int = 0) -> ControllerBoundary:
    """The simulated and the predicted boundary of a controller in one parameter, side by side (module docstring).

    Parameters
    ----------
    template : TrackingScenario
    parameter : str
        One of `BOUNDARY_PARAMETERS`.
    lo, hi : float
        A bracket holding both boundaries.
    members : int
        Simulations per round.
    rtol : float
        The simulated bracket's relative width at the end.
    draws : int
        Draws of the linearisation.
    seed : int
        Its first seed.
    """
    check_number(f"{parameter} lo", lo, 0.0)
    check_number(f"{parameter} hi", hi, lo)
    predicted = predicted_boundary(template, parameter, lo, hi, draws=draws, seed=seed)
    bracket, runs = simulated_boundary(template, parameter, lo, hi, members=members, rtol=rtol)
    simulated = 0.5 * (bracket.lo + bracket.hi)
    return ControllerBoundary(template.controller, parameter, predicted, simulated, bracket.lo, bracket.hi,
                              (simulated - predicted) / predicted, _STABLE_ABOVE[parameter], runs)
