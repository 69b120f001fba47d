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
(bisection on a bracket found by geometric expansion, module `solve`). A law
that is not `monotone` (Khatib's, Ge & Cui's goal-aware law, a law built in
code) is analysed at every one of its wall equilibria, and its α*, L* and the
critical values of its own parameters (f*, or η*, ρ0*, ξ*) are found on each
equilibrium by following it (`pfm_stability.analysis.critical`, docs/fields.md).
An equilibrium with N < 0 is unstable in the field itself: every model's
verdict is "unstable", with the reason. At N = 0 (no restoring force) each
model judges its heading loop, the roots other than the neutral lateral one
(docs/models.md, "N = 0"), with the reason.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from ..checks import check_number, check_type
from .critical import CorridorBranches, CorridorCritical, CriticalValues, WallBranches, WallCritical, in_user_f, is_field_law
from ..laws.fields import finite_goal_gain
from ..laws.force_law import Equilibrium, ForceLaw, PowerLaw, corridor_equilibria, corridor_gain, law_in_force, wall_equilibria, wall_gain, _wall_gain
from ..models import Loop, LoopModel, check_loop_gain, judge, models_for
from ..parameters import RANGES, Controller, Corridor, Robot, Wall, check_corridor_fits, check_parameter, plant_not_kb, to_degrees
from ..numerics.solve import bisect_root, expand_bracket

__all__ = [
    "CriticalValues",
    "WallCritical",
    "CorridorCritical",
    "ModelVerdict",
    "WallEquilibrium",
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
    "model_verdicts",
]


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
    reason : str or None
        Why the verdict does not come from the model (N < 0: an unstable
        equilibrium of the field), or at N = 0 that it is the heading loop's
        (`models.neutral_reason`); None otherwise.
    """

    model: str
    NV: float
    NV_critical: float
    omega_critical: float | None
    margin: float
    verdict: str
    critical: CriticalValues
    rightmost_root: complex | None = 0j
    reason: str | None = None

    @property
    def stable(self) -> bool:
        """True only when the verdict is "stable"."""
        return self.verdict == "stable"


@dataclass(frozen=True)
class WallEquilibrium:
    """One wall equilibrium and every model's verdict there.

    Attributes
    ----------
    d0 : float
        Distance to the wall, m.
    N : float
        Position gain, 1/m (< 0: unstable in the field itself).
    c : float
        Heading gain (0 for a static law).
    NV : float
        1/s.
    models : dict[str, ModelVerdict]
    """

    d0: float
    N: float
    c: float
    NV: float
    models: dict


@dataclass(frozen=True)
class WallAnalysis:
    """Travel along a wall: equilibria, gains and every model's verdict.

    The fields d0, N, NV and models are those of the first (nearest)
    equilibrium; `equilibria` lists every one, sorted by d0.

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
    c : float
        Heading gain of the first equilibrium (0 for a static law).
    equilibria : tuple of WallEquilibrium
        Every equilibrium (one for a `monotone` law).
    """

    alpha: float
    d0: float
    N: float
    NV: float
    models: dict
    c: float = 0.0
    equilibria: tuple = ()

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
        Environment gain in the middle, 1/m (N = 2nfWⁿ/L^(n+1) for KB's law;
        −2P′(L)/(1 + 2Q(L)) in general).
    NV : float
        1/s.
    models : dict[str, ModelVerdict]
        The verdicts in the middle.
    c : float
        Heading gain (0 for a static law).
    equilibria : tuple of Equilibrium
        Every lateral equilibrium (x0, N, c), sorted by x0; the middle x0 = 0 is one.
    N_finite_goal : float or None
        N + 1/ρ_g: the gain with a finite goal straight ahead at the law's goal
        distance (docs/fields.md); None for a target at infinity. Not in NV.
    """

    L: float
    N: float
    NV: float
    models: dict
    c: float = 0.0
    equilibria: tuple = ()
    N_finite_goal: float | None = None


