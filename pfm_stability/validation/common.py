"""What the validations share: the bisected parameters, their domains, the model set, predicted boundaries.

The simulated verdict is the sign of the measured growth rate σ
(`pfm_stability.sim.verdict.simulated_verdict`), not the settled flag
`OscillationMetrics.stable`: that flag also calls a run "not stable" when its
swings change by less than 10 % over the second half of the window (the
limit-cycle test), which near the boundary catches slowly *decaying*
oscillations (|σ| ≲ ln 1.1/(duration/2) ≈ 0.006 1/s over 30 s) and would bias
every bisected boundary towards the stable side — measured on the grid wall
at α = 33°: σ = −0.0009 1/s, flagged as a limit cycle. The loop models have
no limit cycle; the quantity they predict is σ (docs/validation.md).

The lateral law a validation geometry sees is `pfm_stability.sim.scenario_law`'s
(re-exported here); the models are asked through `predict.model_answer` and
`predict.critical_value` only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..analysis.criteria import loop_of
from ..laws.effective_force import GridWallLaw
from ..laws.force_law import ForceLaw
from ..models import MODEL_NAMES, make_model
from ..parameters import CARMEL, Controller, Robot
from ..sim.scenario import scenario_law
from .predict import critical_value, lumped_law, model_answer

__all__ = [
    "SCENARIOS",
    "PARAMETERS",
    "ParameterSpec",
    "parameter_spec",
    "default_parameter",
    "validation_models",
    "predicted_boundaries",
    "lumped_law",
    "relative_errors",
    "scenario_law",
    "parameter_domain",
    "f_av_of",
    "REFERENCE_SETS",
]

SCENARIOS = ("corridor", "wall")
"""Validation geometries of `pfm_stability.sim.presets` (long, straight, target at infinity)."""


@dataclass(frozen=True)
class ParameterSpec:
    """A parameter whose stability boundary can be bisected.

    Attributes
    ----------
    name : str
        ``L``, ``alpha``, ``V`` or ``f``.
    unit : str
        Unit of the reported values (α in degrees).
    scenarios : tuple of str
        Scenarios in which the parameter exists.
    """

    name: str
    unit: str
    scenarios: tuple

    def stable_above(self, scenario: str) -> bool:
        """True if runs are stable for values above the boundary.

        L (KB eq 25) and α (eq 24): wider and shallower is stable; V (eq 20):
        slower is stable; f: a corridor is stable for weaker repulsion (N ∝ f),
        a wall for stronger (the equilibrium moves out to a flatter force).

        Parameters
        ----------
        scenario : str
            ``"corridor"`` or ``"wall"``.
        """
        if self.name == "V":
            return False
        if self.name == "f":
            return scenario == "wall"
        return True


PARAMETERS = {
    "L": ParameterSpec("L", "m", ("corridor",)),
    "alpha": ParameterSpec("alpha", "deg", ("wall",)),
    "V": ParameterSpec("V", "m/s", SCENARIOS),
    "f": ParameterSpec("f", "", SCENARIOS),
}
"""The parameters `validate_boundary` bisects (L, α or V; f as KB's tuning knob, §3; docs/validation.md)."""


def parameter_spec(scenario: str, parameter: str) -> ParameterSpec:
    """The spec of `parameter`, after checking it exists in `scenario`.

    Parameters
    ----------
    scenario : str
        ``"corridor"`` or ``"wall"``.
    parameter : str
        The parameter's name.

    Raises
    ------
    ValueError
        ``"parameter must be one of L, V, f for scenario corridor; got 'alpha'"``.
    """
    allowed = [name for name, spec in PARAMETERS.items() if scenario in spec.scenarios]
    if parameter not in allowed:
        raise ValueError(f"parameter must be one of {', '.join(allowed)} for scenario {scenario}; got {parameter!r}")
    return PARAMETERS[parameter]


def default_parameter(scenario: str) -> str:
    """L for a corridor, α for a wall (the environment parameter of KB eq 25 and 24).

    Parameters
    ----------
    scenario : str
        ``"corridor"`` or ``"wall"``.
    """
    return "L" if scenario == "corridor" else "alpha"


def validation_models(controller: Controller, pade_order: int = 3) -> list:
    """The five models of docs/models.md, ``sampled`` with the controller's hold and compute delay.

    Parameters
    ----------
    controller : Controller
        Hold and compute delay of ``sampled``.
    pade_order : int
        Order of ``pade``.
    """
    return [
        make_model(name, pade_order=pade_order, hold=controller.hold, compute_delay=controller.compute_delay)
        for name in MODEL_NAMES
    ]


def predicted_boundaries(
    scenario: str, parameter: str, robot: Robot, controller: Controller, law: ForceLaw, geometry: float, models
) -> dict:
    """Each model's critical value of `parameter` (reported units), all else fixed.

    Each model's NV* (`predict.model_answer`) through `predict.critical_value`
    (the general-law conditions of `pfm_stability.analysis.criteria`, KB eq 20 with
    1/NV* in place of τ + T): L* (eq 25), α* (eq 24), V* = NV*/N, f*.

    Parameters
    ----------
    scenario : {"corridor", "wall"}
    parameter : {"L", "alpha", "V", "f"}
    robot, controller : Robot, Controller
    law : ForceLaw
        The lateral law the run sees (`Scenario.effective_law`).
    geometry : float
        L (m) for a corridor, α (rad) for a wall: the operating point (not
        used for L* and α*).
    models : list of LoopModel

    Returns
    -------
    dict
        Model name → L* (m), α* (deg), V* (m/s) or f* (KB's f: a grid law's
        critical cell ratio ρ* is converted with f/ρ, ρ ∝ f by calibration);
        ``inf``/0 where a model has no finite boundary.
    """
    parameter_spec(scenario, parameter)
    loop = loop_of(robot, controller)
    return {
        model.name: critical_value(parameter, scenario, law, robot.V, model_answer(model, loop).NV_critical, geometry, controller.f)
        for model in models
    }


def relative_errors(predicted: dict, simulated: float) -> dict:
    """(predicted − simulated)/simulated per model; None where a prediction is not finite.

    Parameters
    ----------
    predicted : dict
        Model name → predicted boundary.
    simulated : float
        The simulated boundary.
    """
    return {
        name: (value - simulated) / simulated if math.isfinite(value) and simulated != 0 else None
        for name, value in predicted.items()
    }


def f_av_of(law: ForceLaw) -> float:
    """KB's f_av of a grid law (§4), or a power law's f (`ForceLaw.lumped_f`).

    Parameters
    ----------
    law : ForceLaw
        A grid or power law.
    """
    return law.lumped_f()


def parameter_domain(parameter: str, scenario: str, env: str, robot: Robot, controller: Controller, law: ForceLaw, alpha, cell_size: float = 0.1):
    """(lo, hi): the values of `parameter` the scenario can be simulated with (reported units).

    L: the robot disc clears both walls (W/2, plus c/2 in the grid, plus a
    margin of max(1 cm, 2 % W)) and, in the grid, the walls lie inside the
    active window (L <= reach − c: beyond the reach (h + ½)c the grid wall
    exerts no force at all, while `GridWallLaw` continues with a power-law
    tail that describes no grid). α (deg) and a wall's f: the equilibrium
    distance d0 (KB eq 23) clears the wall by that margin and, in the grid,
    stays inside the active window (d0 < reach − c) where the wall acts.
    V: (1 mm/s, 100 m/s]. A corridor's f: f·[1e-3, 1e3].
    `alpha` is the wall angle (rad) when f is the parameter.

    Parameters
    ----------
    parameter : str
        ``L``, ``alpha``, ``V`` or ``f``.
    scenario : str
        ``"corridor"`` or ``"wall"``.
    env : {"grid", "analytic"}
        The environment's kind.
    robot, controller : Robot, Controller
        The robot and its controller.
    law : ForceLaw
        The walls' law.
    alpha : float or None
        The wall angle, rad, when f is the parameter.
    cell_size : float
        Cell side c, m.
    """
    contact = robot.W / 2 + (cell_size / 2 if env == "grid" else 0.0)
    margin = max(0.01, 0.02 * robot.W)
    reach = law.reach - cell_size if isinstance(law, GridWallLaw) else math.inf
    if parameter == "L":
        return contact + margin, reach if math.isfinite(reach) else 1e4
    if parameter == "V":
        return 1e-3, 100.0
    if parameter == "alpha":
        # d0 = F⁻¹(cos α) must clear the wall (α > acos F(contact)) and, in the grid, stay inside the window
        near = float(law.force(contact + margin))
        lo = math.degrees(math.acos(min(1.0, near))) if near < 1 else 0.0
        hi = math.degrees(math.acos(min(1.0, float(law.force(reach))))) if math.isfinite(reach) else 90.0
        return max(lo, 0.5), min(hi, 89.5)
    if scenario == "corridor":
        return controller.f * 1e-3, controller.f * 1e3
    cos_a = math.cos(alpha)
    lo = controller.f * cos_a / float(law.force(contact + margin))
    hi = controller.f * cos_a / float(law.force(reach)) if math.isfinite(reach) else controller.f * 1e3
    return max(lo, controller.f * 1e-3), min(hi, controller.f * 1e3)


REFERENCE_SETS = {
    "carmel": (CARMEL.robot, CARMEL.controller),
    "fast": (Robot(V=1.2, tau=0.15, k=4.0, W=0.8), Controller(f=1.5, n=2.0, T=0.1)),
    "slow": (Robot(V=0.5, tau=0.6, k=1.0, W=0.8), Controller(f=0.5, n=2.0, T=0.03)),
}
"""Parameter sets the boundary validation is checked on (tests, ``experiments/validation_summary.py``).

``carmel``: KB's robot (§4, §5.4; k = 2 1/s assumed). ``fast``: a quicker,
stiffer robot with a slow controller (V = 1.2 m/s, τ = 0.15 s, k = 4 1/s,
f = 1.5, T = 0.1 s: kT = 0.4, the sampled loop far from KB's). ``slow``: a
sluggish robot with a fast controller (V = 0.5 m/s, τ = 0.6 s, k = 1 1/s,
f = 0.5, T = 0.03 s: close to the continuous loop). W = 0.8 m, n = 2. The
hold and compute delay are set per check (`Controller.replace`)."""
