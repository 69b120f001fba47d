"""Stability regions and boundary curves for every loop model (no plotting here).

Koren & Borenstein 1991 (KB) reduce every question to the loop gain NV: each
loop model (`pfm_stability.models`) is stable for 0 < NV < NV*(τ, T, k) (KB eq 20 for
``kb_first_order``), and N depends on the environment and the force law only
(KB eq 11, 23, 25). A model's NV* therefore turns into a boundary curve in any
plane of (V, f, α, L) through the force law:

* wall, (V, f) plane at fixed α: f*(V) = cos α [nV/(W·NV*·tan α)]^n (KB eq 24
  with 1/NV* in place of τ + T); stable for f > f*;
* wall, α*(V) at fixed f: N(α*)·V = NV* (KB eq 21 with eq 23); stable for α > α*;
* corridor, (L, V) plane: V*(L) = NV*/N(L) with N = 2nfWⁿ/L^(n+1); stable
  for V < V*; equivalently L*(V) = (2nWⁿVf/NV*)^(1/(n+1)) (KB eq 25), stable
  for L > L*.

For KB's power law these are closed forms (α* by vectorized bisection on the
closed-form N(α)). For any other decreasing law (e.g. the grid's effective
law, `pfm_stability.effective_force.GridWallLaw`) the curves are found by a
vectorized bisection in the equilibrium distance d0, which parametrizes the
wall exactly: cos α = F_r(d0)/F_a and N = −F_r′(d0)/(F_a sin α) (KB eq 11
and 23 with the general law in place of f(W/d)ⁿ); this assumes N decreases as d0 grows (a convex
decreasing law — true for the power law and for the grid law).

Dense stable/unstable maps (`wall_f_region`, `wall_alpha_region`,
`corridor_region`) shade one model's verdicts. In such a plane the loop
parameters (τ, T, k, hold, compute delay) are fixed and only NV varies, so
one `Boundary` decides every point exactly: a point is stable when its NV
lies in the boundary's ``stable_set`` (a sampled loop can have several
stable intervals, or none that starts at NV = 0 — NV* alone is not enough).
The default model is the one the stability report's verdict uses
(`verdict_model`: ``sampled`` with the controller's hold and compute delay).
Asked for ``exact_delay``, the maps keep the vectorized crossing count of
`pfm_stability.vectorized` (one count per point, independent of the boundary
curves; the tests check that the two agree to the grid resolution).

Model comparison (`critical_gain_vs_delay`, `kb_error_map`): NV*τ depends on
the dimensionless kτ and T/τ only (substitute s = p/τ in KB eq 18, or scale
time in the sampled loop), so one map over (kτ, T/τ) shows, for every robot,
where KB's criterion (eq 20) is optimistic (NV*_KB > NV*_model: KB calls
stable a loop that oscillates) or conservative.

`simulated_boundary` bisects the simulator (`pfm_stability.sim`) at a few
values of a second parameter, to set beside the predicted curves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .checks import check_number
from .force_law import ForceLaw, PowerLaw
from .models import Continuous, ExactDelay, KBFirstOrder, Loop, LoopModel, Pade, Sampled, models_for
from .parameters import Controller, Robot, check_parameter
from .serialize import json_array, json_number
from .vectorized import delay_verdicts_from_gain, exact_delay_verdicts, loop_gain_arrays

__all__ = [
    "BoundaryCurve",
    "RegionGrid",
    "GainCurve",
    "KBErrorMap",
    "SimulatedBoundary",
    "default_models",
    "verdict_model",
    "region_model",
    "stable_set_verdicts",
    "model_options",
    "wall_f_curves",
    "wall_alpha_curves",
    "corridor_V_curves",
    "corridor_L_curves",
    "wall_f_region",
    "wall_alpha_region",
    "corridor_region",
    "critical_gain_vs_delay",
    "kb_error_map",
    "kb_error_maps",
    "kb_relative_error",
    "simulated_boundary",
    "SAMPLED_STRUCTURES",
]

SAMPLED_STRUCTURES = (("command", 0), ("command", 1), ("reference", 0), ("reference", 1))
"""Every (hold, compute_delay) of the `sampled` model."""


# ------------------------------------------------------------------ results
def model_options(model: LoopModel) -> dict:
    """The options that configure `model` (``{"order": 3}``, ``{"hold": …, "compute_delay": …}`` or ``{}``)."""
    if isinstance(model, Pade):
        return {"order": model.order}
    if isinstance(model, Sampled):
        return {"hold": model.hold, "compute_delay": model.compute_delay}
    return {}


@dataclass(frozen=True)
class BoundaryCurve:
    """One model's stability boundary as a curve y*(x).

    Attributes
    ----------
    model : LoopModel
        The model (its name is ``model.name``).
    NV_critical : float
        NV*, 1/s (``inf``: stable for every NV; 0: unstable for every NV > 0).
    omega_critical : float or None
        Oscillation frequency at the boundary, rad/s.
    x_name, y_name : str
        Parameter names (``V``, ``f``, ``alpha``, ``L``).
    x_unit, y_unit : str
        Units (``m/s``, ``rad``, ``m``, ``""`` for f).
    x, y : ndarray
        The curve: y[i] is the critical y at x[i] (``inf``/``nan`` where the
        boundary leaves the parameter's range).
    stable_side : {"above", "below"}
        Stable for y above or below the curve.
    """

    model: LoopModel
    NV_critical: float
    omega_critical: float | None
    x_name: str
    x_unit: str
    y_name: str
    y_unit: str
    x: np.ndarray
    y: np.ndarray
    stable_side: str

    def __repr__(self) -> str:
        return (
            f"BoundaryCurve({self.model.name}{model_options(self.model) or ''}: {self.y_name}*({self.x_name}), "
            f"NV* = {self.NV_critical:.6g} 1/s, {len(self.x)} points, stable {self.stable_side})"
        )

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        return {
            "model": self.model.name,
            "options": model_options(self.model),
            "NV_critical": json_number(self.NV_critical),
            "omega_critical": self.omega_critical,
            "x_name": self.x_name,
            "x_unit": self.x_unit,
            "y_name": self.y_name,
            "y_unit": self.y_unit,
            "x": json_array(self.x),
            "y": json_array(self.y),
            "stable_side": self.stable_side,
        }


@dataclass(frozen=True)
class RegionGrid:
    """One model's stable/unstable verdicts on a dense grid.

    Attributes
    ----------
    x_name, x_unit, y_name, y_unit : str
    x : ndarray, shape (nx,)
    y : ndarray, shape (ny,)
    stable : ndarray of bool, shape (ny, nx)
        The model's verdict at (x[j], y[i]).
    NV : ndarray, shape (ny, nx)
        Loop gain NV at each point, 1/s.
    model : str
        Name of the shaded model (``"sampled"`` by default in the region
        functions: the model of the report's verdict).
    options : dict
        The model's options (`model_options`: hold and compute delay of
        ``sampled``, order of ``pade``).
    stable_set : tuple of (float, float) or None
        The NV intervals (1/s) that decided every point (the model's
        `Boundary.stable_set`); None when each point was decided by the
        vectorized `exact_delay` crossing count instead
        (`pfm_stability.vectorized.exact_delay_verdicts`).
    """

    x_name: str
    x_unit: str
    y_name: str
    y_unit: str
    x: np.ndarray
    y: np.ndarray
    stable: np.ndarray
    NV: np.ndarray
    model: str = "exact_delay"
    options: dict = field(default_factory=dict)
    stable_set: tuple | None = None

    def __repr__(self) -> str:
        return (
            f"RegionGrid({self.model}{self.options or ''}: {self.y_name} × {self.x_name}, {self.stable.shape}, "
            f"{100 * self.stable.mean():.1f} % stable)"
        )

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        return {
            "model": self.model,
            "options": dict(self.options),
            "stable_set": None if self.stable_set is None else [[json_number(lo), json_number(hi)] for lo, hi in self.stable_set],
            "x_name": self.x_name,
            "x_unit": self.x_unit,
            "y_name": self.y_name,
            "y_unit": self.y_unit,
            "x": json_array(self.x),
            "y": json_array(self.y),
            "stable": self.stable.tolist(),
            "NV": json_array(self.NV),
        }


@dataclass(frozen=True)
class GainCurve:
    """NV* of one model against one loop parameter.

    Attributes
    ----------
    model : LoopModel
    x_name, x_unit : str
        E.g. ``"T/tau"``, ``""``.
    x : ndarray
    NV_critical : ndarray
        NV*, 1/s (``inf``: no finite boundary; 0: unstable for every NV).
    tau, T, k : float or None
        The fixed loop parameters (s, s, 1/s); the varied one is None.
    """

    model: LoopModel
    x_name: str
    x_unit: str
    x: np.ndarray
    NV_critical: np.ndarray
    tau: float | None = None
    T: float | None = None
    k: float | None = None

    def __repr__(self) -> str:
        return f"GainCurve({self.model.name}{model_options(self.model) or ''}: NV* vs {self.x_name}, {len(self.x)} points)"

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        return {
            "model": self.model.name,
            "options": model_options(self.model),
            "x_name": self.x_name,
            "x_unit": self.x_unit,
            "x": json_array(self.x),
            "NV_critical": json_array(self.NV_critical),
            "tau": self.tau,
            "T": self.T,
            "k": self.k,
        }


@dataclass(frozen=True)
class KBErrorMap:
    """How far KB's criterion (eq 20) is from another model, over (kτ, T/τ).

    Attributes
    ----------
    reference : LoopModel
        The model KB is compared with (usually ``sampled``).
    k_tau : ndarray, shape (nx,)
        Dimensionless steering gain kτ.
    T_over_tau : ndarray, shape (ny,)
        Dimensionless sampling period T/τ.
    NV_tau_kb : ndarray, shape (ny, nx)
        KB's NV*·τ = 1/(1 + T/τ) (eq 20).
    NV_tau_reference : ndarray, shape (ny, nx)
        The reference model's NV*·τ (0 where the loop is unstable for every
        NV > 0: the sampled steering loop alone is unstable).
    relative_error : ndarray, shape (ny, nx)
        NV*_KB/NV*_reference − 1: > 0 KB is optimistic (it calls stable a
        loop that oscillates), < 0 conservative; ``inf`` where NV*_reference = 0.
    """

    reference: LoopModel
    k_tau: np.ndarray
    T_over_tau: np.ndarray
    NV_tau_kb: np.ndarray
    NV_tau_reference: np.ndarray
    relative_error: np.ndarray

    @property
    def optimistic(self) -> np.ndarray:
        """True where KB's NV* exceeds the reference's (KB says stable, the loop oscillates)."""
        return self.relative_error > 0

    def at(self, k_tau: float, T_over_tau: float) -> float:
        """Relative error at one (kτ, T/τ), bilinear in (log kτ, log T/τ) between grid nodes."""
        from scipy.interpolate import RegularGridInterpolator

        values = np.where(np.isfinite(self.relative_error), self.relative_error, np.nan)
        f = RegularGridInterpolator((np.log(self.T_over_tau), np.log(self.k_tau)), values)
        return float(f([[math.log(T_over_tau), math.log(k_tau)]])[0])

    def __repr__(self) -> str:
        e = self.relative_error[np.isfinite(self.relative_error)]
        return (
            f"KBErrorMap(vs {self.reference.name}{model_options(self.reference) or ''}: {self.relative_error.shape}, "
            f"KB optimistic on {100 * self.optimistic.mean():.0f} %, error {e.min():+.2f} … {e.max():+.2f})"
        )

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        return {
            "reference": self.reference.name,
            "options": model_options(self.reference),
            "k_tau": json_array(self.k_tau),
            "T_over_tau": json_array(self.T_over_tau),
            "NV_tau_kb": json_array(self.NV_tau_kb),
            "NV_tau_reference": json_array(self.NV_tau_reference),
            "relative_error": json_array(self.relative_error),
        }


@dataclass(frozen=True)
class SimulatedBoundary:
    """Simulated boundary points: `parameter`* at each value of `over`.

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

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
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
        }


