"""The simulated stability boundary against every model's prediction (issue 5 item 2).

`validate_boundary` bisects the simulated boundary of a straight corridor or
wall (`pfm_stability.sim.presets`: target at infinity, so α is constant as KB
assume) in one parameter — L (KB eq 25), α (eq 24), V (eq 20) or f (eq 13) —
and sets every model of DESIGN §4 beside it, each fed the lateral law the
simulation really has (`Scenario.effective_law`: KB's power law in the
analytic environment, the grid's `GridWallLaw` in the histogram grid, DESIGN
§5). In the grid, the predictions of KB's lumped law with the grid's f_av are
reported beside them, as KB compared (§4).

Bisection (DESIGN §6): each round simulates `members` values spread over the
bracket in one batch (`simulate_batch`), keeps the two neighbours where the
verdict changes, and stops when the bracket is narrower than `rtol`
relative. The verdict is the sign of the measured growth rate σ
(`sim.bisect.simulated_verdict`); the reported boundary interpolates σ linearly to
zero between the final bracket's ends (σ is smooth in the parameter; the
midpoint when σ is undefined at an end). In the grid a corridor's walls lie
on cell centres, so L takes only multiples of c/2 (0.05 m): the bracket is
then two neighbouring widths and the interpolation of σ gives the boundary
between them.

Near the boundary, σ and ω are measured at the boundary and `probe` (3 %)
either side, and compared with the dominant root of the matching `sampled`
model at each run's own operating point (`pfm_stability.sim.predict`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..checks import check_choice, check_integer, check_number
from ..criteria import loop_of
from ..effective_force import GridWallLaw
from ..force_law import corridor_gain, wall_gain
from ..models import Sampled
from ..parameters import CARMEL, Controller, Robot
from ..serialize import json_number
from ..sim.bisect import simulated_verdict
from .common import (
    SCENARIOS,
    default_parameter,
    f_av_of,
    lumped_law,
    parameter_domain,
    parameter_spec,
    predicted_boundaries,
    relative_errors,
    scenario_law,
    validation_models,
)

__all__ = [
    "SimulatedPoint",
    "OscillationCheck",
    "StabilityMap",
    "BoundaryValidation",
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
class SimulatedPoint:
    """One simulated run of the bisection or the stability map.

    Attributes
    ----------
    value : float
        Parameter value (reported units: L m, α deg, V m/s, f).
    verdict : str
        "stable" or "unstable" (`sim.bisect.simulated_verdict`).
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
        from ..serialize import json_ready

        return json_ready(dict(self.__dict__))


