"""Library entry points: one run, or a batch of parameter sets as arrays.

`simulate_batch` is what sweeps and the validation's bisections use: every
robot, controller and scenario parameter may be a scalar or a 1-D array,
broadcast to a common batch size, and each member is the named scenario
built with that member's values (`pfm_stability.sim.presets.make_scenario`).
Members with equal geometry share one compiled grid.
"""

from __future__ import annotations

import numpy as np

from ..checks import check_choice
from ..parameters import CARMEL, Controller, Robot
from .engine import RECORD_MODES, run_batch
from .presets import make_scenario
from .results import BatchResult, RunResult
from .scenario import Scenario

__all__ = ["simulate", "simulate_batch", "batch_scenarios", "ROBOT_PARAMETERS", "CONTROLLER_PARAMETERS", "SCENARIO_PARAMETERS"]

ROBOT_PARAMETERS = ("V", "tau", "k", "W", "max_steering_rate", "dead_time", "plant_gain")
CONTROLLER_PARAMETERS = ("f", "n", "T", "hold", "compute_delay")
SCENARIO_PARAMETERS = (
    "L", "alpha", "offset", "duration", "cell_ratio", "law", "window_cells", "cell_size",
    "speed_law", "seed", "start_jitter", "damping",
)


def simulate(scenario, *, record: str = "trajectory", progress=None, **options) -> RunResult:
    """Simulate one run.

    Parameters
    ----------
    scenario : Scenario or str
        A `Scenario`, or a scenario name built with `options` by
        `make_scenario` (``robot=``, ``controller=``, ``env=``, ``L=``, …).
    record : {"trajectory", "offset"}
    progress : callable, optional
        ``progress(step, total)`` every 1024 samples (`run_batch`).

    Returns
    -------
    RunResult
    """
    if not isinstance(scenario, Scenario):
        scenario = make_scenario(scenario, **options)
    elif options:
        raise ValueError("options apply to a scenario name, not to a Scenario object")
    return run_batch([scenario], record=record, progress=progress).runs[0]


def _broadcast(parameters: dict) -> tuple[int, dict]:
    sizes = {name: np.size(v) for name, v in parameters.items() if np.ndim(v) > 0}
    for name, v in parameters.items():
        if np.ndim(v) > 1:
            raise ValueError(f"{name} must be a scalar or a 1-D array; got shape {np.shape(v)}")
    distinct = set(sizes.values())
    if len(distinct) > 1:
        raise ValueError(f"parameter arrays must have one length; got {sizes}")
    B = distinct.pop() if distinct else 1
    if B == 0:
        raise ValueError("parameter arrays must not be empty")
    out = {}
    for name, v in parameters.items():
        out[name] = list(np.asarray(v, dtype=object).ravel()) if np.ndim(v) > 0 else [v] * B
    return B, out


def _plain(v):
    """numpy scalars → Python numbers (the dataclasses' checks reject nothing numeric, but keep JSON clean)."""
    return v.item() if isinstance(v, np.generic) else v


def simulate_batch(
    scenario: str,
    *,
    env: str = "grid",
    robot: Robot | None = None,
    controller: Controller | None = None,
    record: str = "offset",
    metrics: bool = True,
    progress=None,
    **parameters,
) -> BatchResult:
    """Simulate a named scenario for many parameter sets at once.

    Parameters
    ----------
    scenario : str
        A name of `pfm_stability.sim.presets.SCENARIO_NAMES`.
    env : {"grid", "analytic"}
    robot, controller : Robot, Controller
        Base values (default CARMEL); any of their fields may be overridden
        per member below.
    record : {"offset", "trajectory"}
    metrics : bool
    progress : callable, optional
        ``progress(step, total)`` every 1024 samples (`run_batch`).
    **parameters
        Scalars or equal-length 1-D arrays, one entry per member:
        robot fields ``V, tau, k, W, max_steering_rate, dead_time, plant_gain``; controller fields
        ``f, n, T, hold, compute_delay``; scenario options ``L, alpha`` (rad),
        ``offset, duration, cell_ratio, law, window_cells, cell_size,
        speed_law, seed, start_jitter`` (see `make_scenario`).

    Returns
    -------
    BatchResult
        ``.stable`` (the runs that settled), ``.oscillating``, ``.collided`` (bool arrays),
        ``.growth_rate``, ``.angular_frequency`` (masked arrays) and
        ``.runs[i]`` (events, metrics, inputs) in member order.

    Examples
    --------
    >>> r = simulate_batch("corridor", env="analytic", L=[0.8, 0.9, 1.0], offset=1e-4, duration=15)
    >>> r.stable
    array([False,  True,  True])
    """
    check_choice("record", record, RECORD_MODES)
    scenarios = batch_scenarios(scenario, env=env, robot=robot, controller=controller, **parameters)
    return run_batch(scenarios, record=record, metrics=metrics, progress=progress)


def batch_scenarios(scenario: str, *, env: str = "grid", robot: Robot | None = None, controller: Controller | None = None, **parameters) -> list:
    """The member scenarios `simulate_batch` runs for these arguments (nothing is simulated).

    Parameters
    ----------
    scenario : str
        A name of `pfm_stability.sim.presets.SCENARIO_NAMES`.
    env : {"grid", "analytic"}
        The environment's kind.
    robot, controller : Robot, Controller, optional
        Base values (default CARMEL), overridden per member by `parameters` as in `simulate_batch`.

    Returns
    -------
    list of Scenario
        One per member, in order; members with equal robots and controllers share them.
    """
    known = set(ROBOT_PARAMETERS) | set(CONTROLLER_PARAMETERS) | set(SCENARIO_PARAMETERS)
    for name in parameters:
        if name not in known:
            raise ValueError(f"unknown parameter {name!r}; known: {', '.join(sorted(known))}")
    robot = robot if robot is not None else CARMEL.robot
    controller = controller if controller is not None else CARMEL.controller
    B, values = _broadcast(parameters)
    scenarios = []
    robots, controllers = {}, {}
    for m in range(B):
        member = {name: _plain(v[m]) for name, v in values.items()}
        r_changes = {n: member.pop(n) for n in ROBOT_PARAMETERS if n in member}
        c_changes = {n: member.pop(n) for n in CONTROLLER_PARAMETERS if n in member}
        key_r, key_c = tuple(sorted(r_changes.items())), tuple(sorted(c_changes.items()))
        if key_r not in robots:
            robots[key_r] = robot.replace(**r_changes)
        if key_c not in controllers:
            controllers[key_c] = controller.replace(**c_changes)
        scenarios.append(make_scenario(scenario, robot=robots[key_r], controller=controllers[key_c], env=env, **member))
    return scenarios
