"""The robot loop families and the velocity-aware and fuzzy laws: their laws and their results (docs/velocity_and_fuzzy.md).

`report.stability.build_report` answers every robot family and law; for ``--robot`` and the laws of
`parameters.FAMILY_LAWS` it takes each geometry's result from here (docs/models.md "Robot loop families"):

* ``--law velocity`` (GC2002's velocity attraction with Khatib's repulsion) and ``--law fuzzy``
  (the DFAPF paper's fuzzy-scheduled repulsion) on a steering or kinematic robot: every
  equilibrium's N and heading gain c enter the five steering models (`steering_results`;
  velocity: N = N_static/(1 − q), c = q/(1 − q); fuzzy: the total N and c, N_frozen and the
  robust bracket beside them in a `FuzzySchedule`);
* ``--robot holonomic --law velocity`` (force = acceleration, GC2002 §6): every equilibrium's
  κ and c_h enter the five models of the holonomic loop (`holonomic_results`), and the
  tracking error's ζ and ω_n (GC2002 eq 34–36) are added;
* ``--law velocity-gated`` (GC2002 eq 10–12): no smooth equilibrium, the verdict is
  ``"non-smooth"`` with the Filippov rest band (`non_smooth_results`); the simulated limit
  cycle comes from above this level (`pfm_stability.validation.non_smooth`, which the CLI
  hands to `build_report`).

`FamilyLaw` is such a law with every parameter it takes (`make_family_law`). The results that only
these families have are typed here and give their JSON themselves (``to_dicts``): `HolonomicScene`
(`HolonomicEquilibrium`: every model's `models.holonomic.HolonomicVerdict`), `NonSmoothScene`; the
fuzzy law's `FuzzySchedule` sits beside the steering analyses (`report.stability.StabilityReport`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

from ..checks import check_choice
from ..analysis.critical import CorridorCritical, WallCritical
from ..analysis.criteria import CorridorAnalysis, ModelVerdict, WallAnalysis, WallEquilibrium, check_loop_gain, model_verdicts
from ..laws.fields import KhatibLaw
from ..models import HEADING_GAIN_RANGE, Loop
from ..models.holonomic import HolonomicLoop, holonomic_verdict
from ..laws.registry import (FAMILY_CHOICE_DEFAULTS, FAMILY_DEFAULTS, FAMILY_LAW_CHOICES, FAMILY_LAW_PARAMETERS, FAMILY_LAWS,
                             check_parameters)
from ..parameters import check_parameter
from ..io.serialize import json_number
from ..laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion

__all__ = ["FamilyLaw", "FuzzySchedule", "HolonomicEquilibrium", "HolonomicScene", "NonSmoothScene", "make_family_law", "steering_results",
           "holonomic_results", "non_smooth_results"]

_LIBRARY_VALUES = {"variant": {"paper-eq23": "paper_eq23"}, "symmetrize": {"none": False}}
"""The one place where a user-facing choice (`parameters.FAMILY_LAW_CHOICES`) is spelt as the library spells it:
``--variant paper-eq23`` is `velocity_laws.VelocityGatedRepulsion`'s ``"paper_eq23"``, ``--symmetrize none``
is `fuzzy.load_dfapf`'s ``False``; every other value is passed as it is."""

_VARIANT_TEXT = {
    "gradient": "gradient variant, magnitude eta/D^2 (eq 12, 19)",
    "squared": "squared variant, magnitude eta(1/D - 1/rho0)^2",
    "paper-eq23": "paper-eq23 variant, magnitude eta^3(1/D - 1/rho0)^2 (eq 23 as printed)",
}
"""How the law's description names the velocity-gated repulsion's variant."""


@lru_cache(maxsize=None)
def _dfapf(symmetrize: str):
    """The DFAPF controllers for ``--symmetrize`` (`fuzzy.DfapfControllers`, read once per value: the tables do not change)."""
    from ..laws.fuzzy import load_dfapf

    return load_dfapf(symmetrize=_LIBRARY_VALUES["symmetrize"].get(symmetrize, symmetrize))

