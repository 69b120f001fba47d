"""pfm-stability: will a potential-field controller oscillate, and where?

Koren & Borenstein 1991 ("Potential Field Methods and Their Inherent
Limitations for Mobile Robot Navigation", ICRA) reduce a VFF-controlled robot
near a wall or in a corridor to a third-order loop (their eq 15–20). This
package derives that loop symbolically, decides its stability with five models
of increasing fidelity (docs/models.md), and checks the predictions against a
simulation of the VFF algorithm on a histogram grid.

The public names below are imported lazily (PEP 562) so that the command line
starts fast; ``from pfm_stability import analyze_wall`` works as usual.
"""

from __future__ import annotations

import importlib

from .version import __version__

_EXPORTS = {
    "Robot": "parameters",
    "Controller": "parameters",
    "Wall": "parameters",
    "Corridor": "parameters",
    "Preset": "parameters",
    "CARMEL": "parameters",
    "get_preset": "parameters",
    "PowerLaw": "laws.force_law",
    "ForceLaw": "laws.force_law",
    "wall_gain": "laws.force_law",
    "corridor_gain": "laws.force_law",
    "Loop": "models",
    "Boundary": "models",
    "MODEL_NAMES": "parameters",
    "make_model": "models",
    "make_models": "models",
    "Continuous": "models",
    "KBFirstOrder": "models",
    "Pade": "models",
    "ExactDelay": "models",
    "Sampled": "models",
    "DelayLoop": "numerics.delay",
    "analyze_wall": "analysis.criteria",
    "analyze_corridor": "analysis.criteria",
    "kb_critical_L": "analysis.criteria",
    "kb_critical_f_wall": "analysis.criteria",
    "build_report": "report.stability",
    "routh_array": "numerics.routh",
    "schur_cohn_stable": "numerics.routh",
    "exact_delay_verdicts": "vectorized",
    "GridWallLaw": "laws.effective_force",
    "simulate": "sim",
    "simulate_batch": "sim",
    "validate_boundary": "validation",
    "verdict_sweep": "validation",
}

__all__ = sorted(_EXPORTS) + ["__version__"]


def __getattr__(name):
    if name in _EXPORTS:
        module = importlib.import_module(f".{_EXPORTS[name]}", __name__)
        return getattr(module, name)
    raise AttributeError(f"module 'pfm_stability' has no attribute {name!r}")


def __dir__():
    return __all__