@dataclass(frozen=True)
class OscillationCheck:
    """σ and ω measured near the boundary against the matching `sampled` model's dominant root.

    Attributes
    ----------
    value : float
        Parameter value of the run (reported units; for a grid corridor the L actually drawn).
    growth_rate, angular_frequency : float or None
        Measured σ (1/s) and ω (rad/s), DESIGN §6.
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
        from ..serialize import json_ready

        return json_ready(dict(self.__dict__))


@dataclass(frozen=True)
class StabilityMap:
    """Simulated verdicts on a grid of two parameters, and every model's boundary curve.

    Attributes
    ----------
    x_name, x_unit : str
        Horizontal parameter: V, or the geometry (L, α) when V is bisected.
    y_name, y_unit : str
        The bisected parameter.
    points : tuple of SimulatedPoint
        ``value`` is y, ``x`` is x.
    curve_x : tuple of float
    curves : dict
        Model name → critical y at each ``curve_x`` (None where infinite).
    lumped_curves : dict or None
        The same with KB's lumped law (grid only).
    nominal_x : float
        Where the bisection ran.
    """

    x_name: str
    x_unit: str
    y_name: str
    y_unit: str
    points: tuple
    curve_x: tuple
    curves: dict
    lumped_curves: dict | None
    nominal_x: float

    def to_dict(self) -> dict:
        """Plain JSON form; a curve value is ``"inf"`` where infinite, null where the curve has no value
        inside the plotted range (numbers by `serialize.json_number`)."""
        from ..serialize import json_ready

        curves = lambda d: None if d is None else {k: [json_number(v) for v in values] for k, values in d.items()}
        return {
            "x_name": self.x_name,
            "x_unit": self.x_unit,
            "y_name": self.y_name,
            "y_unit": self.y_unit,
            "points": [p.to_dict() for p in self.points],
            "curve_x": json_ready(list(self.curve_x)),
            "curves": curves(self.curves),
            "lumped_curves": curves(self.lumped_curves),
            "nominal_x": json_number(self.nominal_x),
        }


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

    def to_dict(self) -> dict:
        """JSON form: ``parameter``, ``simulated_boundary``, ``predicted_boundary``, ``relative_error``,
        ``inputs``, and the rest; wall-clock ``seconds`` under ``timing``.

        Numbers by `serialize.json_number`: a model without a finite boundary
        has ``"inf"`` as its predicted boundary and relative error; undefined
        values are null.
        """
        from ..serialize import json_ready

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
def _values(lo, hi, members, quantum):
    """`members` values spread over [lo, hi]; multiples of `quantum` when given (unique)."""
    if quantum is None:
        return np.linspace(lo, hi, members)
    k0, k1 = math.ceil(lo / quantum - 1e-9), math.floor(hi / quantum + 1e-9)  # stay inside [lo, hi]
    k = np.unique(np.round(np.linspace(k0, k1, members))) if k1 >= k0 else np.array([])
    return k * quantum


def _snap(value, quantum, how=round):
    """`value` rounded (or floored, ceiled) to a multiple of `quantum`."""
    return how(value / quantum) * quantum


class _Simulator:
    """Runs batches of one scenario with one parameter varied (and optionally a second one)."""

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
        from ..sim.api import simulate_batch

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


def _actual(run, name):
    """The parameter value a run really used (reported units): grid corridors snap L to c/2."""
    s = run.scenario
    if name == "L":
        return float(s.analysis["L"])
    if name == "alpha":
        return math.degrees(s.analysis["alpha"])
    if name == "V":
        return s.robot.V
    return s.controller.f


def _point(run, name, x_name=None) -> SimulatedPoint:
    verdict, basis = simulated_verdict(run)
    sigma = run.metrics.growth_rate
    return SimulatedPoint(_actual(run, name), verdict, basis, sigma, _actual(run, x_name) if x_name else None)


def _bisect(simulate, name, p, domain, *, stable_above, members, rtol, quantum, progress):
    """Bracket around the prediction p, then batched bisection.

    Returns
    -------
    (SimulatedPoint, SimulatedPoint, list, dict)
        The final bracket's low and high ends, every run, notes.
    """
    points = []
    notes = {}
    width = 1.25
    for _ in range(5):  # widen the bracket (1.25, 1.56, 2.4, 5.96, 35.5) until the verdicts at its ends differ
        lo = max(domain[0], p / width)
        hi = min(domain[1], p * width)
        values = _values(lo, hi, members, quantum)
        if values.size < 2:
            raise ValueError(f"{name}: the bracket [{lo:g}, {hi:g}] holds fewer than two values the simulator can represent")
        runs = simulate(name, values)
        pts = [_point(r, name) for r in runs]
        points += pts
        low_expected = "unstable" if stable_above else "stable"
        if pts[0].verdict == low_expected and pts[-1].verdict != low_expected:
            break
        if lo <= domain[0] and hi >= domain[1]:
            break
        width = width**2
    if pts[0].verdict == pts[-1].verdict:
        raise ValueError(
            f"{name}: the simulated verdict is {pts[0].verdict} at both ends of [{pts[0].value:g}, {pts[-1].value:g}] "
            f"around the sampled model's prediction {p:g}; no boundary to bisect"
        )
    rounds = 1
    seq = pts
    while True:
        change = next(i for i in range(1, len(seq)) if seq[i].verdict == seq[-1].verdict)
        changes = sum(a.verdict != b.verdict for a, b in zip(seq[:-1], seq[1:]))
        if changes > 1:
            notes["non_monotone"] = f"the verdict changed {changes} times inside one bracket; the change nearest the low end was kept"
        lo_pt, hi_pt = seq[change - 1], seq[change]
        lo, hi = lo_pt.value, hi_pt.value
        if progress:
            progress(f"round {rounds}: {name} in [{lo:.6g}, {hi:.6g}]")
        if quantum is not None:
            if round(hi / quantum) - round(lo / quantum) <= 1:
                break
        elif hi - lo <= rtol * abs(lo + hi) / 2:
            break
        if rounds >= 30:
            notes["rounds"] = "stopped after 30 rounds"
            break
        inner = _values(lo, hi, members, quantum)[1:-1]
        if inner.size == 0:
            break
        runs = simulate(name, inner)
        new = [_point(r, name) for r in runs]
        points += new
        seq = [lo_pt] + new + [hi_pt]
        rounds += 1
    notes.setdefault("rounds", f"{rounds} round{'s' if rounds > 1 else ''} of at most {members} runs")
    return lo_pt, hi_pt, points, notes


def _crossing(lo_pt, hi_pt):
    """Zero of σ by linear interpolation between the bracket's ends (midpoint when σ is not usable)."""
    a, b = lo_pt.growth_rate, hi_pt.growth_rate
    if lo_pt.basis == hi_pt.basis == "growth_rate" and a is not None and b is not None and a * b < 0:
        return lo_pt.value + (hi_pt.value - lo_pt.value) * a / (a - b)
    return (lo_pt.value + hi_pt.value) / 2