# ------------------------------------------------------------------ helpers
def default_models(controller: Controller, pade_order: int = 3) -> list[LoopModel]:
    """The five loop models; ``sampled`` with the controller's hold and compute delay (`models.models_for`)."""
    return models_for(controller, pade_order=pade_order)


def verdict_model(controller: Controller) -> LoopModel:
    """The model whose verdict the stability report gives: ``sampled`` with the controller's hold and compute delay."""
    return models_for(controller, ("sampled",))[0]


def region_model(controller: Controller, model: LoopModel | str | None = None) -> LoopModel:
    """The model a region map shades.

    Parameters
    ----------
    controller : Controller
        Its hold and compute delay configure ``sampled``.
    model : LoopModel or str, optional
        A model or a model name (`models.MODEL_NAMES`); default
        `verdict_model` (the report's verdict).

    Returns
    -------
    LoopModel

    Raises
    ------
    ValueError
        Unknown name, or a ``Sampled`` model whose structure contradicts the
        controller (`models.models_for`).
    """
    return verdict_model(controller) if model is None else models_for(controller, (model,))[0]


def stable_set_verdicts(stable_set, NV) -> np.ndarray:
    """True where NV lies strictly inside one of the intervals (`Boundary.contains` for arrays).

    Parameters
    ----------
    stable_set : sequence of (float, float)
        NV intervals (lo, hi), 1/s (`Boundary.stable_set`).
    NV : array_like
        Loop gains, 1/s.

    Returns
    -------
    ndarray of bool
        Shaped like `NV`.
    """
    NV = np.asarray(NV, dtype=float)
    stable = np.zeros(NV.shape, dtype=bool)
    for lo, hi in stable_set:
        stable |= (NV > lo) & (NV < hi)
    return stable


