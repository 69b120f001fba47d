"""The stability report: every model's verdict for a wall and/or a corridor.

`build_report` runs the criteria of `pfm_stability.criteria` for the chosen
models and adds what a user acts on: the margin, the critical value of every
parameter, the change that would make the loop stable, and how far KB's
criterion (Koren & Borenstein 1991 eq 20) is from the sampled loop. The text
and Markdown renderings live in `pfm_stability.render`; `StabilityReport.to_dict`
is the JSON form (infinite values become ``null``: "no finite critical value").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .criteria import CorridorAnalysis, WallAnalysis, analyze_corridor, analyze_wall, loop_of
from .models import MODEL_NAMES, KBFirstOrder, Sampled, make_models
from .parameters import Controller, Corridor, Robot, Wall
from .serialize import json_number

__all__ = ["StabilityReport", "KBError", "build_report", "remedies", "kb_error"]

UNITS = {
    "V": "m/s",
    "tau": "s",
    "T": "s",
    "k": "1/s",
    "f": "",
    "n": "",
    "W": "m",
    "hold": "",
    "compute_delay": "samples",
    "alpha_deg": "deg",
    "L": "m",
    "pade_order": "",
}


@dataclass(frozen=True)
class KBError:
    """How far KB's NV* = 1/(τ+T) (eq 20) is from the sampled loop's NV*.

    Attributes
    ----------
    relative : float
        NV*_kb / NV*_sampled − 1: > 0 optimistic (KB allows gains the sampled
        loop cannot take), < 0 conservative.
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
    def direction(self) -> str:
        return "optimistic" if self.relative > 0 else "conservative"

    def sentence(self) -> str:
        """"KB's criterion is X % optimistic/conservative against `sampled` (…)"."""
        against = f"`sampled` (hold={self.hold}, compute_delay={self.compute_delay})"
        if not math.isfinite(self.relative):
            return f"KB's criterion cannot be compared with {against}: its NV* is {self.NV_sampled:g} 1/s"
        return f"KB's criterion is {abs(self.relative) * 100:.1f} % {self.direction} against {against}"

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {
            "relative": json_number(self.relative),
            "direction": self.direction,
            "NV_critical_kb_first_order": json_number(self.NV_kb),
            "NV_critical_sampled": json_number(self.NV_sampled),
            "hold": self.hold,
            "compute_delay": self.compute_delay,
            "text": self.sentence(),
        }


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
        """The fields as a JSON-ready dict (SI units)."""
        out = {"inputs": self.inputs, "models": self.model_options}
        if self.wall is not None:
            out.setdefault("environment", {})["wall"] = {
                "alpha_deg": math.degrees(self.wall.alpha),
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
        "rightmost_root": {"sigma": float(root.real), "omega": float(abs(root.imag))},
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
        or "lower", "change_percent": relative change, %}. Empty if stable, or
        if no change of that parameter alone can help.
    """
    if verdict.verdict == "stable":
        return {}
    c = verdict.critical
    current = {"V": robot.V, "f": controller.f, "T": controller.T}
    wanted = [("V", "lower", c["V_critical"]), ("T", "lower", c["T_critical"])]
    if scenario == "wall":
        current["alpha_deg"] = None
        wanted += [("alpha_deg", "raise", c["alpha_critical_deg"]), ("f", "raise", c["f_critical"])]
    else:
        current["L"] = None
        wanted += [("L", "raise", c["L_critical"]), ("f", "lower", c["f_critical"])]
    out = {}
    for name, direction, target in wanted:
        if not math.isfinite(target) or target <= 0 or (name == "alpha_deg" and target >= 90):
            continue
        now = current.get(name)
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
    relative = kb / sampled - 1.0 if sampled > 0 and math.isfinite(sampled) else math.inf
    return KBError(relative, kb, sampled, controller.hold, controller.compute_delay)


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
) -> StabilityReport:
    """Analyze a wall (α, rad) and/or a corridor (L, m) with the chosen models.

    Parameters
    ----------
    robot, controller : Robot, Controller
    alpha : float, optional
        Wall target angle, rad, in (0, π/2).
    L : float, optional
        Corridor half-width, m, > W/2.
    models : sequence of str
        Model names (DESIGN §4); all by default.
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
    if alpha is None and L is None:
        raise ValueError("alpha or L must be given: a wall (--alpha DEG, in (0, 90) deg) and/or a corridor (--L M, in (W/2, inf) m)")
    wall = Wall(alpha) if alpha is not None else None
    corridor = Corridor(L) if L is not None else None
    model_objs = make_models(tuple(models), pade_order=pade_order, hold=controller.hold, compute_delay=controller.compute_delay)
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
        values["alpha_deg"] = math.degrees(wall.alpha)
    if corridor is not None:
        values["L"] = corridor.L
    inputs = {name: {"value": value, "unit": UNITS[name], "source": sources.get(name, "user")} for name, value in values.items()}
    options = {}
    for m in model_objs:
        entry = {"equation": m.equation}
        if m.name == "pade":
            entry["order"] = m.order
        if m.name == "sampled":
            entry.update(hold=m.hold, compute_delay=m.compute_delay)
        options[m.name] = entry
    wall_result = analyze_wall(robot, controller, wall, model_objs, law) if wall else None
    corridor_result = analyze_corridor(robot, controller, corridor, model_objs, law) if corridor else None
    fixes = {}
    for scenario, result in (("wall", wall_result), ("corridor", corridor_result)):
        if result is not None:
            for name, verdict in result.models.items():
                fixes[(scenario, name)] = remedies(scenario, verdict, robot, controller)
    return StabilityReport(inputs, options, wall_result, corridor_result, kb_error(robot, controller), fixes)