def loop_of(robot: Robot, controller: Controller) -> Loop:
    """The (τ, T, k) every model needs (`Loop.of`, after checking the types).

    Parameters
    ----------
    robot : Robot
        The robot (τ, s; k, 1/s).
    controller : Controller
        The controller (T, s).
    """
    check_type("robot", robot, Robot, "a Robot")
    check_type("controller", controller, Controller, "a Controller")
    return Loop.of(robot, controller)


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

    Parameters
    ----------
    alpha : float or sympy.Expr
        Target angle to the wall, rad.
    V : float or sympy.Expr
        Speed, m/s.
    tau_plus_T : float or sympy.Expr
        τ + T, s.
    n : float or sympy.Expr
        Force-law exponent (dimensionless).
    W : float or sympy.Expr
        Robot width, m.
    """
    if _numeric((alpha, V, tau_plus_T, n, W)):
        _check_closed_form_inputs(alpha=alpha, V=V, tau_plus_T=tau_plus_T, n=n, W=W)
    with np.errstate(over="ignore"):
        return float(np.cos(alpha) * (n * V * tau_plus_T / (W * np.tan(alpha))) ** n)


def kb_critical_L(n, W, V, tau_plus_T, f):
    """KB eq (25) with the W* misprint corrected: L* = (2nWⁿV(τ+T)f)^(1/(n+1)), m.

    Plain arithmetic, so it accepts sympy symbols: the tests compare it with the
    derivation exactly. Numbers are checked against their ranges (ValueError).

    Parameters
    ----------
    n : float or sympy.Expr
        Force-law exponent (dimensionless).
    W : float or sympy.Expr
        Robot width, m.
    V : float or sympy.Expr
        Speed, m/s.
    tau_plus_T : float or sympy.Expr
        τ + T, s.
    f : float or sympy.Expr
        Force-law strength (dimensionless).
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

    Parameters
    ----------
    law : ForceLaw
        The lateral force law.
    V : float
        Speed, m/s.
    NV_critical : float
        The model's NV*, 1/s.
    """
    _check_critical_inputs(law, V, NV_critical)
    if math.isinf(NV_critical):
        return 0.0
    if NV_critical <= 0:
        return math.pi / 2
    target = NV_critical / V

    def excess(alpha):  # α in RANGES["alpha"], the law checked above
        return _wall_gain(law, alpha)[1] - target

    lo, hi = RANGES["alpha"].low, RANGES["alpha"].high
    if excess(lo) <= 0:
        return 0.0
    if excess(hi) >= 0:
        return math.pi / 2
    return bisect_root(excess, lo, hi, rtol=1e-14)


def critical_f_wall(law: ForceLaw, alpha: float, V: float, NV_critical: float) -> float:
    """f*: the force-law strength above which the wall is stable (KB eq 24).

    Parameters
    ----------
    law : ForceLaw
        The lateral force law (its strength is scaled).
    alpha : float
        Target angle to the wall, rad.
    V : float
        Speed, m/s.
    NV_critical : float
        The model's NV*, 1/s.
    """
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
    """L*, m: corridor half-width above which the middle is stable (KB eq 25).

    Parameters
    ----------
    law : ForceLaw
        The lateral force law.
    V : float
        Speed, m/s.
    NV_critical : float
        The model's NV*, 1/s.
    """
    _check_critical_inputs(law, V, NV_critical)
    if math.isinf(NV_critical):
        return 0.0
    if NV_critical <= 0:
        return math.inf
    if isinstance(law, PowerLaw):
        return kb_critical_L(law.n, law.W, V, 1.0 / NV_critical, law.f)
    return _solve_decreasing(lambda L: _log_ratio(corridor_gain(law, L), V, NV_critical), 1.0)


def critical_f_corridor(law: ForceLaw, L: float, V: float, NV_critical: float) -> float:
    """f*: force-law strength below which the corridor middle is stable (N ∝ f).

    Parameters
    ----------
    law : ForceLaw
        The lateral force law (its strength is scaled).
    L : float
        Corridor half-width, m.
    V : float
        Speed, m/s.
    NV_critical : float
        The model's NV*, 1/s.
    """
    _check_critical_inputs(law, V, NV_critical)
    gain = corridor_gain(law, L) * V
    if math.isinf(NV_critical) or gain == 0:
        return math.inf
    return law.scale * NV_critical / gain


# ------------------------------------------------------------------ analyses
def model_verdicts(controller: Controller, models, loop: Loop, N: float, NV: float, critical_values, geometric) -> dict:
    """Model name → `ModelVerdict` for every model of the analysis.

    `geometric(NV*)` gives the geometry's own critical values (α* and f*, or
    L* and f*); V* = NV*/N, T* and k* are the same for every geometry.

    Parameters
    ----------
    controller : Controller
        Hold and compute delay of the default ``sampled`` model.
    models : sequence of str or LoopModel, or None
        The models (`models.models_for`; None: all five).
    loop : Loop
        τ (s), T (s), k (1/s), c.
    N : float
        Environment gain of the equilibrium, 1/m.
    NV : float
        Operating loop gain, 1/s.
    critical_values : type
        `WallCritical` or `CorridorCritical`, built with the geometry's values and V*, T*, k*.
    geometric : callable
        ``geometric(NV_critical) -> dict``: the geometry's own critical values.
    """
    out = {}
    for model in models_for(controller, models):
        boundary = model.boundary(loop)
        out[model.name] = _verdict(model, loop, NV, boundary, critical_values, N, **geometric(boundary.NV_critical))
    return out


def _negative_gain_root(model: LoopModel, NV: float, loop: Loop):
    """The dominant root at NV < 0, or None where the model does not take a negative gain."""
    try:
        return model.rightmost_root(NV, loop)
    except ValueError:
        return None


def _plant_given(loop: Loop) -> bool:
    """True for a robot with a dead time or a plant gain (not KB's g = 1, D = 0): its verdicts carry D*."""
    return bool(plant_not_kb(loop))


def _verdict(model: LoopModel, loop: Loop, NV: float, boundary, critical_values, N: float, **geometry) -> ModelVerdict:
    """The verdict; `critical_values` (WallCritical or CorridorCritical) built from `geometry` plus V*, T*, k*.

    Verdict, margin, V* and reason follow the one verdict rule (`models.verdicts.judge`): N < 0 diverges
    in every model (no T or k helps: T* = k* = 0); N = 0 is judged by the model like any other point,
    its heading loop (docs/models.md "N = 0").
    """
    if N < 0:
        judgement = judge(NV, N, boundary, False)
        critical = critical_values(**geometry, V_critical=judgement.V_critical, T_critical=0.0, k_critical=0.0,
                                   dead_time_critical=0.0 if _plant_given(loop) else None)
        return ModelVerdict(model.name, NV, boundary.NV_critical, boundary.omega_critical, judgement.margin, judgement.verdict, critical,
                            _negative_gain_root(model, NV, loop), judgement.reason)
    judgement = judge(NV, N, boundary, model.is_stable(NV, loop))
    critical = critical_values(
        **geometry,
        V_critical=judgement.V_critical,
        T_critical=model.critical_delay(NV, loop),
        k_critical=model.critical_gain_k(NV, loop),
        tau_plus_T_critical=(1.0 / NV if NV > 0 else math.inf) if model.name == "kb_first_order" else None,
        dead_time_critical=model.critical_dead_time(NV, loop) if _plant_given(loop) else None,
    )
    return ModelVerdict(
        model=model.name,
        NV=NV,
        NV_critical=boundary.NV_critical,
        omega_critical=boundary.omega_critical,
        margin=judgement.margin,
        verdict=judgement.verdict,
        critical=critical,
        rightmost_root=model.rightmost_root(NV, loop),
        reason=judgement.reason,
    )


def analyze_wall(robot: Robot, controller: Controller, wall: Wall, models=None, law: ForceLaw | None = None) -> WallAnalysis:
    """Stability along a wall for each model (KB §5.3, eq 20–24), at every equilibrium.

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
        Lateral law; KB's power law f(W/d)^n by default. A law that is not
        `monotone` may have several equilibria (`force_law.wall_equilibria`).

    Returns
    -------
    WallAnalysis
        The first equilibrium's verdicts, and `equilibria` (every one).
        Critical values per model (`WallCritical`): ``alpha_critical`` (rad),
        ``alpha_critical_deg``, ``f_critical`` (or ``eta_critical``,
        ``rho0_critical``, ``xi_critical`` for Khatib's and the goal-aware
        law), ``V_critical`` (m/s), ``T_critical`` (s), ``k_critical`` (1/s),
        and ``tau_plus_T_critical`` (s) for ``kb_first_order``.
        A model that is unstable at every NV (NV* = 0) gives V* = 0, α* = 90°
        and f* = inf: no speed, angle or force ratio helps; ``T_critical`` and
        ``k_critical`` say whether a shorter period or a lower gain does. At an
        equilibrium with N < 0 every verdict is "unstable" (``reason``).

    Raises
    ------
    ValueError
        No equilibrium (a law that never balances the target's pull), or N·V
        beyond what the models represent.
    """
    law = law_in_force(robot, controller, law)
    check_type("wall", wall, Wall, "a Wall")
    loop = loop_of(robot, controller)
    if law.monotone:
        equilibria = (Equilibrium(*wall_gain(law, wall.alpha)),)
    else:
        equilibria = wall_equilibria(law, wall.alpha) or (Equilibrium(*wall_gain(law, wall.alpha)),)  # none: wall_gain says why
    analyses = tuple(_wall_equilibrium(robot, controller, wall, models, loop, law, e) for e in equilibria)
    first = analyses[0]
    return WallAnalysis(wall.alpha, first.d0, first.N, first.NV, first.models, first.c, analyses)


def _wall_equilibrium(robot: Robot, controller: Controller, wall: Wall, models, loop: Loop, law: ForceLaw, e: Equilibrium) -> WallEquilibrium:
    """Every model's verdict at one wall equilibrium."""
    NV = check_loop_gain(e.N * robot.V, f"wall equilibrium d0 = {e.x0:g} m (alpha = {wall.alpha_deg:g} deg)")
    if law.monotone:

        def geometric(NV_critical):
            return {
                "alpha_critical": critical_alpha(law, robot.V, NV_critical),
                "f_critical": in_user_f(law, critical_f_wall(law, wall.alpha, robot.V, NV_critical)),
            }

    else:
        geometric = WallBranches(law, wall.alpha, e, robot.V).critical
    return WallEquilibrium(e.x0, e.N, e.c, NV, model_verdicts(controller, models, loop, e.N, NV, WallCritical, geometric))


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
        ``V_critical`` (m/s), ``f_critical`` (or ``eta_critical``,
        ``rho0_critical``, ``xi_critical``), ``T_critical`` (s), ``k_critical`` (1/s),
        and ``tau_plus_T_critical`` (s) for ``kb_first_order``. NV* = 0 gives
        V* = 0, L* = inf and f* = 0 ("unstable at any speed"). `equilibria`
        lists every lateral equilibrium (`force_law.corridor_equilibria`) and
        `N_finite_goal` the gain with a finite goal straight ahead.
    """
    law = law_in_force(robot, controller, law)
    check_type("corridor", corridor, Corridor, "a Corridor")
    check_corridor_fits(corridor, robot)
    loop = loop_of(robot, controller)
    N = corridor_gain(law, corridor.L)
    NV = check_loop_gain(N * robot.V, f"corridor middle (L = {corridor.L:g} m)")
    branches = None if law.monotone else CorridorBranches(law, corridor.L, robot.W, N, robot.V)

    def geometric(NV_critical):
        L_critical, side = (critical_L(law, robot.V, NV_critical), "above") if branches is None else branches.critical_L(NV_critical)
        if L_critical <= robot.W / 2:  # no corridor the robot fits in is on the other side: stable at every L (docs/models.md)
            L_critical, side = 0.0, "above"
        if branches is not None and is_field_law(law):
            own = branches.law_parameters(NV_critical)
            return {"L_critical": L_critical, **own, "sides": (("L_critical", side), *own["sides"])}
        return {"L_critical": L_critical, "f_critical": in_user_f(law, critical_f_corridor(law, corridor.L, robot.V, NV_critical)),
                "sides": (("L_critical", side),)}

    verdicts = model_verdicts(controller, models, loop, N, NV, CorridorCritical, geometric)
    equilibria = corridor_equilibria(law, corridor.L, robot.W)
    return CorridorAnalysis(corridor.L, N, NV, verdicts, 0.0, equilibria, finite_goal_gain(law, N))