def _law(robot: Robot, controller: Controller, law: ForceLaw | None) -> ForceLaw:
    return law if law is not None else PowerLaw(controller.f, controller.n, robot.W)


def _array(name, x, unit=""):
    x = np.atleast_1d(np.asarray(x, dtype=float))
    if x.ndim != 1 or x.size == 0 or not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise ValueError(f"{name} must be a non-empty 1-D array of positive finite numbers{' (' + unit + ')' if unit else ''}")
    return x


def _invert_decreasing(g, targets, lo: float, hi: float, iterations: int = 200):
    """x in [lo, hi] with g(x) = target, g vectorized and decreasing in x > 0.

    Bisection on log x for all targets at once (to round-off). Targets above
    g(lo) give ``lo``-side ``nan``; below g(hi) (after expanding hi up to 2^100
    times) give ``inf``.
    """
    targets = np.asarray(targets, dtype=float)
    for _ in range(100):
        if g(np.array([hi]))[0] <= np.min(targets):
            break
        hi *= 2.0
    a = np.full(targets.shape, math.log(lo))
    b = np.full(targets.shape, math.log(hi))
    for _ in range(iterations):
        m = 0.5 * (a + b)
        above = g(np.exp(m)) > targets
        a = np.where(above, m, a)
        b = np.where(above, b, m)
        if np.all(b - a <= 4e-16 * np.maximum(1.0, np.abs(a))):
            break
    x = np.exp(0.5 * (a + b))
    x = np.where(targets > g(np.array([lo]))[0], np.nan, x)
    return np.where(targets < g(np.array([hi]))[0], np.inf, x)


