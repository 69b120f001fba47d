"""What the loop models predict for a simulated scenario, to set beside the simulation.

For a scenario whose measurement window is a straight corridor or wall
(`Scenario.analysis`), `predict` runs `pfm_stability.criteria` with

* the **matching model**: ``sampled`` with the run's hold and compute delay
  (DESIGN §4), fed the run's own lateral law (`Scenario.effective_law`: the
  grid's `GridWallLaw` in the grid, the analytic law otherwise) — this is
  the model the simulation must agree with;
* **KB's criterion**: ``kb_first_order`` (eq 20, 24, 25) with the lumped
  power law f(W/d)^n; in the grid f is the grid's f_av, as KB compared
  (§4), so the prediction KB would have made is reported beside the exact one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..criteria import analyze_corridor, analyze_wall
from ..effective_force import GridWallLaw, f_average
from ..force_law import PowerLaw
from ..models import KBFirstOrder, Sampled
from ..parameters import Corridor, Wall
from .scenario import Scenario

__all__ = ["ModelPrediction", "Prediction", "predict"]


@dataclass(frozen=True)
class ModelPrediction:
    """One model's prediction for the scenario's geometry.

    Attributes
    ----------
    model : str
    law : str
        The lateral force law used.
    NV, NV_critical : float
        1/s (NV_critical ``inf``: never unstable).
    verdict : str
        "stable", "unstable" or "undecided".
    growth_rate, angular_frequency : float
        Dominant root σ (1/s) and ω (rad/s); for ``sampled`` σ = ln|z|/T.
    critical : float
        L* (m) for a corridor, α* (deg) for a wall.
    """

    model: str
    law: str
    NV: float
    NV_critical: float
    verdict: str
    growth_rate: float
    angular_frequency: float
    critical: float

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units; ``"inf"``/``"-inf"`` for infinite values, null for undefined)."""
        from ..serialize import json_number

        return {
            "model": self.model,
            "law": self.law,
            "NV": json_number(self.NV),
            "NV_critical": json_number(self.NV_critical),
            "verdict": self.verdict,
            "growth_rate": json_number(self.growth_rate),
            "angular_frequency": json_number(self.angular_frequency),
            "critical": json_number(self.critical),
        }


@dataclass(frozen=True)
class Prediction:
    """Predictions for the geometry inside the measurement window.

    Attributes
    ----------
    kind : {"corridor", "wall"}
    value : float
        L (m) or α (deg).
    critical_name : str
        "L_critical (m)" or "alpha_critical (deg)".
    matching : ModelPrediction
        ``sampled`` with the run's own law: what the simulation should show.
    kb : ModelPrediction
        KB's ``kb_first_order`` criterion with the lumped law.
    """

    kind: str
    value: float
    critical_name: str
    matching: ModelPrediction
    kb: ModelPrediction

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units; α in deg)."""
        from ..serialize import json_number

        return {
            "kind": self.kind,
            "value": json_number(self.value),
            "critical_name": self.critical_name,
            "sampled": self.matching.to_dict(),
            "kb_first_order": self.kb.to_dict(),
        }


def _one(scenario: Scenario, model, law) -> ModelPrediction:
    a = scenario.analysis
    if a["kind"] == "corridor":
        result = analyze_corridor(scenario.robot, scenario.controller, Corridor(a["L"]), [model], law=law)
        critical_key, scale = "L_critical", 1.0
    else:
        result = analyze_wall(scenario.robot, scenario.controller, Wall(a["alpha"]), [model], law=law)
        critical_key, scale = "alpha_critical", 180.0 / math.pi
    v = result.models[model.name]
    root = complex(v.rightmost_root)
    return ModelPrediction(
        model.name, law.name, result.NV, v.NV_critical, v.verdict, root.real, abs(root.imag), v.critical[critical_key] * scale
    )


def predict(scenario: Scenario) -> Prediction | None:
    """Model predictions for `scenario` (None when no linear analysis applies)."""
    a = scenario.analysis
    if not a:
        return None
    law = scenario.effective_law()
    c = scenario.controller
    lumped = PowerLaw(f_average(law), c.n, scenario.robot.W) if isinstance(law, GridWallLaw) else law
    matching = _one(scenario, Sampled(c.hold, c.compute_delay), law)
    kb = _one(scenario, KBFirstOrder(), lumped)
    if a["kind"] == "corridor":
        return Prediction("corridor", a["L"], "L_critical (m)", matching, kb)
    return Prediction("wall", math.degrees(a["alpha"]), "alpha_critical (deg)", matching, kb)