_DESCRIPTIONS = {
    "velocity": "Ge & Cui 2002 velocity attraction (eq 1, 7-9) with Khatib's repulsion (GC2000 eq 3-4)",
    "velocity-gated": "Ge & Cui 2002 velocity-gated repulsion (eq 10-12, 19-20): non-smooth",
    "fuzzy": "DFAPF fuzzy-scheduled repulsion (controller 1, {tables})",
}


@dataclass(frozen=True)
class FamilyLaw:
    """A law of `parameters.FAMILY_LAWS` with every parameter it takes (docs/velocity_and_fuzzy.md).

    Attributes
    ----------
    name : str
        ``"velocity"``, ``"velocity-gated"`` or ``"fuzzy"``.
    parameters : dict
        Every key of ``FAMILY_LAW_PARAMETERS[name]`` → value (SI units).
    choices : dict
        Every key of ``FAMILY_LAW_CHOICES[name]`` → value as the user spells it
        (velocity-gated: ``variant``; fuzzy: ``side``, ``symmetrize``); empty for ``velocity``.
    """

    name: str
    parameters: dict
    choices: dict = field(default_factory=dict)

    def choice(self, key: str) -> str:
        """The value of the choice `key` (`parameters.FAMILY_CHOICE_DEFAULTS` when not given).

        Parameters
        ----------
        key : str
            A choice of `parameters.FAMILY_CHOICE_DEFAULTS`.
        """
        return self.choices.get(key, FAMILY_CHOICE_DEFAULTS[key])

    @property
    def side(self) -> str:
        """The wall's side of the fuzzy law (``"left"`` for the laws without one)."""
        return self.choice("side")

    @property
    def attraction(self) -> float:
        """F_a = mα_p ρ_g^(m−1), N: the attraction's position part at the goal distance."""
        p = self.parameters
        return p["attraction_exponent"] * p["alpha_p"] * p["goal_distance"] ** (p["attraction_exponent"] - 1.0)

    def velocity_attraction(self) -> VelocityAttraction:
        """GC2002's attraction (α_v = 0 for the laws without one)."""
        p = self.parameters
        return VelocityAttraction(p["alpha_p"], p.get("alpha_v", 0.0), p["attraction_exponent"], p.get("velocity_exponent", 2.0))

    def repulsion(self) -> KhatibLaw:
        """Khatib's repulsion in units of F_a: ξ = 2α_p makes its attraction (m/2)ξρ_g^(m−1) equal F_a."""
        p = self.parameters
        return KhatibLaw(2.0 * p["alpha_p"], p["eta"], p["rho0"], p["attraction_exponent"], p["goal_distance"])

    def gated(self) -> VelocityGatedRepulsion:
        """GC2002's velocity-gated repulsion in the law's ``variant`` (`velocity_laws.VARIANTS`)."""
        p = self.parameters
        variant = self.choice("variant")
        return VelocityGatedRepulsion(p["eta"], p["rho0"], p["a_max"], variant=_LIBRARY_VALUES["variant"].get(variant, variant))

    def fuzzy(self):
        """The fuzzy-scheduled law (`fuzzy_law.FuzzyScheduledLaw`) with attraction F_a and the DFAPF tables as ``symmetrize`` says (`fuzzy.load_dfapf`)."""
        from ..laws.fuzzy_law import FuzzyScheduledLaw

        p = self.parameters
        controllers = _dfapf(self.choice("symmetrize"))
        return FuzzyScheduledLaw(p["rho0"], self.attraction, p["goal_exponent"], p["goal_distance"], controllers=controllers)

    def described(self) -> dict:
        """``law`` of the report: name, description (naming the law's choices), parameters (JSON-ready)."""
        params = {**self.parameters, "attraction": self.attraction}
        return {"name": self.name, "description": _DESCRIPTIONS[self.name].format(tables=self._tables()) + self._choices_text(),
                "parameters": {k: json_number(v) for k, v in params.items()}}

    def _tables(self) -> str:
        """How the fuzzy law's description names its tables (``symmetrize``)."""
        mirrored = self.choice("symmetrize")
        return "tables as printed" if mirrored == "none" else f"tables made left-right symmetric: {mirrored}-bearing rows mirrored"

    def _choices_text(self) -> str:
        """The description's tail naming the law's choices (nothing for ``velocity``)."""
        if self.name == "velocity-gated":
            return ", " + _VARIANT_TEXT[self.choice("variant")]
        if self.name == "fuzzy":
            return f", wall on the {self.side}"
        return ""