def _wall_parametric(law: ForceLaw, d0):
    """α (rad) and N (1/m) of the wall equilibrium at distance d0 (KB eq 11, 23; general law)."""
    d0 = np.asarray(d0, dtype=float)
    F = np.asarray(law.force(d0), dtype=float)
    with np.errstate(invalid="ignore"):
        alpha = np.arccos(np.clip(F, -1.0, 1.0))
        N = -np.asarray(law.slope(d0), dtype=float) / np.sqrt(np.maximum(1.0 - F * F, 0.0))
    return alpha, N


def _boundaries(models, loop: Loop):
    return [(m, m.boundary(loop)) for m in models]


def _loop(robot: Robot, controller: Controller) -> Loop:
    return Loop(robot.tau, controller.T, robot.k)


# ------------------------------------------------------------- wall curves
def wall_f_curves(robot: Robot, controller: Controller, alpha: float, V, models=None, law: ForceLaw | None = None) -> list[BoundaryCurve]:
    """f*(V) along a wall at target angle α, one curve per model (KB eq 24 generalized).

    Parameters
    ----------
    robot, controller : Robot, Controller
        τ, k, W (robot); T, n (controller). V and f are the plane's axes.
    alpha : float
        Target angle from the wall normal, rad (KB eq 9).
    V : array_like
        Speeds, m/s.
    models : list of LoopModel, optional
        Default `default_models(controller)`.
    law : ForceLaw, optional
        Default KB's power law f(W/d)^n; otherwise y is the law's ``scale``
        (its strength parameter, e.g. the grid's cell ratio).

    Returns
    -------
    list of BoundaryCurve
        y = f* (dimensionless; stable above): for the power law
        f* = cos α [nV/(W·NV*·tan α)]^n; ``inf`` where NV* = 0, 0 where NV* = inf.
    """
    alpha = check_parameter("alpha", alpha)
    V = _array("V", V, "m/s")
    models = default_models(controller) if models is None else list(models)
    law = _law(robot, controller, law)
    out = []
    for model, b in _boundaries(models, _loop(robot, controller)):
        NVs = b.NV_critical
        if NVs == 0:
            y = np.full(V.shape, np.inf)
        elif math.isinf(NVs):
            y = np.zeros(V.shape)
        elif isinstance(law, PowerLaw):
            y = math.cos(alpha) * (law.n * V / (law.W * NVs * math.tan(alpha))) ** law.n
        else:
            y = _wall_scale_general(law, alpha, V, NVs)
        out.append(BoundaryCurve(model, NVs, b.omega_critical, "V", "m/s", "f", "", V, y, "above"))
    return out


