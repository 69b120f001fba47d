"""Simulation against prediction: the only place where the loop models and the simulator meet (docs/validation.md).

* `predict` (module `predict`) — what the models predict for one simulated
  `Scenario`; `model_answer` and `critical_value` are the one path from the
  models to every validation.
* `validate_boundary` (module `boundary`) — bisects the simulated boundary of
  a straight corridor or wall in L, α, V or f and sets every loop model's
  prediction beside it (with the lateral law the simulation really has), and
  checks σ and ω near the boundary against the matching `sampled` model's
  dominant root; with ``stability_map=(nx, ny)`` a `StabilityMap` (module `region`).
* `boundary_by_bisection` (module `bisection`) — the bare simulated boundary
  on a bracket; `simulated_boundary` (module `region`) — one per value of a
  second parameter, beside every model's curve.
* `verdict_sweep` (module `sweep`) — simulates a Latin hypercube of random
  parameter sets in one batch per geometry and counts how often the sign of
  the simulated growth rate agrees with each model's verdict.

Module `common`: the bisected parameters, their domains, the model set,
predicted boundaries. Plots: `pfm_stability.plots.validation`; CLI:
``pfm-stability validate``.
"""

from ..sim.verdict import simulated_verdict
from .bisection import BoundaryEstimate, SimulatedPoint, boundary_by_bisection
from .boundary import BoundaryValidation, OscillationCheck, validate_boundary
from .common import PARAMETERS, REFERENCE_SETS, SCENARIOS, predicted_boundaries
from .predict import ModelPrediction, Prediction, critical_value, model_answer, predict
from .region import SimulatedBoundary, StabilityMap, model_curves, simulated_boundary
from .sweep import SWEEP_RANGES, SweepPoint, SweepResult, verdict_sweep

__all__ = [
    "BoundaryEstimate",
    "BoundaryValidation",
    "ModelPrediction",
    "OscillationCheck",
    "PARAMETERS",
    "Prediction",
    "REFERENCE_SETS",
    "SCENARIOS",
    "SWEEP_RANGES",
    "SimulatedBoundary",
    "SimulatedPoint",
    "StabilityMap",
    "SweepPoint",
    "SweepResult",
    "boundary_by_bisection",
    "critical_value",
    "model_answer",
    "model_curves",
    "predict",
    "predicted_boundaries",
    "simulated_boundary",
    "simulated_verdict",
    "validate_boundary",
    "verdict_sweep",
]
