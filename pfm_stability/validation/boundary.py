"""The simulated stability boundary against every model's prediction (docs/validation.md).

`validate_boundary` bisects the simulated boundary of a straight corridor or
wall (`pfm_stability.sim.presets`: target at infinity, so α is constant as KB
assume) in one parameter — L (KB eq 25), α (eq 24), V (eq 20) or f (eq 13) —
and sets every model of docs/models.md beside it, each fed the lateral law
the simulation really has (`pfm_stability.sim.scenario_law`: KB's power law
in the analytic environment, the grid's `GridWallLaw` in the histogram grid,
docs/simulator.md). In the grid, the predictions of KB's lumped law with the
grid's f_av are reported beside them, as KB compared (§4).

Bisection (`bisection.bisect_boundary`, the package's one batched bisection
`pfm_stability.numerics.solve.bisect_batched`): each round simulates `members` values
spread over the bracket in one batch (`simulate_batch`), keeps the two
neighbours where the verdict changes, and stops when the bracket is narrower
than `rtol` relative. The verdict is the sign of the measured growth rate σ
(`pfm_stability.sim.verdict.simulated_verdict`); the reported boundary
interpolates σ linearly to zero between the final bracket's ends (σ is
smooth in the parameter; the midpoint when σ is undefined at an end). In the
grid a corridor's walls lie on cell centres, so L takes only multiples of
c/2 (0.05 m): the bracket is then two neighbouring widths and the
interpolation of σ gives the boundary between them.

Near the boundary, σ and ω are measured at the boundary and `probe` (3 %)
either side, and compared with the dominant root of the matching `sampled`
model at each run's own operating point (`pfm_stability.validation.predict`).
With ``stability_map=(nx, ny)`` the verdicts on a grid around the boundary and
every model's boundary curve are added (`region.StabilityMap`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..checks import check_choice, check_integer, check_number
from ..analysis.criteria import loop_of
from ..laws.effective_force import GridWallLaw
from ..parameters import CARMEL, Controller, Robot
from ..io.serialize import json_number, json_ready
from .bisection import ParameterRuns, SimulatedPoint, bisect_boundary, crossing, run_value
from .common import SCENARIOS, default_parameter, f_av_of, lumped_law, parameter_domain, parameter_spec, predicted_boundaries, relative_errors, scenario_law, validation_models
from .predict import model_answer, predict
from .region import StabilityMap, stability_map as simulate_stability_map

__all__ = [
    "OscillationCheck",
    "BoundaryValidation",
    "SimulatedPoint",  # re-exported from `bisection`: the type of `BoundaryValidation.points`
    "validate_boundary",
    "ENVS",
    "DEFAULT_OFFSET",
]

ENVS = ("analytic", "grid")

DEFAULT_OFFSET = {"analytic": 1e-7, "grid": 0.01}
"""Start offset from equilibrium, m. Analytic: 1e-7 m keeps the run linear to
round-off (σ, ω exact to ~1e-8, tests/test_sim_validation.py). Grid: the force
ripples with the robot's position in its cell and forces a response of
~1e-4 m; 1 cm keeps the free oscillation well above it while x/L stays ~1 %."""


@dataclass(frozen=True)
class OscillationCheck:
    """σ and ω measured near the boundary against the matching `sampled` model's dominant root.

    Attributes
    ----------
    value : float
        Parameter value of the run (reported units; for a grid corridor the L actually drawn).
    growth_rate, angular_frequency : float or None
        Measured σ (1/s) and ω (rad/s) (docs/simulator.md, measuring oscillation).
    method : str
        Estimator: "linear_prediction" (exact for a linear run) or "peaks".
    predicted_growth_rate, predicted_angular_frequency : float
        Dominant root of `sampled` (σ = ln|z|/T, ω = arg z/T) at the run's NV.
    growth_rate_error : float or None
        σ − σ_model, 1/s.
    frequency_error : float or None
        ω/ω_model − 1.
    """

    value: float
    growth_rate: float | None
    angular_frequency: float | None
    method: str
    predicted_growth_rate: float
    predicted_angular_frequency: float
    growth_rate_error: float | None
    frequency_error: float | None

    def to_dict(self) -> dict:
        """Plain JSON form (field name → value; numbers by `serialize.json_number`)."""
        return json_ready(dict(self.__dict__))


@dataclass(frozen=True)
class BoundaryValidation:
    """Simulated boundary, every model's prediction and the oscillation near it.

    Attributes
    ----------
    scenario : {"corridor", "wall"}
    env : {"analytic", "grid"}
    parameter : {"L", "alpha", "V", "f"}
        The bisected parameter.
    unit : str
        Its unit ("m", "deg", "m/s", "").
    simulated_boundary : float
        Where the simulated σ changes sign.
    bracket : (float, float)
        Final bracket: the verdict differs at its ends.
    stable_above : bool
        True if runs are stable above the boundary.
    predicted_boundary : dict
        Model name → predicted boundary with the run's own law (``inf``/0:
        no finite boundary).
    relative_error : dict
        Model name → (predicted − simulated)/simulated (None if not finite).
    law : str
        The lateral law of the predictions.
    lumped_predicted_boundary, lumped_relative_error : dict or None
        Grid only: the same with KB's lumped law f(W/d)^n, f = the grid's f_av.
    oscillation : tuple of OscillationCheck
        Runs at the boundary and `probe` either side.
    points : tuple of SimulatedPoint
        Every bisection run.
    stability_map : StabilityMap or None
    inputs : dict
        Everything that defined the validation (SI; α in deg).
    notes : dict
        Documented choices (quantization, law, f_av).
    runs : int
        Simulations run.
    seconds : float
        Wall-clock time, s.
    models : tuple of LoopModel
        The validated models, configured (labels and styles for plotting; not in `to_dict`).
    """

    scenario: str
    env: str
    parameter: str
    unit: str
    simulated_boundary: float
    bracket: tuple
    stable_above: bool
    predicted_boundary: dict
    relative_error: dict
    law: str
    lumped_predicted_boundary: dict | None
    lumped_relative_error: dict | None
    oscillation: tuple
    points: tuple
    stability_map: StabilityMap | None
    inputs: dict
    notes: dict = field(default_factory=dict)
    runs: int = 0
    seconds: float = 0.0
    models: tuple = ()

    def plot(self):
        """`plots.validation.plot_validation`: the stability map's overlay (when there is one) and σ against the parameter;
        returns the figure."""
        from ..plots.validation import plot_validation

        return plot_validation(self)

    def to_dict(self) -> dict:
        """JSON form: ``parameter``, ``simulated_boundary``, ``predicted_boundary``, ``relative_error``,
        ``inputs``, and the rest; wall-clock ``seconds`` under ``timing``.

        Numbers by `serialize.json_number`: a model without a finite boundary
        has ``"inf"`` as its predicted boundary and relative error; undefined
        values are null.
        """
        s = self.simulated_boundary

        def relative(predicted, errors):
            if errors is None:
                return None
            out = {}
            for name, e in errors.items():
                p = predicted.get(name) if predicted else None
                if e is None and p is not None and math.isinf(p) and math.isfinite(s) and s != 0:
                    e = math.copysign(math.inf, p / s)  # (p − s)/s with p infinite
                out[name] = json_number(e)
            return out

        boundaries = lambda d: None if d is None else {k: json_number(v) for k, v in d.items()}
        return {
            "scenario": self.scenario,
            "env": self.env,
            "parameter": self.parameter,
            "unit": self.unit,
            "simulated_boundary": json_number(s),
            "bracket": [json_number(v) for v in self.bracket],
            "stable_above": bool(self.stable_above),
            "predicted_boundary": boundaries(self.predicted_boundary),
            "relative_error": relative(self.predicted_boundary, self.relative_error),
            "law": self.law,
            "lumped_predicted_boundary": boundaries(self.lumped_predicted_boundary),
            "lumped_relative_error": relative(self.lumped_predicted_boundary, self.lumped_relative_error),
            "oscillation": [c.to_dict() for c in self.oscillation],
            "points": [p.to_dict() for p in self.points],
            "stability_map": self.stability_map.to_dict() if self.stability_map is not None else None,
            "inputs": json_ready(self.inputs),
            "notes": dict(self.notes),
            "runs": int(self.runs),
            "timing": {"seconds": json_number(self.seconds)},
        }


# ------------------------------------------------------------------ helpers
def _snap(value, quantum, how=round):
    """`value` rounded (or floored, ceiled) to a multiple of `quantum`."""
    return how(value / quantum) * quantum


def _oscillation(runs, name) -> tuple:
    """σ, ω of each run against the matching `sampled` model's dominant root at its own operating point (`predict`)."""
    out = []
    for run in runs:
        m = run.metrics
        p = predict(run.scenario).matching
        sigma, omega = m.growth_rate, m.angular_frequency
        out.append(
            OscillationCheck(
                value=run_value(run, name),
                growth_rate=sigma,
                angular_frequency=omega,
                method=m.method,
                predicted_growth_rate=p.growth_rate,
                predicted_angular_frequency=p.angular_frequency,
                growth_rate_error=None if sigma is None else sigma - p.growth_rate,
                frequency_error=None if omega is None or p.angular_frequency == 0 else omega / p.angular_frequency - 1.0,
            )
        )
    return tuple(out)


