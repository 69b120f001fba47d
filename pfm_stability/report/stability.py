"""The stability report: every model's verdict for a wall and/or a corridor.

`build_report` runs the criteria of `pfm_stability.analysis.criteria` for the chosen
models and adds what a user acts on: the margin, the critical value of every
parameter, the change that would make the loop stable, and how far KB's
criterion (Koren & Borenstein 1991 eq 20) is from the sampled loop
(docs/models.md). The text and Markdown renderings live in
`pfm_stability.cli.render`; `StabilityReport.to_dict` is the JSON form
(infinite values become ``"inf"``: "no finite critical value").

Any `ForceLaw` may be given (docs/fields.md): its parameters join the inputs,
``law`` names it, and a wall lists every equilibrium of the law
(``environment.wall.equilibria``, each with every model's verdict); the
top-level ``wall`` verdicts are those of the first (nearest) equilibrium.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..checks import check_type
from ..analysis.comparison import relative_error
from ..analysis.criteria import CorridorAnalysis, WallAnalysis, analyze_corridor, analyze_wall, loop_of
from ..laws.force_law import ForceLaw, law_in_force
from ..models import HEADING_GAIN_RANGE, STEERING, KBFirstOrder, Loop, Sampled, models_for
from ..parameters import LAW_PARAMETERS, MODEL_NAMES, RANGES, Controller, Corridor, Robot, Wall, check_parameter
from ..io.serialize import SCHEMA_VERSION, json_number, json_ready

__all__ = ["StabilityReport", "KBError", "build_report", "remedies", "remedies_by_key", "kb_error", "kb_errors"]

LAW_INPUTS = ("cell_ratio", "cell_size", "window_cells", "xi", "eta", "rho0", "attraction_exponent", "goal_exponent", "goal_distance", "delta")
"""The law's own parameters, listed after W when the law takes them (`parameters.LAW_PARAMETERS`)."""

INPUTS = ("V", "tau", "T", "k", "f", "n", "W", *LAW_INPUTS, "hold", "compute_delay", "pade_order", "alpha_deg", "L")
"""The report's inputs, in the order it lists them (``alpha_deg`` and ``L`` when given; f and n for KB's laws only)."""

UNITS = {name: RANGES[name].unit if name in RANGES else "" for name in INPUTS}
"""Unit of each input (`parameters.RANGES`; ``hold`` has none)."""

