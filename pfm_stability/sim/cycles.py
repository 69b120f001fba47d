"""Growth rates and wall limit cycles of planar runs (docs/simulator.md, "Planar robots").

`lateral_metrics` projects a `planar.PlanarRun` on a direction (the lateral offset
of a corridor or wall run) and hands it to `sim.metrics.oscillation_metrics`, the
one estimator of σ and ω of the package (linear prediction when the run stayed
linear, peaks otherwise).

`wall_cycle` (defined in `sim.planar`, re-exported here) is the non-smooth run of Ge & Cui 2002's velocity-gated repulsion
(GC2002 eq 12, 19) beside one straight wall: parallel to the wall v_RO = 0 and the
repulsion vanishes, so there is no equilibrium to linearise
(`velocity_laws.NonSmoothWall`). A steering robot settles on a relay limit cycle,
a holonomic one comes to rest inside the Filippov band d ≤ d_s
(docs/velocity_and_fuzzy.md). The run is simulated, its first half discarded as
the transient, and the second half measured (`WallCycle`). Many wall runs at once:
`planar.wall_member` for each, `planar.simulate_planar_batch`, `measure_wall_cycle` of each run.
"""

from __future__ import annotations

import numpy as np

from ..checks import check_number, check_type
from .metrics import OscillationMetrics, oscillation_metrics
from .movers import vector
from .planar import REST_TOLERANCE, PlanarRun, Steering, WallCycle, measure_wall_cycle, wall_cycle

__all__ = ["REST_TOLERANCE", "WallCycle", "lateral_metrics", "loop_order", "measure_wall_cycle", "wall_cycle"]

def loop_order(robot, compute_delay: int) -> int:
    """States of the robot's sampled lateral loop, for the linear-prediction fit.

    Point mass and differential drive: 2 (offset and its rate) + compute_delay; steering:
    (τ > 0) + 2 + compute_delay, as the `sampled` loop models count them.

    Parameters
    ----------
    robot : Steering, PointMass or DiffDrive
        The robot (`sim.planar_robots`).
    compute_delay : int
        Samples from measurement to actuation (0 or 1).
    """
    lag = 1 if isinstance(robot, Steering) and robot.tau > 0 else 0
    return 2 + lag + int(compute_delay)


def lateral_metrics(run: PlanarRun, normal, *, point=(0.0, 0.0), window=None, order: int | None = None, robot=None) -> OscillationMetrics:
    """σ, ω (and the rest of `metrics.OscillationMetrics`) of the offset (p − point)·normal of a run.

    Parameters
    ----------
    run : PlanarRun
    normal : 2-vector
        The lateral direction (normalised here).
    point : 2-vector
        Origin of the offset, m.
    window : (float, float), optional
        Times (s) of the measured part; default the whole run.
    order : int, optional
        Lags of the linear-prediction fit; default `loop_order(robot, run.compute_delay)`, or
        2 + compute_delay when no robot is given.
    robot : PointMass, Steering or DiffDrive, optional
    """
    check_type("run", run, PlanarRun, "a PlanarRun")
    n = np.array(vector("normal", normal, unit=True))
    x = (run.p - np.array(vector("point", point))) @ n
    keep = np.ones(run.t.size, dtype=bool)
    if window is not None:
        lo, hi = (check_number("window", w, -1e12, 1e12, unit="s") for w in window)
        keep = (run.t >= lo - 1e-9) & (run.t <= hi + 1e-9)
    if order is None:
        order = loop_order(robot, run.compute_delay) if robot is not None else 2 + run.compute_delay
    collision = next((e.time for e in run.events if e.kind in ("contact", "collision_unavoidable")), None)
    return oscillation_metrics(run.t[keep], x[keep], run.T, order=order, collision_time=collision)
