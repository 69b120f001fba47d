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
(MPPI's noise, DWB's quantization) carries into the prediction: `prediction_spread` predicts the boundary once per
draw (each draw its own noise and place on the plan's poses and cells) and gives their mean and standard error. What the static gains leave out — the measured yaw rate's share k_ω
(DWB) and a controller's memory between cycles (MPPI's control sequence) — the loop models do not represent;
their effect is what the simulated boundary measures against the prediction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_integer, check_number
from ..controllers.linearize import linearize
from ..models import Loop, make_model
from ..models.memory import memory_loop_matrix as models_memory_loop
from ..numerics.solve import bisect_batched
from ..sim.tracking import TrackingScenario, simulate_tracking
from ..sim.verdict import simulated_verdict

__all__ = ["ControllerBoundary", "PredictionSpread", "BOUNDARY_PARAMETERS", "PREDICTIONS", "scenario_at", "simulated_boundary",
           "predicted_boundary", "prediction_spread", "memory_loop_matrix", "loop_of", "boundary_check"]

BOUNDARY_PARAMETERS = ("V", "lookahead_dist", "dead_time")
"""What a boundary is bisected in: the robot's cruising speed V (m/s), RPP's ``lookahead_dist`` (m), or the plant's
dead time D (s; the controller's gains do not depend on it, so they are linearised once)."""

PREDICTIONS = ("sampled", "memory")
"""How a boundary is predicted: the `sampled` model with the one-step gains (KB's loop, the loop models' view), or
the sampled plant closed by the controller's impulse response (`memory_loop_matrix`: its memory between cycles)."""

_STABLE_ABOVE = {"V": False, "lookahead_dist": True, "dead_time": False}
_PLANT_ONLY = {"dead_time"}


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
    if parameter in ("V", "dead_time"):
        return template.replace(robot=template.robot.replace(**{parameter: float(value)}))
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
    (numerics.solve.Bracket, int)
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


def loop_of(gains, scenario: TrackingScenario, k_theta: float | None = None) -> Loop:
    """KB's steering loop of a linearised controller on the scenario's robot: k = k_θ, the plant's g and D.

    Parameters
    ----------
    gains : controllers.LateralGains
    scenario : TrackingScenario
    k_theta : float, optional
        Instead of the gains' k_θ (1/s).
    """
    r = scenario.robot
    k = gains.k_theta if k_theta is None else k_theta
    return Loop(r.tau, scenario.T, k, plant_gain=r.plant_gain, dead_time=r.dead_time)


def _gains(scenario: TrackingScenario, draws, seed: int, memory_cycles=None):
    return linearize(scenario.controller, scenario.controller_params(), scenario.costmap, T=scenario.T, draws=draws,
                     seed=seed, spacing=scenario.spacing, memory_cycles=memory_cycles)


def memory_loop_matrix(gains, scenario: TrackingScenario) -> np.ndarray:
    """The scenario's sampled plant closed by a linearised controller's impulse response (`models.memory.memory_loop_matrix`:
    the one-step gains alone when the gains have no memory).

    Parameters
    ----------
    gains : controllers.LateralGains
    scenario : TrackingScenario
        The plant (τ, g, D), T and the compute delay.
    """
    r = scenario.robot
    mem = gains.memory
    taps = (mem.theta, mem.y, mem.w) if mem is not None else ((gains.k_theta,), (gains.k_y,), (gains.k_w,))
    loop = Loop(r.tau, scenario.T, 1.0, plant_gain=r.plant_gain, dead_time=r.dead_time)
    return models_memory_loop(loop, taps, gains.V, scenario.compute_delay)


def _verdict(model, gains, scenario: TrackingScenario, prediction: str, shift) -> bool:
    shift_y, shift_theta = (shift, shift) if np.ndim(shift) == 0 else shift
    k_theta, k_y = gains.k_theta + shift_theta * gains.k_theta_se, gains.k_y + shift_y * gains.k_y_se
    if prediction == "memory":
        return bool(np.max(np.abs(np.linalg.eigvals(memory_loop_matrix(gains, scenario)))) < 1.0)
    if k_theta <= 0.0 or k_y <= 0.0:
        return False
    return bool(model.is_stable(k_y * gains.V / k_theta, loop_of(gains, scenario, k_theta)))