def _wall_scale_general(law: ForceLaw, alpha: float, V, NV_critical: float):
    """Law scale c* with N(c*)·V = NV* at angle α, for a law whose force ∝ scale.

    At scale c the equilibrium d0 solves c·g(d0) = cos α (g = F/scale), and
    N = −c·g′(d0)/sin α = cot α · (−F′/F)(d0), independent of c; so solve
    (−F′/F)(d0) = NV*·tan α / V for d0, then c* = scale·cos α / F(d0).
    """

    def log_slope(d):
        return -np.asarray(law.slope(d), dtype=float) / np.asarray(law.force(d), dtype=float)

    lo = max(law.domain()[0], 1e-9)
    d0 = _invert_decreasing(log_slope, NV_critical * math.tan(alpha) / V, lo, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = law.scale * math.cos(alpha) / np.asarray(law.force(np.where(np.isfinite(d0), d0, 1.0)), dtype=float)
    c = np.where(np.isinf(d0), np.inf, c)
    return np.where(np.isnan(d0), 0.0, c)


def wall_alpha_curves(robot: Robot, controller: Controller, V, models=None, law: ForceLaw | None = None) -> list[BoundaryCurve]:
    """α*(V) along a wall, one curve per model (KB eq 21 with eq 23): stable for α > α*.

    Solves N(α*)·V = NV* by vectorized bisection in the equilibrium distance
    d0 (α = arccos F_r(d0)/F_a, N = −F_r′(d0)/(F_a sin α)).

    Parameters
    ----------
    robot, controller : Robot, Controller
        τ, k, W; f, n, T.
    V : array_like
        Speeds, m/s.
    models, law
        As in `wall_f_curves`.

    Returns
    -------
    list of BoundaryCurve
        y = α*, rad (0 where NV* = inf, π/2 where NV* = 0).
    """
    V = _array("V", V, "m/s")
    models = default_models(controller) if models is None else list(models)
    law = _law(robot, controller, law)
    d_contact = law.distance_for(1.0)  # α = 0: the law alone balances the full target force
    out = []
    for model, b in _boundaries(models, _loop(robot, controller)):
        NVs = b.NV_critical
        if NVs == 0:
            y = np.full(V.shape, math.pi / 2)
        elif math.isinf(NVs):
            y = np.zeros(V.shape)
        else:
            d0 = _invert_decreasing(lambda d: _wall_parametric(law, d)[1], NVs / V, d_contact * (1 + 1e-12), max(2 * d_contact, 1.0))
            y = np.where(np.isinf(d0), math.pi / 2, _wall_parametric(law, np.where(np.isfinite(d0), d0, d_contact * 2))[0])
            y = np.where(np.isnan(d0), 0.0, y)
        out.append(BoundaryCurve(model, NVs, b.omega_critical, "V", "m/s", "alpha", "rad", V, y, "above"))
    return out


# --------------------------------------------------------- corridor curves
def corridor_V_curves(robot: Robot, controller: Controller, L, models=None, law: ForceLaw | None = None) -> list[BoundaryCurve]:
    """V*(L) in the middle of a corridor, one curve per model: stable for V < V* = NV*/N(L).

    Parameters
    ----------
    robot, controller : Robot, Controller
    L : array_like
        Half-widths, m (> W/2).
    models, law
        As in `wall_f_curves`; N(L) = −2F_r′(L)/F_a (KB §5.4; 2nfWⁿ/L^(n+1)
        for the power law).

    Returns
    -------
    list of BoundaryCurve
        y = V*, m/s.
    """
    L = _array("L", L, "m")
    if np.any(L <= robot.W / 2):
        raise ValueError(f"L must exceed W/2 = {robot.W / 2:g} m (the robot must fit)")
    models = default_models(controller) if models is None else list(models)
    law = _law(robot, controller, law)
    N = -2.0 * np.asarray(law.slope(L), dtype=float)
    out = []
    for model, b in _boundaries(models, _loop(robot, controller)):
        y = b.NV_critical / N
        out.append(BoundaryCurve(model, b.NV_critical, b.omega_critical, "L", "m", "V", "m/s", L, y, "below"))
    return out


def corridor_L_curves(robot: Robot, controller: Controller, V, models=None, law: ForceLaw | None = None) -> list[BoundaryCurve]:
    """L*(V) in the middle of a corridor, one curve per model (KB eq 25 generalized): stable for L > L*.

    Power law: L* = (2nWⁿVf/NV*)^(1/(n+1)); other laws: N(L*)·V = NV* by
    vectorized bisection.

    Parameters
    ----------
    robot, controller : Robot, Controller
    V : array_like
        Speeds, m/s.
    models, law
        As in `wall_f_curves`.

    Returns
    -------
    list of BoundaryCurve
        y = L*, m (0 where NV* = inf, inf where NV* = 0).
    """
    V = _array("V", V, "m/s")
    models = default_models(controller) if models is None else list(models)
    law = _law(robot, controller, law)
    out = []
    for model, b in _boundaries(models, _loop(robot, controller)):
        NVs = b.NV_critical
        if NVs == 0:
            y = np.full(V.shape, np.inf)
        elif math.isinf(NVs):
            y = np.zeros(V.shape)
        elif isinstance(law, PowerLaw):
            y = (2 * law.n * law.W**law.n * V * law.f / NVs) ** (1 / (law.n + 1))
        else:
            lo = max(law.domain()[0], 1e-9)
            y = _invert_decreasing(lambda d: -2.0 * np.asarray(law.slope(d), dtype=float), NVs / V, lo, 1.0)
        out.append(BoundaryCurve(model, NVs, b.omega_critical, "V", "m/s", "L", "m", V, y, "above"))
    return out


# ------------------------------------------------------- dense region maps
def _general_verdicts(robot: Robot, controller: Controller, NV):
    """`exact_delay` crossing-count verdicts for an array of NV (any force law)."""
    NV = np.asarray(NV, dtype=float)
    tau, T, k = (np.full(NV.size, v) for v in (robot.tau, controller.T, robot.k))
    stable, _, _ = delay_verdicts_from_gain(tau, T, k, k * NV.ravel())
    return stable.reshape(NV.shape)


def _region(robot: Robot, controller: Controller, model: LoopModel, axes, NV, stable=None) -> RegionGrid:
    """A RegionGrid of `model` on NV: the given crossing-count verdicts, else the model's stable set."""
    NV = np.asarray(NV, dtype=float)
    stable_set = None
    if stable is None:
        if isinstance(model, ExactDelay):
            stable = _general_verdicts(robot, controller, NV)
        else:
            b = model.boundary(_loop(robot, controller))
            stable_set = tuple(b.stable_set) or (((0.0, b.NV_critical),) if b.NV_critical > 0 else ())
            stable = stable_set_verdicts(stable_set, NV)
    return RegionGrid(*axes, stable, NV, model.name, model_options(model), stable_set)


def _power_law_parameters(robot: Robot, controller: Controller, law: ForceLaw | None):
    """(f, n, W) of KB's power law: the given law's, else the controller's and the robot's."""
    return (law.f, law.n, law.W) if law is not None else (controller.f, controller.n, robot.W)


def _wall_gain_general(law: ForceLaw, alpha, scale_factor=1.0):
    """N (1/m) at the wall equilibrium for arrays α (rad) and force multipliers c (F = c·law)."""
    alpha, c = np.broadcast_arrays(np.asarray(alpha, dtype=float), np.asarray(scale_factor, dtype=float))
    target = np.cos(alpha) / c  # law.force(d0) = cos α / c
    lo = max(law.domain()[0], 1e-9)
    flat = target.ravel()
    d0 = _invert_decreasing(lambda d: np.asarray(law.force(d), dtype=float), flat, lo, 1.0).reshape(target.shape)
    finite = np.isfinite(d0) & (d0 > 0)
    safe = np.where(finite, d0, 1.0)
    N = np.where(finite, -c * np.asarray(law.slope(safe), dtype=float) / np.sin(alpha), 0.0)
    return np.where(np.isnan(d0), np.inf, N)  # nan: the law never pushes that hard (robot at the wall)


def wall_f_region(robot: Robot, controller: Controller, alpha: float, V, f, law: ForceLaw | None = None, model=None) -> RegionGrid:
    """One model's verdicts on the (V, f) plane along a wall at angle α.

    Parameters
    ----------
    robot, controller : Robot, Controller
        τ, k, W; n, T, hold, compute delay.
    alpha : float
        Rad.
    V : array_like, shape (nx,)
        Speeds, m/s.
    f : array_like, shape (ny,)
        Force ratios (KB eq 13), or the `law`'s scale.
    law : ForceLaw, optional
        Default KB's power law (N in closed form); another law's N comes
        from its equilibrium (vectorized bisection).
    model : LoopModel or str, optional
        The model whose verdicts are shaded (`region_model`); default the
        report's verdict model, ``sampled`` with the controller's hold and
        compute delay. Decided by the model's `Boundary.stable_set` (exact:
        NV is the only quantity that varies over the plane); ``exact_delay``
        is decided point by point by the vectorized crossing count.

    Returns
    -------
    RegionGrid
        ``stable[i, j]`` at (V[j], f[i]).
    """
    alpha = check_parameter("alpha", alpha)
    V, f = _array("V", V, "m/s"), _array("f", f)
    model = region_model(controller, model)
    axes = ("V", "m/s", "f", "", V, f)
    if law is None or isinstance(law, PowerLaw):
        n, W = _power_law_parameters(robot, controller, law)[1:]
        if isinstance(model, ExactDelay):
            r = exact_delay_verdicts(V[None, :], robot.tau, controller.T, robot.k, f[:, None], n, W, alpha=alpha)
            return _region(robot, controller, model, axes, r.NV, r.stable)
        NV = loop_gain_arrays(V[None, :], robot.tau, controller.T, robot.k, f[:, None], n, W, alpha=alpha)[3]
        return _region(robot, controller, model, axes, NV)
    NV = _wall_gain_general(law, alpha, f[:, None] / law.scale) * V[None, :]
    return _region(robot, controller, model, axes, NV)


def wall_alpha_region(robot: Robot, controller: Controller, V, alpha, law: ForceLaw | None = None, model=None) -> RegionGrid:
    """One model's verdicts on the (V, α) plane along a wall.

    Parameters
    ----------
    robot, controller : Robot, Controller
    V : array_like, shape (nx,)
        m/s.
    alpha : array_like, shape (ny,)
        Rad, in (0, π/2).
    law : ForceLaw, optional
        Default KB's power law with the controller's f.
    model : LoopModel or str, optional
        The model whose verdicts are shaded (`region_model`); default the
        report's verdict model, ``sampled`` with the controller's hold and
        compute delay. Decided by the model's `Boundary.stable_set` (exact:
        NV is the only quantity that varies over the plane); ``exact_delay``
        is decided point by point by the vectorized crossing count.

    Returns
    -------
    RegionGrid
        ``stable[i, j]`` at (V[j], α[i]); y in rad.
    """
    V, alpha = _array("V", V, "m/s"), _array("alpha", alpha, "rad")
    model = region_model(controller, model)
    axes = ("V", "m/s", "alpha", "rad", V, alpha)
    if law is None or isinstance(law, PowerLaw):
        f, n, W = _power_law_parameters(robot, controller, law)
        if isinstance(model, ExactDelay):
            r = exact_delay_verdicts(V[None, :], robot.tau, controller.T, robot.k, f, n, W, alpha=alpha[:, None])
            return _region(robot, controller, model, axes, r.NV, r.stable)
        NV = loop_gain_arrays(V[None, :], robot.tau, controller.T, robot.k, f, n, W, alpha=alpha[:, None])[3]
        return _region(robot, controller, model, axes, NV)
    NV = _wall_gain_general(law, alpha[:, None]) * V[None, :]
    return _region(robot, controller, model, axes, NV)


def corridor_region(robot: Robot, controller: Controller, L, V, law: ForceLaw | None = None, model=None) -> RegionGrid:
    """One model's verdicts on the (L, V) plane in the middle of a corridor (KB §5.4, eq 25).

    Parameters
    ----------
    robot, controller : Robot, Controller
    L : array_like, shape (nx,)
        Half-widths, m (> W/2).
    V : array_like, shape (ny,)
        Speeds, m/s.
    law : ForceLaw, optional
        Default KB's power law; otherwise N(L) = −2F_r′(L)/F_a.
    model : LoopModel or str, optional
        The model whose verdicts are shaded (`region_model`); default the
        report's verdict model, ``sampled`` with the controller's hold and
        compute delay. Decided by the model's `Boundary.stable_set` (exact:
        NV is the only quantity that varies over the plane); ``exact_delay``
        is decided point by point by the vectorized crossing count.

    Returns
    -------
    RegionGrid
        ``stable[i, j]`` at (L[j], V[i]).
    """
    L, V = _array("L", L, "m"), _array("V", V, "m/s")
    model = region_model(controller, model)
    axes = ("L", "m", "V", "m/s", L, V)
    if law is None or isinstance(law, PowerLaw):
        f, n, W = _power_law_parameters(robot, controller, law)
        if isinstance(model, ExactDelay):
            r = exact_delay_verdicts(V[:, None], robot.tau, controller.T, robot.k, f, n, W, L=L[None, :])
            return _region(robot, controller, model, axes, r.NV, r.stable)
        NV = loop_gain_arrays(V[:, None], robot.tau, controller.T, robot.k, f, n, W, L=L[None, :])[3]
        return _region(robot, controller, model, axes, NV)
    if np.any(L <= robot.W / 2):
        raise ValueError(f"L must exceed W/2 = {robot.W / 2:g} m (the robot must fit)")
    NV = (-2.0 * np.asarray(law.slope(L), dtype=float))[None, :] * V[:, None]
    return _region(robot, controller, model, axes, NV)


# ---------------------------------------------------------- model comparison
def critical_gain_vs_delay(tau: float, k: float, T_over_tau, models=None, *, pade_order: int = 3) -> list[GainCurve]:
    """NV* (1/s) of every model against the sampling period, T = (T/τ)·τ.

    Parameters
    ----------
    tau : float
        Steering time constant, s (> 0).
    k : float
        Steering gain, 1/s.
    T_over_tau : array_like
        Sampling periods in units of τ.
    models : list of LoopModel, optional
        Default: continuous, kb_first_order, pade, exact_delay and ``sampled``
        in all four structures (`SAMPLED_STRUCTURES`).

    Returns
    -------
    list of GainCurve
        x = T/τ (dimensionless).
    """
    tau = check_number("tau", tau, 0.0, unit="s")
    k = check_parameter("k", k)
    x = _array("T_over_tau", T_over_tau)
    if models is None:
        models = [Continuous(), KBFirstOrder(), Pade(pade_order), ExactDelay()] + [Sampled(h, c) for h, c in SAMPLED_STRUCTURES]
    curves = []
    for model in models:
        values = np.array([model.boundary(Loop(tau, float(r) * tau, k)).NV_critical for r in x])
        curves.append(GainCurve(model, "T/tau", "", x, values, tau=tau, k=k))
    return curves


def kb_error_map(k_tau, T_over_tau, reference: LoopModel | None = None) -> KBErrorMap:
    """NV*_KB/NV*_reference − 1 over (kτ, T/τ): where KB's eq (20) is optimistic (> 0) or conservative (< 0).

    NV*τ is a function of kτ and T/τ only (time scaled by τ), so the map
    holds for every τ; it is computed at τ = 1 s.

    Parameters
    ----------
    k_tau : array_like, shape (nx,)
        Dimensionless steering gains kτ.
    T_over_tau : array_like, shape (ny,)
        Dimensionless sampling periods T/τ.
    reference : LoopModel, optional
        Default ``Sampled("command", 1)`` (CARMEL's structure).

    Returns
    -------
    KBErrorMap
    """
    kx = _array("k_tau", k_tau)
    ty = _array("T_over_tau", T_over_tau)
    reference = Sampled("command", 1) if reference is None else reference
    ref = np.array([[reference.boundary(Loop(1.0, float(t), float(k))).NV_critical for k in kx] for t in ty])
    kb = np.broadcast_to(1.0 / (1.0 + ty[:, None]), ref.shape).copy()
    with np.errstate(divide="ignore"):
        err = np.where(ref > 0, kb / np.where(ref > 0, ref, 1.0) - 1.0, np.inf)
    return KBErrorMap(reference, kx, ty, kb, ref, err)


def kb_error_maps(k_tau, T_over_tau, structures=SAMPLED_STRUCTURES) -> list[KBErrorMap]:
    """`kb_error_map` against ``sampled`` for each (hold, compute_delay)."""
    return [kb_error_map(k_tau, T_over_tau, Sampled(h, c)) for h, c in structures]


def kb_relative_error(loop: Loop, reference: LoopModel) -> float:
    """NV*_KB/NV*_reference − 1 for one loop (> 0: KB's eq 20 optimistic; ``inf`` if NV*_reference = 0)."""
    ref = reference.boundary(loop).NV_critical
    kb = KBFirstOrder().boundary(loop).NV_critical
    return kb / ref - 1.0 if ref > 0 else math.inf


# ---------------------------------------------------------- simulation
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
    **options,
) -> SimulatedBoundary:
    """The simulated boundary in `parameter` at each of several values of `over`.

    One `pfm_stability.sim.boundary_by_bisection` per value (each round a
    batch of `members` runs), e.g. the critical speed V* of the ``corridor``
    scenario at a few half-widths L, or the critical angle α* of the ``wall``
    at a few speeds.

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
    **options
        Other `simulate_batch` arguments (``offset``, ``duration``, ``robot``,
        ``controller``, …).

    Returns
    -------
    SimulatedBoundary
    """
    from .sim import boundary_by_bisection

    values = np.atleast_1d(np.asarray(values, dtype=float))
    est = [
        boundary_by_bisection(scenario, parameter, lo, hi, env=env, rtol=rtol, members=members, **{over: float(v)}, **options)
        for v in values
    ]
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
    )

