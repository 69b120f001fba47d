"""The stability report of every robot family and law: `build_report`, the one entry point, and `StabilityReport`.

`build_report` takes the robot family (``steering``, ``kinematic``, ``holonomic``), the law (a
static lateral law, `fields.make_law`, or a law of `parameters.FAMILY_LAWS`,
`families.make_family_law`), the geometry (a wall, a corridor, a door) and the models; it builds
the models once for the loop the family closes and returns a `StabilityReport` with one result
per geometry, typed by the loop that decides it (docs/velocity_and_fuzzy.md, docs/models.md
"Robot loop families"):

* a steering loop (KB's robot, kinematic steering; every law but the velocity-gated one):
  `analysis.criteria.WallAnalysis` and `CorridorAnalysis`, every model's `ModelVerdict` at
  each equilibrium (the fuzzy law's frozen gains beside them: `families.FuzzySchedule`);
* a holonomic loop (``--robot holonomic --law velocity``): `families.HolonomicScene`, every
  model's `models.holonomic.HolonomicVerdict` at each equilibrium;
* no linear loop (``--law velocity-gated``): `families.NonSmoothScene`, the rest band and the
  simulated cycle.

What a user acts on is assembled once for every family: the margin and the critical value of
every parameter (in the results), the change that would make the loop stable (`remedies`,
held in `StabilityReport.remedies`), and how far KB's criterion (Koren & Borenstein 1991 eq 20)
is from the sampled loop (`kb_errors`, docs/models.md). `StabilityReport.to_dict` is the JSON
form (infinite values become ``"inf"``: "no finite critical value"); the text and Markdown
renderings (`pfm_stability.cli.render`) dispatch on the results' types.

Any `ForceLaw` may be given (docs/fields.md): its parameters join the inputs, ``law`` names it,
and a wall lists every equilibrium of the law (``environment.wall.equilibria``, each with
every model's verdict); the top-level ``wall`` verdicts are those of the first (nearest)
equilibrium.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import partial, singledispatch

from ..analysis.comparison import relative_error
from ..analysis.criteria import CorridorAnalysis, ModelVerdict, WallAnalysis, analyze_corridor, analyze_wall
from ..checks import check_choice, check_type
from ..io.serialize import SCHEMA_VERSION, json_number, json_ready
from ..laws.force_law import ForceLaw, PowerLaw, law_in_force
from ..models import HEADING_GAIN_RANGE, STEERING, KBFirstOrder, Loop, LoopFamily, Sampled, make_models, models_for
from ..models.family import root_json
from ..laws.registry import FAMILY_CHOICE_DEFAULTS, FAMILY_DEFAULTS, FORCE_LAWS, HOLONOMIC_LAWS, LAW_PARAMETERS, parameter_keys
from ..parameters import KB_PLANT, MODEL_NAMES, RANGES, ROBOT_FAMILIES, Controller, Corridor, Robot, Wall, check_parameter
from .remedy import change as _change

__all__ = ["StabilityReport", "KBError", "LawDescription", "build_report", "remedies", "kb_error", "kb_errors", "KINEMATIC_TAU_SOURCE",
           "PLANT_INPUTS", "plant_inputs", "DRIVE_INPUTS", "drive_inputs"]

LAW_INPUTS = parameter_keys(FORCE_LAWS)
"""The static laws' own parameters, listed after W when the law takes them (`laws.registry.parameter_keys`: in
`laws.registry.PARAMETERS` order)."""

PLANT_INPUTS = ("dead_time", "plant_gain", "actuator_lag", "slip_lag")
"""The steering plant's dead time D and gain g (`parameters.Robot`), listed after k only when given: a value other than
the default (D = 0, g = 1) or one the user typed (`plant_inputs`), so reports without them are as before."""

DRIVE_INPUTS = ("yaw_accel_limit", "max_steering_rate")
"""The drive's limits beyond the plant: its yaw acceleration limit R and, when a file gave it with R (a Nav2 velocity
smoother's velocity clamp), its steering-rate limit (`parameters.Robot`), listed after the plant only when the robot has
a finite R, so reports without it are as before (`drive_inputs`)."""

INPUTS = ("V", "tau", "T", "k", *PLANT_INPUTS, *DRIVE_INPUTS, "f", "n", "W", *LAW_INPUTS, "hold", "compute_delay", "pade_order", "alpha_deg", "L")
"""The report's inputs for a static law, in the order it lists them (``alpha_deg`` and ``L`` when given; f and n for KB's laws only)."""

UNITS = {name: RANGES[name].unit if name in RANGES else "" for name in INPUTS}
"""Unit of each input (`parameters.RANGES`; ``hold`` has none)."""

KINEMATIC_TAU_SOURCE = "not used (kinematic robot: no motor lag, tau = 0; --k is K_s)"
"""The source the report gives τ for ``--robot kinematic``."""

HOLONOMIC_UNUSED = "not used (holonomic robot)"
"""The source the report gives τ, k and the hold for ``--robot holonomic``."""


@dataclass(frozen=True)
class KBError:
    """How far KB's criterion (eq 20, `kb_first_order`) is from the sampled loop's NV*, for one loop.

    Attributes
    ----------
    relative : float
        NV*_kb / NV*_sampled − 1: > 0 optimistic (KB allows gains the sampled
        loop cannot take), < 0 conservative; ``inf`` when the sampled loop is
        unstable at every NV (NV*_sampled = 0); NaN (undefined) when both are
        infinite.
    NV_kb, NV_sampled : float
        1/s: `kb_first_order`'s NV* (1/(τ + T) when c = 0) and `sampled`'s, for
        the same loop (τ, T, k, c).
    hold : str
    compute_delay : int
    c : float
        The loop's heading gain (0: KB's loop). With c ≠ 0 KB's criterion is
        that of `kb_first_order` with the heading gain (docs/models.md, "The
        heading gain"): the NV* its table prints.
    where : tuple of str
        The geometries whose loop this is ("wall", "wall equilibrium 2",
        "corridor"); empty for KB's loop (c = 0), which every geometry shares.
    """

    relative: float
    NV_kb: float
    NV_sampled: float
    hold: str
    compute_delay: int
    c: float = 0.0
    where: tuple = ()

    @property
    def direction(self) -> str | None:
        """"optimistic", "conservative", or None when `relative` is undefined or 0."""
        if math.isnan(self.relative) or self.relative == 0:
            return None
        return "optimistic" if self.relative > 0 else "conservative"

    def sentence(self) -> str:
        """"KB's criterion is X % optimistic/conservative against `sampled` (…)" (naming the heading gain when there is one)."""
        against = f"`sampled` (hold={self.hold}, compute_delay={self.compute_delay})"
        kb = "KB's criterion"
        if self.c != 0.0:
            kb += f" with the heading gain c = {self.c:.4g} (kb_first_order{', ' + ', '.join(self.where) if self.where else ''})"
        if math.isnan(self.relative):
            return f"{kb} cannot be compared with {against}: both are stable at every NV"
        if math.isinf(self.relative):
            return (f"{kb} is infinitely optimistic against {against}: the sampled loop is unstable at every NV "
                    f"(NV* = 0) while KB allows NV < {self.NV_kb:.4g} 1/s")
        return f"{kb} is {abs(self.relative) * 100:.1f} % {self.direction or 'off'} against {against}"

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units); ``direction`` only with a value."""
        out = {
            "relative": json_number(self.relative),
            "NV_critical_kb_first_order": json_number(self.NV_kb),
            "NV_critical_sampled": json_number(self.NV_sampled),
            "hold": self.hold,
            "compute_delay": self.compute_delay,
            "text": self.sentence(),
        }
        if self.direction is not None:
            out["direction"] = self.direction
        if self.c != 0.0:
            out["c"] = self.c
        if self.where:
            out["where"] = list(self.where)
        return out


@dataclass(frozen=True)
class LawDescription:
    """The force law a report analyses, as it lists it.

    Attributes
    ----------
    name : str or None
        The law's name (`parameters.FORCE_LAWS` or `parameters.FAMILY_LAWS`); None for a law built in code.
    description : str
        What the law is, in words.
    parameters : dict
        Parameter → value, JSON-ready (SI units).
    """

    name: str | None
    description: str
    parameters: dict

    def to_dict(self) -> dict:
        """``{"name", "description", "parameters"}``."""
        return {"name": self.name, "description": self.description, "parameters": self.parameters}


@dataclass(frozen=True)
class StabilityReport:
    """Everything `pfm-stability report` prints, for every robot family and law (module docstring).

    Attributes
    ----------
    inputs : dict
        Parameter → {"value", "unit", "source"}.
    models : tuple of LoopModel
        The models run, each once.
    family : LoopFamily
        The loop family the models decide (`models.STEERING`, `models.holonomic.HOLONOMIC`): names their equations.
    wall, corridor : WallAnalysis, CorridorAnalysis, families.HolonomicScene, families.NonSmoothScene or None
        The result of each geometry, typed by the loop that decides it (module docstring).
    remedies : dict
        (geometry, model) → the single-parameter changes that make the main
        equilibrium's verdict stable (`stability.remedies`; a holonomic robot's: a
        shorter period T*); (geometry, i, model) → those of wall equilibrium i.
    law : LawDescription or None
    door : DoorPassage or None
        KB's problem 2 (Fig 4) for a door of the given width (`door.door_passage`).
    kb_errors : tuple of KBError
        KB's error for every loop the steering tables decide (one per heading gain, wall first);
        empty for a holonomic robot and the non-smooth law.
    schedule : families.FuzzySchedule or None
        The fuzzy law's frozen gains and robust bracket.
    tracking : models.tracking.TrackingDynamics or None
        The tracking error's ζ and ω_n (a holonomic robot under the velocity law with m = n = 2).
    wobble : analysis.wobble.Wobble or None
        The corridor's wobble past V* (``report --wobble``; JSON ``corridor.wobble``).
    wall_wobble : analysis.wobble.Wobble or None
        The wall's (the biased describing function; JSON ``wall.wobble``).
    disturbance, wall_disturbance : analysis.disturbance.Disturbance or None
        What a start of a given size does in the corridor and beside the wall (``report --disturbance``; JSON
        ``corridor.disturbance``, ``wall.disturbance``).
    path : analysis.path_tracking.PathTracking or None
        A Nav2 controller tracking a straight path or a corridor's centre line (``report --controller``,
        docs/path_tracking.md; JSON ``environment.path`` and ``path.<model>``, its remedies under ("path", model)).
    """

    inputs: dict
    models: tuple = ()
    family: LoopFamily = STEERING
    wall: object | None = None
    corridor: object | None = None
    remedies: dict = field(default_factory=dict)
    law: LawDescription | None = None
    door: object | None = None
    kb_errors: tuple = ()
    schedule: object | None = None
    tracking: object | None = None
    wobble: object | None = None
    wall_wobble: object | None = None
    disturbance: object | None = None
    wall_disturbance: object | None = None
    path: object | None = None

    @property
    def kb_error(self) -> KBError | None:
        """The first of `kb_errors` (the wall's loop when there is one); None without a steering table."""
        return self.kb_errors[0] if self.kb_errors else None

    @property
    def model_options(self) -> dict:
        """Model name → its equation (for the report's family) and options (`LoopFamily.describe`)."""
        return {m.name: self.family.describe(m) for m in self.models}

    def scenes(self):
        """(geometry, result) of the wall, then of the corridor, for each one analysed."""
        return tuple((geometry, scene) for geometry, scene in (("wall", self.wall), ("corridor", self.corridor)) if scene is not None)

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units; infinities as ``"inf"``, undefined as null)."""
        out = {"schema_version": SCHEMA_VERSION, "command": "report", "inputs": self.inputs, "models": self.model_options}
        if self.law is not None:
            out["law"] = self.law.to_dict()
        for geometry, scene in self.scenes():
            env, verdicts = _scene_json(scene, self)
            out.setdefault("environment", {})[geometry] = env
            if verdicts is not None:
                out[geometry] = verdicts
        if self.wobble is not None and "corridor" in out:
            out["corridor"]["wobble"] = self.wobble.to_dict()
        if self.wall_wobble is not None and "wall" in out:
            out["wall"]["wobble"] = self.wall_wobble.to_dict()
        if self.disturbance is not None and "corridor" in out:
            out["corridor"]["disturbance"] = self.disturbance.to_dict()
        if self.wall_disturbance is not None and "wall" in out:
            out["wall"]["disturbance"] = self.wall_disturbance.to_dict()
        if self.tracking is not None:
            t = self.tracking
            out["tracking"] = json_ready({"damping_ratio": t.damping_ratio, "natural_frequency": t.natural_frequency, "regime": t.regime})
        if self.door is not None:
            out["door"] = self.door.to_dict()
        if self.path is not None:
            from .path import path_json

            out.setdefault("environment", {})["path"], out["path"] = path_json(self.path, self.remedies)
        if self.kb_errors:
            out["kb_error"] = self.kb_errors[0].to_dict()
        if len(self.kb_errors) > 1:
            out["kb_errors"] = [e.to_dict() for e in self.kb_errors]
        return out


# ------------------------------------------------------------------ JSON of each result type
@singledispatch
def _scene_json(result, report: StabilityReport) -> tuple:
    """(environment entry, top-level verdicts or None) of one geometry's result, JSON-ready, by the result's type: a steering
    loop's here, another family's by its own ``to_dicts`` (`report.families`)."""
    return result.to_dicts(report)


@_scene_json.register
def _(wall: WallAnalysis, report: StabilityReport) -> tuple:
    """A steering loop beside a wall: every equilibrium with its verdicts (the fuzzy law's gains beside them), the first's on top."""
    fixes, schedule = report.remedies, report.schedule
    equilibria = []
    for i, e in enumerate(wall.equilibria):
        item = {"d0": json_number(e.d0), "N": e.N, "c": e.c, "NV": e.NV,
                "models": {name: _verdict_dict(v, fixes.get(("wall", i, name))) for name, v in e.models.items()}}
        if schedule is not None:
            s = schedule.wall[i]
            item.update({k: json_number(v) for k, v in (("N_frozen", s.N_frozen), ("eta", s.eta), ("eta_d", s.eta_d), ("c_plus", s.c_plus),
                                                        ("c_minus", s.c_minus))})
        equilibria.append(item)
    env = {"alpha_deg": wall.alpha_deg, "d0": json_number(wall.d0), "N": wall.N, "NV": wall.NV, "c": wall.c, "equilibria": equilibria}
    if schedule is not None and schedule.bracket is not None:
        b = schedule.bracket
        env["robust_bracket"] = json_ready({"eta": list(b.eta), "N": list(b.N), "d0": list(b.d0)})
    return env, {name: _verdict_dict(v, fixes.get(("wall", name))) for name, v in wall.models.items()}


@_scene_json.register
def _(corridor: CorridorAnalysis, report: StabilityReport) -> tuple:
    """A steering loop in a corridor: the equilibria (the fuzzy law's N_frozen beside them), the verdicts in the middle."""
    equilibria = [{"x0": e.x0, "N": e.N, "c": e.c} for e in corridor.equilibria]
    if report.schedule is not None:
        for item, s in zip(equilibria, report.schedule.corridor):
            item["N_frozen"] = json_number(s.N_frozen)
    env = {"L": corridor.L, "N": corridor.N, "NV": corridor.NV, "c": corridor.c, "equilibria": equilibria}
    if corridor.N_finite_goal is not None:
        env["N_finite_goal"] = corridor.N_finite_goal
    return env, {name: _verdict_dict(v, report.remedies.get(("corridor", name))) for name, v in corridor.models.items()}


def _verdict_dict(v, remedy) -> dict:
    """A steering model's `ModelVerdict` with its remedy, JSON-ready."""
    out = {
        "stable": v.stable,
        "verdict": v.verdict,
        "NV": v.NV,
        "NV_critical": json_number(v.NV_critical),
        "margin": json_number(v.margin),
        "omega_critical": json_number(v.omega_critical),
        "rightmost_root": root_json(v.rightmost_root),
    }
    out.update({key: json_number(value) for key, value in v.critical.items()})
    out["stable_side"] = {"NV_critical": None if math.isnan(v.NV_critical) else "below", **v.critical.stable_sides()}
    out["to_stabilize"] = remedy or {}
    if v.reason is not None:
        out["reason"] = v.reason
    return out


# ------------------------------------------------------------------ the one entry point
def build_report(
    robot: Robot,
    controller: Controller,
    *,
    family: str = "steering",
    law=None,
    alpha: float | None = None,
    alpha_deg: float | None = None,
    L: float | None = None,
    models=MODEL_NAMES,
    pade_order: int = 3,
    mass: float = 1.0,
    sources: dict | None = None,
    door: float | None = None,
    door_obstacle: str = "posts",
    post_radius: float = 0.0,
    simulate_cycle=None,
    wobble=None,
    disturbance=None,
    tracker=None,
    gains=None,
) -> StabilityReport:
    """The report of any robot family and law for a wall (α) and/or a corridor (L, m), and a door with a static law.

    Parameters
    ----------
    robot, controller : Robot, Controller
        ``family="kinematic"`` uses k as K_s and ignores τ; ``holonomic`` uses T, the
        compute delay and V (which enters only through a velocity exponent n ≠ 2).
    family : {"steering", "kinematic", "holonomic"}
        The robot family (`parameters.ROBOT_FAMILIES`, docs/models.md "Robot loop families").
    law : ForceLaw or families.FamilyLaw, optional
        A static law (`fields.make_law` builds any law of `parameters.FORCE_LAWS`;
        KB's power law by default): a law named in `parameters.LAW_PARAMETERS` lists
        the parameters it takes among the inputs (f and n only where it uses them).
        Or a law of `parameters.FAMILY_LAWS` (`families.make_family_law`); a
        holonomic robot takes ``velocity`` or ``velocity-gated`` only.
    alpha : float, optional
        Wall target angle, rad, in [1e-6°, 90° − 1e-6°] (a steering robot with a static law).
    alpha_deg : float, optional
        The same in degrees (checked in degrees; `Wall.from_degrees`).
    L : float, optional
        Corridor half-width, m, > W/2.
    models : sequence of str
        Model names (`parameters.MODEL_NAMES`, docs/models.md); all by default.
    pade_order : int
        Order m of the ``pade`` model.
    mass : float
        The holonomic robot's mass, kg (κ = −F_x′/m, c_h = nα_v V^(n−2)/m).
    sources : dict, optional
        Provenance of each input (shown in the report).
    door : float, optional
        Door width, m (KB Fig 4, `door.door_passage`; a steering robot with a static law).
    door_obstacle : {"posts", "walls"}
        What bounds the door.
    post_radius : float
        Post radius or the walls' half-thickness, m.
    simulate_cycle : callable, optional
        The velocity-gated law's simulated cycle beside a wall,
        ``simulate_cycle(family, robot, controller, law, alpha, mass=…) -> dict``
        (`validation.non_smooth.simulated_cycle`, above this level); None: not simulated.
    wobble : float or bool, optional
        The wobble past V* in the corridor and beside the wall (`analysis.wobble.corridor_wobble`, `wall_wobble`,
        docs/wobble.md): the tolerance on its lateral amplitude, m, or True for the default (a tenth of the clearance:
        L − W/2, or the room before the wall); None or False: not computed. A steering or kinematic robot with a static law.
    disturbance : float, optional
        A start this far off the equilibrium, m, in the corridor and beside the wall (`analysis.disturbance`,
        docs/wobble.md): the speed V*(D) at or below which it settles, what it grows into past it, the criticality, with
        the robot's `yaw_accel_limit`; None: not computed. A steering or kinematic robot with a static law.
    tracker : io.nav2.Nav2Tracker, optional
        A Nav2 path-tracking controller with its parameters (docs/path_tracking.md): the report is then its loop about a
        straight path, or in the corridor of half-width `L`, for every model (`report.path.path_report`); robot.V is its
        cruising speed parameter, robot.k is not used. No wall, door, law or wobble with it.
    gains : analysis.path_laws.MeasuredGains, optional
        MPPI's or DWB's gains measured from the algorithm (required for them with `tracker`).

    Returns
    -------
    StabilityReport

    Raises
    ------
    ValueError
        An unknown family, a law the family does not take, no geometry, a door with a
        family or a law it does not apply to, any parameter out of range, or a wall where
        the law has no equilibrium.
    """
    check_choice("robot", family, ROBOT_FAMILIES)
    if tracker is not None:
        return _path_report(robot, controller, tracker, gains, family=family, law=law, alpha=alpha, alpha_deg=alpha_deg, L=L, models=models,
                            pade_order=pade_order, sources=sources, door=door, wobble=wobble, disturbance=disturbance)
    if disturbance is not None:
        return _with_disturbance(disturbance, robot, controller, family=family, law=law, alpha=alpha, alpha_deg=alpha_deg, L=L, models=models,
                                 pade_order=pade_order, mass=mass, sources=sources, door=door, door_obstacle=door_obstacle,
                                 post_radius=post_radius, simulate_cycle=simulate_cycle, wobble=wobble)
    if wobble is not None and wobble is not False:
        return _with_wobble(wobble, robot, controller, family=family, law=law, alpha=alpha, alpha_deg=alpha_deg, L=L, models=models,
                            pade_order=pade_order, mass=mass, sources=sources, door=door, door_obstacle=door_obstacle,
                            post_radius=post_radius, simulate_cycle=simulate_cycle)
    if law is not None and not isinstance(law, ForceLaw):
        from .families import FamilyLaw

        check_type("law", law, FamilyLaw, "a ForceLaw (fields.make_law) or a FamilyLaw (families.make_family_law)")
        return _family_law_report(robot, controller, family, law, alpha, alpha_deg, L, models, pade_order, mass, sources, door, simulate_cycle)
    if family == "steering":
        return _static_report(robot, controller, law, alpha, alpha_deg, L, models, pade_order, sources, door, door_obstacle, post_radius)
    shown = getattr(law, "key", None) or "power"
    if door is not None:
        raise ValueError(_DOOR_REFUSED.format(family=family, law=shown))
    if alpha is None and alpha_deg is None and L is None:
        raise ValueError(_NO_GEOMETRY)
    if family == "holonomic":
        raise ValueError(f"--robot holonomic takes --law velocity or velocity-gated (a force in newtons on a mass, Ge & Cui 2002 Sec 6); got --law {shown}")
    sources = {**(sources or {}), "tau": KINEMATIC_TAU_SOURCE}
    report = _static_report(robot.replace(tau=0.0), controller, law, alpha, alpha_deg, L, models, pade_order, sources, None, door_obstacle, post_radius)
    return replace(report, inputs={"robot": {"value": family, "unit": "", "source": sources.get("robot", "user")}, **report.inputs})


_WOBBLE_REFUSED = ("--wobble applies to a wall (--alpha) or a corridor (--L) with --robot steering or kinematic and a static law "
                   "(power, grid, khatib, gnron)")
"""The message when a wobble is asked of a report without a corridor, or of a robot family or law it does not apply to."""


def _with_wobble(wobble, robot, controller, *, family, law, L, **options) -> StabilityReport:
    """`build_report` and the corridor's wobble (`analysis.wobble.corridor_wobble`; the sampled loop with the controller's
    hold and compute delay, the exact-delay loop for a continuous controller), or the reason it has none (N <= 0, …)."""
    from ..analysis.wobble import Wobble, corridor_wobble, wall_wobble

    _check_nonlinear(_WOBBLE_REFUSED, family, law, L, options)
    tolerance = None if wobble is True else check_parameter("wobble", wobble)
    report = build_report(robot, controller, family=family, law=law, L=L, **options)
    corridor, wall = _each_geometry(report, robot, controller, family, law, (corridor_wobble, wall_wobble), tolerance,
                                    lambda reason: Wobble.unavailable(reason, tolerance))
    return replace(report, wobble=corridor, wall_wobble=wall)


_DISTURBANCE_REFUSED = ("--disturbance applies to a wall (--alpha) or a corridor (--L) with --robot steering or kinematic and a static law "
                        "(power, grid, khatib, gnron)")
"""The message when a disturbance is asked of a report without a wall or corridor, or of a robot family or law it does not apply to."""


def _with_disturbance(disturbance, robot, controller, *, family, law, L, **options) -> StabilityReport:
    """`build_report` (with its wobble, if asked) and what a start of size D does in the corridor and beside the wall
    (`analysis.disturbance`), or why it cannot be said (N <= 0, no oscillatory boundary, …)."""
    from ..analysis.disturbance import Disturbance, corridor_disturbance, wall_disturbance

    _check_nonlinear(_DISTURBANCE_REFUSED, family, law, L, options)
    D = check_parameter("disturbance", disturbance)
    report = build_report(robot, controller, family=family, law=law, L=L, **options)
    corridor, wall = _each_geometry(report, robot, controller, family, law, (corridor_disturbance, wall_disturbance), D,
                                    lambda reason: Disturbance.unavailable(D, robot.yaw_accel_limit, reason))
    return replace(report, disturbance=corridor, wall_disturbance=wall)


def _check_nonlinear(refusal: str, family: str, law, L, options: dict) -> None:
    """ValueError(`refusal`) unless a wall or corridor, a steering or kinematic robot and a static law: what the
    describing functions take (``--wobble``, ``--disturbance``)."""
    if (L is None and options["alpha"] is None and options["alpha_deg"] is None) or family == "holonomic" \
            or (law is not None and not isinstance(law, ForceLaw)):
        raise ValueError(refusal)


def _each_geometry(report, robot, controller, family, law, functions, value, unavailable) -> tuple:
    """(corridor, wall): ``function(robot, controller, law, L or α, value, model=…)`` for each geometry of `report`, the
    sampled loop with the controller's hold and compute delay (`exact_delay` for T = 0), ``unavailable(reason)`` where it
    raises ValueError; None for a geometry the report has not."""
    steering = robot.replace(tau=0.0) if family == "kinematic" else robot
    force_law = law_in_force(robot, controller, law)
    model = "sampled" if controller.T > 0 else "exact_delay"

    def predicted(function, where):
        try:
            return function(steering, controller, force_law, where, value, model=model)
        except ValueError as exc:
            return unavailable(str(exc))

    corridor_function, wall_function = functions
    corridor = predicted(corridor_function, report.corridor.L) if report.corridor is not None else None
    wall = predicted(wall_function, math.radians(report.wall.alpha_deg)) if report.wall is not None else None
    return corridor, wall


_PATH_REFUSED = "{what} applies to --controller vff (the VFF loop); a Nav2 controller tracks a straight path or a corridor (--L)"
"""The message when a path tracker's report is asked for what only the VFF loop has."""


def _path_report(robot, controller, tracker, gains, *, family, law, alpha, alpha_deg, L, models, pade_order, sources, door, wobble,
                 disturbance=None):
    """A Nav2 controller's report (`report.path.path_report`): refuses the VFF loop's geometries and options."""
    for what, given in (("alpha", alpha is not None or alpha_deg is not None), ("--door", door is not None), ("--law", law is not None),
                        ("--wobble", wobble not in (None, False)), ("--disturbance", disturbance is not None),
                        (f"--robot {family}", family != "steering")):
        if given:
            raise ValueError(_PATH_REFUSED.format(what=what))
    from .path import path_report

    L = None if L is None else check_parameter("L", L)
    inputs, model_objs, loop_family, result, fixes = path_report(robot, controller, tracker, gains=gains, L=L, models=models,
                                                                 pade_order=pade_order, sources=sources)
    return StabilityReport(inputs, model_objs, loop_family, remedies=fixes, path=result)


_NO_GEOMETRY = f"alpha or L must be given: a wall (--alpha DEG, in {RANGES['alpha_deg'].describe()}) and/or a corridor (--L M)"
"""The message when a robot family's or a family law's report has no geometry."""

_DOOR_REFUSED = "--door applies to --robot steering with a static law (power, grid, khatib, gnron), not to --robot {family} --law {law}"
"""The message when a door is asked of a robot family or a family law."""


# ------------------------------------------------------------------ a static law (steering and kinematic robots)
def _static_report(robot, controller, law, alpha, alpha_deg, L, models, pade_order, sources, door, door_obstacle, post_radius) -> StabilityReport:
    """A steering (or kinematic, τ = 0) robot with a static law: `analysis.criteria` at the wall and in the corridor, the door."""
    if alpha is not None and alpha_deg is not None:
        raise ValueError("give alpha (rad) or alpha_deg, not both")
    if alpha is None and alpha_deg is None and L is None and door is None:
        raise ValueError(
            f"alpha or L must be given, or a door: a wall (--alpha DEG, in {RANGES['alpha_deg'].describe()}), "
            f"a corridor (--L M, in (W/2, {RANGES['L'].high:g}] m) and/or a door (--door WIDTH, m)"
        )
    wall = Wall.from_degrees(alpha_deg) if alpha_deg is not None else (Wall(alpha) if alpha is not None else None)
    corridor = Corridor(L) if L is not None else None
    check_type("robot", robot, Robot, "a Robot")
    check_type("controller", controller, Controller, "a Controller")
    models = MODEL_NAMES if models is None else models
    if isinstance(models, str) or not isinstance(models, (list, tuple)) or not all(isinstance(m, str) for m in models):
        raise ValueError(f"models must be a list or tuple of model names ({', '.join(MODEL_NAMES)}); got {models!r}")
    if sources is not None and not isinstance(sources, dict):
        raise ValueError(f"sources must be a dict of parameter name to provenance; got {sources!r}")
    model_objs = tuple(models_for(controller, tuple(dict.fromkeys(models)), pade_order=pade_order))
    sources = sources or {}
    values = {"V": robot.V, "tau": robot.tau, "T": controller.T, "k": robot.k, **plant_inputs(robot, sources), **drive_inputs(robot, sources), "f": controller.f,
              "n": controller.n, "W": robot.W, "hold": controller.hold, "compute_delay": controller.compute_delay, "pade_order": pade_order}
    law = law_in_force(robot, controller, law)
    values = _law_inputs(values, law)
    if wall is not None:
        values["alpha_deg"] = wall.alpha_deg
    if corridor is not None:
        values["L"] = corridor.L
    inputs = {name: {"value": value, "unit": UNITS[name], "source": sources.get(name, "user")} for name, value in values.items()}
    wall_result = analyze_wall(robot, controller, wall, model_objs, law) if wall else None
    corridor_result = analyze_corridor(robot, controller, corridor, model_objs, law) if corridor else None

    def fix(geometry, verdict):
        return remedies(geometry, verdict, robot, controller, law, wall.alpha_deg if geometry == "wall" else corridor.L)

    passage = None
    if door is not None:
        from ..analysis.door import door_passage

        passage = door_passage(law, check_parameter("door", door), obstacle=door_obstacle, post_radius=check_parameter("post_radius", post_radius),
                               robot_width=robot.W, find_smallest=True, name="door")
    return StabilityReport(inputs, model_objs, Loop.of(robot, controller).family, wall_result, corridor_result, _remedies(wall_result, corridor_result, fix),
                           LawDescription(law.key, law.name, json_ready(law.parameters())), passage,
                           kb_errors(robot, controller, wall_result, corridor_result, model_objs))


def _law_inputs(values: dict, law: ForceLaw) -> dict:
    """The inputs with the law's own parameters after W, and without f and n where a named law does not use them."""
    taken = LAW_PARAMETERS.get(law.key)
    if taken is None:
        return values
    own = {k: v for k, v in law.parameters().items() if k in LAW_INPUTS and k in taken}
    out = {}
    for name, value in values.items():
        if name not in ("f", "n") or name in taken:
            out[name] = value
        if name == "W":
            out.update(own)
    return out


# ------------------------------------------------------------------ a law of FAMILY_LAWS (every robot family)
def _family_law_report(robot, controller, family, law, alpha, alpha_deg, L, models, pade_order, mass, sources, door, simulate_cycle) -> StabilityReport:
    """The velocity, velocity-gated or fuzzy law (`families`): steering, holonomic or non-smooth results."""
    from .families import holonomic_results, non_smooth_results, steering_results

    if door is not None:
        raise ValueError(_DOOR_REFUSED.format(family=family, law=law.name))
    if alpha is not None and alpha_deg is not None:
        raise ValueError("give alpha (rad) or alpha_deg, not both")
    if alpha is None and alpha_deg is None and L is None:
        raise ValueError(_NO_GEOMETRY)
    sources = dict(sources or {})
    mass = check_parameter("mass", mass)
    if family == "holonomic" and law.name not in HOLONOMIC_LAWS:
        raise ValueError(f"--robot holonomic takes --law velocity or velocity-gated (a force in newtons on a mass, Ge & Cui 2002 Sec 6); got --law {law.name}")
    if family == "kinematic":
        robot = robot.replace(tau=0.0)
        sources["tau"] = KINEMATIC_TAU_SOURCE
    models = tuple(dict.fromkeys(MODEL_NAMES if models is None else models))
    for name in models:
        check_choice("model", name, MODEL_NAMES)
    wall = Wall.from_degrees(alpha_deg) if alpha_deg is not None else (Wall(alpha) if alpha is not None else None)
    corridor = Corridor(L) if L is not None else None
    inputs = _family_inputs(robot, controller, family, law, mass, pade_order, wall, corridor, sources)
    if law.name == "velocity-gated":
        cycle = None
        if simulate_cycle is not None and controller.T != 0:  # T = 0: a continuous controller, nothing sampled to simulate
            cycle = partial(simulate_cycle, family, robot, controller, law, mass=mass)
        wall_result, corridor_result = non_smooth_results(law, wall, corridor, cycle)
        return StabilityReport(inputs, (), STEERING, wall_result, corridor_result, law=LawDescription(**law.described()))
    if family == "holonomic":
        from ..models.holonomic import HOLONOMIC

        model_objs = tuple(make_models(list(models), pade_order=pade_order, compute_delay=controller.compute_delay))
        wall_result, corridor_result, tracking = holonomic_results(robot, controller, law, wall, corridor, model_objs, mass)
        fixes = _remedies(wall_result, corridor_result, lambda geometry, v: _delay_remedy(v, controller.T))
        return StabilityReport(inputs, model_objs, HOLONOMIC, wall_result, corridor_result, fixes, LawDescription(**law.described()),
                               tracking=tracking)
    model_objs = tuple(models_for(controller, models, pade_order=pade_order))
    wall_result, corridor_result, schedule = steering_results(robot, controller, law, wall, corridor, model_objs)
    static = law.repulsion() if law.name == "velocity" else PowerLaw(controller.f, controller.n, robot.W)

    def fix(geometry, verdict):  # what the verdict's critical values support: V, T, k (the law's own are not followed)
        return {k: v for k, v in remedies(geometry, verdict, robot, controller, static).items() if k in ("V", "T", "k")}

    return StabilityReport(inputs, model_objs, Loop.of(robot, controller).family, wall_result, corridor_result, _remedies(wall_result, corridor_result, fix),
                           LawDescription(**law.described()), None, kb_errors(robot, controller, wall_result, corridor_result, model_objs), schedule)


def plant_inputs(robot: Robot, sources: dict | None) -> dict:
    """{name: value} of the steering plant's D, g, τ_a and τ_s that the report lists (`PLANT_INPUTS`).

    Each is listed when it differs from KB's robot (`parameters.KB_PLANT`: D = 0, g = 1, τ_a = τ_s = 0) or when it was
    typed (source ``user``: `cli.options.resolve_parameters`), so every report
    that does not give them — a file that states KB's values included — keeps
    its inputs (and its JSON keys) as before.

    Parameters
    ----------
    robot : parameters.Robot
        The robot, with `dead_time` (s) and `plant_gain`.
    sources : dict or None
        Parameter name → provenance (`build_report`'s ``sources``).
    """
    sources = sources or {}
    shown = {}
    for name in PLANT_INPUTS:
        value, source = getattr(robot, name), sources.get(name)
        if value != KB_PLANT[name] or source == "user":
            shown[name] = value
    return shown


def drive_inputs(robot: Robot, sources: dict | None = None) -> dict:
    """{"yaw_accel_limit": R} when the robot's drive limits its commanded yaw rate's change (R finite, rad/s²), and its
    ``max_steering_rate`` (rad/s) when `sources` says where it came from (a Nav2 velocity smoother's clamp); else {}.

    The loop models are linear and do not see them: their verdicts are those of small disturbances, where the limiter
    passes every command (docs/wobble.md, ``--disturbance``).

    Parameters
    ----------
    robot : parameters.Robot
        The robot, with `yaw_accel_limit` (inf: none).
    sources : dict, optional
        Parameter name → provenance.
    """
    if not math.isfinite(robot.yaw_accel_limit):
        return {}
    shown = {"yaw_accel_limit": robot.yaw_accel_limit}
    if "max_steering_rate" in (sources or {}):
        shown["max_steering_rate"] = robot.max_steering_rate
    return shown


def _family_inputs(robot, controller, family, law, mass, pade_order, wall, corridor, sources) -> dict:
    """The report's inputs: the robot family, the robot and controller, the law's parameters and choices, the geometry."""
    holonomic = family == "holonomic"
    values = {"robot": family, "V": robot.V, "tau": robot.tau, "T": controller.T, "k": robot.k, **plant_inputs(robot, sources),
              **drive_inputs(robot, sources)}
    if holonomic:
        values["mass"] = mass
    values.update(law.parameters)
    values.update(law.choices)
    values.update({"hold": controller.hold, "compute_delay": controller.compute_delay, "pade_order": pade_order})
    if wall is not None:
        values["alpha_deg"] = wall.alpha_deg
    if corridor is not None:
        values["L"] = corridor.L
    out = {}
    for name, value in values.items():
        source = sources.get(name, "default" if name in FAMILY_DEFAULTS or name in FAMILY_CHOICE_DEFAULTS else "user")
        if holonomic and name in ("tau", "k", "hold", *PLANT_INPUTS, *DRIVE_INPUTS):
            source = HOLONOMIC_UNUSED
        out[name] = {"value": value, "unit": UNITS.get(name, RANGES[name].unit if name in RANGES else ""), "source": source}
    return out


# ------------------------------------------------------------------ remedies, once for every family
def _remedies(wall, corridor, fix) -> dict:
    """`StabilityReport.remedies`: ``fix(geometry, verdict)`` once for every verdict of each result, under each of its keys
    (`_keyed_verdicts`)."""
    out, fixed = {}, {}
    for result in (wall, corridor):
        for key, verdict in _keyed_verdicts(result) if result is not None else ():
            if id(verdict) not in fixed:
                fixed[id(verdict)] = fix(key[0], verdict)
            out[key] = fixed[id(verdict)]
    return out


@singledispatch
def _keyed_verdicts(result) -> tuple:
    """((geometry, model) or (geometry, i, model), verdict) of every verdict of a result, by its type: a steering loop's here,
    another family's by its own ``keyed_verdicts`` (`report.families`)."""
    return result.keyed_verdicts()


@_keyed_verdicts.register
def _(wall: WallAnalysis) -> tuple:
    """Each equilibrium's verdicts under ("wall", i, model), the first's also under ("wall", model)."""
    keyed = [(("wall", i, name), v) for i, e in enumerate(wall.equilibria) for name, v in e.models.items()]
    return (*keyed, *((("wall", name), v) for name, v in wall.equilibria[0].models.items()))


@_keyed_verdicts.register
def _(corridor: CorridorAnalysis) -> tuple:
    """The verdicts under ("corridor", model)."""
    return tuple((("corridor", name), v) for name, v in corridor.models.items())


def _delay_remedy(verdict, T: float) -> dict:
    """A holonomic verdict's remedy: a period shorter than T* (`models.holonomic.HolonomicVerdict`), when it helps."""
    if verdict.stable:
        return {}
    entry = _change("T", verdict.T_critical, "lower", T)
    return {"T": entry} if entry is not None else {}


def remedies(scenario: str, verdict: ModelVerdict, robot: Robot, controller: Controller, law: ForceLaw | None = None, at: float | None = None) -> dict:
    """Single-parameter changes that make an unstable steering loop stable.

    Parameters
    ----------
    scenario : {"wall", "corridor"}
    verdict : criteria.ModelVerdict
    robot, controller : Robot, Controller
        The current parameters.
    law : ForceLaw, optional
        The law analysed (KB's power law by default). For a law that is not
        `monotone` the critical values of α, L and of the law's parameters are
        the nearest values at which the verdict changes (docs/fields.md), so
        the direction is the one towards them.
    at : float, optional
        The current α (deg, wall) or L (m, corridor): the direction towards α*
        or L* for a law that is not monotone (without it, "raise").

    Returns
    -------
    dict
        Parameter → {"to": critical value (SI, α in deg; f in the user's f,
        a grid law's f_av: `ForceLaw.lumped_f`), "direction": "raise" or
        "lower", "change_percent": relative change, %}. Each value leaves
        the loop stable over the whole way from it to 0 (V, T, k) or beyond it
        (α, L), by the definitions of the critical values (for a law that is
        not monotone: just past it). Empty if stable; a parameter is left out
        when no value of it alone helps (e.g. V, α, L and f when the model is
        unstable at every NV: then only a shorter T or a lower k can work).
    """
    if verdict.verdict == "stable":
        return {}
    law = law_in_force(robot, controller, law)
    c = verdict.critical
    current = {**law.parameters(), "V": robot.V, "f": law.lumped_f(), "T": controller.T, "k": robot.k}  # f: the user's (a grid's f_av)
    wanted = [("V", "V_critical", "lower"), ("T", "T_critical", "lower"), ("k", "k_critical", "lower")]  # (parameter, critical key, direction)
    if "dead_time_critical" in c:  # a robot with a dead time or a plant gain (docs/models.md, "Plant gain and dead time")
        current["dead_time"] = robot.dead_time
        wanted.append(("dead_time", "dead_time_critical", "lower"))
    if scenario == "wall":
        wanted.append(("alpha_deg", "alpha_critical_deg", _towards(c.alpha_critical_deg, at, law)))
    else:
        wanted.append(("L", "L_critical", _towards(c.L_critical, at, law)))
    if "f_critical" in c:
        wanted.append(("f", "f_critical", ("raise" if scenario == "wall" else "lower") if law.monotone else _towards(c.f_critical, current["f"], law)))
    wanted += [(name, f"{name}_critical", _towards(c[f"{name}_critical"], current[name], law)) for name in ("eta", "rho0", "xi") if f"{name}_critical" in c]
    changes = ((name, _change(name, c[key], direction, current.get(name))) for name, key, direction in wanted)
    return {name: entry for name, entry in changes if entry is not None}


def _towards(target: float, now: float | None, law: ForceLaw) -> str | None:
    """"raise" or "lower": towards `target` for a law that is not monotone; "raise" (α, L) for one that is."""
    if law.monotone or now is None:
        return "raise"
    if not math.isfinite(target) or target == now:
        return None
    return "raise" if target > now else "lower"


# ------------------------------------------------------------------ KB's error
def kb_error(robot: Robot, controller: Controller, c: float = 0.0, where: tuple = (), models: tuple = ()) -> KBError:
    """KB's eq (20) against the `sampled` loop with the controller's structure, for the loop with heading gain `c`.

    With c ≠ 0 (a velocity or fuzzy law) KB's criterion is `kb_first_order`'s
    with the heading gain, so both sides are the NV* the report's table prints
    for that loop; `where` names the geometries whose loop it is.

    Parameters
    ----------
    robot : Robot
        τ (s) and k (1/s).
    controller : Controller
        T (s) and the sampled structure (hold, compute_delay).
    c : float, optional
        Heading gain of the loop, dimensionless (0: KB's loop).
    where : tuple of str, optional
        The geometries whose loop it is.
    models : tuple of LoopModel, optional
        The report's models: its ``kb_first_order`` and its ``sampled`` of the controller's structure are used
        (their boundaries are the ones the report computed) instead of new ones.
    """
    loop = Loop.of(robot, controller, c=c)
    structure = {"hold": controller.hold, "compute_delay": controller.compute_delay}
    kb_model = next((m for m in models if m.name == "kb_first_order"), None) or KBFirstOrder()
    sampled_model = (next((m for m in models if m.name == "sampled" and m.options() == structure), None)
                     or Sampled(controller.hold, controller.compute_delay))
    kb = kb_model.boundary(loop).NV_critical
    sampled = sampled_model.boundary(loop).NV_critical
    return KBError(relative_error(kb, sampled), kb, sampled, controller.hold, controller.compute_delay, c, tuple(where))


def kb_errors(robot: Robot, controller: Controller, wall: WallAnalysis | None, corridor: CorridorAnalysis | None,
              models: tuple = ()) -> tuple:
    """`kb_error` for every loop the report's steering tables decide: one per heading gain c, naming its geometries, wall first.

    A static law gives one loop (c = 0, KB's own; also without a wall or corridor: a door's
    report); a velocity or fuzzy law one per heading gain, each compared as its table prints
    it. A loop whose c is beyond the models (`models.HEADING_GAIN_RANGE`: no table value) has none.
    None with a held reference and a dead time: the sampled model takes no dead time inside the continuous servo.

    Parameters
    ----------
    robot : Robot
        τ (s) and k (1/s).
    controller : Controller
        T (s) and the sampled structure.
    wall : WallAnalysis or None
        The wall's analysis (its equilibria's heading gains).
    corridor : CorridorAnalysis or None
        The corridor's analysis.
    models : tuple of LoopModel, optional
        The report's models, reused (`kb_error`).
    """
    loops = {}
    if wall is not None:
        for i, e in enumerate(wall.equilibria):
            loops.setdefault(e.c, []).append("wall" if len(wall.equilibria) == 1 else f"wall equilibrium {i + 1}")
    if corridor is not None:
        loops.setdefault(corridor.c, []).append("corridor")
    low, high = HEADING_GAIN_RANGE
    if controller.hold == "reference" and robot.dead_time > 0:  # no sampled loop to compare with (`models.sampled.continuous_plant`)
        return ()
    return tuple(kb_error(robot, controller, c, tuple(where) if c != 0.0 else (), models)
                 for c, where in (loops or {0.0: []}).items() if low <= c <= high)
