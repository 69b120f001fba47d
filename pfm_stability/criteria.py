"""Wall and corridor stability criteria for every loop model.

Koren & Borenstein 1991 (KB) state stability as NV(τ + T) < 1 (eq 20) and turn
it into conditions on the environment: eq (21)/(24) for a wall, eq (25) for a
corridor. Every model of `pfm_stability.models` gives its own critical NV*, and
since N depends on the force law, α, f and L but not on V, the same algebra
gives each model's critical values with 1/NV* in place of KB's (τ + T):

* wall (power law): N = (n/W) f^(−1/n) cos^((n+1)/n) α / sin α, so
  f* = cos α [nV/(W·NV*·tan α)]^n (eq 24 generalized), V* = NV*/N, and α*
  solves N(α)V = NV*;
* corridor (power law): N = 2nfWⁿ/L^(n+1), so
  L* = (2nWⁿVf/NV*)^(1/(n+1)) (eq 25 generalized), f* = L^(n+1)NV*/(2nWⁿV).

For any other force law the same conditions are solved numerically
(bisection on a bracket found by geometric expansion, module `solve`).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np

from .checks import check_number, check_type
from .force_law import ForceLaw, PowerLaw, corridor_gain, law_in_force, wall_gain
from .models import Loop, LoopModel, gain_margin, models_for, verdict_label
from .parameters import RANGES, Controller, Corridor, Robot, Wall, check_corridor_fits, check_parameter, to_degrees
from .solve import bisect_root, expand_bracket

__all__ = [
    "CriticalValues",
    "WallCritical",
    "CorridorCritical",
    "ModelVerdict",
    "WallAnalysis",
    "CorridorAnalysis",
    "analyze_wall",
    "analyze_corridor",
    "critical_alpha",
    "critical_f_wall",
    "critical_f_corridor",
    "critical_L",
    "kb_critical_f_wall",
    "kb_critical_L",
    "loop_of",
]


class CriticalValues(Mapping):
    """Critical values of one model in one geometry: named fields, read-only mapping too.

    Subclasses are frozen dataclasses. As a `Mapping` they hold their fields
    in declaration order, leaving out those that are None (``critical["L_critical"]``,
    ``.items()``, ``in``, ``len``, iteration): the keys and the order of the
    report's JSON. Equality is the mapping's (so a plain dict of the same
    items compares equal).
    """

    __slots__ = ()

    def _keys(self) -> tuple:
        return tuple(f.name for f in fields(self) if getattr(self, f.name) is not None)

    def __getitem__(self, key: str):
        if isinstance(key, str) and key in self._keys():
            return getattr(self, key)
        raise KeyError(key)

    def __iter__(self):
        return iter(self._keys())

    def __len__(self) -> int:
        return len(self._keys())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in self.items())})"


@dataclass(frozen=True, eq=False, repr=False)
class WallCritical(CriticalValues):
    """One model's critical values along a wall, each with the other inputs fixed (docs/models.md).

    Attributes
    ----------
    alpha_critical : float
        α*, rad: stable for α > α* (0 when NV* = inf; π/2 when NV* = 0).
    alpha_critical_deg : float
        α* in degrees (set from `alpha_critical`).
    f_critical : float
        f*: stable for f > f* (KB eq 24 generalized; ``inf`` when NV* = 0).
    V_critical : float
        V* = NV*/N, m/s: every slower speed is stable.
    T_critical : float
        T*, s: the smallest sampling period / delay at which the operating
        point loses stability (0: already at T → 0; ``inf``: stable up to 100 s).
    k_critical : float
        k*, 1/s: the smallest steering gain at which it loses stability.
    tau_plus_T_critical : float or None
        (τ + T)* = 1/NV, s: KB eq (20) solved for the loop's time constants
        (``kb_first_order`` only; None, and no key, otherwise).
    """

    alpha_critical: float
    alpha_critical_deg: float = field(init=False)
    f_critical: float
    V_critical: float
    T_critical: float
    k_critical: float
    tau_plus_T_critical: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "alpha_critical_deg", to_degrees(self.alpha_critical))


@dataclass(frozen=True, eq=False, repr=False)
class CorridorCritical(CriticalValues):
    """One model's critical values in the middle of a corridor, each with the other inputs fixed (docs/models.md).

    Attributes
    ----------
    L_critical : float
        L*, m: stable for L > L* (KB eq 25 generalized; ``inf`` when NV* = 0).
    V_critical : float
        V* = NV*/N, m/s: every slower speed is stable.
    f_critical : float
        f*: stable for f < f* (N ∝ f; 0 when NV* = 0).
    T_critical : float
        T*, s (see `WallCritical`).
    k_critical : float
        k*, 1/s (see `WallCritical`).
    tau_plus_T_critical : float or None
        (τ + T)* = 1/NV, s (``kb_first_order`` only; None, and no key, otherwise).
    """

    L_critical: float
    V_critical: float
    f_critical: float
    T_critical: float
    k_critical: float
    tau_plus_T_critical: float | None = None


@dataclass(frozen=True)
class ModelVerdict:
    """One model's answer for one scenario.

    Attributes
    ----------
    model : str
        Model name (`parameters.MODEL_NAMES`, docs/models.md).
    NV : float
        Operating NV, 1/s.
    NV_critical : float
        NV*, 1/s (``inf``: stable for every NV).
    omega_critical : float or None
        Oscillation frequency at the boundary, rad/s.
    margin : float
        NV*/NV − 1: > 0 stable, < 0 unstable (relative gain margin).
    verdict : str
        "stable", "unstable" or "undecided" (|margin| <= 1e-9).
    critical : WallCritical or CorridorCritical
        Critical value of each parameter with the others fixed (SI units;
        angles in rad, plus ``alpha_critical_deg``); also a read-only mapping
        by key (``critical["L_critical"]``).
    rightmost_root : complex or None
        Dominant root σ + jω (1/s, rad/s) at the operating point (None where
        the model cannot resolve it; the verdict does not depend on it).
    """

    model: str
    NV: float
    NV_critical: float
    omega_critical: float | None
    margin: float
    verdict: str
    critical: CriticalValues
    rightmost_root: complex | None = 0j

    @property
    def stable(self) -> bool:
        """True only when the verdict is "stable"."""
        return self.verdict == "stable"


@dataclass(frozen=True)
class WallAnalysis:
    """Travel along a wall: equilibrium, gain and every model's verdict.

    Attributes
    ----------
    alpha : float
        Target angle, rad.
    d0 : float
        Equilibrium distance, m (KB eq 23).
    N : float
        Environment gain, 1/m (KB eq 11).
    NV : float
        1/s.
    models : dict[str, ModelVerdict]
    """

    alpha: float
    d0: float
    N: float
    NV: float
    models: dict

    @property
    def alpha_deg(self) -> float:
        """α in degrees (`parameters.to_degrees`), for output."""
        return to_degrees(self.alpha)


@dataclass(frozen=True)
class CorridorAnalysis:
    """Travel down a corridor: gain and every model's verdict.

    Attributes
    ----------
    L : float
        Half-width, m.
    N : float
        Environment gain, 1/m (N = 2nfWⁿ/L^(n+1) for KB's law).
    NV : float
        1/s.
    models : dict[str, ModelVerdict]
    """

    L: float
    N: float
    NV: float
    models: dict


def loop_of(robot: Robot, controller: Controller) -> Loop:
    """The (τ, T, k) every model needs."""
    check_type("robot", robot, Robot, "a Robot")
    check_type("controller", controller, Controller, "a Controller")
    return Loop(robot.tau, controller.T, robot.k)


NV_MAX = 1e12
"""Largest loop gain NV (1/s) the loop models represent; a geometry beyond it is refused."""


def _check_gain(NV: float, where: str) -> float:
    """NV after checking it is finite and <= NV_MAX; otherwise a message that names the geometry."""
    if not (math.isfinite(NV) and NV <= NV_MAX):
        raise ValueError(
            f"N*V = {NV:g} 1/s at the {where} exceeds what the loop models represent (<= {NV_MAX:g} 1/s); "
            f"choose a less extreme force law (f, n), angle or width"
        )
    return NV


# --------------------------------------------------------------- root finding
def _solve_decreasing(func, x0: float) -> float:
    """Root in (0, inf) of a decreasing function, bracketed geometrically from x0.

    The search goes up when func(x0) > 0 and down otherwise; if no sign change
    is found within a factor 2^±200 the answer is that end (``inf`` or 0):
    no finite value of the parameter reaches the boundary.
    """
    value = func(x0)
    if value == 0:
        return x0
    upward = value > 0
    bracket = expand_bracket(func, x0, upward=upward)
    if bracket is None:
        return math.inf if upward else 0.0
    return bisect_root(func, *bracket)


def _log_ratio(N: float, V: float, NV_critical: float) -> float:
    """log(NV/NV*): > 0 unstable; −inf when N = 0 (no equilibrium: no loop gain)."""
    return math.log(N * V / NV_critical) if N > 0 else -math.inf


# ------------------------------------------------------------- closed forms
def _numeric(values) -> bool:
    """True unless some value is symbolic (a sympy expression): then the closed form is plain arithmetic."""
    return not any(type(v).__module__.startswith("sympy") for v in values)


def _check_closed_form_inputs(**values) -> None:
    """The closed forms' inputs in their ranges (τ + T may be 0 … 200 s)."""
    for name, value in values.items():
        if name == "tau_plus_T":
            check_number("tau_plus_T", value, 0.0, 2 * RANGES["T"].high, high_open=False, unit="s")
        else:
            check_parameter(name, value)


def kb_critical_f_wall(alpha, V, tau_plus_T, n, W):
    """KB eq (24): f* = cos α [nV(τ+T)/(W tan α)]^n (α in rad, V in m/s, τ+T in s, W in m).

    ``inf`` when the value overflows (α → 0). Numbers are checked against their
    ranges (ValueError); sympy symbols pass through (the tests compare this with
    the derivation exactly).
    """
    if _numeric((alpha, V, tau_plus_T, n, W)):
        _check_closed_form_inputs(alpha=alpha, V=V, tau_plus_T=tau_plus_T, n=n, W=W)
    with np.errstate(over="ignore"):
        return float(np.cos(alpha) * (n * V * tau_plus_T / (W * np.tan(alpha))) ** n)


def kb_critical_L(n, W, V, tau_plus_T, f):
    """KB eq (25) with the W* misprint corrected: L* = (2nWⁿV(τ+T)f)^(1/(n+1)), m.

    Plain arithmetic, so it accepts sympy symbols: the tests compare it with the
    derivation exactly. Numbers are checked against their ranges (ValueError).
    """
    if _numeric((n, W, V, tau_plus_T, f)):
        _check_closed_form_inputs(n=n, W=W, V=V, tau_plus_T=tau_plus_T, f=f)
        return float((2 * n * W**n * V * tau_plus_T * f) ** (1 / (n + 1)))
    return (2 * n * W**n * V * tau_plus_T * f) ** (1 / (n + 1))


def _check_critical_inputs(law, V, NV_critical) -> None:
    """The law, V and NV* of the critical-value solvers (NV* may be 0 or inf)."""
    check_type("law", law, ForceLaw, "a ForceLaw (e.g. PowerLaw or GridWallLaw)")
    check_parameter("V", V)
    if isinstance(NV_critical, bool) or not isinstance(NV_critical, numbers.Real) or not NV_critical >= 0:
        raise ValueError(f"NV_critical must be a number in [0, inf] 1/s; got {NV_critical!r}")


def critical_alpha(law: ForceLaw, V: float, NV_critical: float) -> float:
    """α*, rad: N(α)·V = NV* (stable for α > α* when N decreases with α).

    0 when NV* is infinite; π/2 when NV* = 0.
    """
    _check_critical_inputs(law, V, NV_critical)
    if math.isinf(NV_critical):
        return 0.0
    if NV_critical <= 0:
        return math.pi / 2
    target = NV_critical / V

    def excess(alpha):
        return wall_gain(law, alpha)[1] - target

    lo, hi = RANGES["alpha"].low, RANGES["alpha"].high
    if excess(lo) <= 0:
        return 0.0
    if excess(hi) >= 0:
        return math.pi / 2
    return bisect_root(excess, lo, hi, rtol=1e-14)


def critical_f_wall(law: ForceLaw, alpha: float, V: float, NV_critical: float) -> float:
    """f*: the force-law strength above which the wall is stable (KB eq 24)."""
    _check_critical_inputs(law, V, NV_critical)
    check_parameter("alpha", alpha)
    if math.isinf(NV_critical):
        return 0.0
    if NV_critical <= 0:
        return math.inf
    if isinstance(law, PowerLaw):
        return kb_critical_f_wall(alpha, V, 1.0 / NV_critical, law.n, law.W)
    # N falls as the law gets stronger (the equilibrium moves out to flatter force)
    return _solve_decreasing(lambda c: _log_ratio(wall_gain(law.with_scale(c), alpha)[1], V, NV_critical), law.scale)


def critical_L(law: ForceLaw, V: float, NV_critical: float) -> float:
    """L*, m: corridor half-width above which the middle is stable (KB eq 25)."""
    _check_critical_inputs(law, V, NV_critical)
    if math.isinf(NV_critical):
        return 0.0
    if NV_critical <= 0:
        return math.inf
    if isinstance(law, PowerLaw):
        return kb_critical_L(law.n, law.W, V, 1.0 / NV_critical, law.f)
    return _solve_decreasing(lambda L: _log_ratio(corridor_gain(law, L), V, NV_critical), 1.0)


def critical_f_corridor(law: ForceLaw, L: float, V: float, NV_critical: float) -> float:
    """f*: force-law strength below which the corridor middle is stable (N ∝ f)."""
    _check_critical_inputs(law, V, NV_critical)
    gain = corridor_gain(law, L) * V
    if math.isinf(NV_critical) or gain == 0:
        return math.inf
    return law.scale * NV_critical / gain


# ------------------------------------------------------------------ analyses
def _verdicts(controller: Controller, models, loop: Loop, N: float, NV: float, critical_values, geometric) -> dict:
    """Model name → `ModelVerdict` for every model of the analysis.

    `geometric(NV*)` gives the geometry's own critical values (α* and f*, or
    L* and f*); V* = NV*/N, T* and k* are the same for every geometry.
    """
    out = {}
    for model in models_for(controller, models):
        boundary = model.boundary(loop)
        V_critical = boundary.NV_critical / N if N > 0 else math.inf
        out[model.name] = _verdict(model, loop, NV, boundary, critical_values, V_critical=V_critical, **geometric(boundary.NV_critical))
    return out


def _verdict(model: LoopModel, loop: Loop, NV: float, boundary, critical_values, **geometry) -> ModelVerdict:
    """The verdict; `critical_values` (WallCritical or CorridorCritical) built from `geometry` plus T*, k*."""
    if NV == 0:  # no equilibrium force gradient: nothing to oscillate
        critical = critical_values(**geometry, T_critical=math.inf, k_critical=math.inf)
        return ModelVerdict(model.name, NV, boundary.NV_critical, boundary.omega_critical, math.inf, "stable", critical, 0j)
    stable = model.is_stable(NV, loop)
    critical = critical_values(
        **geometry,
        T_critical=model.critical_delay(NV, loop),
        k_critical=model.critical_gain_k(NV, loop),
        tau_plus_T_critical=1.0 / NV if model.name == "kb_first_order" else None,
    )
    return ModelVerdict(
        model=model.name,
        NV=NV,
        NV_critical=boundary.NV_critical,
        omega_critical=boundary.omega_critical,
        margin=gain_margin(NV, boundary, stable),
        verdict=verdict_label(NV, boundary, stable),
        critical=critical,
        rightmost_root=model.rightmost_root(NV, loop),
    )


def analyze_wall(robot: Robot, controller: Controller, wall: Wall, models=None, law: ForceLaw | None = None) -> WallAnalysis:
    """Stability along a wall for each model (KB §5.3, eq 20–24).

    Parameters
    ----------
    robot, controller : Robot, Controller
    wall : Wall
        Target angle α.
    models : iterable of LoopModel or str, optional
        Default: every model, ``sampled`` with the controller's hold and
        compute delay (the controller is the one source of truth: a
        ``Sampled`` model that contradicts it raises ValueError).
    law : ForceLaw, optional
        Lateral repulsion law; KB's power law f(W/d)^n by default.

    Returns
    -------
    WallAnalysis
        Critical values per model (`WallCritical`): ``alpha_critical`` (rad),
        ``alpha_critical_deg``, ``f_critical``, ``V_critical`` (m/s), ``T_critical`` (s),
        ``k_critical`` (1/s), and ``tau_plus_T_critical`` (s) for ``kb_first_order``.
        A model that is unstable at every NV (NV* = 0) gives V* = 0, α* = 90°
        and f* = inf: no speed, angle or force ratio helps; ``T_critical`` and
        ``k_critical`` say whether a shorter period or a lower gain does.
    """
    law = law_in_force(robot, controller, law)
    check_type("wall", wall, Wall, "a Wall")
    loop = loop_of(robot, controller)
    d0, N = wall_gain(law, wall.alpha)
    NV = _check_gain(N * robot.V, f"wall equilibrium d0 = {d0:g} m (alpha = {wall.alpha_deg:g} deg)")

    def geometric(NV_critical):
        return {
            "alpha_critical": critical_alpha(law, robot.V, NV_critical),
            "f_critical": critical_f_wall(law, wall.alpha, robot.V, NV_critical),
        }

    return WallAnalysis(wall.alpha, d0, N, NV, _verdicts(controller, models, loop, N, NV, WallCritical, geometric))


def analyze_corridor(robot: Robot, controller: Controller, corridor: Corridor, models=None, law: ForceLaw | None = None) -> CorridorAnalysis:
    """Stability in the middle of a corridor for each model (KB §5.4, eq 25).

    Parameters
    ----------
    robot, controller : Robot, Controller
    corridor : Corridor
        Half-width L (must exceed W/2).
    models : iterable of LoopModel or str, optional
        Default: every model, ``sampled`` with the controller's structure
        (see `analyze_wall`).
    law : ForceLaw, optional
        KB's power law by default.

    Returns
    -------
    CorridorAnalysis
        Critical values per model (`CorridorCritical`): ``L_critical`` (m),
        ``V_critical`` (m/s), ``f_critical``, ``T_critical`` (s), ``k_critical`` (1/s),
        and ``tau_plus_T_critical`` (s) for ``kb_first_order``. NV* = 0 gives
        V* = 0, L* = inf and f* = 0 ("unstable at any speed").
    """
    law = law_in_force(robot, controller, law)
    check_type("corridor", corridor, Corridor, "a Corridor")
    check_corridor_fits(corridor, robot)
    loop = loop_of(robot, controller)
    N = corridor_gain(law, corridor.L)
    NV = _check_gain(N * robot.V, f"corridor middle (L = {corridor.L:g} m)")

    def geometric(NV_critical):
        return {
            "L_critical": critical_L(law, robot.V, NV_critical),
            "f_critical": critical_f_corridor(law, corridor.L, robot.V, NV_critical),
        }

    return CorridorAnalysis(corridor.L, N, NV, _verdicts(controller, models, loop, N, NV, CorridorCritical, geometric))
