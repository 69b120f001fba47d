"""Stability boundary curves for every loop model: y*(x) in the planes of (V, f, α, L) (no plotting here).

Koren & Borenstein 1991 (KB) reduce every question to the loop gain NV: each
loop model (`pfm_stability.models`) is stable for 0 < NV < NV*(τ, T, k) (KB eq 20 for
``kb_first_order``), and N depends on the environment and the force law only
(KB eq 11, 23, 25). A model's NV* therefore turns into a boundary curve in any
plane of (V, f, α, L) through the force law:

* wall, (V, f) plane at fixed α: f*(V) = cos α [nV/(W·NV*·tan α)]^n (KB eq 24
  with 1/NV* in place of τ + T); stable for f > f*;
* wall, α*(V) at fixed f: N(α*)·V = NV* (KB eq 21 with eq 23); stable for α > α*;
  V*(α) = NV*/N(α), stable for V < V*;
* corridor, (L, V) plane: V*(L) = NV*/N(L) with N = 2nfWⁿ/L^(n+1); stable
  for V < V*; equivalently L*(V) = (2nWⁿVf/NV*)^(1/(n+1)) (KB eq 25), stable
  for L > L*.

For KB's power law these are closed forms (α* by vectorized bisection on the
closed-form N(α)). For any other decreasing law (e.g. the grid's effective
law, `pfm_stability.laws.effective_force.GridWallLaw`) the curves are found by a
vectorized bisection in the equilibrium distance d0, which parametrizes the
wall exactly: cos α = F_r(d0)/F_a and N = −F_r′(d0)/(F_a sin α) (KB eq 11
and 23 with the general law in place of f(W/d)ⁿ); this assumes N decreases as d0 grows (a convex
decreasing law — true for the power law and for the grid law). A law that does not declare
itself `monotone` is checked on a grid of its domain first: where the inverted quantity is
not monotone (Khatib's law, the goal-aware law: several equilibria, N not monotone in d0 —
docs/fields.md) the curve would not be one curve, and a ValueError says so; V*(α) and V*(L)
need no inversion and take the first equilibrium.

Dense stable/unstable maps of one model are `pfm_stability.analysis.regions`; how the
models differ from one another is `pfm_stability.analysis.comparison`; the simulated
boundary set beside these curves is `pfm_stability.validation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_positive_axis
from .criteria import loop_of
from ..laws.force_law import ForceLaw, PowerLaw, corridor_gain, law_in_force, wall_equilibria, wall_gain_arrays, wall_gain_at_distance
from ..models import Loop, LoopModel, models_for
from ..parameters import RANGES, Controller, Robot, check_parameter
from ..numerics.solve import invert_decreasing
from ..io.serialize import json_array, json_number

__all__ = [
    "BoundaryCurve",
    "default_models",
    "wall_f_curves",
    "wall_alpha_curves",
    "wall_V_curves",
    "corridor_V_curves",
    "corridor_L_curves",
]


# ------------------------------------------------------------------ results
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
    x_name, x_unit : str
        The x parameter's name (``V``, ``f``, ``alpha``, ``L``) and unit (``m/s``, ``rad``, ``m``, ``""`` for f).
    y_name, y_unit : str
        The y parameter's name and unit, likewise.
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
            f"BoundaryCurve({self.model.name}{self.model.options() or ''}: {self.y_name}*({self.x_name}), "
            f"NV* = {self.NV_critical:.6g} 1/s, {len(self.x)} points, stable {self.stable_side})"
        )

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        return {
            "model": self.model.name,
            "options": self.model.options(),
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


# ------------------------------------------------------------------ helpers
def default_models(controller: Controller, pade_order: int = 3) -> list[LoopModel]:
    """The five loop models; ``sampled`` with the controller's hold and compute delay (`models.models_for`).

    Parameters
    ----------
    controller : Controller
        Hold and compute delay of ``sampled``.
    pade_order : int
        Order of the ``pade`` model.
    """
    return models_for(controller, pade_order=pade_order)


def _boundaries(models, loop: Loop):
    return [(m, m.boundary(loop)) for m in models]


def _over_speed(NV_critical: float, V, solve, unstable: float = math.inf):
    """A critical value y*(V) over the speeds V for a model's NV*: `unstable` where NV* = 0 (no V is stable: f*, L*
    infinite, α* = π/2), 0 where NV* = inf (every V is), else ``solve(NV*)``."""
    if NV_critical == 0:
        return np.full(V.shape, unstable)
    if math.isinf(NV_critical):
        return np.zeros(V.shape)
    return solve(NV_critical)


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
    V = check_positive_axis("V", V, "m/s")
    models = default_models(controller) if models is None else list(models)
    law = law_in_force(robot, controller, law)
    def solve(NVs):
        if isinstance(law, PowerLaw):
            return math.cos(alpha) * (law.n * V / (law.W * NVs * math.tan(alpha))) ** law.n
        return _wall_scale_general(law, alpha, V, NVs)

    return [BoundaryCurve(model, b.NV_critical, b.omega_critical, "V", "m/s", "f", "", V, _over_speed(b.NV_critical, V, solve), "above")
            for model, b in _boundaries(models, loop_of(robot, controller))]


def _check_decreasing(law: ForceLaw, g, lo: float, what: str, hi: float = math.inf) -> None:
    """ValueError unless g (vectorized) does not increase on [lo, hi] (a log grid), for a law not declared `monotone`."""
    if law.monotone:
        return
    top = min(hi, law.domain()[1])
    top = top if math.isfinite(top) else max(1e6, 1e3 * lo)
    with np.errstate(all="ignore"):
        v = np.asarray(g(np.geomspace(lo, top, 2000)), dtype=float)
    v = v[np.isfinite(v)]
    if np.any(np.diff(v) > 1e-9 * np.max(np.abs(v), initial=0.0)) or (law.has_goal_part and what.startswith("the law's strength")):
        raise ValueError(
            f"{what} is not monotone for {law.name}: the boundary is not one curve; analyse each point with "
            f"criteria.analyze_wall / analyze_corridor instead (docs/fields.md)"
        )


def _wall_scale_general(law: ForceLaw, alpha: float, V, NV_critical: float):
    """Law scale c* with N(c*)·V = NV* at angle α, for a law whose force ∝ scale.

    At scale c the equilibrium d0 solves c·g(d0) = cos α (g = F/scale), and
    N = −c·g′(d0)/sin α = cot α · (−F′/F)(d0), independent of c; so solve
    (−F′/F)(d0) = NV*·tan α / V for d0, then c* = scale·cos α / F(d0).
    """

    def log_slope(d):
        return -np.asarray(law.slope(d), dtype=float) / np.asarray(law.force(d), dtype=float)

    lo = max(law.domain()[0], 1e-9)
    _check_decreasing(law, log_slope, lo, "the law's strength against N (-F'/F in d0)")
    d0 = invert_decreasing(log_slope, NV_critical * math.tan(alpha) / V, lo, 1.0)
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
    V = check_positive_axis("V", V, "m/s")
    models = default_models(controller) if models is None else list(models)
    law = law_in_force(robot, controller, law)
    lo = max(law.domain()[0], 1e-9)
    _check_decreasing(law, law.wall_ratio, lo, "the equilibrium condition P/(1 + Q) in d0")
    _check_decreasing(law, lambda d: wall_gain_at_distance(law, d)[1], lo, "N against the equilibrium distance d0")
    # α = 0: the law alone balances the full target force
    d_contact = law.distance_for(1.0) if not law.has_goal_part else wall_equilibria(law, RANGES["alpha"].low)[0].x0
    def solve(NVs):
        d0 = invert_decreasing(lambda d: wall_gain_at_distance(law, d)[1], NVs / V, d_contact * (1 + 1e-12), max(2 * d_contact, 1.0))
        y = np.where(np.isinf(d0), math.pi / 2, wall_gain_at_distance(law, np.where(np.isfinite(d0), d0, d_contact * 2))[0])
        return np.where(np.isnan(d0), 0.0, y)

    return [BoundaryCurve(model, b.NV_critical, b.omega_critical, "V", "m/s", "alpha", "rad", V,
                          _over_speed(b.NV_critical, V, solve, unstable=math.pi / 2), "above")
            for model, b in _boundaries(models, loop_of(robot, controller))]


# --------------------------------------------------------- corridor curves
def wall_V_curves(robot: Robot, controller: Controller, alpha, models=None, law: ForceLaw | None = None) -> list[BoundaryCurve]:
    """V*(α) along a wall, one curve per model: stable for V < V* = NV*/N(α) (KB eq 21, 23 generalized).

    Parameters
    ----------
    robot, controller : Robot, Controller
    alpha : array_like
        Target angles from the wall normal, rad, in (0, π/2).
    models, law
        As in `wall_f_curves`; N(α) from the wall equilibrium
        (`force_law.wall_gain_arrays`; (n/d0)·cot α for the power law).

    Returns
    -------
    list of BoundaryCurve
        y = V*, m/s (``inf`` where N = 0: the law never balances the target's pull).
    """
    alpha = check_positive_axis("alpha", alpha, "rad")
    if np.any(alpha >= math.pi / 2):
        raise ValueError("alpha must be below pi/2 rad (90 deg): the target must pull towards the wall")
    models = default_models(controller) if models is None else list(models)
    N = wall_gain_arrays(law_in_force(robot, controller, law), alpha)[1]
    out = []
    for model, b in _boundaries(models, loop_of(robot, controller)):
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(N > 0, b.NV_critical / np.where(N > 0, N, 1.0), np.inf)
        out.append(BoundaryCurve(model, b.NV_critical, b.omega_critical, "alpha", "rad", "V", "m/s", alpha, y, "below"))
    return out


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
    L = check_positive_axis("L", L, "m")
    if np.any(L <= robot.W / 2):
        raise ValueError(f"L must exceed W/2 = {robot.W / 2:g} m (the robot must fit)")
    models = default_models(controller) if models is None else list(models)
    law = law_in_force(robot, controller, law)
    N = corridor_gain(law, L)
    out = []
    for model, b in _boundaries(models, loop_of(robot, controller)):
        with np.errstate(divide="ignore"):  # N = 0 (a law with a finite reach, beyond it): stable at every V
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
    V = check_positive_axis("V", V, "m/s")
    models = default_models(controller) if models is None else list(models)
    law = law_in_force(robot, controller, law)
    def solve(NVs):
        if isinstance(law, PowerLaw):
            return (2 * law.n * law.W**law.n * V * law.f / NVs) ** (1 / (law.n + 1))
        lo = max(law.domain()[0], 1e-9)
        _check_decreasing(law, lambda d: corridor_gain(law, d), max(lo, robot.W / 2), "N against the corridor half-width L")
        return invert_decreasing(lambda d: corridor_gain(law, d), NVs / V, lo, 1.0)

    return [BoundaryCurve(model, b.NV_critical, b.omega_critical, "V", "m/s", "L", "m", V, _over_speed(b.NV_critical, V, solve), "above")
            for model, b in _boundaries(models, loop_of(robot, controller))]


