"""Simulation against prediction: the stability boundary and a random sweep (issue 5 items 2–3).

`validate_boundary` bisects the simulated boundary of a straight corridor or
wall in L, α, V or f and sets every loop model's prediction beside it (with
the lateral law the simulation really has), and checks σ and ω near the
boundary against the matching `sampled` model's dominant root.
`verdict_sweep` simulates a Latin hypercube of random parameter sets in one
batch per geometry and counts how often the sign of the simulated growth rate
agrees with each model's verdict.

Modules: `common` (parameters, the simulated verdict, predictions),
`boundary`, `sweep`. Plots: `pfm_stability.plots.validation`; CLI:
``pfm-stability validate``.
"""

from .boundary import BoundaryValidation, OscillationCheck, SimulatedPoint, StabilityMap, validate_boundary
from ..sim.bisect import simulated_verdict
from .common import PARAMETERS, REFERENCE_SETS, SCENARIOS, predicted_boundaries
from .sweep import SWEEP_RANGES, SweepPoint, SweepResult, verdict_sweep

__all__ = [
    "BoundaryValidation",
    "OscillationCheck",
    "PARAMETERS",
    "REFERENCE_SETS",
    "SCENARIOS",
    "SWEEP_RANGES",
    "SimulatedPoint",
    "StabilityMap",
    "SweepPoint",
    "SweepResult",
    "predicted_boundaries",
    "simulated_verdict",
    "validate_boundary",
    "verdict_sweep",
]