def _oscillation(runs, name) -> tuple:
    from ..sim.predict import predict

    out = []
    for run in runs:
        m = run.metrics
        p = predict(run.scenario).matching
        sigma, omega = m.growth_rate, m.angular_frequency
        out.append(
            OscillationCheck(
                value=_actual(run, name),
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


def _gain(scenario, parameter, y, law, geometry, f):
    """Environment gain N (1/m) with `parameter` = y (reported units) and the rest fixed."""
    if parameter == "f":
        law = law.with_scale(law.scale * y / f)
    elif parameter == "L":
        geometry = y
    elif parameter == "alpha":
        geometry = math.radians(y)
    return corridor_gain(law, geometry) if scenario == "corridor" else wall_gain(law, geometry)[1]


def _curves(scenario, parameter, x_name, xs, y_range, robot, controller, law, geometry, models):
    """Critical `parameter` of each model at each x, for drawing.

    x = V: the boundary is N(y)·V = NV*, and N does not depend on V, so N is
    tabulated once over `y_range` (400 points) and inverted by interpolation
    of log N (exact to plotting precision; None outside the table). x = L or
    α (V bisected): V* = NV*/N(x) directly.
    """
    loop = loop_of(robot, controller)
    stars = {m.name: m.boundary(loop).NV_critical for m in models}
    if x_name != "V":
        N = np.array([_gain(scenario, x_name, x, law, geometry, controller.f) for x in xs])
        return {name: [json_number(s / n) if n > 0 else None for n in N] for name, s in stars.items()}
    ys = np.linspace(y_range[0], y_range[1], 400)
    N = np.array([_gain(scenario, parameter, y, law, geometry, controller.f) for y in ys])
    ok = N > 0
    order = np.argsort(N[ok])
    logN, table = np.log(N[ok][order]), ys[ok][order]
    out = {}
    for name, s in stars.items():
        values = []
        for x in xs:
            target = math.log(s / x) if math.isfinite(s) and s > 0 else math.nan
            inside = logN.size > 1 and logN[0] <= target <= logN[-1]
            values.append(float(np.interp(target, logN, table)) if inside else None)
        out[name] = values
    return out


def _map(simulate, scenario, spec, env, robot, controller, law, geometry, boundary, domain, shape, cell_size, models, progress):
    """Simulate an nx × ny map around the boundary in one batch, and every model's boundary curve over it."""
    nx, ny = shape
    quantum = cell_size / 2 if env == "grid" else None  # grid corridors: L in steps of c/2
    geometry_name = "L" if scenario == "corridor" else "alpha"
    x_name = geometry_name if spec.name == "V" else "V"
    if x_name == "V":
        x0 = robot.V
        x_lo, x_hi = 0.6 * x0, 1.4 * x0
        x_quantum = None
    else:
        x0 = geometry if x_name == "L" else math.degrees(geometry)
        x_dom = parameter_domain(x_name, scenario, env, robot, controller, law, None, cell_size)
        x_lo, x_hi = max(0.75 * x0, x_dom[0]), min(1.25 * x0, x_dom[1])
        x_quantum = quantum if x_name == "L" else None
    xs = _values(x_lo, x_hi, nx, x_quantum)
    ys = _values(max(0.7 * boundary, domain[0]), min(1.3 * boundary, domain[1]), ny, quantum if spec.name == "L" else None)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    if progress:
        progress(f"stability map: {X.size} runs")
    runs = simulate(spec.name, Y.ravel(), second=(x_name, X.ravel()))
    points = tuple(_point(r, spec.name, x_name) for r in runs)
    curve_x = np.linspace(xs.min(), xs.max(), 41)
    y_range = (max(0.5 * ys.min(), domain[0]), min(1.5 * ys.max(), domain[1]))
    curves = _curves(scenario, spec.name, x_name, curve_x, y_range, robot, controller, law, geometry, models)
    lumped = None
    if isinstance(law, GridWallLaw):
        lumped = _curves(scenario, spec.name, x_name, curve_x, y_range, robot, controller, lumped_law(law), geometry, models)
    units = {"V": "m/s", "L": "m", "alpha": "deg"}
    return StabilityMap(x_name, units[x_name], spec.name, spec.unit, points, tuple(curve_x.tolist()), curves, lumped, float(x0))


# --------------------------------------------------------------------- API
def _no_boundary_message(parameter: str, predicted: float, models, robot, controller) -> str:
    """Why there is no simulated boundary to bisect, and what would give one."""
    from ..criteria import loop_of

    loop = loop_of(robot, controller)
    sampled = next(m for m in models if m.name == "sampled")
    NV_star = sampled.boundary(loop).NV_critical
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
        Grid window (odd, KB: 33) and cell size (m, KB: 0.1).
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
    law = scenario_law(env, robot, controller, window_cells, cell_size)
    models = validation_models(controller, pade_order)
    predicted = predicted_boundaries(scenario, parameter, robot, controller, law, geometry, models)
    p = predicted["sampled"]
    if not (math.isfinite(p) and p > 0):
        raise ValueError(_no_boundary_message(parameter, p, models, robot, controller))
    lumped = lumped_law(law) if isinstance(law, GridWallLaw) else None
    lumped_predicted = (
        predicted_boundaries(scenario, parameter, robot, controller, lumped, geometry, models) if lumped is not None else None
    )

    boundary = Sampled(controller.hold, controller.compute_delay).boundary(loop_of(robot, controller))
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
    if env == "grid":
        common.update(window_cells=window_cells, cell_size=cell_size)
    simulate = _Simulator(scenario, env, robot, controller, fixed, common)

    if progress:
        progress(f"validate {scenario} ({env}): bisecting {parameter} around the sampled prediction {p:.6g} {spec.unit}".rstrip())
    lo_pt, hi_pt, points, notes = _bisect(
        simulate, parameter, p, domain, stable_above=spec.stable_above(scenario), members=members, rtol=rtol,
        quantum=quantum, progress=progress,
    )
    simulated = _crossing(lo_pt, hi_pt)

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
        smap = _map(simulate, scenario, spec, env, robot, controller, law, geometry, simulated, domain, shape, cell_size, models, progress)

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
    if env == "grid":
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
    )
