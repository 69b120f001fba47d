"""The linear-stability verdict of a simulated run: what the loop models predict.

Two questions, two names:

* **settled** — `OscillationMetrics.stable` (and `BatchResult.stable`): the
  run ended without a collision, neither grows nor keeps a limit cycle, and
  decays (σ < 0) when σ is defined. It describes the run as a robot would
  behave (docs/simulator.md, measuring oscillation). A slowly *decaying*
  run whose swings change by less than 10 % over the second half of the
  window is flagged as a limit cycle and is not "stable" in this sense.
* **linearly stable** — `simulated_verdict` / `linearly_stable`: the sign of
  the measured growth rate σ (σ from the linear-prediction fit, exact in the
  linear regime), a collision being unstable. This is the quantity the loop
  models predict (they have no limit cycle), so every comparison of the
  simulator with the models (`pfm_stability.validation`) uses it; with the
  settled flag, near the boundary a slow decay (|σ| ≲ ln 1.1/(duration/2))
  would be called unstable and every bisected boundary biased towards the
  stable side (docs/validation.md).

Where σ is undefined (too few turning points and a rejected linear fit) the
verdict falls back on the settled flag, which is explicit there
(`pfm_stability.sim.metrics`): a run with fewer than 8 samples in its window
(unmeasurable) or whose offset is not settling (a drift) is unstable, a
constant or decaying one stable; a collision (also between samples, `pfm_stability.sim.contact`) is
unstable in both senses.
"""

from __future__ import annotations

import numpy as np

__all__ = ["linearly_stable", "simulated_verdict"]


def simulated_verdict(run) -> tuple[str, str]:
    """(verdict, basis) of one simulated run: "stable" or "unstable" in the linear sense, and why.

    A collision is unstable; otherwise the sign of the measured growth rate σ
    (linear stability, what the loop models predict); when σ is undefined (too
    few turning points and a rejected linear fit) the run's settled flag
    `OscillationMetrics.stable` decides.

    Parameters
    ----------
    run : RunResult
        One simulated run.

    Returns
    -------
    (str, str)
        Verdict, and its basis: ``"collision"``, ``"growth_rate"`` or ``"metrics"``.
    """
    if run.collided:
        return "unstable", "collision"
    m = run.metrics
    if m is None:
        raise ValueError("run has no metrics: simulate with metrics=True")
    if m.growth_rate is not None:
        return ("stable" if m.growth_rate < 0 else "unstable"), "growth_rate"
    return ("stable" if m.stable else "unstable"), "metrics"


def linearly_stable(result) -> np.ndarray:
    """`simulated_verdict` == "stable" for every member of a `BatchResult` (bool array).

    Not `BatchResult.stable` (the runs that settled): see the module docstring.

    Parameters
    ----------
    result : BatchResult
        The simulated batch.
    """
    return np.array([simulated_verdict(run)[0] == "stable" for run in result.runs], dtype=bool)
