"""What the loop models predict for a simulated run: the one path from the models to the validation.

Two functions ask the models, and every prediction of the validation goes
through them:

* `model_answer(model, loop, NV)` — one model's boundary NV* (and ω*) and,
  at an operating point NV, its verdict: "stable", "unstable", or
  "undecided" within `models.base.UNDECIDED_RTOL` of an edge of its stable
  set (`models.verdict_label`, the rule of the stability report;
  docs/models.md, verdicts and margins), and on request its dominant root;
* `critical_value(parameter, …)` — a model's NV* turned into the critical
  L, α, V or f of a corridor or wall, all else fixed (KB eq 20 with 1/NV*
  in place of τ + T, through `pfm_stability.analysis.criteria`'s general-law
  conditions: eq 24, 25; docs/models.md, critical values).

Their users: `predict` (one `Scenario` whose measurement window is a
straight corridor or wall, below), `common.predicted_boundaries` (each
model's critical value of a bisected parameter) and the random sweep
(`sweep`: each model's verdict per member).

`predict` reports

* the **matching model**: ``sampled`` with the run's hold and compute delay
  (docs/models.md), fed the run's own lateral law (`Scenario.effective_law`:
  the grid's `GridWallLaw` in the grid, the analytic law otherwise) — the
  model the simulation must agree with;
* **KB's criterion**: ``kb_first_order`` (eq 20, 24, 25) with the lumped
  power law f(W/d)^n; in the grid f is the grid's f_av, as KB compared
  (§4), so the prediction KB would have made is reported beside the exact one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..analysis.criteria import critical_alpha, critical_f_corridor, critical_f_wall, critical_L, loop_of
from ..laws.effective_force import GridWallLaw
from ..laws.force_law import ForceLaw, PowerLaw, corridor_gain, wall_gain
from ..models import KBFirstOrder, Loop, LoopModel, Sampled, verdict_label
from ..io.serialize import json_number
from ..sim.scenario import Scenario

__all__ = [
    "ModelAnswer",
    "ModelPrediction",
    "Prediction",
    "critical_value",
    "environment_gain",
    "lumped_law",
    "model_answer",
    "predict",
]


@dataclass(frozen=True)
class ModelAnswer:
    """One model asked about one loop (and optionally one operating point).

    Attributes
    ----------
    model : str
    NV_critical : float
        NV*, 1/s (``inf``: stable for every NV; 0: unstable for every NV > 0).
    omega_critical : float or None
        Oscillation frequency at the boundary, rad/s.
    NV : float or None
        The operating point asked about, 1/s (None: the boundary only).
    verdict : str or None
        "stable", "unstable" or "undecided" at NV (None without NV).
    root : complex or None
        Dominant root σ + jω at NV (1/s, rad/s), when asked for.
    """

    model: str
    NV_critical: float
    omega_critical: float | None
    NV: float | None = None
    verdict: str | None = None
    root: complex | None = None


def model_answer(model: LoopModel, loop: Loop, NV: float | None = None, *, root: bool = False) -> ModelAnswer:
    """Ask `model` for its boundary on `loop` and, given NV, its verdict (and dominant root if `root`).

    The verdict is `models.verdict_label` (within `UNDECIDED_RTOL` of an edge
    of the stable set: "undecided"); at NV = 0 the model judges its heading
    loop, as in `pfm_stability.analysis.criteria` (docs/models.md, "N = 0").

    Parameters
    ----------
    model : LoopModel
        The model.
    loop : Loop
        τ (s), T (s), k (1/s) and the heading gain c.
    NV : float, optional
        The operating loop gain, 1/s.
    root : bool
        Also the dominant root.
    """
    boundary = model.boundary(loop)
    if NV is None:
        return ModelAnswer(model.name, boundary.NV_critical, boundary.omega_critical)
    verdict = verdict_label(NV, boundary, model.is_stable(NV, loop))
    dominant = model.rightmost_root(NV, loop) if root else None
    return ModelAnswer(model.name, boundary.NV_critical, boundary.omega_critical, NV, verdict, dominant)


def environment_gain(kind: str, law: ForceLaw, geometry: float) -> float:
    """N (1/m) of a corridor of half-width L = `geometry` (m) or a wall at α = `geometry` (rad), KB eq 11, 23, 25.

    Parameters
    ----------
    kind : {"corridor", "wall"}
        The geometry.
    law : ForceLaw
        The walls' law.
    geometry : float
        L (m) or α (rad).
    """
    return corridor_gain(law, geometry) if kind == "corridor" else wall_gain(law, geometry)[1]


def critical_value(parameter: str, kind: str, law: ForceLaw, V: float, NV_critical: float, geometry: float, f: float) -> float:
    """The critical `parameter` (reported units) for a model with boundary NV*, all else fixed.

    L* (m, `critical_L`, eq 25), α* (deg, `critical_alpha`, eq 24), V* = NV*/N
    (m/s; ``inf`` when N = 0) or KB's f* (`critical_f_corridor`,
    `critical_f_wall`: a law's critical scale, converted to KB's f with
    f/scale, the scale being ∝ f by calibration).

    Parameters
    ----------
    parameter : {"L", "alpha", "V", "f"}
    kind : {"corridor", "wall"}
    law : ForceLaw
        The lateral law of the run.
    V : float
        Speed, m/s.
    NV_critical : float
        The model's NV*, 1/s.
    geometry : float
        L (m) or α (rad) at the operating point (not used for L* and α*).
    f : float
        The controller's f.
    """
    if parameter == "L":
        return float(critical_L(law, V, NV_critical))
    if parameter == "alpha":
        return float(math.degrees(critical_alpha(law, V, NV_critical)))
    if parameter == "V":
        N = environment_gain(kind, law, geometry)
        return float(NV_critical / N) if N > 0 else math.inf
    critical_f = critical_f_corridor if kind == "corridor" else critical_f_wall
    return float(critical_f(law, geometry, V, NV_critical) * f / law.scale)


def lumped_law(law: ForceLaw) -> PowerLaw:
    """KB's lumped law beside a grid law: f = the grid's f_av (KB §4); a power law is its own.

    Parameters
    ----------
    law : ForceLaw
        A grid or power law.
    """
    return law.lumped() if isinstance(law, GridWallLaw) else law


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
        return {
            "kind": self.kind,
            "value": json_number(self.value),
            "critical_name": self.critical_name,
            "sampled": self.matching.to_dict(),
            "kb_first_order": self.kb.to_dict(),
        }


def _one(scenario: Scenario, model: LoopModel, law: ForceLaw) -> ModelPrediction:
    a = scenario.analysis
    kind = a["kind"]
    geometry = a["L"] if kind == "corridor" else a["alpha"]
    V = scenario.robot.V
    NV = environment_gain(kind, law, geometry) * V
    answer = model_answer(model, loop_of(scenario.robot, scenario.controller), NV, root=True)
    critical = critical_value("L" if kind == "corridor" else "alpha", kind, law, V, answer.NV_critical, geometry, scenario.controller.f)
    root = complex(answer.root)
    return ModelPrediction(model.name, law.name, NV, answer.NV_critical, answer.verdict, root.real, abs(root.imag), critical)


def predict(scenario: Scenario) -> Prediction | None:
    """Model predictions for `scenario` (None when no linear analysis applies).

    Parameters
    ----------
    scenario : Scenario
        A simulated scenario.
    """
    a = scenario.analysis
    if not a:
        return None
    law = scenario.effective_law()
    c = scenario.controller
    matching = _one(scenario, Sampled(c.hold, c.compute_delay), law)
    kb = _one(scenario, KBFirstOrder(), lumped_law(law))
    if a["kind"] == "corridor":
        return Prediction("corridor", a["L"], "L_critical (m)", matching, kb)
    return Prediction("wall", math.degrees(a["alpha"]), "alpha_critical (deg)", matching, kb)
