"""Loop models by name (docs/models.md; the names are `parameters.MODEL_NAMES`).

=================  ============================================  ==========================
name               characteristic equation                       decided by
=================  ============================================  ==========================
continuous         τs³ + s² + ks + kNV = 0 (KB 17)                Routh; NV* = 1/τ
kb_first_order     τs³ + s² + k(1 − NVT)s + kNV = 0 (KB 19)       Routh; NV* = 1/(τ+T) (KB 20)
pade               (18) with Padé(m, m) of e^(−sT)                Routh; axis crossings
exact_delay        τs³ + s² + ks + kNV e^(−sT) = 0 (KB 18)        crossing count, pseudospectral roots
sampled            det(zI − Φ_cl(kNV)) = 0, ZOH                   eigenvalues, Schur–Cohn
=================  ============================================  ==========================

The steering plant's gain g and dead time D (``Loop(…, plant_gain=g, dead_time=D)``,
`Loop.of` takes them from the robot; defaults 1 and 0, KB's robot) make the loop's
steering gain g·k and the continuous-time models' delay T + D; the sampled model
carries the commands on their way (docs/models.md, "Plant gain and dead time").

A heading gain c (``Loop(tau, T, k, c=…)``, default 0) turns the gain term kNV
into k(cs + NV) in every model (docs/models.md, "The heading gain"); NV < 0 is
unstable in every model (`divergent_reason`); at NV = 0 every model judges its
heading loop, the roots other than the neutral lateral one (`neutral_reason`).

Every model also decides the holonomic robot's loop s² + (c_h s + κ)e^(−sT)
(`models.holonomic.HolonomicLoop`, docs/models.md "Robot loop families"): a loop
is a `Characteristic`, a(s) + (δ·s + K)·e^(−sT), and each model reads it through
that interface only; `STEERING` and `models.holonomic.HOLONOMIC` name each
family's gain and equations (`LoopFamily.describe`).
"""

from __future__ import annotations

from ..checks import check_choice
from ..parameters import MODEL_NAMES, Controller
from .base import LoopModel
from .loop import HEADING_GAIN_RANGE, STEERING, Boundary, Loop
from .continuous import Continuous
from .exact_delay import ExactDelay
from .family import Characteristic, LoopFamily
from .kb_first_order import KBFirstOrder
from .pade import Pade, pade_coefficients
from .sampled import Sampled
from .verdicts import (DIVERGENT_REASON, NEUTRAL_REASON, check_loop_gain, critical_speed, divergent_reason, gain_margin, interval_margin,
                       interval_verdict, judge, judge_arrays, neutral_reason, verdict_label)

__all__ = [
    "MODEL_NAMES",
    "DIVERGENT_REASON",
    "HEADING_GAIN_RANGE",
    "NEUTRAL_REASON",
    "STEERING",
    "Boundary",
    "Characteristic",
    "Loop",
    "LoopFamily",
    "LoopModel",
    "Continuous",
    "KBFirstOrder",
    "Pade",
    "ExactDelay",
    "Sampled",
    "check_loop_gain",
    "critical_speed",
    "divergent_reason",
    "judge",
    "judge_arrays",
    "gain_margin",
    "interval_margin",
    "interval_verdict",
    "make_model",
    "make_models",
    "models_for",
    "neutral_reason",
    "pade_coefficients",
    "verdict_label",
]


def make_model(name: str, *, pade_order: int = 3, hold: str = "command", compute_delay: int = 0) -> LoopModel:
    """The model called `name`, configured.

    Parameters
    ----------
    name : str
        One of `MODEL_NAMES` (``continuous``, ``kb_first_order``, ``pade``, ``exact_delay``, ``sampled``).
    pade_order : int
        Order m of the ``pade`` model.
    hold, compute_delay
        Structure of the ``sampled`` model (docs/models.md).

    Raises
    ------
    ValueError
        Unknown name or option.
    """
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


def make_models(names=MODEL_NAMES, *, controller=None, **options) -> list[LoopModel]:
    """`make_model` for each name, in order.

    With `controller`, the ``sampled`` model takes the controller's hold and
    compute delay (giving ``hold``/``compute_delay`` as well is an error).

    Parameters
    ----------
    names : list or tuple of str
        Model names (`parameters.MODEL_NAMES`).
    controller : Controller, optional
        Gives ``sampled`` its hold and compute delay.
    **options
        Passed to `make_model` (``pade_order``, ``hold``, ``compute_delay``).
    """
    if isinstance(names, str) or not isinstance(names, (list, tuple)) or not all(isinstance(n, str) for n in names):
        raise ValueError(f"names must be a list or tuple of model names ({', '.join(MODEL_NAMES)}); got {names!r}")
    if controller is not None:
        if not isinstance(controller, Controller):
            raise ValueError(f"controller must be a Controller; got {controller!r}")
        if "hold" in options or "compute_delay" in options:
            raise ValueError("hold and compute_delay come from the controller; do not give them as well")
        options = dict(options, hold=controller.hold, compute_delay=controller.compute_delay)
    return [make_model(name, **options) for name in names]


def models_for(controller, models=None, *, pade_order: int = 3) -> list[LoopModel]:
    """The models an analysis of this controller runs, consistent with it.

    Parameters
    ----------
    controller : Controller
        Its ``hold`` and ``compute_delay`` are the one source of truth for the
        ``sampled`` model.
    models : iterable of str or LoopModel, optional
        Names are built for the controller; a ``Sampled`` object must match
        the controller. Default: every model.
    pade_order : int
        Order of a ``pade`` model built by name.

    Raises
    ------
    ValueError
        A ``Sampled`` model whose structure contradicts the controller, or an
        unknown name.
    """
    if not isinstance(controller, Controller):
        raise ValueError(f"controller must be a Controller; got {controller!r}")
    if models is None:
        models = MODEL_NAMES
    if isinstance(models, (str, LoopModel)) or not isinstance(models, (list, tuple)):
        raise ValueError(f"models must be a list or tuple of model names or LoopModel objects; got {models!r}")
    out = []
    for model in models:
        if isinstance(model, str):
            model = make_model(model, pade_order=pade_order, hold=controller.hold, compute_delay=controller.compute_delay)
        elif not isinstance(model, LoopModel):
            raise ValueError(f"models must hold model names or LoopModel objects; got {model!r}")
        elif isinstance(model, Sampled) and (model.hold, model.compute_delay) != (controller.hold, controller.compute_delay):
            raise ValueError(
                f"models: {model!r} contradicts the controller (hold={controller.hold!r}, "
                f"compute_delay={controller.compute_delay}); the controller decides how the loop is sampled"
            )
        out.append(model)
    return out