def make_family_law(name: str, choices: dict | None = None, **parameters) -> FamilyLaw:
    """The law `name` of `parameters.FAMILY_LAWS` with `parameters` over `parameters.FAMILY_DEFAULTS`.

    `choices` (`parameters.FAMILY_LAW_CHOICES`, e.g. ``{"side": "right"}``) go over
    `parameters.FAMILY_CHOICE_DEFAULTS`; a choice may also be a keyword (``symmetrize="negative"``).

    Parameters
    ----------
    name : str
        A law of `FAMILY_LAWS`.
    choices : dict, optional
        Choice → value (e.g. ``{"side": "right"}``).
    **parameters
        The law's parameters (over `FAMILY_DEFAULTS`), or choices as keywords.

    Raises
    ------
    ValueError
        An unknown law, a parameter or choice the law does not take, a value out of range,
        or a choice value not allowed (naming the choice and its values).
    """
    check_choice("law", name, FAMILY_LAWS)
    allowed = FAMILY_LAW_CHOICES[name]
    named = {k: v for k, v in parameters.items() if k in FAMILY_CHOICE_DEFAULTS and v is not None}
    picked = {**{k: v for k, v in (choices or {}).items() if v is not None}, **named}
    given = {k: v for k, v in parameters.items() if v is not None and k not in FAMILY_CHOICE_DEFAULTS}
    check_parameters(name, [*picked, *given], law_shown=f"law {name}", laws=FAMILY_LAWS, required=False)  # `refusal`
    for key, value in picked.items():
        check_choice(key, value, allowed[key])
    taken = FAMILY_LAW_PARAMETERS[name]
    values = {key: check_parameter(key, given.get(key, FAMILY_DEFAULTS[key])) for key in taken}
    return FamilyLaw(name, values, {key: picked.get(key, FAMILY_CHOICE_DEFAULTS[key]) for key in allowed})


# ------------------------------------------------------------------ the families' results
@dataclass(frozen=True)
class HolonomicEquilibrium:
    """One holonomic equilibrium: its gains and every model's verdict there.

    Attributes
    ----------
    gains : velocity_laws.HolonomicGains
        x0 (m), κ (1/s²) and c_h (1/s) of the equilibrium.
    models : dict[str, models.holonomic.HolonomicVerdict]
    """

    gains: object
    models: dict


@dataclass(frozen=True)
class HolonomicScene:
    """A wall or corridor for a holonomic robot: every equilibrium, the verdicts at the first (wall) or the middle (corridor).

    Attributes
    ----------
    geometry : str
        ``"wall"`` or ``"corridor"``.
    value : float
        α (deg) or L (m).
    equilibria : tuple of HolonomicEquilibrium
    main : int
        Index of the equilibrium whose verdicts are the top-level ones.
    """

    geometry: str
    value: float
    equilibria: tuple
    main: int

    @property
    def models(self) -> dict:
        """The verdicts at the main equilibrium (model → `HolonomicVerdict`)."""
        return self.equilibria[self.main].models

    def keyed_verdicts(self) -> tuple:
        """((geometry, i, model), verdict) for each wall equilibrium, ((geometry, model), verdict) for the main one."""
        keyed = [((self.geometry, i, name), v) for i, e in enumerate(self.equilibria) for name, v in e.models.items()] if self.geometry == "wall" else []
        return (*keyed, *(((self.geometry, name), v) for name, v in self.models.items()))

    def to_dicts(self, report) -> tuple:
        """(environment entry, top-level verdicts) as the report's JSON holds them, each verdict with its remedy
        (`report.remedies`: (geometry, model), and (geometry, i, model) for each wall equilibrium).

        Parameters
        ----------
        report : StabilityReport
            The report holding this geometry (its remedies).
        """
        geometry, fixes = self.geometry, report.remedies
        first = self.equilibria[self.main]
        key, where = ("alpha_deg", "d0") if geometry == "wall" else ("L", "x0")
        env = {key: self.value, "N": None, "NV": None, "kappa": first.gains.kappa, "c_h": first.gains.c_h}
        if geometry == "wall":
            env["d0"] = json_number(first.gains.x0)
        env["equilibria"] = [
            {where: json_number(e.gains.x0), "N": None, "c": None, "kappa": e.gains.kappa, "c_h": e.gains.c_h,
             **({"NV": None, "models": {name: v.to_dict(fixes.get((geometry, i, name))) for name, v in e.models.items()}}
                if geometry == "wall" else {})}
            for i, e in enumerate(self.equilibria)
        ]
        return env, {name: v.to_dict(fixes.get((geometry, name))) for name, v in first.models.items()}


