"""Stability region maps: one model's stable/unstable verdicts on a dense grid (no plotting here).

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
curves of `pfm_stability.analysis.curves`; the tests check that the two agree to the
grid resolution).

Any `ForceLaw` may be shaded (docs/fields.md). For a law that is not
`monotone` each point takes its first (nearest) wall equilibrium
(`force_law.wall_gain_arrays`, one root search per angle) and the middle of the
corridor; the (V, f) plane scales the law's force, so it needs a law without a
goal-directed part (a ValueError says so).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..checks import check_positive_axis
from .criteria import loop_of
from ..laws.force_law import ForceLaw, PowerLaw, corridor_gain, wall_gain_arrays
from ..models import ExactDelay, LoopModel, models_for
from ..models.verdicts import in_stable_set
from ..parameters import Controller, Robot, check_parameter, plant_not_kb
from ..io.serialize import json_array, json_number
from ..vectorized import delay_verdicts_from_gain, exact_delay_verdicts, loop_gain_arrays

__all__ = [
    "RegionGrid",
    "verdict_model",
    "region_model",
    "wall_f_region",
    "wall_alpha_region",
    "corridor_region",
]


# ------------------------------------------------------------------ results
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
        The model's options (`LoopModel.options`: hold and compute delay of
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


# ------------------------------------------------------------------ helpers
def verdict_model(controller: Controller) -> LoopModel:
    """The model whose verdict the stability report gives: ``sampled`` with the controller's hold and compute delay.

    Parameters
    ----------
    controller : Controller
        Hold and compute delay.
    """
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


# ------------------------------------------------------- dense region maps
def _delay_loop(robot: Robot, controller: Controller) -> tuple:
    """(τ, T + D, g·k): the exact delay loop's τ, delay and steering gain with the plant's dead time and gain
    (docs/models.md, "Plant gain and dead time"; τ, T, k for KB's robot, the same floats)."""
    return robot.tau, controller.T + robot.dead_time, robot.plant_gain * robot.k


def _array_delay_route(model: LoopModel, robot: Robot) -> bool:
    """Whether `exact_delay`'s verdicts come from the vectorized crossing count: its one-delay loop, KB's plant or only a
    plant gain (g·k); a dead time, a second lag or a slide makes the general loop, decided by the model's stable set."""
    return isinstance(model, ExactDelay) and set(plant_not_kb(robot)) <= {"plant_gain"}


def _general_verdicts(robot: Robot, controller: Controller, NV):
    """`exact_delay` crossing-count verdicts for an array of NV (any force law)."""
    NV = np.asarray(NV, dtype=float)
    tau, T, k = (np.full(NV.size, v) for v in _delay_loop(robot, controller))
    stable, _, _ = delay_verdicts_from_gain(tau, T, k, k * NV.ravel())
    return stable.reshape(NV.shape)


def _region(robot: Robot, controller: Controller, model: LoopModel, axes, NV, stable=None) -> RegionGrid:
    """A RegionGrid of `model` on NV: the given crossing-count verdicts, else the model's stable set."""
    NV = np.asarray(NV, dtype=float)
    stable_set = None
    if stable is None:
        if _array_delay_route(model, robot):
            stable = _general_verdicts(robot, controller, NV)
        else:
            b = model.boundary(loop_of(robot, controller))
            stable_set = tuple(b.stable_set) or (((0.0, b.NV_critical),) if b.NV_critical > 0 else ())
            stable = in_stable_set(stable_set, NV)
    return RegionGrid(*axes, stable, NV, model.name, model.options(), stable_set)


def _power_law_parameters(robot: Robot, controller: Controller, law: ForceLaw | None):
    """(f, n, W) of KB's power law: the given law's, else the controller's and the robot's."""
    return (law.f, law.n, law.W) if law is not None else (controller.f, controller.n, robot.W)


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
    V, f = check_positive_axis("V", V, "m/s"), check_positive_axis("f", f)
    model = region_model(controller, model)
    axes = ("V", "m/s", "f", "", V, f)
    if law is None or isinstance(law, PowerLaw):
        n, W = _power_law_parameters(robot, controller, law)[1:]
        if _array_delay_route(model, robot):
            r = exact_delay_verdicts(V[None, :], *_delay_loop(robot, controller), f[:, None], n, W, alpha=alpha)
            return _region(robot, controller, model, axes, r.NV, r.stable)
        NV = loop_gain_arrays(V[None, :], *_delay_loop(robot, controller), f[:, None], n, W, alpha=alpha)[3]
        return _region(robot, controller, model, axes, NV)
    NV = wall_gain_arrays(law, alpha, f[:, None] / law.scale)[1] * V[None, :]
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
    V, alpha = check_positive_axis("V", V, "m/s"), check_positive_axis("alpha", alpha, "rad")
    model = region_model(controller, model)
    axes = ("V", "m/s", "alpha", "rad", V, alpha)
    if law is None or isinstance(law, PowerLaw):
        f, n, W = _power_law_parameters(robot, controller, law)
        if _array_delay_route(model, robot):
            r = exact_delay_verdicts(V[None, :], *_delay_loop(robot, controller), f, n, W, alpha=alpha[:, None])
            return _region(robot, controller, model, axes, r.NV, r.stable)
        NV = loop_gain_arrays(V[None, :], *_delay_loop(robot, controller), f, n, W, alpha=alpha[:, None])[3]
        return _region(robot, controller, model, axes, NV)
    NV = wall_gain_arrays(law, alpha[:, None])[1] * V[None, :]
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
    L, V = check_positive_axis("L", L, "m"), check_positive_axis("V", V, "m/s")
    model = region_model(controller, model)
    axes = ("L", "m", "V", "m/s", L, V)
    if law is None or isinstance(law, PowerLaw):
        f, n, W = _power_law_parameters(robot, controller, law)
        if _array_delay_route(model, robot):
            r = exact_delay_verdicts(V[:, None], *_delay_loop(robot, controller), f, n, W, L=L[None, :])
            return _region(robot, controller, model, axes, r.NV, r.stable)
        NV = loop_gain_arrays(V[:, None], *_delay_loop(robot, controller), f, n, W, L=L[None, :])[3]
        return _region(robot, controller, model, axes, NV)
    if np.any(L <= robot.W / 2):
        raise ValueError(f"L must exceed W/2 = {robot.W / 2:g} m (the robot must fit)")
    NV = corridor_gain(law, L)[None, :] * V[:, None]
    return _region(robot, controller, model, axes, NV)
