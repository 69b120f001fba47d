"""Simulations in a plane of two parameters, beside every model's boundary curve.

Two questions, two results, one set of model curves:

* `StabilityMap` — *which runs near a validated boundary are stable?* The
  simulated verdicts on an nx × ny grid of points around the boundary that
  `validate_boundary` bisected (no bisection: one batch), in reported units
  (α in degrees). Built by `stability_map` for
  ``validate_boundary(stability_map=(nx, ny))``.
* `SimulatedBoundary` — *where is the simulated boundary at each of several
  values of a second parameter?* One `boundary_by_bisection` per value (the
  package's batched bisection), in `simulate_batch` units (α in radians), to
  set beside the predicted curves (`plots.validation.plot_simulated_boundary`).

Both carry every model's boundary curve over their horizontal axis,
computed by `model_curves` from `pfm_stability.analysis.curves` (KB eq 20, 24, 25
with each model's NV* in place of 1/(τ + T); docs/models.md, critical
values) with the lateral law the simulation really has (and, in the grid,
KB's lumped law at the grid's f_av), so that a plot only draws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..laws.effective_force import GridWallLaw
from ..analysis.curves import corridor_L_curves, corridor_V_curves, wall_alpha_curves, wall_f_curves, wall_V_curves
from ..io.serialize import json_array, json_number, json_ready
from ..sim.api import batch_scenarios
from ..numerics.solve import spread_values
from .bisection import boundary_by_bisection, simulated_point
from .common import lumped_law, parameter_domain, validation_models

__all__ = ["CURVE_AXES", "SimulatedBoundary", "StabilityMap", "model_curves", "simulated_boundary", "stability_map"]

CURVE_AXES = {("V", "L"), ("V", "alpha"), ("V", "f"), ("L", "V"), ("alpha", "V")}
"""(x, y) planes `model_curves` draws: the bisected y against V, or V* against the geometry."""

_UNITS = {"V": "m/s", "L": "m", "alpha": "deg", "f": ""}


def model_curves(scenario: str, y_name: str, x_name: str, x, robot, controller, law, geometry: float, models) -> dict:
    """Each model's critical `y_name` at each x, all else fixed (SI units: α in rad).

    From `pfm_stability.analysis.curves`: L*(V) `corridor_L_curves`, α*(V)
    `wall_alpha_curves`, f*(V) along a wall `wall_f_curves` (a law's critical
    scale, converted to KB's f with f/scale), V*(L) `corridor_V_curves`, and
    f*(V) in a corridor from V*(L) (N ∝ f, so f* = f·V*(L)/V), V*(α) along a
    wall `wall_V_curves`.

    Parameters
    ----------
    scenario : {"corridor", "wall"}
    y_name, x_name : str
        One of `CURVE_AXES` as (x_name, y_name).
    x : array_like
        Positive values of x (m/s, m or rad).
    robot, controller : Robot, Controller
    law : ForceLaw
        The lateral law of the run.
    geometry : float
        L (m) or α (rad) of the operating point (used when it is not an axis).
    models : list of LoopModel

    Returns
    -------
    dict
        Model name → ndarray of y (``inf``/``nan`` where the boundary leaves the
        parameter's range, as in `curves.BoundaryCurve`).
    """
    if (x_name, y_name) not in CURVE_AXES:
        raise ValueError(f"model curves exist for (x, y) in {sorted(CURVE_AXES)}; got ({x_name!r}, {y_name!r})")
    x = np.asarray(x, dtype=float)
    if x_name == "V" and y_name == "L":
        curves = corridor_L_curves(robot, controller, x, models, law)
    elif x_name == "V" and y_name == "alpha":
        curves = wall_alpha_curves(robot, controller, x, models, law)
    elif x_name == "V" and scenario == "wall":  # f* along a wall at α = geometry
        return {c.model.name: c.y * (controller.f / law.scale) for c in wall_f_curves(robot, controller, geometry, x, models, law)}
    elif x_name == "V":  # f* in a corridor of half-width L = geometry
        return {c.model.name: controller.f * c.y[0] / x for c in corridor_V_curves(robot, controller, [geometry], models, law)}
    elif x_name == "L":
        curves = corridor_V_curves(robot, controller, x, models, law)
    else:  # V*(α) along a wall
        curves = wall_V_curves(robot, controller, x, models, law)
    return {c.model.name: c.y for c in curves}


# ------------------------------------------------------------ stability map
@dataclass(frozen=True)
class StabilityMap:
    """Simulated verdicts on a grid of two parameters around a validated boundary, and every model's boundary curve.

    Answers "which runs near the bisected boundary are stable?" (one batch,
    no bisection); `SimulatedBoundary` answers "where is the simulated
    boundary at several values of a second parameter?". Reported units (α in deg).

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
        Model name → critical y at each ``curve_x`` (`model_curves`; None
        where undefined, ``inf`` where infinite).
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
        """Plain JSON form; a curve value is ``"inf"`` where infinite, null where the curve is undefined
        (numbers by `serialize.json_number`)."""
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


def _reported_curves(scenario, y_name, x_name, curve_x, robot, controller, law, geometry, models) -> dict:
    """`model_curves` in reported units (α in degrees), as lists with None where undefined."""
    x = np.radians(curve_x) if x_name == "alpha" else curve_x
    out = {}
    for name, y in model_curves(scenario, y_name, x_name, x, robot, controller, law, geometry, models).items():
        y = np.degrees(y) if y_name == "alpha" else np.asarray(y, dtype=float)
        out[name] = [None if math.isnan(v) else float(v) for v in y]
    return out


def stability_map(simulate, scenario, spec, env, robot, controller, law, geometry, boundary, domain, shape, cell_size, models, progress) -> StabilityMap:
    """Simulate an nx × ny map around `boundary` in one batch, and every model's boundary curve over it.

    x is V (0.6–1.4 × V), or the geometry (0.75–1.25 × L or α, inside the
    simulable domain) when V is bisected; y is the bisected parameter
    (0.7–1.3 × the boundary). In the grid corridor widths are multiples of c/2.

    Parameters
    ----------
    simulate : bisection.ParameterRuns
    scenario : {"corridor", "wall"}
    spec : common.ParameterSpec
        The bisected parameter.
    env, robot, controller, law, geometry
        As in `validate_boundary` (geometry: L m or α rad).
    boundary : float
        The bisected boundary (reported units).
    domain : (float, float)
        The simulable values of the bisected parameter.
    shape : (int, int)
        (nx, ny).
    cell_size : float
        As in `validate_boundary`: cell side c, m.
    models : list of LoopModel
    progress : callable or None
    """
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
    xs = spread_values(x_lo, x_hi, nx, x_quantum, False)
    ys = spread_values(max(0.7 * boundary, domain[0]), min(1.3 * boundary, domain[1]), ny, quantum if spec.name == "L" else None, False)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    if progress:
        progress(f"stability map: {X.size} runs")
    runs = simulate(spec.name, Y.ravel(), second=(x_name, X.ravel()))
    points = tuple(simulated_point(r, spec.name, x_name) for r in runs)
    curve_x = np.linspace(xs.min(), xs.max(), 41)
    curves = _reported_curves(scenario, spec.name, x_name, curve_x, robot, controller, law, geometry, models)
    lumped = None
    if isinstance(law, GridWallLaw):
        lumped = _reported_curves(scenario, spec.name, x_name, curve_x, robot, controller, lumped_law(law), geometry, models)
    return StabilityMap(x_name, _UNITS[x_name], spec.name, spec.unit, points, tuple(curve_x.tolist()), curves, lumped, float(x0))


# ------------------------------------------------------- simulated boundary
@dataclass(frozen=True)
class SimulatedBoundary:
    """Simulated boundary points: `parameter`* at each value of `over`, beside every model's curve.

    Answers "where is the simulated boundary at several values of a second
    parameter?" (a bisection per value); `StabilityMap` answers "which runs
    near one bisected boundary are stable?". `simulate_batch` units (α in rad).

    Attributes
    ----------
    scenario, env : str
        Scenario name and environment (``grid`` or ``analytic``).
    parameter : str
        The bisected parameter (``V`` m/s, ``alpha`` rad, ``L`` m, ``f``).
    over : str
        The parameter held at each of `values`.
    values : ndarray
        Values of `over`.
    critical, lo, hi : ndarray
        Bisected boundary (bracket midpoint) and final bracket, per value.
    stable_above : ndarray of bool
        Runs are stable above the boundary.
    runs : int
        Simulations run in total.
    options : dict
        The other `simulate_batch` arguments used.
    curve_x : ndarray or None
        41 values of `over` across `values` (None: no model curves for this plane,
        `CURVE_AXES`, or a scenario without a linear analysis).
    curves : dict or None
        Model name → critical `parameter` at each ``curve_x`` (`model_curves`).
    lumped_curves : dict or None
        The same with KB's lumped law (grid only).
    models : tuple of LoopModel
        The models of the curves (labels and styles for plotting).
    """

    scenario: str
    env: str
    parameter: str
    over: str
    values: np.ndarray
    critical: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    stable_above: np.ndarray
    runs: int
    options: dict = field(default_factory=dict)
    curve_x: np.ndarray | None = None
    curves: dict | None = None
    lumped_curves: dict | None = None
    models: tuple = ()

    def plot(self, ax=None, **kwargs):
        """`plots.validation.plot_simulated_boundary` of these points; returns the figure.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on; None: a new figure.
        **kwargs
            Passed on to `plots.validation.plot_simulated_boundary`.
        """
        from ..plots.validation import plot_simulated_boundary

        return plot_simulated_boundary(self, ax=ax, **kwargs)

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        curves = lambda d: None if d is None else {k: json_array(v) for k, v in d.items()}
        return {
            "scenario": self.scenario,
            "env": self.env,
            "parameter": self.parameter,
            "over": self.over,
            "values": json_array(self.values),
            "critical": json_array(self.critical),
            "lo": json_array(self.lo),
            "hi": json_array(self.hi),
            "stable_above": self.stable_above.tolist(),
            "runs": self.runs,
            "options": {k: (v if isinstance(v, (int, float, str, bool)) or v is None else repr(v)) for k, v in self.options.items()},
            "curve_x": None if self.curve_x is None else json_array(self.curve_x),
            "curves": curves(self.curves),
            "lumped_curves": curves(self.lumped_curves),
        }


def simulated_boundary(
    scenario: str,
    parameter: str,
    lo: float,
    hi: float,
    *,
    over: str,
    values,
    env: str = "analytic",
    rtol: float = 2e-3,
    members: int = 9,
    pade_order: int = 3,
    **options,
) -> SimulatedBoundary:
    """The simulated boundary in `parameter` at each of several values of `over`, and every model's curve.

    One `boundary_by_bisection` per value (each round a batch of `members`
    runs), e.g. the critical speed V* of the ``corridor`` scenario at a few
    half-widths L, or the critical angle α* of the ``wall`` at a few speeds.
    The model curves (`model_curves`, for the planes of `CURVE_AXES`) use the
    law, robot and controller of the scenario these arguments build.

    Parameters
    ----------
    scenario : str
        ``corridor`` or ``wall`` (any `pfm_stability.sim` scenario name).
    parameter : str
        Bisected `simulate_batch` parameter (``V``, ``alpha`` in rad, ``L``, ``f``).
    lo, hi : float
        Bracket of `parameter`; the simulated verdict must differ at its ends.
    over : str
        The parameter set to each of `values`.
    values : array_like
    env : {"analytic", "grid"}
    rtol : float
        Relative bracket width at which bisection stops.
    members : int
        Runs per bisection round.
    pade_order : int
        Order of the ``pade`` model's curve.
    **options
        Other `simulate_batch` arguments (``offset``, ``duration``, ``robot``,
        ``controller``, …).

    Returns
    -------
    SimulatedBoundary
    """
    values = np.atleast_1d(np.asarray(values, dtype=float))
    est = [
        boundary_by_bisection(scenario, parameter, lo, hi, env=env, rtol=rtol, members=members, **{over: float(v)}, **options)
        for v in values
    ]
    curve_x = curves = lumped = None
    models = ()
    member = batch_scenarios(scenario, env=env, **{over: float(values[0])}, **options)[0]
    if member.analysis and (over, parameter) in CURVE_AXES:
        kind = member.analysis["kind"]
        geometry = member.analysis["L"] if kind == "corridor" else member.analysis["alpha"]
        law = member.effective_law()
        models = tuple(validation_models(member.controller, pade_order))
        curve_x = np.linspace(values.min(), values.max(), 41) if np.ptp(values) > 0 else values.copy()
        args = (member.robot, member.controller)
        curves = model_curves(kind, parameter, over, curve_x, *args, law, geometry, models)
        if isinstance(law, GridWallLaw):
            lumped = model_curves(kind, parameter, over, curve_x, *args, lumped_law(law), geometry, models)
    return SimulatedBoundary(
        scenario,
        env,
        parameter,
        over,
        values,
        np.array([e.value for e in est]),
        np.array([e.lo for e in est]),
        np.array([e.hi for e in est]),
        np.array([e.stable_above for e in est]),
        sum(e.runs for e in est),
        dict(options, rtol=rtol, members=members),
        curve_x,
        curves,
        lumped,
        models,
    )