@dataclass(frozen=True)
class NonSmoothScene:
    """The velocity-gated repulsion's non-smooth verdict at a wall or in a corridor (`velocity_laws`).

    Attributes
    ----------
    geometry : str
        ``"wall"`` or ``"corridor"``.
    value : float
        α (deg) or L (m).
    result : NonSmoothWall or NonSmoothCorridor
    cycle : dict or None
        The simulated cycle of a wall (`validation.non_smooth.simulated_cycle`: mean and minimum distance,
        peak-to-peak, heading amplitude, period, …); None when not simulated.
    """

    geometry: str
    value: float
    result: object
    cycle: dict | None = None

    def keyed_verdicts(self) -> tuple:
        """No model decides a non-smooth loop: ``()``."""
        return ()

    def to_dicts(self, report) -> tuple:
        """(environment entry, None): the verdict, the band (a wall's) or the friction levels (a corridor's), the cycle.

        Parameters
        ----------
        report : StabilityReport
            The report holding this geometry (unused: no remedies).
        """
        key = "alpha_deg" if self.geometry == "wall" else "L"
        env = {key: self.value, "N": None, "NV": None, "verdict": "non-smooth"}
        r = self.result
        if self.geometry == "wall":
            env.update(d0=None, rest_band=[r.rest_band[0], r.rest_band[1]], d_s=r.d_s, friction=r.friction)
        else:
            env.update(rest_band=[-self.value, self.value], offsets=[float(x) for x in r.offsets],
                       friction_left=[float(x) for x in r.friction_left], friction_right=[float(x) for x in r.friction_right])
        env["cycle"] = self.cycle
        return env, None


@dataclass(frozen=True)
class FuzzySchedule:
    """The fuzzy-scheduled law's gains beside the steering verdicts (docs/velocity_and_fuzzy.md).

    Attributes
    ----------
    wall : tuple of fuzzy_law.ScheduledEquilibrium
        Every wall equilibrium's frozen gain N_frozen, η, dη/dd and one-sided heading gains, as `WallAnalysis.equilibria`.
    corridor : tuple of fuzzy_law.ScheduledEquilibrium
        Every corridor equilibrium's N_frozen, as `CorridorAnalysis.equilibria`.
    bracket : fuzzy_law.RobustBracket or None
        N and d0 at a wall for η at both ends of the controller's output range.
    """

    wall: tuple = ()
    corridor: tuple = ()
    bracket: object | None = None



# ------------------------------------------------------------------ steering with a heading gain
def _steering_verdicts(controller, models, robot, e, NV: float, critical_values, geometry: dict, where: str, law: str) -> dict:
    """Every steering model at one (x0, N, c): the loop k(cs + NV)e^(−sT); with c beyond `models.HEADING_GAIN_RANGE` every
    verdict "undecided", its values null, with the reason (docs/velocity_and_fuzzy.md: no model decides that loop)."""
    low, high = HEADING_GAIN_RANGE
    if low <= e.c <= high:
        return model_verdicts(controller, models, Loop.of(robot, controller, c=e.c), e.N, NV, critical_values, lambda _: geometry)
    reason = (f"c = {e.c:.4g}: the heading gain of --law {law} at the {where} is outside the range the loop models take, "
              f"[{low:g}, {high:g}]; no model decides this loop (docs/velocity_and_fuzzy.md)")
    critical = critical_values(**geometry, V_critical=math.nan, T_critical=math.nan, k_critical=math.nan)
    return {m.name: ModelVerdict(m.name, NV, math.nan, None, math.nan, "undecided", critical, None, reason) for m in models}