# --------------------------------------------------------------------- API
def _no_boundary_message(parameter: str, predicted: float, models, robot, controller) -> str:
    """Why there is no simulated boundary to bisect, and what would give one."""
    sampled = next(m for m in models if m.name == "sampled")
    NV_star = model_answer(sampled, loop_of(robot, controller)).NV_critical
    if NV_star == 0:
        return (
            f"{parameter}: the sampled loop is unstable at every NV for these parameters (NV* = 0: unstable at any speed), "
            f"so no {parameter} gives a stable run and there is no boundary to bisect; a shorter T or a lower k can help "
            f"(pfm-stability report gives T* and k*)"
        )
    if math.isinf(NV_star):
        return f"{parameter}: the sampled loop is stable at every NV for these parameters (NV* = inf); there is no boundary to bisect"
    return f"{parameter}: no value of {parameter} reaches the sampled boundary NV* = {NV_star:.4g} 1/s (predicted {parameter}* = {predicted:g}); nothing to bisect"


def validate_boundary(
    scenario: str,
    parameter: str | None = None,
    *,
    robot: Robot | None = None,
    controller: Controller | None = None,
    env: str = "analytic",
    L: float | None = None,
    alpha: float | None = None,
    rtol: float | None = None,
    members: int = 9,
    offset: float | None = None,
    duration: float | None = None,
    pade_order: int = 3,
    window_cells: int = 33,
    cell_size: float = 0.1,
    law: str | None = None,
    cell_ratio: float | None = None,
    probe: float = 0.03,
    stability_map: tuple | None = None,
    progress=None,
) -> BoundaryValidation:
    """Bisect the simulated stability boundary and compare it with every model.

    Parameters
    ----------
    scenario : {"corridor", "wall"}
        Straight corridor (KB §5.4) or wall (KB Fig 2, §5.3), target at infinity.
    parameter : {"L", "alpha", "V", "f"}, optional
        Bisected parameter; default L (corridor) or α (wall).
    robot, controller : Robot, Controller
        Default KB's CARMEL (command hold, one-sample compute delay, k = 2 1/s assumed).
    env : {"analytic", "grid"}
        Continuous walls with KB's lumped law, or the VFF histogram grid
        (cell ratio calibrated to f_av = f, `calibrate_cell_ratio`).
    L : float, optional
        Corridor half-width, m, when another parameter is bisected (default 1 m).
    alpha : float, optional
        Wall angle α, rad, when another parameter is bisected (default 45°).
    rtol : float, optional
        Relative width of the final bracket (default 1e-4 analytic, 1e-3 grid);
        grid L stops at neighbouring widths (c/2 apart).
    members : int
        Runs per bisection round, >= 3 (one batch each).
    offset : float, optional
        Start offset from equilibrium, m (default `DEFAULT_OFFSET`).
    duration : float, optional
        Simulated time per run, s (default: 10 periods of the sampled
        boundary oscillation, at least 20 s analytic / 30 s grid, at most 150 s).
    pade_order : int
        Order m of the ``pade`` model.
    window_cells, cell_size
        Grid window (odd, KB: 33) and cell size (m, KB: 0.1); also those of
        the analytic ``law="grid"``.
    law : {"power", "grid"}, optional
        ``env="analytic"``: the walls' lateral law, KB's lumped power law
        (default) or the grid's effective law (`sim.scenario_law`, as
        `make_scenario` and a configuration file's ``law`` take it). The
        simulation and every prediction use it.
    cell_ratio : float, optional
        ρ = F_cr/F_ct of the grid (``env="grid"``) or of ``law="grid"``;
        default: calibrated to f_av = f. Not with ``parameter="f"`` (with ρ
        given, f changes nothing the simulation sees).
    probe : float
        Relative distance of the oscillation checks from the boundary, in (0, 0.5).
    stability_map : (int, int), optional
        (nx, ny): also simulate an nx × ny map around the boundary (x = V, or
        L/α when V is bisected) and compute every model's boundary curve.
    progress : callable, optional
        Called with one line of text after each batch.

    Returns
    -------
    BoundaryValidation

    Raises
    ------
    ValueError
        Bad input (one line naming the parameter and its range), no finite
        `sampled` boundary, or no verdict change around the prediction.

    Examples
    --------
    >>> v = validate_boundary("corridor", env="analytic")      # doctest: +SKIP
    >>> v.simulated_boundary, v.predicted_boundary["sampled"]  # doctest: +SKIP
    (0.8507..., 0.8507...)
    """
    started = time.perf_counter()
    check_choice("scenario", scenario, SCENARIOS)
    check_choice("env", env, ENVS)
    parameter = default_parameter(scenario) if parameter is None else parameter
    spec = parameter_spec(scenario, parameter)
    robot = robot if robot is not None else CARMEL.robot
    controller = controller if controller is not None else CARMEL.controller
    members = check_integer("members", members, 3, 1000)
    probe = check_number("probe", probe, 0.0, 0.5)
    rtol = check_number("rtol", rtol if rtol is not None else (1e-4 if env == "analytic" else 1e-3), 0.0, 0.5)
    if scenario == "corridor":
        if alpha is not None:
            raise ValueError("alpha does not apply to scenario corridor")
        if parameter == "L" and L is not None:
            raise ValueError("L is the bisected parameter; do not fix it")
        geometry = check_number("L", L if L is not None else 1.0, robot.W / 2, unit="m")
    else:
        if L is not None:
            raise ValueError("L does not apply to scenario wall")
        if parameter == "alpha" and alpha is not None:
            raise ValueError("alpha is the bisected parameter; do not fix it")
        geometry = check_number("alpha", alpha if alpha is not None else math.radians(45.0), 0.0, math.pi / 2, unit="rad")
    if controller.T <= 0:
        raise ValueError(f"T must be a finite number in (0, 100] s (the simulator samples); got {controller.T!r}")

    snapped = None
    if env == "grid" and scenario == "corridor" and parameter != "L":  # walls on cell centres, as make_scenario draws them
        snapped, geometry = geometry, round(2 * geometry / cell_size) * cell_size / 2
    if law is not None and env == "grid":
        raise ValueError(f"law applies to env=analytic only (the grid's law is its cells); got law={law!r} with env=grid")
    if cell_ratio is not None:
        cell_ratio = check_number("cell_ratio", cell_ratio, 0.0)
        if parameter == "f":
            raise ValueError(
                f"f cannot be bisected with a given cell_ratio ({cell_ratio:g}): the grid wall's force is set by the cell ratio, "
                "f only calibrates it; leave cell_ratio out to bisect f"
            )
    law = scenario_law(env, robot, controller, window_cells, cell_size, law=law, cell_ratio=cell_ratio)
    models = validation_models(controller, pade_order)
    predicted = predicted_boundaries(scenario, parameter, robot, controller, law, geometry, models)
    p = predicted["sampled"]
    if not (math.isfinite(p) and p > 0):
        raise ValueError(_no_boundary_message(parameter, p, models, robot, controller))
    lumped = lumped_law(law) if isinstance(law, GridWallLaw) else None
    lumped_predicted = (
        predicted_boundaries(scenario, parameter, robot, controller, lumped, geometry, models) if lumped is not None else None
    )

    sampled = next(m for m in models if m.name == "sampled")
    boundary = model_answer(sampled, loop_of(robot, controller))
    if duration is None:
        period = 2 * math.pi / boundary.omega_critical if boundary.omega_critical else 0.0
        duration = min(150.0, max(20.0 if env == "analytic" else 30.0, 10 * period))
    duration = check_number("duration", duration, 0.0, 1e6, unit="s")
    offset = check_number("offset", offset if offset is not None else DEFAULT_OFFSET[env], unit="m")

    quantum = cell_size / 2 if (env == "grid" and parameter == "L") else None
    domain = parameter_domain(parameter, scenario, env, robot, controller, law, geometry if scenario == "wall" else None, cell_size)
    if quantum is not None:  # the representable values: multiples of c/2
        domain = (math.ceil(domain[0] / quantum - 1e-9) * quantum, math.floor(domain[1] / quantum + 1e-9) * quantum)
    why = "the robot must fit (clear of the walls)" + (" and the wall must lie inside the active window" if env == "grid" else "")
    if not domain[0] < domain[1]:
        raise ValueError(f"{parameter}: no value of {parameter} gives a run that can be simulated with these settings ({why})")
    if not domain[0] < p < domain[1]:
        raise ValueError(
            f"{parameter}: the sampled model's boundary {p:.4g} {spec.unit} lies outside the values this scenario can be "
            f"simulated with, [{domain[0]:.4g}, {domain[1]:.4g}] {spec.unit} ({why})".replace(" ]", "]")
        )
    fixed = {}
    if parameter != ("L" if scenario == "corridor" else "alpha"):
        fixed["L" if scenario == "corridor" else "alpha"] = geometry
    common = dict(offset=offset, duration=duration)
    if isinstance(law, GridWallLaw):  # the grid, or analytic walls with the grid's law: the same ρ, window and cells
        common.update(window_cells=window_cells, cell_size=cell_size)
        if env == "analytic":
            common["law"] = "grid"
        if cell_ratio is not None:
            common["cell_ratio"] = cell_ratio
    simulate = ParameterRuns(scenario, env, robot, controller, fixed, common)

    if progress:
        progress(f"validate {scenario} ({env}): bisecting {parameter} around the sampled prediction {p:.6g} {spec.unit}".rstrip())
    lo_pt, hi_pt, points, notes = bisect_boundary(
        simulate, parameter, p, domain, stable_above=spec.stable_above(scenario), members=members, rtol=rtol,
        quantum=quantum, progress=progress,
    )
    simulated = crossing(lo_pt, hi_pt)

    # σ and ω at the boundary and `probe` either side
    probes = [simulated * (1 - probe), simulated, simulated * (1 + probe)]
    if quantum is not None:
        probes = [_snap(probes[0], quantum, math.floor), _snap(simulated, quantum), _snap(probes[2], quantum, math.ceil)]
    probes = sorted({round(min(max(v, domain[0]), domain[1]), 12) for v in probes})
    oscillation = _oscillation(simulate(parameter, np.asarray(probes)), parameter)
    if progress:
        progress(f"oscillation checks: {len(oscillation)} runs")

    smap = None
    if stability_map is not None:
        shape = tuple(check_integer("stability_map", int(v), 2, 50) for v in stability_map)
        smap = simulate_stability_map(simulate, scenario, spec, env, robot, controller, law, geometry, simulated, domain, shape, cell_size, models, progress)

    notes = dict(notes)
    notes["verdict"] = "sign of the measured growth rate sigma (collision: unstable); boundary where sigma crosses 0, interpolated linearly between the final bracket's ends"
    if quantum is not None:
        notes["quantization"] = (
            f"grid corridor walls lie on cell centres: L takes multiples of c/2 = {quantum:g} m only; "
            "the bracket is two neighbouring widths"
        )
    if snapped is not None and abs(snapped - geometry) > 1e-12:
        notes["L"] = f"{geometry:g} m (walls on cell centres: L rounded to a multiple of c/2 = {cell_size / 2:g} m from {snapped:g})"
    if isinstance(law, GridWallLaw):
        notes["law"] = (
            f"predictions use the grid's effective law (GridWallLaw, cell ratio {law.ratio:.6g}); "
            f"lumped_* use KB's power law with the grid's f_av = {f_av_of(law):.4g}"
        )
    inputs = {
        "scenario": scenario,
        "env": env,
        "parameter": parameter,
        **{k: getattr(robot, k) for k in ("V", "tau", "k", "W")},
        "max_steering_rate_deg": math.degrees(robot.max_steering_rate),
        "dead_time": robot.dead_time,
        "plant_gain": robot.plant_gain,
        **{k: getattr(controller, k) for k in ("f", "n", "T", "hold", "compute_delay")},
        "L": geometry if scenario == "corridor" and parameter != "L" else None,
        "alpha_deg": math.degrees(geometry) if scenario == "wall" and parameter != "alpha" else None,
        "offset": offset,
        "duration": duration,
        "rtol": rtol,
        "members": members,
        "probe": probe,
        "pade_order": pade_order,
        "law": law.name,
    }
    if isinstance(law, GridWallLaw):
        inputs.update(cell_ratio=law.ratio, f_av=f_av_of(law), window_cells=window_cells, cell_size=cell_size)
    return BoundaryValidation(
        scenario=scenario,
        env=env,
        parameter=parameter,
        unit=spec.unit,
        simulated_boundary=float(simulated),
        bracket=(lo_pt.value, hi_pt.value) if lo_pt.value <= hi_pt.value else (hi_pt.value, lo_pt.value),
        stable_above=spec.stable_above(scenario),
        predicted_boundary=predicted,
        relative_error=relative_errors(predicted, simulated),
        law=law.name,
        lumped_predicted_boundary=lumped_predicted,
        lumped_relative_error=relative_errors(lumped_predicted, simulated) if lumped_predicted is not None else None,
        oscillation=oscillation,
        points=tuple(points),
        stability_map=smap,
        inputs=inputs,
        notes=notes,
        runs=simulate.runs,
        seconds=time.perf_counter() - started,
        models=tuple(models),
    )
