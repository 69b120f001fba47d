"""The stability report: every model's verdict for a wall and/or a corridor.

`build_report` runs the criteria of `pfm_stability.criteria` for the chosen
models and adds what a user acts on: the margin, the critical value of every
parameter, the change that would make the loop stable, and how far KB's
criterion (Koren & Borenstein 1991 eq 20) is from the sampled loop
(docs/models.md). The text and Markdown renderings live in
`pfm_stability.cli.render`; `StabilityReport.to_dict` is the JSON form
(infinite values become ``"inf"``: "no finite critical value").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .checks import check_type
from .comparison import relative_error
from .criteria import CorridorAnalysis, WallAnalysis, analyze_corridor, analyze_wall, loop_of
from .models import KBFirstOrder, Sampled, models_for
from .parameters import MODEL_NAMES, RANGES, Controller, Corridor, Robot, Wall
from .serialize import SCHEMA_VERSION, json_number

__all__ = ["StabilityReport", "KBError", "build_report", "remedies", "kb_error"]

INPUTS = ("V", "tau", "T", "k", "f", "n", "W", "hold", "compute_delay", "pade_order", "alpha_deg", "L")
"""The report's inputs, in the order it lists them (``alpha_deg`` and ``L`` when given)."""

UNITS = {name: RANGES[name].unit if name in RANGES else "" for name in INPUTS}
"""Unit of each input (`parameters.RANGES`; ``hold`` has none)."""

REMEDY_PARAMETERS = ("V", "T", "k", "alpha_deg", "L", "f")
"""Parameters a remedy may change (one at a time), in the order they are listed."""


@dataclass(frozen=True)
class KBError:
    """How far KB's NV* = 1/(τ+T) (eq 20) is from the sampled loop's NV*.

    Attributes
    ----------
    relative : float
        NV*_kb / NV*_sampled − 1: > 0 optimistic (KB allows gains the sampled
        loop cannot take), < 0 conservative; ``inf`` when the sampled loop is
        unstable at every NV (NV*_sampled = 0); NaN (undefined) when both are
        infinite.
    NV_kb, NV_sampled : float
        1/s.
    hold : str
    compute_delay : int
    """

    relative: float
    NV_kb: float
    NV_sampled: float
    hold: str
    compute_delay: int

    @property
    def direction(self) -> str | None:
        """"optimistic", "conservative", or None when `relative` is undefined or 0."""
        if math.isnan(self.relative) or self.relative == 0:
            return None
        return "optimistic" if self.relative > 0 else "conservative"

    def sentence(self) -> str:
        """"KB's criterion is X % optimistic/conservative against `sampled` (…)"."""
        against = f"`sampled` (hold={self.hold}, compute_delay={self.compute_delay})"
        if math.isnan(self.relative):
            return f"KB's criterion cannot be compared with {against}: both are stable at every NV"
        if math.isinf(self.relative):
            return (f"KB's criterion is infinitely optimistic against {against}: the sampled loop is unstable at every NV "
                    f"(NV* = 0) while KB allows NV < {self.NV_kb:.4g} 1/s")
        return f"KB's criterion is {abs(self.relative) * 100:.1f} % {self.direction or 'off'} against {against}"

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
    """

    inputs: dict
    model_options: dict
    wall: WallAnalysis | None = None
    corridor: CorridorAnalysis | None = None
    kb_error: KBError | None = None
    remedies: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units; infinities as ``"inf"``, undefined as null)."""
        out = {"schema_version": SCHEMA_VERSION, "command": "report", "inputs": self.inputs, "models": self.model_options}
        if self.wall is not None:
            out.setdefault("environment", {})["wall"] = {
                "alpha_deg": self.wall.alpha_deg,
                "d0": json_number(self.wall.d0),
                "N": self.wall.N,
                "NV": self.wall.NV,
            }
            out["wall"] = {name: _verdict_dict(v, self.remedies.get(("wall", name))) for name, v in self.wall.models.items()}
        if self.corridor is not None:
            out.setdefault("environment", {})["corridor"] = {"L": self.corridor.L, "N": self.corridor.N, "NV": self.corridor.NV}
            out["corridor"] = {name: _verdict_dict(v, self.remedies.get(("corridor", name))) for name, v in self.corridor.models.items()}
        if self.kb_error is not None:
            out["kb_error"] = self.kb_error.to_dict()
        return out


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
    out["to_stabilize"] = remedy or {}
    return out