def _steering_wall(robot, controller, wall, models, equilibria, fixed_V: bool, law: str) -> WallAnalysis:
    """Every steering model at each (d0, N, c): the loop k(cs + NV)e^(−sT); α* is not followed (NaN)."""
    analyses = []
    for e in equilibria:
        where = f"wall equilibrium d0 = {e.x0:g} m (alpha = {wall.alpha_deg:g} deg)"
        NV = check_loop_gain(e.N * robot.V, where)
        verdicts = _steering_verdicts(controller, models, robot, e, NV, WallCritical, {"alpha_critical": math.nan}, where, law)
        analyses.append(WallEquilibrium(e.x0, e.N, e.c, NV, _speed_free(verdicts, fixed_V)))
    if not analyses:
        raise ValueError(f"alpha = {wall.alpha_deg:g} deg: the law has no equilibrium beside the wall (it never balances the pull)")
    first = analyses[0]
    return WallAnalysis(wall.alpha, first.d0, first.N, first.NV, first.models, first.c, tuple(analyses))


def _steering_corridor(robot, controller, corridor, models, equilibria, fixed_V: bool, law: str) -> CorridorAnalysis:
    """Every steering model at the equilibrium nearest the centre line; L* is not followed (NaN)."""
    if not equilibria:
        raise ValueError(f"L = {corridor.L:g} m: the law has no lateral equilibrium in this corridor")
    e = min(equilibria, key=lambda q: abs(q.x0))
    where = f"corridor equilibrium x0 = {e.x0:g} m (L = {corridor.L:g} m)"
    NV = check_loop_gain(e.N * robot.V, where)
    verdicts = _steering_verdicts(controller, models, robot, e, NV, CorridorCritical, {"L_critical": math.nan}, where, law)
    return CorridorAnalysis(corridor.L, e.N, NV, _speed_free(verdicts, fixed_V), e.c, tuple(equilibria))


def _speed_free(verdicts: dict, fixed_V: bool) -> dict:
    """The verdicts; with N and c moving with V (the velocity law) V* = NV*/N does not hold: NaN (null)."""
    if fixed_V:
        return verdicts
    return {name: replace(v, critical=replace(v.critical, V_critical=math.nan)) for name, v in verdicts.items()}


def steering_results(robot, controller, law: FamilyLaw, wall, corridor, models) -> tuple:
    """(wall, corridor, schedule) of the velocity or fuzzy law on a steering robot: every model at each equilibrium's (N, c).

    Parameters
    ----------
    robot, controller : Robot, Controller
        A kinematic robot with τ = 0 already.
    law : FamilyLaw
        ``velocity`` or ``fuzzy``.
    wall : parameters.Wall or None
    corridor : parameters.Corridor or None
    models : tuple of LoopModel
        The steering models, built once (`models.models_for`).

    Returns
    -------
    tuple
        (`WallAnalysis` or None, `CorridorAnalysis` or None, `results.FuzzySchedule` or None: the fuzzy law's).
    """
    if law.name == "velocity":
        att, rep, rho_g = law.velocity_attraction(), law.repulsion(), law.parameters["goal_distance"]
        wall_eq = att.steering_wall_equilibria(rep, wall.alpha, robot.V, rho_g) if wall else None
        corr_eq = att.steering_corridor_equilibria(rep, corridor.L, robot.V, rho_g) if corridor else None
        bracket = None
    else:
        fuzzy = law.fuzzy()
        wall_eq = fuzzy.wall_equilibria(wall.alpha, law.side) if wall else None
        corr_eq = fuzzy.corridor_equilibria(corridor.L) if corridor else None
        bracket = fuzzy.robust_bracket(wall.alpha) if wall else None
    fixed_V = law.name == "fuzzy"
    wall_result = _steering_wall(robot, controller, wall, models, wall_eq, fixed_V, law.name) if wall else None
    corridor_result = _steering_corridor(robot, controller, corridor, models, corr_eq, fixed_V, law.name) if corridor else None
    schedule = None
    if law.name == "fuzzy":
        schedule = FuzzySchedule(tuple(wall_eq or ()), tuple(corridor_result.equilibria) if corridor_result else (), bracket)
    return wall_result, corridor_result, schedule


