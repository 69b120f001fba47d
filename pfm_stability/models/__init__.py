"""Loop models by name (DESIGN §4).

=================  ============================================  ==========================
name               characteristic equation                       decided by
=================  ============================================  ==========================
continuous         τs³ + s² + ks + kNV = 0 (KB 17)                Routh; NV* = 1/τ
kb_first_order     τs³ + s² + k(1 − NVT)s + kNV = 0 (KB 19)       Routh; NV* = 1/(τ+T) (KB 20)
pade               (18) with Padé(m, m) of e^(−sT)                Routh; axis crossings
exact_delay        τs³ + s² + ks + kNV e^(−sT) = 0 (KB 18)        crossing count, pseudospectral roots
sampled            det(zI − Φ_cl(kNV)) = 0, ZOH                   eigenvalues, Schur–Cohn
=================  ============================================  ==========================
"""

from __future__ import annotations

from .base import Boundary, Loop, LoopModel, verdict_label
from .continuous import Continuous
from .exact_delay import ExactDelay
from .kb_first_order import KBFirstOrder
from .pade import Pade, pade_coefficients
from .sampled import Sampled

__all__ = [
    "MODEL_NAMES",
    "Boundary",
    "Loop",
    "LoopModel",
    "Continuous",
    "KBFirstOrder",
    "Pade",
    "ExactDelay",
    "Sampled",
    "make_model",
    "make_models",
    "pade_coefficients",
    "verdict_label",
]

MODEL_NAMES = ("continuous", "kb_first_order", "pade", "exact_delay", "sampled")


def make_model(name: str, *, pade_order: int = 3, hold: str = "command", compute_delay: int = 0) -> LoopModel:
    """The model called `name`, configured.

    Parameters
    ----------
    name : {"continuous", "kb_first_order", "pade", "exact_delay", "sampled"}
    pade_order : int
        Order m of the ``pade`` model.
    hold, compute_delay
        Structure of the ``sampled`` model (DESIGN §4).

    Raises
    ------
    ValueError
        Unknown name or option.
    """
    from ..checks import check_choice

    check_choice("model", name, MODEL_NAMES)
    if name == "continuous":
        return Continuous()
    if name == "kb_first_order":
        return KBFirstOrder()
    if name == "pade":
        return Pade(pade_order)
    if name == "exact_delay":
        return ExactDelay()
    return Sampled(hold, compute_delay)


def make_models(names=MODEL_NAMES, **options) -> list[LoopModel]:
    """`make_model` for each name, in order."""
    return [make_model(name, **options) for name in names]
