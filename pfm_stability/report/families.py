"""The report for the robot loop families and the velocity-aware and fuzzy laws.

`pfm_stability.report.stability.build_report` answers KB's steering robot with a static
lateral law. `build_family_report` answers the rest of ``report --robot`` and
``report --law`` (docs/velocity_and_fuzzy.md, docs/models.md "Robot loop families"):

* ``--robot kinematic`` (Ge & Cui 2002 §7: ω = K_s(θ_f − θ), no motor lag): KB's loop
  with τ = 0 and k = K_s, any law;
* ``--law velocity`` (GC2002's velocity attraction with Khatib's repulsion): on a
  steering robot every equilibrium's N and heading gain c (N = N_static/(1 − q),
  c = q/(1 − q)) enter the five steering models; on a holonomic robot (force =
  acceleration, GC2002 §6) every equilibrium's κ and c_h enter the five holonomic
  models, and the tracking error's ζ and ω_n (GC2002 eq 34–36) are added;
* ``--law fuzzy`` (the DFAPF paper's fuzzy-scheduled repulsion): the total N and c
  enter the steering models; N_frozen and the robust bracket are reported beside them;
* ``--law velocity-gated`` (GC2002 eq 10–12): no smooth equilibrium, the verdict is
  ``"non-smooth"`` with the Filippov rest band; the simulated limit cycle is added
  above this level (`pfm_stability.validation.non_smooth`, which the CLI calls).

The result is a `report.StabilityReport`, so the JSON (`to_dict`) and the text keep
the static report's shape wherever it applies; what is new goes in its ``extras``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

from ..checks import check_choice
from ..analysis.critical import CorridorCritical, WallCritical
from ..analysis.criteria import CorridorAnalysis, ModelVerdict, WallAnalysis, WallEquilibrium, check_loop_gain, model_verdicts
from ..laws.fields import KhatibLaw
from ..laws.fuzzy import DfapfControllers, load_dfapf
from ..laws.fuzzy_law import FuzzyScheduledLaw
from ..models import HEADING_GAIN_RANGE, Loop, interval_margin, interval_verdict, models_for
from ..models import STEERING, make_models
from ..models.holonomic import HOLONOMIC, HolonomicLoop
from ..parameters import FAMILY_CHOICE_DEFAULTS, FAMILY_DEFAULTS, FAMILY_LAW_CHOICES, FAMILY_LAW_PARAMETERS, FAMILY_LAWS, HOLONOMIC_LAWS, MODEL_NAMES, RANGES, ROBOT_FAMILIES, Controller, Corridor, Robot, Wall, check_parameter
from .stability import UNITS, StabilityReport, build_report, kb_errors, remedies, remedies_by_key
from ..io.serialize import json_number
from ..models.tracking import tracking_dynamics
from ..laws.velocity_laws import HolonomicGains, VelocityAttraction, VelocityGatedRepulsion

__all__ = ["FamilyLaw", "HolonomicVerdict", "make_family_law", "build_family_report", "KINEMATIC_TAU_SOURCE"]

KINEMATIC_TAU_SOURCE = "not used (kinematic robot: no motor lag, tau = 0; --k is K_s)"
"""The source the report gives τ for ``--robot kinematic``."""

HOLONOMIC_UNUSED = "not used (holonomic robot)"
"""The source the report gives τ, k (and f, n, W) for ``--robot holonomic``."""

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
def _dfapf(symmetrize: str) -> DfapfControllers:
    """The DFAPF controllers for ``--symmetrize`` (read once per value: the tables do not change)."""
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
        """The value of the choice `key` (`parameters.FAMILY_CHOICE_DEFAULTS` when not given)."""
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

    def fuzzy(self) -> FuzzyScheduledLaw:
        """The fuzzy-scheduled law with attraction F_a and the DFAPF tables as ``symmetrize`` says (`fuzzy.load_dfapf`)."""
        p = self.parameters
        controllers = _dfapf(self.choice("symmetrize"))
        return FuzzyScheduledLaw(p["rho0"], self.attraction, p["goal_exponent"], p["goal_distance"], controllers=controllers)

    def described(self) -> dict:
        """``law`` of the report: name, description (naming the law's choices), parameters."""
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
    for key, value in picked.items():
        if key not in allowed:
            takers = [law for law in FAMILY_LAWS if key in FAMILY_LAW_CHOICES[law]]
            if not takers:
                raise ValueError(f"{key} is not a choice of law {name} (it takes {', '.join(allowed) or 'none'})")
            raise ValueError(f"{key} applies to law {' or '.join(takers)}, not to law {name}")
        check_choice(key, value, allowed[key])
    taken = FAMILY_LAW_PARAMETERS[name]
    given = {k: v for k, v in parameters.items() if v is not None and k not in FAMILY_CHOICE_DEFAULTS}
    for key in given:
        if key not in taken:
            raise ValueError(f"{key} is not a parameter of law {name} (it takes {', '.join(taken)})")
    values = {key: check_parameter(key, given.get(key, FAMILY_DEFAULTS[key])) for key in taken}
    return FamilyLaw(name, values, {key: picked.get(key, FAMILY_CHOICE_DEFAULTS[key]) for key in allowed})


# ------------------------------------------------------------------ holonomic verdicts
@dataclass(frozen=True)
class HolonomicVerdict:
    """One holonomic model's answer at one equilibrium: s² + (c_h s + κ)e^(−sT) (docs/models.md).

    Attributes
    ----------
    model : str
    kappa : float
        κ, 1/s².
    kappa_critical : float
        κ*, 1/s²: stable for 0 < κ < κ* (``inf``: every κ > 0; 0: none).
    omega_critical : float or None
        rad/s at κ*.
    margin : float
        κ_edge/κ − 1 (as the steering gain margin, docs/models.md): > 0 stable, < 0 unstable.
    verdict : str
        "stable", "unstable" or "undecided" (within 1e-9 of an edge of the stable set).
    T_critical : float
        T*, s: stable for every delay / period in [0, T*) (0: unstable already at T = 0).
    damping_range : tuple of (float, float)
        Every interval of c_h (1/s) that makes this κ stable at the loop's T.
    rightmost_root : complex or None
    """

    model: str
    kappa: float
    kappa_critical: float
    omega_critical: float | None
    margin: float
    verdict: str
    T_critical: float
    damping_range: tuple
    rightmost_root: complex | None

    @property
    def stable(self) -> bool:
        """True only when the verdict is "stable"."""
        return self.verdict == "stable"

    def to_dict(self, T: float) -> dict:
        """JSON-ready (SI units); ``stable_side`` of κ* and T* (below), ``to_stabilize`` the period T* when a shorter one helps."""
        root = self.rightmost_root
        fix = {}
        if not self.stable and 0 < self.T_critical < T:
            fix["T"] = {"to": self.T_critical, "direction": "lower", "change_percent": (self.T_critical / T - 1.0) * 100}
        return {
            "stable": self.stable,
            "verdict": self.verdict,
            "kappa": self.kappa,
            "kappa_critical": json_number(self.kappa_critical),
            "margin": json_number(self.margin),
            "omega_critical": json_number(self.omega_critical),
            "rightmost_root": {"sigma": json_number(root.real), "omega": json_number(abs(root.imag))} if root is not None else {"sigma": None, "omega": None},
            "T_critical": json_number(self.T_critical),
            "damping_range": [[json_number(lo), json_number(hi)] for lo, hi in self.damping_range],
            "stable_side": {"kappa_critical": "below", "T_critical": "below"},  # stable for 0 < κ < κ*, for T in [0, T*)
            "to_stabilize": fix,
        }


def _kappa_margin(kappa: float, boundary, stable: bool) -> tuple:
    """(margin, verdict) of κ against the model's stable set: the steering report's `interval_margin`/`interval_verdict` in κ.

    κ <= 0 (no restoring force) has margin −1; within 1e-9 of an edge the verdict is "undecided" with margin 0.
    """
    if kappa <= 0:
        return -1.0, "stable" if stable else "unstable"
    verdict = interval_verdict(kappa, boundary.stable_set, boundary.kappa_critical, stable)
    if verdict == "undecided":
        return 0.0, verdict
    return interval_margin(kappa, boundary.stable_set, boundary.kappa_critical, stable), verdict




def _verdict_of(model, kappa: float, c_h: float, controller: Controller) -> HolonomicVerdict:
    """`holonomic_verdict` for a model object (the report builds each model once)."""
    name = model.name
    loop = HolonomicLoop(controller.T, c_h)
    boundary = model.boundary(loop)
    stable = model.is_stable(kappa, loop)
    margin, verdict = _kappa_margin(kappa, boundary, stable)
    return HolonomicVerdict(name, kappa, boundary.kappa_critical, boundary.omega_critical, margin, verdict,
                            model.critical_delay(kappa, loop), model.damping_range(kappa, loop), model.rightmost_root(kappa, loop))


@dataclass(frozen=True)
class HolonomicEquilibrium(HolonomicGains):
    """Every holonomic model's verdict at one equilibrium, with its gains (`velocity_laws.HolonomicGains`: x0 m, κ 1/s², c_h 1/s).

    Attributes
    ----------
    models : dict[str, HolonomicVerdict]
    """

    models: dict

    def models_dict(self, T: float) -> dict:
        return {name: v.to_dict(T) for name, v in self.models.items()}


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
    T : float
        The loop's period, s.
    """

    geometry: str
    value: float
    equilibria: tuple
    main: int
    T: float

    def to_dicts(self) -> tuple:
        """(environment entry, top-level verdicts), JSON-ready."""
        first = self.equilibria[self.main]
        key, where = ("alpha_deg", "d0") if self.geometry == "wall" else ("L", "x0")
        env = {key: self.value, "N": None, "NV": None, "kappa": first.kappa, "c_h": first.c_h}
        if self.geometry == "wall":
            env["d0"] = json_number(first.x0)
        env["equilibria"] = [{where: json_number(e.x0), "N": None, "c": None, "kappa": e.kappa, "c_h": e.c_h,
                              **({"NV": None, "models": e.models_dict(self.T)} if self.geometry == "wall" else {})}
                             for e in self.equilibria]
        return env, first.models_dict(self.T)


@dataclass(frozen=True)
class NonSmoothScene:
    """The velocity-gated repulsion's non-smooth verdict at a wall or in a corridor (`velocity_laws`).

    Attributes
    ----------
    geometry : str
    value : float
        α (deg) or L (m).
    result : NonSmoothWall or NonSmoothCorridor
    cycle : dict or None
        The simulated cycle (`validation.non_smooth.simulated_cycle`), filled above this level.
    """

    geometry: str
    value: float
    result: object
    cycle: dict | None = None

    def to_dicts(self) -> tuple:
        """(environment entry, top-level verdicts = {}): the verdict, the band and the cycle."""
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


# ------------------------------------------------------------------ steering with a heading gain
def _steering_verdicts(controller, models, robot: Robot, e, NV: float, critical_values, geometry: dict, where: str, law: str) -> dict:
    """Every steering model at one (x0, N, c): the loop k(cs + NV)e^(−sT); with c beyond `models.HEADING_GAIN_RANGE` every
    verdict "undecided", its values null, with the reason (docs/velocity_and_fuzzy.md: no model decides that loop)."""
    low, high = HEADING_GAIN_RANGE
    if low <= e.c <= high:
        return model_verdicts(controller, models, Loop(robot.tau, controller.T, robot.k, c=e.c), e.N, NV, critical_values, lambda _: geometry)
    reason = (f"c = {e.c:.4g}: the heading gain of --law {law} at the {where} is outside the range the loop models take, "
              f"[{low:g}, {high:g}]; no model decides this loop (docs/velocity_and_fuzzy.md)")
    critical = critical_values(**geometry, V_critical=math.nan, T_critical=math.nan, k_critical=math.nan)
    return {m.name: ModelVerdict(m.name, NV, math.nan, None, math.nan, "undecided", critical, None, reason) for m in models_for(controller, models)}


def _steering_wall(robot: Robot, controller: Controller, wall: Wall, models, equilibria, fixed_V: bool, law: str) -> WallAnalysis:
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


def _steering_corridor(robot: Robot, controller: Controller, corridor: Corridor, models, equilibria, fixed_V: bool, law: str) -> CorridorAnalysis:
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


def _holonomic_scene(geometry, value, gains, controller, model_objs, main) -> HolonomicScene:
    if not gains:
        raise ValueError(f"{'alpha' if geometry == 'wall' else 'L'} = {value:g}: the law has no equilibrium here (it never balances the pull)")
    flat = [g.x0 for g in gains if g.kappa == 0.0]
    if flat:
        raise ValueError(f"{'alpha' if geometry == 'wall' else 'L'} = {value:g}: no lateral stiffness at x0 = {flat[0]:g} m (kappa = 0: "
                         f"the repulsion does not reach there, rho0 too short); raise --rho0")
    equilibria = tuple(
        HolonomicEquilibrium(g.x0, g.kappa, g.c_h, {m.name: _verdict_of(m, g.kappa, g.c_h, controller) for m in model_objs})
        for g in gains
    )
    index = 0 if main == "first" else min(range(len(gains)), key=lambda i: abs(gains[i].x0))
    return HolonomicScene(geometry, value, equilibria, index, controller.T)


# ------------------------------------------------------------------ the report
def build_family_report(
    robot: Robot,
    controller: Controller,
    *,
    family: str = "steering",
    law=None,
    alpha_deg: float | None = None,
    L: float | None = None,
    models=MODEL_NAMES,
    pade_order: int = 3,
    mass: float = 1.0,
    sources: dict | None = None,
) -> StabilityReport:
    """The report of any robot family and law (module docstring; docs/velocity_and_fuzzy.md).

    Parameters
    ----------
    robot, controller : Robot, Controller
        ``--robot kinematic`` uses k as K_s and ignores τ; ``holonomic`` uses T, the
        compute delay and V (which enters only through a velocity exponent n ≠ 2).
    family : {"steering", "kinematic", "holonomic"}
    law : ForceLaw or FamilyLaw, optional
        A static law (`fields.make_law`; KB's power law by default) or a `FamilyLaw`
        (`make_family_law`). A holonomic robot takes ``velocity`` or ``velocity-gated`` only.
    alpha_deg : float, optional
        Wall target angle, deg.
    L : float, optional
        Corridor half-width, m.
    models, pade_order
        As `report.build_report`.
    mass : float
        The holonomic robot's mass, kg (κ = −F_x′/m, c_h = nα_v V^(n−2)/m).
    sources : dict, optional
        Provenance of each input.

    Returns
    -------
    StabilityReport
        With ``extras``: ``tracking`` (holonomic ``velocity``, m = n = 2), the
        holonomic scenes and the non-smooth scenes (filled by `to_dict`).

    Raises
    ------
    ValueError
        An unknown family, a law the family does not take, no geometry, or any parameter out of range.
    """
    check_choice("robot", family, ROBOT_FAMILIES)
    if alpha_deg is None and L is None:
        raise ValueError(f"alpha or L must be given: a wall (--alpha DEG, in {RANGES['alpha_deg'].describe()}) and/or a corridor (--L M)")
    sources = dict(sources or {})
    mass = check_parameter("mass", mass)
    family_law = law if isinstance(law, FamilyLaw) else None
    if family == "holonomic" and (family_law is None or family_law.name not in HOLONOMIC_LAWS):
        shown = family_law.name if family_law is not None else getattr(law, "key", None) or "power"
        raise ValueError(f"--robot holonomic takes --law velocity or velocity-gated (a force in newtons on a mass, Ge & Cui 2002 Sec 6); got --law {shown}")
    if family == "kinematic":
        robot = robot.replace(tau=0.0)
        sources["tau"] = KINEMATIC_TAU_SOURCE
    if family_law is None:
        report = build_report(robot, controller, alpha_deg=alpha_deg, L=L, models=models, pade_order=pade_order, sources=sources, law=law)
        return _with_family(report, family, sources)
    models = tuple(dict.fromkeys(models))
    for name in models:
        check_choice("model", name, MODEL_NAMES)
    wall = Wall.from_degrees(alpha_deg) if alpha_deg is not None else None
    corridor = Corridor(L) if L is not None else None
    inputs = _inputs(robot, controller, family, family_law, mass, pade_order, wall, corridor, sources)
    if family_law.name == "velocity-gated":
        return _non_smooth(inputs, family_law, wall, corridor)
    model_objs = _model_objects(controller, models, pade_order, family)
    if family == "holonomic":
        return _holonomic(inputs, family_law, controller, robot, wall, corridor, model_objs, mass)
    extras = {}
    if family_law.name == "velocity":
        att, rep, rho_g = family_law.velocity_attraction(), family_law.repulsion(), family_law.parameters["goal_distance"]
        wall_eq = att.steering_wall_equilibria(rep, wall.alpha, robot.V, rho_g) if wall else None
        corr_eq = att.steering_corridor_equilibria(rep, corridor.L, robot.V, rho_g) if corridor else None
    else:
        fuzzy = family_law.fuzzy()
        wall_eq = fuzzy.wall_equilibria(wall.alpha, family_law.side) if wall else None
        corr_eq = fuzzy.corridor_equilibria(corridor.L) if corridor else None
        if wall:
            bracket = fuzzy.robust_bracket(wall.alpha)
            extras["environment"] = {"wall": {
                "equilibria": [{"N_frozen": e.N_frozen, "eta": e.eta, "eta_d": e.eta_d, "c_plus": e.c_plus, "c_minus": e.c_minus} for e in wall_eq],
                "robust_bracket": {"eta": list(bracket.eta), "N": list(bracket.N), "d0": list(bracket.d0)},
            }}
    fixed_V = family_law.name == "fuzzy"
    wall_result = _steering_wall(robot, controller, wall, model_objs, wall_eq, fixed_V, family_law.name) if wall else None
    corridor_result = _steering_corridor(robot, controller, corridor, model_objs, corr_eq, fixed_V, family_law.name) if corridor else None
    if corridor and family_law.name == "fuzzy":
        extras.setdefault("environment", {})["corridor"] = {"equilibria": [{"N_frozen": e.N_frozen} for e in corridor_result.equilibria]}
    static = family_law.repulsion() if family_law.name == "velocity" else None
    fixes = remedies_by_key(wall_result, corridor_result, lambda scenario, verdict: _loop_remedies(scenario, verdict, robot, controller, static))
    options = {m.name: STEERING.describe(m) for m in model_objs}
    errors = kb_errors(robot, controller, wall_result, corridor_result)
    return StabilityReport(inputs, options, wall_result, corridor_result, errors[0] if errors else None, fixes, family_law.described(), None, extras,
                           errors if len(errors) > 1 else ())


def _loop_remedies(scenario: str, verdict, robot: Robot, controller: Controller, static) -> dict:
    """`report.remedies` limited to what the verdict's critical values support (V, T, k)."""
    from ..laws.force_law import PowerLaw

    law = static if static is not None else PowerLaw(controller.f, controller.n, robot.W)
    return {k: v for k, v in remedies(scenario, verdict, robot, controller, law).items() if k in ("V", "T", "k")}


def _model_objects(controller: Controller, models, pade_order: int, family: str) -> tuple:
    """The steering models (`models.models_for`, ``sampled`` as the controller samples) or the holonomic ones."""
    if family == "holonomic":
        return tuple(make_models(list(models), pade_order=pade_order, compute_delay=controller.compute_delay))
    return tuple(models_for(controller, models, pade_order=pade_order))


def _inputs(robot, controller, family, family_law, mass, pade_order, wall, corridor, sources) -> dict:
    """The report's inputs: the robot family, the robot and controller, the law's parameters, the geometry."""
    holonomic = family == "holonomic"
    values = {"robot": family, "V": robot.V, "tau": robot.tau, "T": controller.T, "k": robot.k}
    if holonomic:
        values["mass"] = mass
    values.update(family_law.parameters)
    values.update(family_law.choices)
    values.update({"hold": controller.hold, "compute_delay": controller.compute_delay, "pade_order": pade_order})
    if wall is not None:
        values["alpha_deg"] = wall.alpha_deg
    if corridor is not None:
        values["L"] = corridor.L
    out = {}
    for name, value in values.items():
        source = sources.get(name, "default" if name in FAMILY_DEFAULTS or name in FAMILY_CHOICE_DEFAULTS else "user")
        if holonomic and name in ("tau", "k", "hold"):
            source = HOLONOMIC_UNUSED
        out[name] = {"value": value, "unit": _unit(name), "source": source}
    return out


def _unit(name: str) -> str:
    if name in UNITS:
        return UNITS[name]
    return RANGES[name].unit if name in RANGES else ""


def _with_family(report: StabilityReport, family: str, sources: dict) -> StabilityReport:
    """A static law's report with the robot family among its inputs (nothing added for KB's steering robot)."""
    if family == "steering":
        return report
    inputs = {"robot": {"value": family, "unit": "", "source": sources.get("robot", "user")}, **report.inputs}
    return replace(report, inputs=inputs)


def _holonomic(inputs, family_law, controller, robot, wall, corridor, model_objs, mass) -> StabilityReport:
    """κ, c_h and every holonomic model at each equilibrium; the tracking error's ζ, ω_n for m = n = 2."""
    att, rep, rho_g = family_law.velocity_attraction(), family_law.repulsion(), family_law.parameters["goal_distance"]
    scenes = {}
    if wall is not None:
        gains = att.holonomic_wall_gains(rep, wall.alpha, rho_g, mass, robot.V)
        scenes["wall"] = _holonomic_scene("wall", wall.alpha_deg, gains, controller, model_objs, "first")
    if corridor is not None:
        gains = att.holonomic_corridor_gains(rep, corridor.L, rho_g, mass, robot.V)
        scenes["corridor"] = _holonomic_scene("corridor", corridor.L, gains, controller, model_objs, "middle")
    extras = {"scenes": scenes}
    if att.m == 2.0 and att.n == 2.0:
        t = tracking_dynamics(att.alpha_p, att.alpha_v, mass)
        extras["tracking"] = {"damping_ratio": t.damping_ratio, "natural_frequency": t.natural_frequency, "regime": t.regime}
    options = {m.name: HOLONOMIC.describe(m) for m in model_objs}
    return StabilityReport(inputs, options, None, None, None, {}, family_law.described(), None, extras)


def _non_smooth(inputs, family_law, wall, corridor) -> StabilityReport:
    """The non-smooth verdict: the rest band at a wall, the friction levels in a corridor; the cycle is filled above."""
    gated = family_law.gated()
    scenes = {}
    if wall is not None:
        scenes["wall"] = NonSmoothScene("wall", wall.alpha_deg, gated.non_smooth_wall(family_law.attraction, wall.alpha))
    if corridor is not None:
        scenes["corridor"] = NonSmoothScene("corridor", corridor.L, gated.non_smooth_corridor(corridor.L))
    return StabilityReport(inputs, {}, None, None, None, {}, family_law.described(), None, {"scenes": scenes})