# ------------------------------------------------------------------ holonomic
def _holonomic_scene(geometry, value, gains, controller, models, main) -> HolonomicScene:
    """Every holonomic model at each equilibrium's (κ, c_h) (`models.holonomic.holonomic_verdict`)."""
    if not gains:
        raise ValueError(f"{'alpha' if geometry == 'wall' else 'L'} = {value:g}: the law has no equilibrium here (it never balances the pull)")
    flat = [g.x0 for g in gains if g.kappa == 0.0]
    if flat:
        raise ValueError(f"{'alpha' if geometry == 'wall' else 'L'} = {value:g}: no lateral stiffness at x0 = {flat[0]:g} m (kappa = 0: "
                         f"the repulsion does not reach there, rho0 too short); raise --rho0")
    equilibria = tuple(
        HolonomicEquilibrium(g, {m.name: holonomic_verdict(m, g.kappa, HolonomicLoop.of(controller, c_h=g.c_h)) for m in models})
        for g in gains
    )
    index = 0 if main == "first" else min(range(len(gains)), key=lambda i: abs(gains[i].x0))
    return HolonomicScene(geometry, value, equilibria, index)


def holonomic_results(robot, controller, law: FamilyLaw, wall, corridor, models, mass: float) -> tuple:
    """(wall, corridor, tracking) of the velocity law on a holonomic robot: κ, c_h and every model at each equilibrium.

    Parameters
    ----------
    robot, controller : Robot, Controller
        V (which enters only through a velocity exponent n ≠ 2), T and the compute delay.
    law : FamilyLaw
        ``velocity``.
    wall : parameters.Wall or None
    corridor : parameters.Corridor or None
    models : tuple of LoopModel
        The models, built once; each decides the holonomic loop (`models.holonomic`).
    mass : float
        The robot's mass, kg (κ = −F_x′/m, c_h = nα_v V^(n−2)/m).

    Returns
    -------
    tuple
        (`HolonomicScene` or None, `HolonomicScene` or None, `tracking.TrackingDynamics` or None: the tracking
        error's ζ and ω_n when m = n = 2).
    """
    att, rep, rho_g = law.velocity_attraction(), law.repulsion(), law.parameters["goal_distance"]
    wall_result = corridor_result = tracking = None
    if wall is not None:
        gains = att.holonomic_wall_gains(rep, wall.alpha, rho_g, mass, robot.V)
        wall_result = _holonomic_scene("wall", wall.alpha_deg, gains, controller, models, "first")
    if corridor is not None:
        gains = att.holonomic_corridor_gains(rep, corridor.L, rho_g, mass, robot.V)
        corridor_result = _holonomic_scene("corridor", corridor.L, gains, controller, models, "middle")
    if att.m == 2.0 and att.n == 2.0:
        from ..models.tracking import tracking_dynamics

        tracking = tracking_dynamics(att.alpha_p, att.alpha_v, mass)
    return wall_result, corridor_result, tracking


# ------------------------------------------------------------------ non-smooth
def non_smooth_results(law: FamilyLaw, wall, corridor, cycle=None) -> tuple:
    """(wall, corridor) of the velocity-gated law: the rest band at a wall, the friction levels in a corridor.

    Parameters
    ----------
    law : FamilyLaw
        ``velocity-gated``.
    wall : parameters.Wall or None
    corridor : parameters.Corridor or None
    cycle : callable, optional
        ``cycle(alpha) -> dict``: the simulated cycle beside the wall (rad in; None: not simulated).

    Returns
    -------
    tuple
        (`NonSmoothScene` or None, `NonSmoothScene` or None).
    """
    gated = law.gated()
    wall_result = corridor_result = None
    if wall is not None:
        wall_result = NonSmoothScene("wall", wall.alpha_deg, gated.non_smooth_wall(law.attraction, wall.alpha), cycle(wall.alpha) if cycle else None)
    if corridor is not None:
        corridor_result = NonSmoothScene("corridor", corridor.L, gated.non_smooth_corridor(corridor.L))
    return wall_result, corridor_result