REMEDY_PARAMETERS = ("V", "T", "k", "alpha_deg", "L", "f", "eta", "rho0", "xi")
"""Parameters a remedy may change (one at a time), in the order they are listed."""


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
class StabilityReport:
    """Everything `pfm-stability report` prints.

    Attributes
    ----------
    inputs : dict
        Parameter → {"value", "unit", "source"}.
    model_options : dict
        Model name → its equation and options.
    wall : WallAnalysis or None
    corridor : CorridorAnalysis or None
    kb_error : KBError
    remedies : dict
        (scenario, model) → `remedies` of the first wall equilibrium or the
        corridor; ("wall", i, model) → those of wall equilibrium i.
    law : dict or None
        The law: ``name`` (`parameters.FORCE_LAWS`, or None for a law built in
        code), ``description`` and ``parameters``.
    door : DoorPassage or None
        KB's problem 2 (Fig 4) for a door of the given width (`door.door_passage`).
    extras : dict
        What the other robot families and laws add (`family_report.build_family_report`):
        ``scenes`` (geometry → a holonomic or non-smooth scene with ``to_dicts()``),
        ``environment`` (geometry → keys merged into the environment entry, and
        per-equilibrium keys under ``equilibria``), ``tracking``. Empty for KB's report.
    kb_errors : tuple of KBError
        Every loop's KB error when the geometries close different loops (a heading
        gain that differs between them); empty otherwise (`kb_error` is then the one).
    """

    inputs: dict
    model_options: dict
    wall: WallAnalysis | None = None
    corridor: CorridorAnalysis | None = None
    kb_error: KBError | None = None
    remedies: dict = field(default_factory=dict)
    law: dict | None = None
    door: object | None = None
    extras: dict = field(default_factory=dict)
    kb_errors: tuple = ()

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units; infinities as ``"inf"``, undefined as null)."""
        out = {"schema_version": SCHEMA_VERSION, "command": "report", "inputs": self.inputs, "models": self.model_options}
        if self.law is not None:
            out["law"] = self.law
        if self.wall is not None:
            out.setdefault("environment", {})["wall"] = {
                "alpha_deg": self.wall.alpha_deg,
                "d0": json_number(self.wall.d0),
                "N": self.wall.N,
                "NV": self.wall.NV,
                "c": self.wall.c,
                "equilibria": [
                    {"d0": json_number(e.d0), "N": e.N, "c": e.c, "NV": e.NV,
                     "models": {name: _verdict_dict(v, self.remedies.get(("wall", i, name))) for name, v in e.models.items()}}
                    for i, e in enumerate(self.wall.equilibria)
                ],
            }
            out["wall"] = {name: _verdict_dict(v, self.remedies.get(("wall", name))) for name, v in self.wall.models.items()}
        if self.corridor is not None:
            c = self.corridor
            env = {"L": c.L, "N": c.N, "NV": c.NV, "c": c.c, "equilibria": [{"x0": e.x0, "N": e.N, "c": e.c} for e in c.equilibria]}
            if c.N_finite_goal is not None:
                env["N_finite_goal"] = c.N_finite_goal
            out.setdefault("environment", {})["corridor"] = env
            out["corridor"] = {name: _verdict_dict(v, self.remedies.get(("corridor", name))) for name, v in c.models.items()}
        if self.extras:
            _merge_extras(out, self.extras)
        if self.door is not None:
            out["door"] = self.door.to_dict()
        if self.kb_error is not None:
            out["kb_error"] = self.kb_error.to_dict()
        if len(self.kb_errors) > 1:
            out["kb_errors"] = [e.to_dict() for e in self.kb_errors]
        return out


def _merge_extras(out: dict, extras: dict) -> None:
    """Add `StabilityReport.extras` to its JSON form `out` (in place)."""
    for geometry, scene in extras.get("scenes", {}).items():
        env, verdicts = scene.to_dicts()
        out.setdefault("environment", {})[geometry] = env
        if verdicts is not None:
            out[geometry] = verdicts
    for geometry, added in extras.get("environment", {}).items():
        entry = out["environment"][geometry]
        for key, value in added.items():
            if key == "equilibria":
                for item, more in zip(entry["equilibria"], value):
                    item.update({k: json_number(v) for k, v in more.items()})
            else:
                entry[key] = json_ready(value)
    if "tracking" in extras:
        out["tracking"] = json_ready(extras["tracking"])


def _verdict_dict(v, remedy) -> dict:
    root = v.rightmost_root
    out = {
        "stable": v.stable,
        "verdict": v.verdict,
        "NV": v.NV,
        "NV_critical": json_number(v.NV_critical),
        "margin": json_number(v.margin),
        "omega_critical": json_number(v.omega_critical),
        "rightmost_root": {"sigma": json_number(root.real), "omega": json_number(abs(root.imag))} if root is not None else {"sigma": None, "omega": None},
    }
    out.update({key: json_number(value) for key, value in v.critical.items()})
    out["stable_side"] = {"NV_critical": None if math.isnan(v.NV_critical) else "below", **v.critical.stable_sides()}
    out["to_stabilize"] = remedy or {}
    if v.reason is not None:
        out["reason"] = v.reason
    return out


def remedies(scenario: str, verdict, robot: Robot, controller: Controller, law: ForceLaw | None = None, at: float | None = None) -> dict:
    """Single-parameter changes that make an unstable loop stable.

    Parameters
    ----------
    scenario : {"wall", "corridor"}
    verdict : criteria.ModelVerdict
    robot, controller : the current parameters
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
    if scenario == "wall":
        wanted.append(("alpha_deg", "alpha_critical_deg", _towards(c.alpha_critical_deg, at, law)))
    else:
        wanted.append(("L", "L_critical", _towards(c.L_critical, at, law)))
    if "f_critical" in c:
        wanted.append(("f", "f_critical", ("raise" if scenario == "wall" else "lower") if law.monotone else _towards(c.f_critical, current["f"], law)))
    wanted += [(name, f"{name}_critical", _towards(c[f"{name}_critical"], current[name], law)) for name in ("eta", "rho0", "xi") if f"{name}_critical" in c]
    out = {}
    for name, key, direction in wanted:
        target = c[key]
        if direction is None or not math.isfinite(target) or target <= 0 or (name == "alpha_deg" and target >= 90):
            continue
        now = current.get(name)
        if now is not None and (target >= now if direction == "lower" else target <= now):
            continue  # not a change in the helpful direction (on the boundary)
        entry = {"to": target, "direction": direction}
        if now:
            entry["change_percent"] = (target / now - 1.0) * 100
        out[name] = entry
    return out


def remedies_by_key(wall: WallAnalysis | None, corridor: CorridorAnalysis | None, fix) -> dict:
    """`StabilityReport.remedies`: ``fix(scenario, verdict)`` for every verdict, under the report's keys.

    ("wall", i, model) for wall equilibrium i, ("wall", model) for the first,
    ("corridor", model) for the corridor.
    """
    out = {}
    if wall is not None:
        out.update({("wall", i, name): fix("wall", v) for i, e in enumerate(wall.equilibria) for name, v in e.models.items()})
        out.update({("wall", name): out[("wall", 0, name)] for name in wall.models})
    if corridor is not None:
        out.update({("corridor", name): fix("corridor", v) for name, v in corridor.models.items()})
    return out


def _towards(target: float, now: float | None, law: ForceLaw) -> str | None:
    """"raise" or "lower": towards `target` for a law that is not monotone; "raise" (α, L) for one that is."""
    if law.monotone or now is None:
        return "raise"
    if not math.isfinite(target) or target == now:
        return None
    return "raise" if target > now else "lower"