def remedies(scenario: str, verdict, robot: Robot, controller: Controller) -> dict:
    """Single-parameter changes that make an unstable loop stable.

    Parameters
    ----------
    scenario : {"wall", "corridor"}
    verdict : criteria.ModelVerdict
    robot, controller : the current parameters

    Returns
    -------
    dict
        Parameter → {"to": critical value (SI, α in deg), "direction": "raise"
        or "lower", "change_percent": relative change, %}. Each value leaves
        the loop stable over the whole way from it to 0 (V, T, k) or beyond it
        (α, L), by the definitions of the critical values. Empty if stable; a
        parameter is left out when no value of it alone helps (e.g. V, α, L
        and f when the model is unstable at every NV: then only a shorter T or
        a lower k can work).
    """
    if verdict.verdict == "stable":
        return {}
    c = verdict.critical
    current = {"V": robot.V, "f": controller.f, "T": controller.T, "k": robot.k}
    wanted = [("V", "lower", c.V_critical), ("T", "lower", c.T_critical), ("k", "lower", c.k_critical)]
    if scenario == "wall":
        wanted += [("alpha_deg", "raise", c.alpha_critical_deg), ("f", "raise", c.f_critical)]
    else:
        wanted += [("L", "raise", c.L_critical), ("f", "lower", c.f_critical)]
    out = {}
    for name, direction, target in wanted:
        if not math.isfinite(target) or target <= 0 or (name == "alpha_deg" and target >= 90):
            continue
        now = current.get(name)
        if now is not None and (target >= now if direction == "lower" else target <= now):
            continue  # not a change in the helpful direction (on the boundary)
        entry = {"to": target, "direction": direction}
        if now:
            entry["change_percent"] = (target / now - 1.0) * 100
        out[name] = entry
    return out


def kb_error(robot: Robot, controller: Controller) -> KBError:
    """KB's eq (20) against the `sampled` loop with the controller's structure."""
    loop = loop_of(robot, controller)
    kb = KBFirstOrder().boundary(loop).NV_critical
    sampled = Sampled(controller.hold, controller.compute_delay).boundary(loop).NV_critical
    return KBError(relative_error(kb, sampled), kb, sampled, controller.hold, controller.compute_delay)


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
        KB's power law by default.

    Raises
    ------
    ValueError
        Neither α nor L given, or any parameter out of range.
    """
    if alpha is not None and alpha_deg is not None:
        raise ValueError("give alpha (rad) or alpha_deg, not both")
    if alpha is None and alpha_deg is None and L is None:
        raise ValueError(
            f"alpha or L must be given: a wall (--alpha DEG, in {RANGES['alpha_deg'].describe()}) "
            f"and/or a corridor (--L M, in (W/2, {RANGES['L'].high:g}] m)"
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
    if wall is not None:
        values["alpha_deg"] = wall.alpha_deg
    if corridor is not None:
        values["L"] = corridor.L
    inputs = {name: {"value": value, "unit": UNITS[name], "source": sources.get(name, "user")} for name, value in values.items()}
    options = {m.name: {"equation": m.equation, **m.options()} for m in model_objs}
    wall_result = analyze_wall(robot, controller, wall, model_objs, law) if wall else None
    corridor_result = analyze_corridor(robot, controller, corridor, model_objs, law) if corridor else None
    fixes = {}
    for scenario, result in (("wall", wall_result), ("corridor", corridor_result)):
        if result is not None:
            for name, verdict in result.models.items():
                fixes[(scenario, name)] = remedies(scenario, verdict, robot, controller)
    return StabilityReport(inputs, options, wall_result, corridor_result, kb_error(robot, controller), fixes)
