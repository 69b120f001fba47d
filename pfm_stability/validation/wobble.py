"""The simulated wobble: a corridor (or wall) robot's limit cycle measured by the VFF simulator, to check `analysis.wobble` (docs/wobble.md).

Each `WobbleCase` is one robot in the middle of a corridor started at a lateral offset;
the batched simulator (`sim.engine.run_batch`) runs them together and `measure_wobble`
reads the settled motion: the half peak-to-peak lateral amplitude over the last part of
the run, its frequency by the one estimator of the package (`sim.metrics.oscillation_metrics`
on that part), whether it is steady, and whether the robot touched a wall.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..parameters import Controller, Robot
from ..sim.engine import run_batch
from ..sim.metrics import oscillation_metrics
from ..sim.presets import make_scenario
from ..sim.scenario import scenario_law

__all__ = ["WobbleCase", "MeasuredWobble", "case_law", "measure_wobble", "simulate_wobbles", "STEADY"]

STEADY = 0.03
"""A cycle is steady when the amplitudes of the two halves of the measured tail differ by at most this fraction."""


@dataclass(frozen=True)
class WobbleCase:
    """One simulated corridor run.

    Attributes
    ----------
    robot : Robot
        V, τ, k, W, `max_steering_rate`.
    controller : Controller
        f, n, T, hold, compute delay.
    L : float
        Half-width, m.
    offset : float
        Start offset from the centre line, m.
    duration : float
        Simulated time, s.
    env : {"analytic", "grid"}
        Continuous walls or a histogram grid.
    law : {"power", "grid"}
        The analytic walls' law (``env="grid"``: the grid itself, whose averaged law is "grid").
    alpha : float or None
        Beside a wall: the target angle from its normal, rad (`L` unused; the offset from d0, positive away from the
        wall); None: the corridor.
    """

    robot: Robot
    controller: Controller
    L: float
    offset: float
    duration: float
    env: str = "analytic"
    law: str = "power"
    alpha: float | None = None


@dataclass(frozen=True)
class MeasuredWobble:
    """What the simulator shows at the end of one run.

    Attributes
    ----------
    amplitude : float
        Half peak-to-peak lateral offset over the measured tail, m.
    omega : float or None
        Its angular frequency, rad/s (None without turning points).
    steady : bool
        The two halves of the tail have amplitudes within `STEADY` of each other.
    collided : bool
        The robot touched a wall.
    """

    amplitude: float
    omega: float | None
    steady: bool
    collided: bool


def case_law(case: WobbleCase):
    """The lateral law the prediction takes for `case`: the simulator's own (`sim.scenario.scenario_law`).

    Parameters
    ----------
    case : WobbleCase
        The run.
    """
    if case.env == "grid":
        return scenario_law("grid", case.robot, case.controller)
    return scenario_law("analytic", case.robot, case.controller, law=case.law)


def measure_wobble(t, x, T: float, *, collided: bool, tail: float = 0.3) -> MeasuredWobble:
    """The settled wobble of a lateral offset x(t) sampled every T: amplitude, frequency, steadiness over the last `tail`.

    Parameters
    ----------
    t : array_like
        Sample times, s.
    x : array_like
        Lateral offset, m.
    T : float
        Sampling period, s.
    collided : bool
        Whether the run ended at a wall.
    tail : float
        Fraction of the run measured (its end).
    """
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    keep = t >= t[-1] - tail * (t[-1] - t[0])
    tt, xx = t[keep], x[keep]
    half = tt.size // 2
    amplitude = 0.5 * float(np.ptp(xx))
    first, second = 0.5 * float(np.ptp(xx[:half])), 0.5 * float(np.ptp(xx[half:]))
    steady = bool(abs(second - first) <= STEADY * max(first, second)) if max(first, second) > 0 else True
    omega = oscillation_metrics(tt, xx, T).angular_frequency if amplitude > 0 else None
    return MeasuredWobble(amplitude, omega, steady, collided)


def simulate_wobbles(cases) -> tuple:
    """Run every case together (one batch) and measure each (`measure_wobble`).

    Parameters
    ----------
    cases : sequence of WobbleCase
        The runs.

    Returns
    -------
    tuple of MeasuredWobble
        In the order of `cases`.
    """
    scenarios = [
        make_scenario("corridor" if c.alpha is None else "wall", robot=c.robot, controller=c.controller, env=c.env, offset=c.offset,
                      duration=c.duration, **({"L": c.L} if c.alpha is None else {"alpha": c.alpha}),
                      **({"law": c.law} if c.env == "analytic" else {}))
        for c in cases
    ]
    batch = run_batch(scenarios, record="offset", metrics=False)
    out = []
    for case, run in zip(cases, batch.runs):
        collided = any(e.type == "collision" for e in run.events)
        out.append(measure_wobble(run.offset_t, run.offset, case.controller.T, collided=collided))
    return tuple(out)