def kb_error(robot: Robot, controller: Controller, c: float = 0.0, where: tuple = ()) -> KBError:
    """KB's eq (20) against the `sampled` loop with the controller's structure, for the loop with heading gain `c`.

    With c ≠ 0 (a velocity or fuzzy law) KB's criterion is `kb_first_order`'s
    with the heading gain, so both sides are the NV* the report's table prints
    for that loop; `where` names the geometries whose loop it is.
    """
    loop = loop_of(robot, controller)
    if c != 0.0:
        loop = Loop(loop.tau, loop.T, loop.k, c=c)
    kb = KBFirstOrder().boundary(loop).NV_critical
    sampled = Sampled(controller.hold, controller.compute_delay).boundary(loop).NV_critical
    return KBError(relative_error(kb, sampled), kb, sampled, controller.hold, controller.compute_delay, c, tuple(where))


def kb_errors(robot: Robot, controller: Controller, wall: WallAnalysis | None, corridor: CorridorAnalysis | None) -> tuple:
    """`kb_error` for every loop the report's tables decide: one per heading gain c, naming its geometries, wall first.

    A static law gives one loop (c = 0, KB's own); a velocity or fuzzy law one per
    heading gain, each compared as its table prints it. A loop whose c is beyond
    the models (`models.HEADING_GAIN_RANGE`: no table value) has none.
    """
    loops = {}
    if wall is not None:
        for i, e in enumerate(wall.equilibria):
            loops.setdefault(e.c, []).append("wall" if len(wall.equilibria) == 1 else f"wall equilibrium {i + 1}")
    if corridor is not None:
        loops.setdefault(corridor.c, []).append("corridor")
    low, high = HEADING_GAIN_RANGE
    return tuple(kb_error(robot, controller, c, tuple(where) if c != 0.0 else ()) for c, where in (loops or {0.0: []}).items() if low <= c <= high)


def build_report(
    robot: Robot,
    controller: Controller,
    *,
    alpha: float | None = None,
    L: float | None = None,
    models=MODEL_NAMES,
    pade_order: int = 3,
    sources: dict | None = None,
    law=None,
    alpha_deg: float | None = None,
    door: float | None = None,
    door_obstacle: str = "posts",
    post_radius: float = 0.0,
) -> StabilityReport:
    """Analyze a wall (α) and/or a corridor (L, m) with the chosen models.

    Parameters
    ----------
    robot, controller : Robot, Controller
    alpha : float, optional
        Wall target angle, rad, in [1e-6°, 90° − 1e-6°].
    alpha_deg : float, optional
        The same in degrees (checked in degrees; `Wall.from_degrees`).
    L : float, optional
        Corridor half-width, m, > W/2.
    models : sequence of str
        Model names (`parameters.MODEL_NAMES`, docs/models.md); all by default.
    pade_order : int
        Order m of the ``pade`` model.
    sources : dict, optional
        Provenance of each input (shown in the report).
    law : ForceLaw, optional
        KB's power law by default (`fields.make_law` builds any law of
        `parameters.FORCE_LAWS`). A law named in `parameters.LAW_PARAMETERS`
        lists the parameters it takes among the inputs (f and n only where it
        uses them).

    Raises
    ------
    ValueError
        Neither α nor L given, any parameter out of range, or a wall where the
        law has no equilibrium.
    """
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
    model_objs = models_for(controller, tuple(dict.fromkeys(models)), pade_order=pade_order)
    sources = sources or {}
    values = {
        "V": robot.V,
        "tau": robot.tau,
        "T": controller.T,
        "k": robot.k,
        "f": controller.f,
        "n": controller.n,
        "W": robot.W,
        "hold": controller.hold,
        "compute_delay": controller.compute_delay,
        "pade_order": pade_order,
    }
    law = law_in_force(robot, controller, law)
    values = _law_inputs(values, law)
    if wall is not None:
        values["alpha_deg"] = wall.alpha_deg
    if corridor is not None:
        values["L"] = corridor.L
    inputs = {name: {"value": value, "unit": UNITS[name], "source": sources.get(name, "user")} for name, value in values.items()}
    options = {m.name: STEERING.describe(m) for m in model_objs}
    wall_result = analyze_wall(robot, controller, wall, model_objs, law) if wall else None
    corridor_result = analyze_corridor(robot, controller, corridor, model_objs, law) if corridor else None
    fixes = remedies_by_key(wall_result, corridor_result,
                            lambda scenario, verdict: remedies(scenario, verdict, robot, controller, law, wall.alpha_deg if scenario == "wall" else corridor.L))
    described = {"name": law.key, "description": law.name, "parameters": json_ready(law.parameters())}
    passage = None
    if door is not None:
        from ..analysis.door import door_passage

        passage = door_passage(law, check_parameter("door", door), obstacle=door_obstacle, post_radius=check_parameter("post_radius", post_radius),
                               robot_width=robot.W, find_smallest=True, name="door")
    return StabilityReport(inputs, options, wall_result, corridor_result, kb_error(robot, controller), fixes, described, passage)


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
