"""The discrete gradient-step planner: constant speed, the force sets the direction.

A planner that moves the robot a step h = VT per cycle in the direction δ of
the field's force (docs/models.md, "Robot loop families") moves its lateral
coordinate by x_{k+1} = x_k + h·sin δ_k. Linearised about an equilibrium x0
where δ ≈ −N·(x − x0) (N: the environment gain, 1/m, as in KB's loop),

    x_{k+1} − x0 = (1 − hN)·(x_k − x0),

so the deviation is multiplied by 1 − hN each step:

==============  =====================  =========================================
hN              regime                 the deviation
==============  =====================  =========================================
< 0 (N < 0)     divergent              grows without changing sign
(0, 1)          monotone               shrinks without changing sign
1               deadbeat               is gone after one step
(1, 2)          zig-zag                shrinks, changing sign every step
2               neutral                keeps its size, changing sign every step
> 2             divergent              grows, changing sign every step
==============  =====================  =========================================

The critical step is h* = 2/N (the planner zig-zags without settling from
there on); with N < 0 no step converges (h* = 0).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..checks import check_number
from ..parameters import check_parameter

__all__ = ["BOUNDARY_RTOL", "PLANNER_REGIMES", "GradientStep", "gradient_step"]

BOUNDARY_RTOL = 1e-12
"""hN within this relative distance of 1 or 2 is "deadbeat" or "neutral" (round-off of h = 2/N·N)."""

PLANNER_REGIMES = ("monotone", "deadbeat", "zig-zag", "neutral", "divergent")


@dataclass(frozen=True)
class GradientStep:
    """The linearised gradient-step planner x_{k+1} − x0 = (1 − hN)(x_k − x0).

    Attributes
    ----------
    step : float
        h = VT, m.
    N : float
        Environment gain, 1/m.
    factor : float
        1 − hN: the deviation's factor per step.
    regime : str
        One of `PLANNER_REGIMES`.
    critical_step : float
        h* = 2/N, m (0 when N < 0: no step converges).
    """

    step: float
    N: float
    factor: float
    regime: str
    critical_step: float


def gradient_step(h, N) -> GradientStep:
    """Regime and critical step of the gradient-step planner at step h and gain N.

    Parameters
    ----------
    h : float
        Step h = VT, m, > 0 (``RANGES["step"]``).
    N : float
        Environment gain, 1/m, finite and non-zero (N = 0: no restoring field).

    Returns
    -------
    GradientStep
    """
    h = check_parameter("step", h)
    N = check_number("N", N, unit="1/m")
    if N == 0.0:
        raise ValueError("N must be a finite non-zero number 1/m (N = 0: no force gradient, the planner drifts); got 0.0")
    hN = h * N
    if hN < 0:
        regime = "divergent"
    elif abs(hN - 1.0) <= BOUNDARY_RTOL:
        regime = "deadbeat"
    elif abs(hN - 2.0) <= 2.0 * BOUNDARY_RTOL:
        regime = "neutral"
    else:
        regime = "monotone" if hN < 1.0 else "zig-zag" if hN < 2.0 else "divergent"
    return GradientStep(h, N, 1.0 - hN, regime, 2.0 / N if N > 0 else 0.0)