def predicted_boundary(template: TrackingScenario, parameter: str, lo: float, hi: float, *, prediction: str = "sampled",
                       draws: int | None = None, seed: int = 0, rtol: float = 1e-6, shift: float = 0.0,
                       memory_cycles: int | None = None):
    """Bisect the predicted verdict with the linearised controller at each value (module docstring).

    Parameters
    ----------
    template : TrackingScenario
    parameter : str
        One of `BOUNDARY_PARAMETERS`.
    lo, hi : float
        The bracket; the predicted verdict must differ at its ends.
    prediction : str
        One of `PREDICTIONS`.
    draws : int, optional
        Draws of the linearisation at each value (`controllers.linearize`; default the controller's).
    seed : int
        Its first seed.
    rtol : float
        Stop when hi − lo <= rtol·hi.
    shift : float or (float, float)
        With ``sampled``, the gains are taken at their mean + `shift` standard errors (k_y and k_θ together, or
        (for k_y, for k_θ)): the prediction's sensitivity to the linearisation's sampling error.
    memory_cycles : int, optional
        Cycles of the impulse response for ``memory`` (default 16; ``sampled`` measures one).

    Returns
    -------
    float
        The boundary (the middle of the final bracket).
    """
    check_choice("prediction", prediction, PREDICTIONS)
    model = make_model("sampled", hold="command", compute_delay=template.compute_delay)
    cycles = (16 if memory_cycles is None else memory_cycles) if prediction == "memory" else 1
    fixed = _gains(template, draws, seed, cycles) if parameter in _PLANT_ONLY else None

    def stable(values):
        out = []
        for v in values:
            s = scenario_at(template, parameter, v)
            g = fixed if fixed is not None else _gains(s, draws, seed, cycles)
            out.append(_verdict(model, g, s, prediction, shift))
        return out

    b = bisect_batched(stable, lo, hi, members=5, rtol=rtol, max_rounds=60)
    return 0.5 * (b.lo + b.hi)


@dataclass(frozen=True)
class PredictionSpread:
    """The predicted boundary draw by draw, and its mean and standard error (module docstring).

    Attributes
    ----------
    values : tuple of float
        One prediction per draw (seeds ``seed`` …).
    mean : float
    se : float
        Standard error of the mean.
    """

    values: tuple
    mean: float
    se: float

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict."""
        return {"values": list(self.values), "mean": self.mean, "se": self.se}


def prediction_spread(template: TrackingScenario, parameter: str, lo: float, hi: float, *, prediction: str = "sampled",
                      draws: int = 8, seed: int = 0, rtol: float = 1e-4, memory_cycles: int | None = None) -> PredictionSpread:
    """`predicted_boundary` with one draw of the linearisation at a time, seeds ``seed`` … ``seed + draws − 1``.

    Parameters
    ----------
    template : TrackingScenario
    parameter : str
        One of `BOUNDARY_PARAMETERS`.
    lo, hi : float
        The bracket.
    prediction : str
        One of `PREDICTIONS`.
    draws : int
        Draws (>= 2).
    seed : int
        The first seed.
    rtol : float
        Each bisection's relative width.
    memory_cycles : int, optional
        For ``memory``.
    """
    draws = check_integer("draws", draws, 2, 10_000)
    values = [predicted_boundary(template, parameter, lo, hi, prediction=prediction, draws=1, seed=seed + d, rtol=rtol,
                                 memory_cycles=memory_cycles) for d in range(draws)]
    return PredictionSpread(tuple(values), float(np.mean(values)), float(np.std(values, ddof=1) / np.sqrt(draws)))


def boundary_check(template: TrackingScenario, parameter: str, lo: float, hi: float, *, members: int = 5,
                   rtol: float = 2e-3, prediction: str = "sampled", draws: int | None = None, seed: int = 0,
                   around: float | None = None) -> ControllerBoundary:
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
    prediction : str
        One of `PREDICTIONS`.
    draws : int, optional
        Draws of the linearisation (default the controller's).
    seed : int
        Its first seed.
    around : float, optional
        Simulate in [p/around, p·around] ∩ [lo, hi] around the prediction p (far from a boundary the real algorithm
        leaves the linear regime: saturates, rotates in place); default [lo, hi].
    """
    check_number(f"{parameter} lo", lo, 0.0, low_open=False)
    check_number(f"{parameter} hi", hi, lo)
    predicted = predicted_boundary(template, parameter, lo, hi, prediction=prediction, draws=draws, seed=seed)
    if around is not None:
        w = check_number("around", around, 1.0, 100.0)
        lo, hi = max(lo, predicted / w), min(hi, predicted * w)
    bracket, runs = simulated_boundary(template, parameter, lo, hi, members=members, rtol=rtol)
    simulated = 0.5 * (bracket.lo + bracket.hi)
    return ControllerBoundary(template.controller, parameter, predicted, simulated, bracket.lo, bracket.hi,
                              (simulated - predicted) / predicted, _STABLE_ABOVE[parameter], runs)
